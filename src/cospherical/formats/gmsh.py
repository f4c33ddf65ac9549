"""Gmsh mesh files (``.msh``): tetrahedra in named physical volumes, triangles in named physical surfaces.

Gmsh's format is what most finite-element and finite-volume solvers read (DEVSIM,
FEniCS/dolfinx through meshio, Elmer, Code_Aster's converters).  Two versions:

- **MSH 2.2**, the legacy one that DEVSIM and many readers still take: each element
  carries two tags, its physical group and its elementary entity.
- **MSH 4.1**, Gmsh's current one: nodes and elements in blocks per entity, the
  entities listed with their physical groups in ``$Entities``.

Both in ASCII or binary (native little-endian, the layout Gmsh itself writes:
a ``1`` written as an int after the header lets a reader check the byte order).

Layout: one elementary entity per physical group, with the same tag; volumes
take tags ``1..R`` and surfaces ``R+1..R+S`` (unique over both dimensions, so a
reader that ignores the dimension still tells them apart).  Nodes are tagged
``1..n`` in the mesh's vertex order (in MSH 4.1 they are all listed on the first
volume), elements ``1..`` surfaces first, then volumes, each group in the order
given.  The bytes depend only on the arrays and names (floats written with 17
significant digits, no date or host), and the file is written atomically.

Names are data: a name with a double quote, a line break or another control
character would end its line early in ``$PhysicalNames``, and is refused.

Examples
--------
>>> import io, numpy as np
>>> from cospherical.mesh.tetrahedra import SimplexMesh
>>> points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
>>> simplices = SimplexMesh(points, np.array([[0, 1, 2, 3]]), np.array([0]), ("silicon",),
...                         np.array([[0, 2, 1]]), np.array([0]), ("bottom",))
>>> print(msh_bytes(simplices, "2.2").decode().split("$Elements")[1].strip())
2
1 2 2 2 2 1 3 2
2 4 2 1 1 1 2 3 4
$EndElements
"""

from __future__ import annotations

import io
from typing import TYPE_CHECKING
from pathlib import Path

import numpy as np

from ..errors import InputError, shown
from ..files.outputs import atomic_open

if TYPE_CHECKING:  # GMSH_VERSIONS is read by every mesh command: the tetrahedra's module only when one is written
    from ..mesh.tetrahedra import SimplexMesh

__all__ = ["GMSH_VERSIONS", "msh_bytes", "write_msh"]

GMSH_VERSIONS = ("2.2", "4.1")
_TRIANGLE, _TETRAHEDRON = 2, 4  # Gmsh's element type numbers


def _check_name(name: str) -> str:
    if not isinstance(name, str) or not name or '"' in name or any(ord(c) < 32 or ord(c) == 127 for c in name):
        raise InputError(f"Gmsh physical name {shown(name)}: must be a non-empty line without double quotes or "
                         "control characters")
    return name


# A physical group: its dimension, tag, name, element rows (1-based node ids) and Gmsh element type.
_Group = tuple[int, int, str, np.ndarray, int]


def _groups(simplices: SimplexMesh) -> list[_Group]:
    """(dimension, tag, name, elements (rows of 1-based node tags), element type) per physical group."""
    groups = []
    volumes, surfaces = list(simplices.volumes), list(simplices.surfaces)
    for k, name in enumerate(surfaces):
        rows = np.asarray(simplices.triangles)[np.asarray(simplices.surface) == k]
        groups.append((2, len(volumes) + k + 1, _check_name(name), rows.astype(np.int64) + 1, _TRIANGLE))
    for k, name in enumerate(volumes):
        rows = np.asarray(simplices.tetrahedra)[np.asarray(simplices.volume) == k]
        groups.append((3, k + 1, _check_name(name), rows.astype(np.int64) + 1, _TETRAHEDRON))
    if len(set(volumes)) != len(volumes) or len(set(surfaces)) != len(surfaces):
        raise InputError("Gmsh physical names: each volume and each surface needs its own name")
    return groups


def _text_rows(rows: np.ndarray, float_columns: int = 0) -> str:
    """Rows as text lines: integers, then ``float_columns`` floats with 17 significant digits."""
    if not len(rows):
        return ""
    columns = rows.shape[1]
    fmt = " ".join(["%d"] * (columns - float_columns) + ["%.17g"] * float_columns)
    buffer = io.StringIO()
    np.savetxt(buffer, rows, fmt=fmt)
    return buffer.getvalue()


def msh_bytes(simplices: SimplexMesh, version: str = "4.1", binary: bool = False) -> bytes:
    """The Gmsh file of a :class:`~cospherical.mesh.tetrahedra.SimplexMesh` as bytes (see the module docstring)."""
    if version not in GMSH_VERSIONS:
        raise InputError(f"Gmsh version {shown(version)}: write one of {', '.join(GMSH_VERSIONS)}")
    groups = _groups(simplices)
    points = np.asarray(simplices.points, dtype=np.float64)
    out = io.BytesIO()
    out.write(f"$MeshFormat\n{version} {1 if binary else 0} 8\n".encode())
    if binary:
        out.write(np.array([1], dtype="<i4").tobytes() + b"\n")
    out.write(b"$EndMeshFormat\n$PhysicalNames\n")
    out.write(f"{len(groups)}\n".encode())
    out.write("".join(f'{dim} {tag} "{name}"\n' for dim, tag, name, _, _ in groups).encode())
    out.write(b"$EndPhysicalNames\n")
    (_write_22 if version == "2.2" else _write_41)(out, points, groups, binary)
    return out.getvalue()


