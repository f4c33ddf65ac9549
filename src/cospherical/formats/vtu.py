"""VTU files (VTK XML unstructured grids) written from numpy arrays; a tessellation as one.

:func:`write_grid` writes one unstructured grid, every array zlib-compressed in
the file's appended section as raw binary (VTK's own layout: a ``UInt64``
header of block sizes, then the compressed blocks).  That is what ParaView and
``vtkXMLUnstructuredGridReader`` read fastest, and meshio reads it too.  The
bytes depend only on the arrays: no time stamp, no machine name, so the same
mesh gives the same file.

Cells are VTK's standard ones (tetra, pyramid, wedge, hexahedron: nodes in
VTK order) where an element is one, and ``VTK_POLYHEDRON`` with its faces
(``faces``/``faceoffsets``, the layout VTK has always read) only for the
others, all in the one grid.  meshio's VTU reader (5.3.5) refuses a grid that
mixes polyhedra with other cells in any layout (``_organize_cells`` raises when a
piece holds type 42 beside another type); VTK and ParaView read it.
"""

from __future__ import annotations

import zlib
from pathlib import Path
from typing import TYPE_CHECKING, Sequence

import numpy as np

from ..core.tessellation import Tessellation
from ..errors import InputError
from ..files.yamlio import atomic_open
from .deflated import deflating

if TYPE_CHECKING:  # the threads' modules are imported where a file has blocks to share among them
    from concurrent.futures import Executor

__all__ = ["VTK_CELL", "narrow", "quoteattr", "text_array", "write_grid", "write_vtu"]

# VTK's cell type numbers (vtkCellType.h) of the cells an element can be.
VTK_CELL = {"tetra": 10, "hexahedron": 12, "wedge": 13, "pyramid": 14, "polyhedron": 42}
_VTK_TYPE = {np.dtype(t): name for t, name in (
    (np.int8, "Int8"), (np.uint8, "UInt8"), (np.int16, "Int16"), (np.uint16, "UInt16"), (np.int32, "Int32"),
    (np.uint32, "UInt32"), (np.int64, "Int64"), (np.uint64, "UInt64"), (np.float32, "Float32"),
    (np.float64, "Float64"))}
# Large blocks: fewer zlib calls and headers; meshio joins a file's blocks by repeated
# concatenation, which is quadratic in their number.
BLOCK = 1 << 22
# zlib's fastest level. Measured on the README sphere tree's 55.7 MB of arrays: level 1 12.5 MB in 0.38 s CPU,
# VTK's default (zlib's 6) 12.3 MB in 2.4 s, level 9 12.4 MB in 11 s; run-length or Huffman-only 25 MB in 0.3 s.
LEVEL = 1


def quoteattr(text: str) -> str:
    """``text`` as a quoted XML attribute value, as :func:`xml.sax.saxutils.quoteattr` writes it.

    Here because importing :mod:`xml.sax.saxutils` imports :mod:`urllib.request` (and with it
    :mod:`http.client`, :mod:`email`, :mod:`ssl`): a good part of the mesh command's start-up.
    """
    for raw, entity in (("&", "&amp;"), (">", "&gt;"), ("<", "&lt;"), ("\n", "&#10;"), ("\r", "&#13;"),
                        ("\t", "&#9;")):
        text = text.replace(raw, entity)
    if '"' not in text:
        return f'"{text}"'
    if "'" not in text:
        return f"'{text}'"
    return '"{}"'.format(text.replace('"', "&quot;"))


