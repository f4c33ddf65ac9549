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

import hashlib
import itertools
import json
import os
import re
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from collections.abc import Iterator, Mapping
from typing import TYPE_CHECKING, Any, Sequence, TypedDict

import numpy as np

from ..catalogue import Catalogue
from ..choices import POINT_POLICIES
from ..core.configuration import Box, Configuration
from ..errors import FormatError, InputError
from ..files.yamlio import (atomic_write, parse_json, parse_yaml, read_bytes, read_text, utf8_text, validate,
                              validated_data)
from ..mesh.assembly import Lookup, Mesh
from ..mesh.octree import check_leaf_count, leaf_bound
from .patterns import Entries, PatternTable, load, table_from_text
from .sqlite_store import is_store
from .vtu import quoteattr

if TYPE_CHECKING:  # imported where used: a device's modules, the threads (deflate), the symmetries (a table lacks one)
    from concurrent.futures import Executor

    from ..core.symmetry import Symmetry
    from ..mesh.regions import RegionFaces
    from .check import EntryCheck

__all__ = ["CHECKED_TABLES", "MAX_LEAF_DIGITS", "REPORT_SCHEMA_VERSION", "SortedLines", "checked_table", "load_table", "orbit_lookup", "read_leaves", "report_json", "table_lookup", "VtuGrid", "vtu_arrays", "vtu_grid",
           "write_faces_vtu",
           "write_piece", "write_pvtu", "write_report", "write_vtu"]

REPORT_SCHEMA_VERSION = 1
_MAX_LEAF_FILE = 2 * 1024**3
# A level is at most MAX_LEVEL and a position below 2**MAX_LEVEL: a longer number is out of
# range whatever its value, and int() of thousands of digits is slow and then refused.
MAX_LEAF_DIGITS = 12
_LEAF_NUMBER = re.compile(rf"-?[0-9]{{1,{MAX_LEAF_DIGITS}}}")
_LONG_NUMBER = re.compile(rf"[0-9]{{{MAX_LEAF_DIGITS + 1},}}")


