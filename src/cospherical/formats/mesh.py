"""Files of ``cospherical mesh``: the leaf list it reads, the VTU mesh and the JSON report it writes.

Leaf list (``--leaves FILE``), one leaf per entry, ``level i j k``: the cell at
``level`` with integer position ``(i, j, k)``, ``0 <= i, j, k < 2**level`` (the box
``[i, i+1] x [j, j+1] x [k, k+1]`` times the domain lengths over ``2**level``).
Either JSON, ``{"leaves": [[level, i, j, k], ...]}`` (or the bare list), or text,
one leaf per line as four integers, blank lines and ``#`` comments ignored::

    # the domain refined once: eight leaves of level 1
    1 0 0 0
    1 1 0 0
    ...

The report is JSON, validated against ``schemas/mesh-report.schema.json`` before
it is written.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..core.configuration import POINT_POLICIES, Box, Configuration
from ..errors import FormatError, InputError
from ..files.yamlio import atomic_write, check_nesting, read_text, validate
from ..mesh.assembly import Lookup, Mesh
from .vtu import write_meshio

__all__ = ["REPORT_SCHEMA_VERSION", "read_leaves", "report_json", "table_lookup", "to_meshio", "write_report",
           "write_vtu"]

REPORT_SCHEMA_VERSION = 1
MAX_LEAF_FILE = 2 * 1024**3


def read_leaves(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Levels and positions of a leaf list (JSON or text); a malformed file raises :class:`FormatError`.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.NamedTemporaryFile("w", suffix=".txt", delete=False) as f:
    ...     _ = f.write("# one leaf\\n0 0 0 0\\n")
    >>> levels, positions = read_leaves(f.name); os.unlink(f.name)
    >>> levels.tolist(), positions.tolist()
    ([0], [[0, 0, 0]])
    """
    path = Path(path)
    text = read_text(path, MAX_LEAF_FILE)
    stripped = text.lstrip()
    rows = []
    if stripped.startswith(("{", "[")):
        check_nesting(text, str(path))
        try:
            data = json.loads(text)
        except json.JSONDecodeError as error:
            raise FormatError(f"{path}: line {error.lineno}: not valid JSON: {error.msg}") from None
        leaves = data.get("leaves") if isinstance(data, dict) else data
        if not isinstance(leaves, list):
            raise FormatError(f'{path}: expected {{"leaves": [[level, i, j, k], ...]}}')
        for n, leaf in enumerate(leaves):
            if not (isinstance(leaf, list) and len(leaf) == 4
                    and all(isinstance(x, int) and not isinstance(x, bool) for x in leaf)):
                raise FormatError(f"{path}: leaf {n}: {json.dumps(leaf)[:60]} is not [level, i, j, k] (four integers)")
            rows.append(leaf)
    else:
        for number, line in enumerate(text.splitlines(), 1):
            content = line.split("#", 1)[0].split()
            if not content:
                continue
            if len(content) != 4 or not all(x.lstrip("-").isascii() and x.lstrip("-").isdigit() for x in content):
                raise FormatError(f"{path}: line {number}: {line.strip()[:60]!r} is not 'level i j k' (four integers)")
            rows.append([int(x) for x in content])
    if not rows:
        raise FormatError(f"{path}: no leaves")
    if any(abs(x) >= 2**40 for row in rows for x in row):
        raise FormatError(f"{path}: a number is out of range")
    array = np.array(rows, dtype=np.int64)
    return array[:, 0], array[:, 1:]