def _compressed(arrays: Sequence[np.ndarray], pool: Executor | None) -> list[bytes]:
    """Each array in VTK's compressed layout: (blocks, block size, last block size, compressed sizes), blocks.

    Every block is compressed on its own (VTK's layout), so ``pool``'s threads take them all at once, the
    largest first, and each block's bytes are what one thread would make of it: the same file whatever the
    threads do.  Without a pool, the arrays go to threads of the call's own where their bytes are worth them
    (:func:`~cospherical.formats.deflated.deflating`), else are compressed in this thread.
    """
    raws = [np.ascontiguousarray(array).view(np.uint8).reshape(-1).data for array in arrays]  # memoryviews
    blocks = [[raw[i:i + BLOCK] for i in range(0, len(raw), BLOCK)] for raw in raws]
    flat = [block for parts in blocks for block in parts]
    with deflating(sum(len(raw) for raw in raws), pool, "mesh.vtu", most=len(flat)) as threads:
        # zlib releases the GIL: the largest blocks first, so that no thread is left with one at the end
        futures = {n: threads.submit(zlib.compress, flat[n], LEVEL)
                   for n in sorted(range(len(flat)), key=lambda n: -len(flat[n]))}
        done = [futures[n].result() for n in range(len(flat))]
    out, at = [], 0
    for raw, parts in zip(raws, blocks):
        mine = done[at:at + len(parts)]
        at += len(parts)
        header = np.array([len(mine), BLOCK, len(raw) % BLOCK] + [len(b) for b in mine], dtype="<u8")
        out.append(header.tobytes() + b"".join(mine))
    return out


def _array(name: str, data: np.ndarray) -> tuple[str, np.ndarray, int]:
    data = np.asarray(data)
    if data.dtype == bool:
        data = data.astype(np.uint8)
    if data.dtype.newbyteorder("=") not in _VTK_TYPE:
        raise InputError(f"{name}: no VTK array type for {data.dtype}")
    data = data.astype(data.dtype.newbyteorder("<"), copy=False)
    return name, data, 1 if data.ndim == 1 else int(np.prod(data.shape[1:]))


def narrow(values: np.ndarray) -> np.ndarray:
    """Integers as ``Int32`` when they fit (half the bytes to compress and read), else as ``Int64``."""
    values = np.asarray(values)
    fits = not len(values) or (int(values.min()) >= -2**31 and int(values.max()) < 2**31)
    return values.astype(np.int32 if fits else np.int64, copy=False)


def text_array(text: str) -> np.ndarray:
    """Text as a ``UInt8`` array of its UTF-8 bytes: field data every VTU reader takes (meshio has no strings)."""
    return np.frombuffer(text.encode(), dtype=np.uint8)