def read_leaves(path: str | Path, max_leaves: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Levels and positions of a leaf list (JSON or text); a malformed file raises :class:`FormatError`.

    More leaves than a mesh may have (``max_leaves``, default
    :func:`~cospherical.mesh.octree.leaf_bound`) are refused from a count of the
    file's lines (or brackets) before any is parsed, and each number must be a
    plain integer of at most :data:`MAX_LEAF_DIGITS` digits, so a hostile file
    costs the time of reading it.

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
    bound = leaf_bound() if max_leaves is None else max_leaves
    # a leaf takes at least 8 bytes ("0 0 0 0\\n"); a line of a hand-written list rarely more than 64
    most = min(_MAX_LEAF_FILE, 64 * bound + 4096)
    try:
        size = os.stat(path).st_size
    except OSError:
        size = 0  # the reader says why it cannot read it
    if size > most:
        raise FormatError(f"{path}: {size:,} bytes, more than a list of {bound:,} leaves (the bound; "
                          f"--max-leaves N sets it) takes at 64 bytes a leaf")
    text = read_text(path, most)
    stripped = text.lstrip()
    if stripped.startswith(("{", "[")):
        # every leaf opens a bracket: count them before the parser builds a list per leaf
        check_leaf_count(text.count("[") - 1, f"{path}: up to", bound)
        long = _LONG_NUMBER.search(text)
        if long:
            raise FormatError(f"{path}: a number of {len(long.group(0)):,} digits (at most {MAX_LEAF_DIGITS})")
        data = parse_json(text, str(path))
        leaves = data.get("leaves") if isinstance(data, dict) else data
        if not isinstance(leaves, list):
            raise FormatError(f'{path}: expected {{"leaves": [[level, i, j, k], ...]}}')
        # the types of all numbers at once (a loop per leaf costs seconds on millions); the first bad leaf named
        if not all(type(leaf) is list and len(leaf) == 4 for leaf in leaves) \
                or set(map(type, itertools.chain.from_iterable(leaves))) - {int}:
            n, leaf = next((n, leaf) for n, leaf in enumerate(leaves) if not (
                type(leaf) is list and len(leaf) == 4 and all(type(x) is int for x in leaf)))
            raise FormatError(f"{path}: leaf {n}: {json.dumps(leaf)[:60]} is not [level, i, j, k] (four integers)")
        rows = leaves
    else:
        # lines bound the leaves: a file of more lines than the bound is refused before any is read
        lines = text.count("\n") + (not text.endswith("\n"))
        check_leaf_count(lines, f"{path}: {lines:,} lines, so up to", bound)
        rows = []
        for number, line in enumerate(text.splitlines(), 1):
            content = line.split("#", 1)[0].split()
            if not content:
                continue
            if len(content) != 4 or not all(_LEAF_NUMBER.fullmatch(x) for x in content):
                raise FormatError(f"{path}: line {number}: {line.strip()[:60]!r} is not 'level i j k' "
                                  f"(four integers of at most {MAX_LEAF_DIGITS} digits)")
            rows.append([int(x) for x in content])
    if not rows:
        raise FormatError(f"{path}: no leaves")
    array = np.array(rows, dtype=np.int64)  # every number below 10**MAX_LEAF_DIGITS: int64 holds it
    return array[:, 0], array[:, 1:]


# The committed pattern tables (patterns/*.yaml) by the SHA-256 of their bytes, each with the version of the
# catalogue it was checked against: every entry of each, under every criterion, passes ``cospherical check``
# (run on all of them when a table is added or regenerated; tests/formats/test_mesh.py holds this list to the
# files, the tests check every type and a sample of entries of each, ``--full`` every entry).  Such a table's
# entries are proven: the mesher need not hold them to ``check``'s rules again (``--check all`` still does).
CHECKED_TABLES: dict[str, tuple[str, str]] = {
    "3dca5c535acbd5341cda50ff917d087f478a171449a1079181094a71e1229189": ("bisection-1x1.4142x1.4142.yaml",
                                                                         "0c8dbfebf3fd"),
    "1700ace6e1ff991052ea554630497ddb00de6a1e665844d0d968914c0f812956": ("bisection-1x1x1.yaml", "0c8dbfebf3fd"),
    "a93dc3d00f34f6efd7efd887b34738f496d3b466ca21e6e72373b915b6a7c559": ("bisection-1x2x4.yaml", "0c8dbfebf3fd"),
    "7292147952d09c2a89826d3bc8c33abde7fa802b9bcd6c40255984ed7c67dff0": ("bisection-1xsqrt2xsqrt2.yaml",
                                                                         "0c8dbfebf3fd"),
    "ec496b27310d0dc17575d9473879800828e4cb1505e8d9ada3ed40e43a2e9c93": ("bisection-prism-1x1x1.yaml",
                                                                         "0c8dbfebf3fd"),
    "4ce1e5fbad84617c22bebd1e947c2b29de238a923bf1012784d7a5e666d88b22": ("bisection-pyramid-1x1x1.yaml",
                                                                         "0c8dbfebf3fd"),
    "55dbe744f8f656ea555dfb19344b262b15fce263ce22da461befc32246f0ecf2": ("bisection-tetrahedron-1x1x1.yaml",
                                                                         "0c8dbfebf3fd"),
    "3fc551314021aaeaa641f0c133fb26c04defa582b40c85f7ae3a9b3f404ffe23": ("leaves-1x1x1.yaml", "0c8dbfebf3fd"),
    "cd33fe2c1f9ef63c4eda3f699695b10245248f2ba91a91889b6182cab64b66a1": ("leaves-1x2x4.yaml", "0c8dbfebf3fd"),
}


def load_table(path: str | Path) -> tuple[PatternTable, str | None]:
    """:func:`cospherical.formats.patterns.load`, and the SHA-256 of the bytes it parsed (``None`` for an
    indexed store, which is read a configuration at a time): see :func:`checked_table`.

    A committed table's bytes (:data:`CHECKED_TABLES`) are read as :class:`SortedLines`: its header as
    :func:`~cospherical.formats.patterns.table_from_text` reads and validates it (the data kept once
    validated), each entry found when asked for, instead of the whole section cut into entries (~20 ms
    of a 9 MB table's reading); the same entries.
    """
    if is_store(path):
        return load(path), None
    data = read_bytes(path)
    digest = hashlib.sha256(data).hexdigest()
    if digest in CHECKED_TABLES:  # UTF-8 throughout (its digest says so): each part decoded as it is read
        lines = SortedLines(data)
        # the header as table_from_text reads it (the text before "configurations:"), validated with no entries
        # by the schema; its data kept as the schema validators are (files.yamlio.validated_data): no YAML parser
        header_text = data[:lines.start - len(b"configurations:\n")].decode("utf-8")
        header = {key: value for key, value in validated_data(header_text, "patterns", str(path), _header_data).items()
                  if key != "configurations"}
        return PatternTable(header, Entries(lines, header, str(path))), digest
    return table_from_text(utf8_text(data, path), str(path)), digest


def _header_data(text: str, name: str) -> Any:
    """A pattern table's header text parsed, with no configurations, as its schema validates it."""
    header = parse_yaml(text, name)
    return {**header, "configurations": {}} if isinstance(header, dict) else header


class SortedLines(Mapping[str, str]):
    """A committed table's entries as written, code -> JSON text, each found by bisection over its lines.

    The layout every committed table has (tests/formats/test_mesh.py holds each to it, and its bytes
    are known by their digest): the header, then ``configurations:`` and to the end of the file one
    line an entry, ``  'CODE': {...}``, in the order of the codes.  A mesher asks for ~100 entries
    of thousands: about 15 lines read each, and only the lines found decoded (``data``: the file's
    UTF-8 bytes), not the whole section cut up front.
    """

    def __init__(self, data: bytes) -> None:
        self._data = data
        self.start = data.index(b"\nconfigurations:\n") + len(b"\nconfigurations:\n")  # the first entry's line
        self._all: dict[str, str] | None = None
        self._found: dict[str, str] = {}  # what a lookup found: a table is asked "in it?", then for the entry

    def _line(self, start: int) -> tuple[bytes, int, int]:
        """The code of the line starting at ``start`` (bytes), where its JSON text starts, and the line's end."""
        data = self._data
        quote = data.index(b"'", start + 3)
        return data[start + 3:quote], quote + 3, data.index(b"\n", start)

    def __getitem__(self, code: str) -> str:
        if not isinstance(code, str):
            raise KeyError(code)
        found = self._found.get(code)
        if found is not None:
            return found
        key = code.encode("utf-8")  # byte order is code point order in UTF-8: the codes' order
        data = self._data
        low, high = self.start, len(data)  # line starts: the entry, if there, starts in [low, high)
        while low < high:
            middle = max(data.rfind(b"\n", low, (low + high) // 2) + 1, low)  # a line start in [low, middle]
            line, entry, end = self._line(middle)
            if line == key:
                text = self._found[code] = data[entry:end].decode("utf-8")
                return text
            if line < key:
                low = end + 1
            else:
                high = middle
        raise KeyError(code)

    def _entries(self) -> dict[str, str]:
        if self._all is None:
            self._all = {}
            at = self.start
            while at < len(self._data):
                code, entry, end = self._line(at)
                self._all[code.decode("utf-8")] = self._data[entry:end].decode("utf-8")
                at = end + 1
        return self._all

    def __iter__(self) -> Iterator[str]:
        return iter(self._entries())

    def __len__(self) -> int:
        return len(self._entries())


def checked_table(digest: str | None, catalogue: Catalogue) -> str | None:
    """Why the entries of the table whose bytes have SHA-256 ``digest`` need no check against ``catalogue``
    (one of :data:`CHECKED_TABLES`, checked against this catalogue's version), else ``None``.

    The digest is of the very bytes the table was parsed from (:func:`load_table`): a copy of a
    committed table anywhere is proven, a table changed by one byte is not.
    """
    known = CHECKED_TABLES.get(digest) if digest is not None else None
    if digest is None or known is None or known[1] != catalogue.version:
        return None
    return (f"the bytes of the committed {known[0]} (SHA-256 {digest[:16]}...), every entry of which passes "
            "cospherical check (--check all checks them)")


def table_lookup(table: PatternTable, criterion: str, box: Box, name: str = "pattern table",
                 catalogue: Catalogue | None = None, every_criterion: bool = False,
                 check_entries: bool = True) -> Lookup:
    """A lookup for :func:`cospherical.mesh.assembly.assemble` reading a pattern table.

    The table is asked for the leaf's whole-point-set code (``800000000000+f``), and
    where its header names a point policy, for the bare edge code when that policy
    gives the same point set.  The table's box must have the domain's proportions
    (every leaf is the domain scaled down).  ``catalogue``: the element catalogue
    naming the table's types (default: the shipped one), see :func:`orbit_lookup`.

    The table is data from disk: each entry the lookup uses is held, the first time, to
    the rules of ``cospherical check`` (:class:`~cospherical.formats.check.EntryCheck`:
    node order, recomputed types, tiling, faces met from both sides), so a damaged or
    forged entry raises :class:`FormatError` naming the table and the configuration
    instead of giving inverted or overlapping cells.  Its elements under ``criterion`` are
    the ones checked (the others never reach the mesh: half the leaf table's entries have
    split elements of their own, a third of the elements); ``every_criterion``: all of them,
    as ``check`` does (``mesh --check all``).  ``check_entries=False``: none, for a table whose
    entries are proven (:func:`checked_table`).
    """
    if catalogue is None:
        from ..catalogue import shipped_catalogue

        catalogue = shipped_catalogue()
    header = table.header
    element = header.get("element", "cuboid")
    if element != "cuboid":
        raise InputError(f"{name}: a table of {element} elements, but the mesh's leaves are cuboids "
                         f"of the domain {' x '.join(box.texts)}")
    if "criteria" in header and criterion not in header["criteria"]:
        raise InputError(f"{name}: no {criterion!r} elements (it has {', '.join(header['criteria'])})")
    if "box" in header:
        theirs = Box.parse(header["box"]).squared
        ours = box.squared
        if any(theirs[a] * ours[0] != ours[a] * theirs[0] for a in range(3)):
            raise InputError(f"{name}: its box {' x '.join(header['box'])} is not shaped like the domain "
                             f"{' x '.join(box.texts)}: its tessellations are not the leaves'")
    policy = header.get("face_points", "octree")
    check: EntryCheck | None = None
    if check_entries:  # check's module (and what it reads) imported only when an entry is to be checked
        from .check import EntryCheck

        check = EntryCheck(header, catalogue, name, only=None if every_criterion else criterion)
    checked: set[str] = set()

    def elements(code: str) -> list[dict[str, Any]] | None:
        """The table's elements of ``code``, its entry checked as ``check`` does the first time (KeyError: none)."""
        found = table.elements(code, criterion)
        if check is not None and code not in checked:
            check(code, table.configurations[code])
            checked.add(code)
        return found

    def lookup(configuration: Configuration) -> list[dict[str, Any]] | None:
        code = configuration.point_set_code
        if code is None:  # a table holds configurations by their point-set codes
            return None
        try:
            return elements(code)
        except KeyError:
            pass
        digits = code.split("+")[0]
        if policy in POINT_POLICIES and \
                Configuration.from_code(digits, configuration.box, policy).point_set_code == code:
            try:
                return elements(digits)
            except KeyError:
                return None
        return None

    return orbit_lookup(lookup, box, catalogue)


# Node orders that turn a VTK cell's mirror image back into a VTK cell (the first face's
# right-hand normal pointing into the cell again): a reflection reverses every face.
_MIRRORED_VTK = {"tetra": (0, 2, 1, 3), "pyramid": (0, 3, 2, 1, 4), "wedge": (0, 2, 1, 3, 5, 4),
                 "hexahedron": (0, 3, 2, 1, 4, 7, 6, 5)}


def orbit_lookup(lookup: Lookup, box: Box, catalogue: Catalogue) -> Lookup:
    """``lookup``, and for a configuration it lacks, its orbit representative's elements carried back.

    A table of orbit representatives (the intersection store) holds one
    configuration per orbit of the box's symmetries: the smallest image code.  A
    leaf's configuration is sent to its representative by a symmetry
    (:func:`cospherical.core.symmetry.orbit_representatives`), the representative
    looked up, and each element's nodes mapped back through that symmetry's node
    map; a reflection also reverses a VTK cell's faces, so its nodes are put back in
    VTK order (the VTK cell of each type from ``catalogue``, the element catalogue
    naming the table's types).  Mapped elements carry ``mapped_from`` (the
    representative's code).
    """
    symmetries: list[Symmetry] = []  # made at the first configuration the table lacks (a leaf table lacks none)
    vtk = {entry.id: entry.vtk for entry in catalogue}

    def mapped(configuration: Configuration) -> list[dict[str, Any]] | None:
        found = lookup(configuration)
        if found is not None:
            return found
        code = configuration.point_set_code
        if code is None:  # a table holds configurations by their point-set codes
            return None
        from ..core.symmetry import box_symmetries, orbit_representatives  # imported, too, where first needed

        if not symmetries:
            symmetries.extend(box_symmetries(box))
        (representative,), (index,) = orbit_representatives([code], symmetries)
        if representative == code:
            return None
        symmetry = symmetries[index]
        found = lookup(symmetry.configuration(configuration))
        if found is None:
            return None
        back = {image: node for node, image in enumerate(symmetry.node_map)}
        elements = []
        for element in found:
            nodes = [back[int(n)] for n in element["nodes"]]
            kind = vtk.get(element["type"])
            order = None if symmetry.proper or kind is None else _MIRRORED_VTK.get(kind)
            if order is not None and len(order) == len(nodes):
                nodes = [nodes[i] for i in order]
            elements.append({**element, "nodes": nodes, "mapped_from": representative})
        return elements

    return mapped


class VtuArrays(TypedDict):
    """What :func:`vtu_arrays` gives: the type ids, the cells' order and VTK types, connectivity and offsets, the
    polyhedra's face streams (``None`` without polyhedra), each element's type index."""

    ids: list[str]
    order: np.ndarray
    types: np.ndarray
    connectivity: np.ndarray
    offsets: np.ndarray
    faces: np.ndarray | None
    faceoffsets: np.ndarray | None
    element_type: np.ndarray


def vtu_arrays(mesh: Mesh) -> VtuArrays:
    """The mesh as the arrays of a VTU grid (see :func:`write_vtu`), built per block of alike elements, never per element.

    Cells are sorted by VTK cell type (stable: in element order within a type), so a
    reader that groups cells into blocks of one type (meshio) meets few blocks;
    ``order[c]`` is the element written as cell ``c``.  Each block's vertex ids are
    gathered once and written straight to their cells' places in ``connectivity`` (and,
    for polyhedra, in the face streams): no padded table of every element's ids.
    """
    from .vtu import VTK_CELL

    ids, element_type = mesh.element_types()
    kind_of_type = np.array([VTK_CELL[mesh.type_vtk(t) or "polyhedron"] for t in ids],
                            dtype=np.uint8)
    kinds = kind_of_type[element_type] if len(ids) else np.zeros(0, dtype=np.uint8)
    order = np.argsort(kinds, kind="stable")
    polyhedral = kinds == VTK_CELL["polyhedron"]
    blocks = [block for block in mesh.blocks() if len(block.rows)]
    # per block of polyhedra, a face stream template: counts as -1 - count, else node columns
    templates = [np.array([-1 - len(block.faces)] + [x for f in block.faces for x in (-1 - len(f), *f)], dtype=np.int64)
                 if block.type_id is not None and kind_of_type[ids.index(block.type_id)] == VTK_CELL["polyhedron"]
                 else None for block in blocks]
    sizes = np.zeros(len(mesh), dtype=np.int64)
    stream = np.zeros(len(mesh), dtype=np.int64)
    for block, template in zip(blocks, templates):
        sizes[block.rows] = block.nodes.shape[1]
        if template is not None:
            stream[block.rows] = len(template)
    offsets = np.cumsum(sizes[order])
    start = np.empty(len(mesh), dtype=np.int64)
    start[order] = offsets - sizes[order]  # where each element's ids begin in connectivity
    connectivity = np.empty(int(offsets[-1]) if len(offsets) else 0,
                            dtype=np.int32 if len(mesh.vertices) < 2**31 else np.int64)
    faces = faceoffsets = None
    if polyhedral.any():
        cells = order[polyhedral[order]]  # the polyhedra in cell order
        ends = np.cumsum(stream[cells])
        stream_start = np.zeros(len(mesh), dtype=np.int64)
        stream_start[cells] = ends - stream[cells]
        faces = np.empty(int(ends[-1]), dtype=connectivity.dtype)
        faceoffsets = np.full(len(mesh), -1, dtype=np.int64)
        faceoffsets[polyhedral[order]] = ends
    for (rows, nodes, _, _), template in zip(blocks, templates):
        connectivity[start[rows][:, None] + np.arange(nodes.shape[1])] = nodes
        if template is not None and faces is not None:
            columns = template >= 0
            values = np.broadcast_to(np.where(columns, 0, -1 - template), (len(rows), len(template))).copy()
            values[:, columns] = nodes[:, template[columns]]
            faces[stream_start[rows][:, None] + np.arange(len(template))] = values
    return {"ids": ids, "order": order, "types": kinds[order], "connectivity": connectivity, "offsets": offsets,
            "faces": faces, "faceoffsets": faceoffsets, "element_type": element_type}


def write_vtu(mesh: Mesh, path: str | Path, point_data: dict[str, np.ndarray] | None = None, cell_data: dict[str, np.ndarray] | None = None,
              leaves: np.ndarray | None = None, field_data: dict[str, np.ndarray] | None = None, origin: Sequence[Fraction] | None = None,
              pool: Executor | None = None) -> None:
    """Write the mesh as one compressed binary VTU grid, atomically (a complete new file or the old one).

    Standard VTK cells (tetra, pyramid, wedge, hexahedron, nodes in VTK order) for
    the elements that are one, ``VTK_POLYHEDRON`` with faces for the others, sorted
    by cell type; the cell data say which element each cell is.  The grid's arrays
    and data are :func:`vtu_grid`'s (see it for each array).  ``pool``: the threads that deflate its
    blocks (see :func:`~cospherical.formats.vtu.write_grid`: the same bytes with any).
    """
    from .vtu import write_grid

    grid = vtu_grid(mesh, point_data, cell_data, leaves, field_data, origin)
    write_grid(path, grid.points, grid.types, grid.connectivity, grid.offsets, grid.faces, grid.faceoffsets,
               point_data=grid.point_data, cell_data=grid.cell_data, field_data=grid.field_data, pool=pool)


@dataclass(frozen=True)
class VtuGrid:
    """A mesh as a VTK unstructured grid's arrays (VTK's layout, see :func:`cospherical.formats.vtu.write_grid`) and data."""

    points: np.ndarray
    types: np.ndarray
    connectivity: np.ndarray
    offsets: np.ndarray
    faces: np.ndarray | None
    faceoffsets: np.ndarray | None
    point_data: dict[str, np.ndarray]
    cell_data: dict[str, np.ndarray]
    field_data: dict[str, np.ndarray]


def vtu_grid(mesh: Mesh, point_data: dict[str, np.ndarray] | None = None, cell_data: dict[str, np.ndarray] | None = None,
             leaves: np.ndarray | None = None, field_data: dict[str, np.ndarray] | None = None, origin: Sequence[Fraction] | None = None) -> VtuGrid:
    """The grid :func:`write_vtu` writes (and the pyvista adapter builds in memory), cells sorted by VTK cell type.

    Point data: ``grid_coordinates`` (the exact integer grid point of each vertex),
    then ``point_data`` (one row per vertex, in ``mesh.vertices`` order).
    Cell data: ``element`` (the element's index in the mesh), ``type`` (index into
    the field data ``type_ids``), ``leaf`` (the leaf's index in the octree's order: by
    level, then by the key ``(i * 2**level + j) * 2**level + k`` of its position; or
    ``leaves[index]`` when ``leaves`` is given), ``fvm`` (its circumcenter lies in its
    closed leaf, decided exactly), then ``cell_data`` (one row per element, in
    element order: written in cell order).  ``leaves``: the number ``leaf`` gives each
    leaf of the mesh's tree, for example its index in a whole tree when ``mesh`` is a
    piece of it, or its line in a ``--leaves`` file.
    Field data (text as UTF-8 bytes, ``bytes(array).decode()``): ``type_ids`` and
    ``type_names`` (one per line, in ``type`` order), ``domain`` (the lengths as
    given), ``domain_squared`` (their exact squares), and ``grid_intervals``: a point's
    exact coordinate along an axis is ``grid_coordinates * length / grid_intervals``;
    the ``Points`` are the same as floats.  ``field_data``: more of them (text as
    above); ``origin``: the real point of grid point 0 (a device's bounding box's low
    corner; default the origin).
    """
    from .vtu import narrow, text_array

    arrays = vtu_arrays(mesh)
    order = arrays["order"]
    ids = arrays["ids"]
    fields = {
        "type_ids": text_array("\n".join(ids)),
        "type_names": text_array("\n".join(mesh.type_name(t) for t in ids)),
        "domain": text_array(" ".join(mesh.box.texts)),
        "domain_squared": text_array(" ".join(str(s) for s in mesh.box.squared)),
        "grid_intervals": np.array([mesh.grid], dtype=np.int64),
    }
    cells = {"element": order.astype(np.int32), "type": arrays["element_type"][order].astype(np.int32),
             "leaf": (mesh.element_leaf if leaves is None else leaves[mesh.element_leaf])[order].astype(np.int32), "fvm": mesh.element_fvm()[order].astype(np.uint8)}
    for name, values in (cell_data or {}).items():
        if name in cells:
            raise InputError(f"cell data {name!r}: the writer's own")
        if len(values) != len(mesh):
            raise InputError(f"cell data {name!r}: {len(values)} rows for {len(mesh)} elements")
        cells[name] = np.asarray(values)[order]
    points = {"grid_coordinates": narrow(mesh.vertices)}
    for name, values in (point_data or {}).items():
        if name in points:
            raise InputError(f"point data {name!r}: the writer's own")
        points[name] = values
    for name, values in (field_data or {}).items():
        if name in fields:
            raise InputError(f"field data {name!r}: the writer's own")
        fields[name] = values
    coordinates = mesh.points()
    if origin is not None:
        coordinates = coordinates + np.array([float(x) for x in origin])
    return VtuGrid(coordinates, arrays["types"], arrays["connectivity"], arrays["offsets"], arrays["faces"],
                   arrays["faceoffsets"], points, cells, fields)


def report_json(report: dict[str, Any]) -> str:
    """The report as JSON text (deterministic), validated against its schema."""
    validate(report, "mesh-report", "mesh report")
    return json.dumps(report, indent=1) + "\n"


def write_report(report: dict[str, Any], path: str | Path) -> None:
    atomic_write(path, report_json(report))


def write_piece(mesh: Mesh, path: str | Path, leaves: np.ndarray) -> None:
    """One piece of a partitioned mesh as a VTU grid (see :func:`write_vtu`), atomically.

    Only the vertices its elements use, in the order of their ids; point data
    ``global_id`` (Int64, VTK's ``vtkIdType``) is each one's id in the whole mesh, the
    same in every piece that holds it.  ``leaves``: the piece's leaves' indices in
    the whole tree (cell data ``leaf``); ``element`` counts the piece's own elements,
    and ``type`` indexes the piece's own ``type_ids``: a reader that joins the pieces
    keeps one piece's field data, so cell data ``type_hash`` (the six hexadecimal
    digits that end the type id, as an integer) names the type the same in every piece.
    """
    from dataclasses import replace

    conn, _ = mesh.connectivity()
    used = np.unique(conn[conn >= 0])
    index = np.full(len(mesh.vertices), -1, dtype=np.int64)
    index[used] = np.arange(len(used))

    def local(ids: np.ndarray) -> np.ndarray:
        return np.where(ids >= 0, index[np.maximum(ids, 0)], -1).astype(ids.dtype)

    cells = replace(mesh.cells, nodes=local(mesh.cells.nodes)) if mesh.cells is not None else None
    piece = replace(mesh, vertices=mesh.vertices[used], slots=local(mesh.slots), cells=cells, _groups=None)
    ids, element_type = mesh.element_types()
    hashes = np.array([int(t.rsplit("-", 1)[1], 16) for t in ids], dtype=np.int32)
    write_vtu(piece, path, point_data={"global_id": used.astype(np.int64)},
              cell_data={"type_hash": hashes[element_type] if len(ids) else np.zeros(0, dtype=np.int32)},
              leaves=leaves)


_DECLARED = re.compile(r"<(PointData|CellData|Points)>(.*?)</\1>", re.S)
_DATA_ARRAY = re.compile(r'<DataArray type="(\w+)" Name=("[^"]*")(?: NumberOfComponents="(\d+)")?')


def write_pvtu(path: str | Path, pieces: list[Path]) -> None:
    """The ``.pvtu`` file (VTK's PUnstructuredGrid) that opens ``pieces`` (VTU files beside it) as one mesh, atomically.

    The point and cell data arrays are declared as the pieces have them, read from
    their headers; pieces that do not agree are refused.  ParaView and VTK's
    ``vtkXMLPUnstructuredGridReader`` read it.
    """
    declared = None
    for piece in pieces:
        with open(piece, "rb") as handle:
            head = handle.read(1 << 16).split(b"<AppendedData", 1)[0].decode()
        mine = {section: _DATA_ARRAY.findall(body) for section, body in _DECLARED.findall(head)}
        if declared is None:
            declared = mine
        elif mine != declared:
            raise FormatError(f"{piece}: its arrays are not the first piece's")

    def arrays(section: str) -> list[str]:
        return [f'<PDataArray type="{kind}"' + (f" Name={name}" if section != "Points" else "")
                + (f' NumberOfComponents="{components}"' if components else "") + "/>"
                for kind, name, components in (declared or {}).get(section, [])]

    xml = ['<?xml version="1.0"?>',
           '<VTKFile type="PUnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">',
           '<PUnstructuredGrid GhostLevel="0">',
           "<PPointData>", *arrays("PointData"), "</PPointData>",
           "<PCellData>", *arrays("CellData"), "</PCellData>",
           "<PPoints>", *arrays("Points"), "</PPoints>",
           *(f"<Piece Source={quoteattr(Path(piece).name)}/>" for piece in pieces),
           "</PUnstructuredGrid>", "</VTKFile>"]
    atomic_write(path, "\n".join(xml) + "\n")


def write_faces_vtu(mesh: Mesh, faces: RegionFaces, path: str | Path, origin: Sequence[Fraction] | None = None) -> None:
    """Write a device's contact and interface faces as one VTU of polygons, atomically.

    Cells: every contact face (cell data ``contact``: its index in the field data
    ``contact_names``, ``interface`` -1), then every interface face (``interface``: its
    index in ``interface_names``, ``contact`` -1), each polygon counter-clockwise seen
    from outside its element (an interface face: from outside its first region's
    element).  Points: only the vertices the faces use, point data ``global_id`` (the
    vertex's index in ``mesh.vtu``) and ``grid_coordinates``.
    """
    from .vtu import narrow, text_array, write_grid

    polygons = np.concatenate(_padded(faces.contact_nodes, faces.interface_nodes))
    used = polygons >= 0
    ids = np.unique(polygons[used])
    local = np.searchsorted(ids, np.where(used, polygons, ids[0] if len(ids) else 0))
    connectivity = local[used].astype(np.int64)
    offsets = np.cumsum(used.sum(axis=1), dtype=np.int64)
    n_contact = len(faces.contact_nodes)
    contact = np.r_[faces.contact_face_contact, np.full(len(faces.interface_nodes), -1)].astype(np.int32)
    interface = np.r_[np.full(n_contact, -1), faces.interface_face_interface].astype(np.int32)
    coordinates = mesh.vertices[ids] * (np.array(mesh.box.to_float()) / mesh.grid)
    if origin is not None:
        coordinates = coordinates + np.array([float(x) for x in origin])
    layout = mesh.regions.layout if mesh.regions is not None else None
    if layout is None:
        raise ValueError("write_faces_vtu: the mesh of a device (regions with their layout) has the faces")
    device = layout.device
    fields = {"contact_names": text_array("\n".join(c.name for c in device.contacts)),
              "interface_names": text_array("\n".join(faces.interface_names)),
              "grid_intervals": np.array([mesh.grid], dtype=np.int64)}
    write_grid(path, coordinates, np.full(len(polygons), 7, dtype=np.uint8), connectivity, offsets,
               point_data={"global_id": ids.astype(np.int64), "grid_coordinates": narrow(mesh.vertices[ids])},
               cell_data={"contact": contact, "interface": interface}, field_data=fields)


def _padded(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two -1 padded arrays of rows brought to one width."""
    width = max(a.shape[1], b.shape[1], 1)
    return (np.pad(a, ((0, 0), (0, width - a.shape[1])), constant_values=-1),
            np.pad(b, ((0, 0), (0, width - b.shape[1])), constant_values=-1))