def _write_22(out: io.BytesIO, points: np.ndarray, groups: list[_Group], binary: bool) -> None:
    n = len(points)
    out.write(f"$Nodes\n{n}\n".encode())
    if binary:
        record = np.zeros(n, dtype=[("tag", "<i4"), ("xyz", "<f8", 3)])
        record["tag"], record["xyz"] = np.arange(1, n + 1), points
        out.write(record.tobytes() + b"\n")
    else:
        out.write(_text_rows(np.column_stack([np.arange(1, n + 1), points]), 3).encode())
    total = sum(len(rows) for *_, rows, _ in groups)
    out.write(f"$EndNodes\n$Elements\n{total}\n".encode())
    first = 1
    for _, tag, _, rows, kind in groups:
        count = len(rows)
        if not count:
            continue
        numbers = np.arange(first, first + count)
        table = np.column_stack([numbers, np.full(count, tag), np.full(count, tag), rows])
        if binary:
            out.write(np.array([kind, count, 2], dtype="<i4").tobytes() + table.astype("<i4").tobytes())
        else:
            head = np.column_stack([numbers, np.full(count, kind), np.full(count, 2)])
            out.write(_text_rows(np.column_stack([head, table[:, 1:]])).encode())
        first += count
    out.write(b"\n$EndElements\n" if binary else b"$EndElements\n")


def _write_41(out: io.BytesIO, points: np.ndarray, groups: list[_Group], binary: bool) -> None:
    n = len(points)
    surfaces = [g for g in groups if g[0] == 2]
    volumes = [g for g in groups if g[0] == 3]
    low, high = (points.min(axis=0), points.max(axis=0)) if n else (np.zeros(3), np.zeros(3))

    def box_of(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if not len(rows):
            return low, high
        used = points[rows.reshape(-1) - 1]
        return used.min(axis=0), used.max(axis=0)

    out.write(b"$Entities\n")
    if binary:
        out.write(np.array([0, 0, len(surfaces), len(volumes)], dtype="<u8").tobytes())
        for _, tag, _, rows, _ in surfaces + volumes:
            lo, hi = box_of(rows)
            out.write(np.array([tag], dtype="<i4").tobytes() + np.r_[lo, hi].astype("<f8").tobytes()
                      + np.array([1], dtype="<u8").tobytes() + np.array([tag], dtype="<i4").tobytes()
                      + np.array([0], dtype="<u8").tobytes())
        out.write(b"\n")
    else:
        lines = [f"0 0 {len(surfaces)} {len(volumes)}"]
        for _, tag, _, rows, _ in surfaces + volumes:
            lo, hi = box_of(rows)
            lines.append(f"{tag} " + " ".join("%.17g" % x for x in (*lo, *hi)) + f" 1 {tag} 0")
        out.write(("\n".join(lines) + "\n").encode())
    out.write(b"$EndEntities\n$Nodes\n")
    # every node on the first volume entity (a mesh has at least one volume when it has nodes)
    holder = volumes[0][1] if volumes else (surfaces[0][1] if surfaces else 1)
    holder_dim = 3 if volumes else 2
    tags = np.arange(1, n + 1)
    if binary:
        out.write(np.array([1 if n else 0, n, 1 if n else 0, n], dtype="<u8").tobytes())
        if n:
            out.write(np.array([holder_dim, holder, 0], dtype="<i4").tobytes() + np.array([n], dtype="<u8").tobytes()
                      + tags.astype("<u8").tobytes() + points.astype("<f8").tobytes())
        out.write(b"\n")
    else:
        out.write(f"{1 if n else 0} {n} {1 if n else 0} {n}\n".encode())
        if n:
            out.write(f"{holder_dim} {holder} 0 {n}\n".encode())
            out.write(_text_rows(tags[:, None]).encode())
            out.write(_text_rows(points, 3).encode())
    out.write(b"$EndNodes\n$Elements\n")
    blocks = [g for g in groups if len(g[3])]
    total = sum(len(g[3]) for g in blocks)
    if binary:
        out.write(np.array([len(blocks), total, 1 if total else 0, total], dtype="<u8").tobytes())
    else:
        out.write(f"{len(blocks)} {total} {1 if total else 0} {total}\n".encode())
    first = 1
    for dim, tag, _, rows, kind in blocks:
        count = len(rows)
        table = np.column_stack([np.arange(first, first + count), rows])
        if binary:
            out.write(np.array([dim, tag, kind], dtype="<i4").tobytes() + np.array([count], dtype="<u8").tobytes()
                      + table.astype("<u8").tobytes())
        else:
            out.write(f"{dim} {tag} {kind} {count}\n".encode() + _text_rows(table).encode())
        first += count
    out.write(b"\n$EndElements\n" if binary else b"$EndElements\n")


def write_msh(simplices: SimplexMesh, path: str | Path, version: str = "4.1", binary: bool = False) -> None:
    """Write a :class:`~cospherical.mesh.tetrahedra.SimplexMesh` as a Gmsh file, atomically."""
    data = msh_bytes(simplices, version, binary)
    with atomic_open(path, binary=True) as handle:
        handle.write(data)