def write_grid(path: str | Path, points: np.ndarray, cell_types: np.ndarray, connectivity: np.ndarray,
               offsets: np.ndarray, faces: np.ndarray | None = None, faceoffsets: np.ndarray | None = None,
               point_data: dict[str, np.ndarray] | None = None, cell_data: dict[str, np.ndarray] | None = None,
               field_data: dict[str, np.ndarray] | None = None, pool: Executor | None = None) -> None:
    """Write one unstructured grid as a compressed binary VTU, atomically.

    ``connectivity`` lists every cell's points one after the other, ``offsets`` is
    where each cell ends in it (VTK's layout); for ``VTK_POLYHEDRON`` cells ``faces``
    holds each one's face stream (number of faces, then per face its number of points
    and the points) and ``faceoffsets`` where that stream ends (-1 for other cells).
    Data arrays have one row per point, per cell, or any length (field data).  The arrays' blocks are
    deflated on ``pool``'s threads (default: threads of the call's own when there is more than one block);
    the file is the same byte for byte with any pool or none.
    """
    if (faces is None) != (faceoffsets is None):
        raise InputError("write_grid: faces and faceoffsets go together")
    arrays: list[tuple[str, list[tuple[str, np.ndarray, int]]]] = [
        ("FieldData", [_array(k, v) for k, v in (field_data or {}).items()]),
        ("PointData", [_array(k, v) for k, v in (point_data or {}).items()]),
        ("CellData", [_array(k, v) for k, v in (cell_data or {}).items()]),
        ("Points", [_array("Points", np.asarray(points, dtype=np.float64))]),
        ("Cells", [_array("connectivity", narrow(connectivity)), _array("offsets", narrow(offsets)),
                   _array("types", np.asarray(cell_types, dtype=np.uint8))]
         + ([_array("faces", narrow(faces)), _array("faceoffsets", narrow(faceoffsets))]
            if faces is not None and faceoffsets is not None else [])),
    ]
    n_points, n_cells = len(points), len(cell_types)
    for section, items in arrays[1:3]:
        for name, data, _ in items:
            if len(data) != (n_points if section == "PointData" else n_cells):
                raise InputError(f"{section} {name}: {len(data)} rows for {n_points} points and {n_cells} cells")
    # every block of every array deflated at once (the XML's offsets need the compressed sizes first)
    blobs = _compressed([data for _, items in arrays for _, data, _ in items], pool)
    sizes = iter(len(blob) for blob in blobs)  # in the order data_array is called: the arrays' order
    xml, offset = [], 0

    def data_array(name: str, data: np.ndarray, components: int, tuples: bool) -> str:
        nonlocal offset
        size = next(sizes)
        text = (f'<DataArray type="{_VTK_TYPE[data.dtype.newbyteorder("=")]}" Name={quoteattr(name)} '
                + (f'NumberOfTuples="{len(data)}" ' if tuples else "")
                + (f'NumberOfComponents="{components}" ' if components != 1 or tuples else "")
                + f'format="appended" offset="{offset}"/>')
        offset += size
        return text

    for section, items in arrays:
        if section == "FieldData":
            xml.append("<UnstructuredGrid>")
            body = [data_array(n, d, c, True) for n, d, c in items]
            xml += ["<FieldData>", *body, "</FieldData>"] if body else []
            xml.append(f'<Piece NumberOfPoints="{n_points}" NumberOfCells="{n_cells}">')
        else:
            xml += [f"<{section}>", *(data_array(n, d, c, False) for n, d, c in items), f"</{section}>"]
    head = ('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
            'header_type="UInt64" compressor="vtkZLibDataCompressor">\n' + "\n".join(xml)
            + '\n</Piece>\n</UnstructuredGrid>\n<AppendedData encoding="raw">\n_')
    with atomic_open(path, binary=True) as handle:
        handle.write(head.encode())
        for blob in blobs:
            handle.write(blob)
        handle.write(b"\n</AppendedData>\n</VTKFile>\n")


def write_vtu(tess: Tessellation, path: str | Path) -> None:
    """Write one tessellation as a VTU grid, atomically: its nodes in id order, its elements in order.

    Standard VTK cells when every element has one, else every element a
    ``VTK_POLYHEDRON`` with its faces: a grid meshio reads too.  Cell data:
    ``type_hash`` (the 6 hex digits of the element type id, as an integer) and
    ``vertices``.
    """
    real = tess.configuration.real_nodes()
    ids = sorted(real)
    index = {node: i for i, node in enumerate(ids)}
    standard = all(e.type.vtk for e in tess.elements)
    types, connectivity, offsets, faces, faceoffsets = [], [], [], [], []
    for element in tess.elements:
        connectivity += [index[n] for n in element.nodes]
        offsets.append(len(connectivity))
        types.append(VTK_CELL[(element.type.vtk if standard else None) or "polyhedron"])
        if not standard:
            faces.append(len(element.polyhedron.faces))
            for face in element.polyhedron.faces:
                faces += [len(face), *(index[n] for n in face)]
            faceoffsets.append(len(faces))
    cell_data = {"type_hash": np.array([int(e.type.id.rsplit("-", 1)[1], 16) for e in tess.elements], dtype=np.int64),
                 "vertices": np.array([len(e.nodes) for e in tess.elements], dtype=np.int64)}
    write_grid(path, np.array([real[i] for i in ids], dtype=float), np.array(types), np.array(connectivity),
               np.array(offsets), None if standard else np.array(faces), None if standard else np.array(faceoffsets),
               cell_data=cell_data)
