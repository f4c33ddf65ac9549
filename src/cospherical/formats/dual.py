"""``dual.npz``: the finite-volume dual of a mesh, for a solver (reading and writing only).

A zip of ``.npy`` arrays (``numpy.load`` opens it; no pickles), written
deterministically (fixed member order and time stamps: the same mesh gives the
same bytes) and atomically.  Members, ``n`` vertices, ``m`` edges, ``e`` elements:

===========================  ==========  ==================================================
``manifest``                 uint8       JSON text: ``format`` (``cospherical-dual``),
                                         ``version`` (2), ``domain`` (the box, exact
                                         texts), ``grid``, the exact denominators and
                                         factors (decimal texts), ``sha256`` of every
                                         other member
``grid_vertices``            int64 n x3  exact vertices: integers of the grid of ``grid``
                                         intervals per domain side
``vertices``                 f8 n x 3    real coordinates (``grid_vertices / grid * box``)
``edges``                    int64 m x2  vertex pairs ``i < j``, sorted
``length``, ``area``,        f8 m        edge length, signed dual-face area,
``coefficient``                          ``area / length`` (the box method's coupling)
``coefficient_exact``        int64 m     ``coefficient = coefficient_exact * sqrt(
                                         volume_factor_squared) / coefficient_denominator``
                                         (decimal text, ``U``, when int64 is too narrow)
``control_volume``           f8 n        each vertex's control volume
``volume_exact``             int64 n     ``control_volume = volume_exact * sqrt(
                                         volume_factor_squared) / volume_denominator``
``boundary``                 bool n      the vertex is on the domain's boundary
``boundary_area``            f8 n        the boundary's area in its control volume
``boundary_area_exact``      int64 n x3  per axis k, the part in the two sides normal
                                         to k: ``boundary_area = sum over k of
                                         boundary_area_exact[:, k] * sqrt(
                                         boundary_factors_squared[k]) /
                                         boundary_area_denominator``, the factors
                                         ``(b^2 c^2, a^2 c^2, a^2 b^2)`` for a box
                                         ``a x b x c`` (decimal text, ``U``, when int64
                                         is too narrow); each column sums to twice the
                                         denominator
``element_circumcenter``     f8 e x 3    the real circumcenter of each element (mesh order)
===========================  ==========  ==================================================

The reader refuses, with one line, a file that is not such a zip, lacks or adds a
member, has an array of the wrong kind or shape, fails a checksum (a truncated or
tampered file) or has edges that name no vertex.  Version 1 (no exact boundary
areas) is refused with its version named.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import re
import stat
import zipfile
import zlib
from fractions import Fraction
from pathlib import Path

import numpy as np

from ..core.configuration import Box
from ..errors import FormatError
from ..files.yamlio import atomic_write, machine_memory, parse_json
from ..mesh.dual import Dual

__all__ = ["DUAL_FORMAT_VERSION", "read_dual", "write_dual"]

DUAL_FORMAT_VERSION = 2
MAX_DUAL_FILE = 16 * 1024**3
# member -> (dtype kind, columns or None, which count: n vertices, m edges, e elements)
MEMBERS = {
    "grid_vertices": ("i", 3, "n"), "vertices": ("f", 3, "n"), "edges": ("i", 2, "m"), "length": ("f", None, "m"),
    "area": ("f", None, "m"), "coefficient": ("f", None, "m"), "coefficient_exact": ("iU", None, "m"),
    "control_volume": ("f", None, "n"), "volume_exact": ("iU", None, "n"), "boundary": ("b", None, "n"),
    "boundary_area": ("f", None, "n"), "boundary_area_exact": ("iU", 3, "n"), "element_circumcenter": ("f", 3, "e"),
}
_STAMP = (1980, 1, 1, 0, 0, 0)
_MAX_DIGITS = 200
# the manifest's exact numbers as written: plain integers and fractions of bounded length, so that a
# hostile text such as "1e999999999" never reaches Fraction (which would compute 10**999999999)
_INTEGER = re.compile(r"-?[0-9]{1,%d}" % _MAX_DIGITS)
_MAX_TEXT_DIGITS = 1000  # the manifest's exact numbers, written as text
_POSITIVE = re.compile(r"[1-9][0-9]{0,%d}" % (_MAX_TEXT_DIGITS - 1))
_POSITIVE_FRACTION = re.compile(r"[1-9][0-9]{0,%d}(/[1-9][0-9]{0,%d})?" % (_MAX_TEXT_DIGITS - 1, _MAX_TEXT_DIGITS - 1))
MAX_GRID = 1 << 40


def _npy(array: np.ndarray) -> bytes:
    buffer = io.BytesIO()
    np.lib.format.write_array(buffer, np.ascontiguousarray(array), allow_pickle=False)
    return buffer.getvalue()


def _exact(array: np.ndarray) -> np.ndarray:
    if array.dtype != object:
        return array
    return np.array([str(int(x)) for x in array.reshape(-1)], dtype=f"U{_MAX_DIGITS}").reshape(array.shape)


def write_dual(dual: Dual, path: str | Path) -> None:
    """Write ``dual`` as ``dual.npz`` (see the module), atomically and deterministically."""
    arrays = {name: getattr(dual, name) for name in MEMBERS}
    arrays["coefficient_exact"] = _exact(arrays["coefficient_exact"])
    arrays["volume_exact"] = _exact(arrays["volume_exact"])
    arrays["boundary_area_exact"] = _exact(arrays["boundary_area_exact"])
    blobs = {name: _npy(array) for name, array in arrays.items()}
    manifest = {
        "format": "cospherical-dual", "version": DUAL_FORMAT_VERSION, "domain": list(dual.box.texts),
        "grid": int(dual.grid), "coefficient_denominator": str(dual.coefficient_denominator),
        "volume_denominator": str(dual.volume_denominator), "volume_factor_squared": str(dual.volume_factor_squared),
        "boundary_area_denominator": str(dual.boundary_area_denominator),
        "boundary_factors_squared": [str(f) for f in dual.boundary_factors_squared],
        "sha256": {name: hashlib.sha256(blob).hexdigest() for name, blob in blobs.items()},
    }
    blobs = {"manifest": _npy(np.frombuffer(json.dumps(manifest, sort_keys=True).encode(), dtype=np.uint8)), **blobs}
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED, allowZip64=True) as archive:
        for name, blob in blobs.items():
            info = zipfile.ZipInfo(f"{name}.npy", date_time=_STAMP)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            archive.writestr(info, blob, compresslevel=6)
    atomic_write(path, buffer.getvalue())


def _regular(path: Path) -> None:
    try:
        info = os.stat(path)
    except OSError as error:
        raise FormatError(f"{path}: cannot read: {error.strerror or error}") from None
    if not stat.S_ISREG(info.st_mode):
        raise FormatError(f"{path}: cannot read: not a regular file")
    if info.st_size > MAX_DUAL_FILE:
        raise FormatError(f"{path}: cannot read: too large ({info.st_size} bytes; at most {MAX_DUAL_FILE})")


def _member(archive: zipfile.ZipFile, name: str, path: Path, limit: int) -> tuple[bytes, np.ndarray]:
    info = archive.getinfo(f"{name}.npy")
    if info.file_size > limit:
        raise FormatError(f"{path}: member {name}: {info.file_size} bytes, more than the file can hold")
    blob = archive.read(info)  # checks the zip's CRC: a damaged member raises here
    try:
        array = np.lib.format.read_array(io.BytesIO(blob), allow_pickle=False)
    except (ValueError, EOFError, OSError) as error:
        raise FormatError(f"{path}: member {name}: not a numpy array: {error}") from None
    return blob, array


def _check_headers(archive: zipfile.ZipFile, path: Path) -> None:
    """Every member's type and shape from its .npy header, checked against the others and against
    this machine's memory before any member's data is read.

    A file of 2 MB whose one member inflated to 2 GB of zeros took 4 GB and 13 CPU-seconds
    to refuse (after it was read, as a checksum mismatch); re-signed, it would have been read
    whole. The headers are a few hundred bytes; a member whose data is not what its header
    says is damaged.
    """
    headers = {}
    for name in MEMBERS:
        info = archive.getinfo(f"{name}.npy")
        with archive.open(info) as stream:
            try:
                version = np.lib.format.read_magic(stream)
                read_header = {(1, 0): np.lib.format.read_array_header_1_0,
                               (2, 0): np.lib.format.read_array_header_2_0}.get(version)
                if read_header is None:
                    raise ValueError(f"format version {version}, not 1.0 or 2.0")
                shape, _, dtype = read_header(stream)
            except (ValueError, EOFError, OSError, SyntaxError) as error:
                raise FormatError(f"{path}: member {name}: not a numpy array: {error}") from None
            offset = stream.tell()
        if dtype.hasobject or info.file_size != offset + math.prod(shape) * dtype.itemsize:
            raise FormatError(f"{path}: member {name}: its data is not the {dtype} {shape} its header says")
        headers[name] = dtype, shape
    counts = {"n": headers["grid_vertices"][1][:1], "m": headers["edges"][1][:1],
              "e": headers["element_circumcenter"][1][:1]}
    for name, (kinds, columns, count) in MEMBERS.items():
        dtype, shape = headers[name]
        expected = counts[count] + (() if columns is None else (columns,))
        if dtype.kind not in kinds or shape != expected:
            raise FormatError(f"{path}: member {name}: {dtype} {shape}, expected {'/'.join(kinds)} {expected}")
    needed = 2 * sum(archive.getinfo(f"{name}.npy").file_size for name in MEMBERS)  # the data and its array
    if needed > machine_memory() // 2:
        raise FormatError(f"{path}: cannot read: its members need {needed:,} bytes, more than half this "
                          f"machine's memory ({machine_memory() // 2:,})")


def read_dual(path: str | Path) -> Dual:
    """Read a ``dual.npz``; a malformed, truncated or tampered file raises :class:`FormatError` (one line)."""
    path = Path(path)
    _regular(path)
    size = os.stat(path).st_size
    try:
        with zipfile.ZipFile(path) as archive:
            names = sorted(archive.namelist())
            expected = sorted(f"{name}.npy" for name in ("manifest", *MEMBERS))
            if names != expected:
                extra = sorted(set(names) ^ set(expected))
                raise FormatError(f"{path}: not a cospherical dual: member {extra[0] if extra else '?'} "
                                  f"{'unexpected' if extra and extra[0] in names else 'missing'}")
            limit = max(size * 1100, 1 << 20)  # deflate's best ratio is about 1000
            _, raw = _member(archive, "manifest", path, 1 << 20)
            manifest = _manifest(raw, path)
            _check_headers(archive, path)
            arrays = {}
            for name in MEMBERS:
                blob, arrays[name] = _member(archive, name, path, limit)
                if hashlib.sha256(blob).hexdigest() != manifest["sha256"].get(name):
                    raise FormatError(f"{path}: member {name}: checksum mismatch (the file was changed or damaged)")
    except MemoryError:
        raise FormatError(f"{path}: cannot read: its members need more memory than this process may use") from None
    except (zipfile.BadZipFile, zipfile.LargeZipFile, zlib.error, EOFError, OSError, ValueError) as error:
        if isinstance(error, FormatError):
            raise
        raise FormatError(f"{path}: not a readable dual.npz (truncated or damaged): {error}") from None
    return _dual(arrays, manifest, path)


def _manifest(raw: np.ndarray, path: Path) -> dict:
    try:
        text = raw.astype(np.uint8).tobytes().decode()
    except (ValueError, UnicodeDecodeError):
        raise FormatError(f"{path}: member manifest: not JSON") from None
    # the readers' one JSON parser: bounded nesting (100,000 brackets were a RecursionError
    # traceback), no repeated key, no number of thousands of digits
    manifest = parse_json(text, f"{path}: member manifest", max_digits=_MAX_TEXT_DIGITS)
    if not isinstance(manifest, dict) or manifest.get("format") != "cospherical-dual":
        raise FormatError(f"{path}: not a cospherical dual (its manifest names no format cospherical-dual)")
    if manifest.get("version") != DUAL_FORMAT_VERSION:
        raise FormatError(f"{path}: dual format version {manifest.get('version')!r}; this reads {DUAL_FORMAT_VERSION}")
    for key, kind in (("domain", list), ("grid", int), ("coefficient_denominator", str), ("volume_denominator", str),
                      ("volume_factor_squared", str), ("boundary_area_denominator", str),
                      ("boundary_factors_squared", list), ("sha256", dict)):
        if not isinstance(manifest.get(key), kind):
            raise FormatError(f"{path}: manifest: {key} missing or not a {kind.__name__}")
    return manifest


def _integers(array: np.ndarray, name: str, path: Path) -> np.ndarray:
    if array.dtype.kind == "i":
        return array.astype(np.int64)
    text = array.astype(str).reshape(-1).tolist()
    if any(not _INTEGER.fullmatch(x) for x in text):
        raise FormatError(f"{path}: member {name}: not integers of at most {_MAX_DIGITS} digits")
    return np.array([int(x) for x in text], dtype=object).reshape(array.shape)


def _dual(arrays: dict, manifest: dict, path: Path) -> Dual:
    edges = arrays["edges"]
    if len(edges) and (edges.min() < 0 or edges.max() >= len(arrays["grid_vertices"]) or np.any(edges[:, 0] >= edges[:, 1])):
        raise FormatError(f"{path}: member edges: a pair that is not two vertices i < j")
    factors = manifest["boundary_factors_squared"]
    if len(factors) != 3 or not all(isinstance(f, str) and _POSITIVE_FRACTION.fullmatch(f) for f in factors):
        raise FormatError(f"{path}: manifest: boundary_factors_squared is not three positive fractions of at most "
                          "1000 digits")
    for key, pattern in (("coefficient_denominator", _POSITIVE), ("volume_denominator", _POSITIVE),
                         ("volume_factor_squared", _POSITIVE_FRACTION), ("boundary_area_denominator", _POSITIVE)):
        if not pattern.fullmatch(manifest[key]):
            raise FormatError(f"{path}: manifest: {key} is not a positive integer or fraction of at most 1000 digits")
    if not 0 < manifest["grid"] <= MAX_GRID:
        raise FormatError(f"{path}: manifest: grid {manifest['grid']} is not in 1..{MAX_GRID}")
    try:
        box = Box.parse(manifest["domain"])
        grid = int(manifest["grid"])
        cden, vden = int(manifest["coefficient_denominator"]), int(manifest["volume_denominator"])
        bden = int(manifest["boundary_area_denominator"])
        factor_squared = Fraction(manifest["volume_factor_squared"])
        factor = math.sqrt(factor_squared)
        plane_squared = tuple(Fraction(f) for f in factors)
    except (ValueError, TypeError, ZeroDivisionError, OverflowError) as error:
        raise FormatError(f"{path}: manifest: {error}") from None
    vertices = arrays["grid_vertices"]
    if len(vertices) and (vertices.min() < 0 or vertices.max() > grid):
        raise FormatError(f"{path}: member grid_vertices: a vertex outside the grid of {grid} intervals per side")
    squared = tuple(Fraction(x) for x in box.squared)
    if plane_squared != tuple(squared[(k + 1) % 3] * squared[(k + 2) % 3] for k in range(3)):
        raise FormatError(f"{path}: manifest: boundary_factors_squared are not the domain's (b^2 c^2, a^2 c^2, a^2 b^2)")
    return Dual(box=box, grid=grid, grid_vertices=arrays["grid_vertices"].astype(np.int64),
                vertices=arrays["vertices"], edges=edges.astype(np.int64), length=arrays["length"],
                area=arrays["area"], coefficient=arrays["coefficient"], control_volume=arrays["control_volume"],
                boundary=arrays["boundary"], boundary_area=arrays["boundary_area"],
                coefficient_exact=_integers(arrays["coefficient_exact"], "coefficient_exact", path),
                coefficient_denominator=cden, volume_exact=_integers(arrays["volume_exact"], "volume_exact", path),
                volume_denominator=vden, volume_factor=factor, volume_factor_squared=factor_squared,
                boundary_area_exact=_integers(arrays["boundary_area_exact"], "boundary_area_exact", path),
                boundary_area_denominator=bden, boundary_factors_squared=plane_squared,
                element_circumcenter=arrays["element_circumcenter"])