def table_lookup(table, criterion: str, box: Box, name: str = "pattern table") -> Lookup:
    """A lookup for :func:`cospherical.mesh.assembly.assemble` reading a pattern table.

    The table is asked for the leaf's whole-point-set code (``800000000000+f``), and
    where its header names a point policy, for the bare edge code when that policy
    gives the same point set.  The table's box must have the domain's proportions
    (every leaf is the domain scaled down).
    """
    header = getattr(table, "header", None) or {}
    if "criteria" in header and criterion not in header["criteria"]:
        raise InputError(f"{name}: no {criterion!r} elements (it has {', '.join(header['criteria'])})")
    if "box" in header:
        theirs = Box.parse(header["box"]).squared
        ours = box.squared
        if any(theirs[a] * ours[0] != ours[a] * theirs[0] for a in range(3)):
            raise InputError(f"{name}: its box {' x '.join(header['box'])} is not shaped like the domain "
                             f"{' x '.join(box.texts)}: its tessellations are not the leaves'")
    policy = header.get("face_points", "octree")

    def lookup(configuration: Configuration):
        code = configuration.point_set_code
        try:
            return table.elements(code, criterion)
        except KeyError:
            pass
        digits = code.split("+")[0]
        if policy in POINT_POLICIES and \
                Configuration.from_code(digits, configuration.box, policy).point_set_code == code:
            try:
                return table.elements(digits, criterion)
            except KeyError:
                return None
        return None

    return lookup


def to_meshio(mesh: Mesh):
    """The mesh as a :class:`meshio.Mesh` in real coordinates.

    Standard VTK cells (tetra, pyramid, wedge, hexahedron) when every element has
    one, else every element as a polyhedron with its faces (VTU cannot mix them).
    Cell data: ``type`` (index into the sorted type ids, listed in the report),
    ``type_hash`` (the type id's 6 hex digits as an integer), ``leaf`` and ``fvm``
    (its circumcenter lies in its closed leaf).
    """
    import meshio

    points = mesh.vertices * (np.array(mesh.box.to_float()) / mesh.grid)
    ids, element_type = mesh.element_types()
    hashes = np.array([int(t.rsplit("-", 1)[1], 16) for t in ids], dtype=np.int64)
    fvm = mesh.element_fvm()
    vtk = [mesh.types.get(t, {}).get("vtk") for t in ids]
    conn, sizes = mesh.connectivity()
    cells, data = [], {"type": [], "type_hash": [], "leaf": [], "fvm": []}

    def block(rows: np.ndarray):
        data["type"].append(element_type[rows])
        data["type_hash"].append(hashes[element_type[rows]])
        data["leaf"].append(mesh.element_leaf[rows].astype(np.int64))
        data["fvm"].append(fvm[rows].astype(np.int8))

    if all(vtk):
        kinds = np.array(vtk, dtype=object)[element_type]
        for kind in sorted(set(vtk)):
            rows = np.flatnonzero(kinds == kind)
            width = int(sizes[rows[0]])
            cells.append(meshio.CellBlock(kind, conn[rows, :width].astype(np.int64)))
            block(rows)
    else:
        element_faces: list = [None] * len(mesh)  # per element, its faces in global ids
        for _, pattern, leaves in mesh.groups():
            first = mesh.element_offsets[leaves]
            slots = mesh.slots[leaves]
            for j, element in enumerate(pattern.elements):
                local = [slots[:, list(cycle)] for cycle in element.faces]
                for n, e in enumerate((first + j).tolist()):
                    element_faces[e] = [f[n] for f in local]
        for width in sorted(set(sizes.tolist())):
            rows = np.flatnonzero(sizes == width)
            cells.append(meshio.CellBlock(f"polyhedron{width}", [element_faces[e] for e in rows.tolist()]))
            block(rows)
    return meshio.Mesh(points, cells, cell_data=data)


def write_vtu(mesh: Mesh, path: str | Path) -> None:
    """Write the mesh as VTU, atomically (a complete new file or the old one)."""
    write_meshio(to_meshio(mesh), path)


def report_json(report: dict) -> str:
    """The report as JSON text (deterministic), validated against its schema."""
    validate(report, "mesh-report", "mesh report")
    return json.dumps(report, indent=1) + "\n"


def write_report(report: dict, path: str | Path) -> None:
    atomic_write(path, report_json(report))
