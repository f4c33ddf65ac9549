"""``dual.npz``: the finite-volume dual of a mesh, for a solver (reading and writing only).

A zip of ``.npy`` arrays (``numpy.load`` opens it; no pickles), each deflated at
zlib's fastest level (a fifth of the default level's time for about a quarter more
bytes) in blocks on every core (:mod:`~cospherical.formats.deflated`), written deterministically (fixed member order and time stamps: the same mesh
gives the same bytes) and atomically.  Members, ``n`` vertices, ``m`` edges, ``e`` elements:

===========================  ==========  ==================================================
``manifest``                 uint8       JSON text: ``format`` (``cospherical-dual``),
                                         ``version`` (3; 5 for a device, below), ``domain`` (the box, exact
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
``boundary_area_exact``      int64 n x3  per axis k, the part in the boundary faces normal
                                         to k (a box's two sides): ``boundary_area = sum over k of
                                         boundary_area_exact[:, k] * sqrt(
                                         boundary_factors_squared[k]) /
                                         boundary_area_denominator``, the factors
                                         ``(b^2 c^2, a^2 c^2, a^2 b^2)`` for a box
                                         ``a x b x c`` (decimal text, ``U``, when int64
                                         is too narrow); on a box each column sums to
                                         twice the denominator
``element_circumcenter``     f8 e x 3    the real circumcenter of each element (mesh order)
``element_nodes``            int e x w   each element's global vertex ids (mesh order),
                                         padded with -1; ``4 <= w <= 64``
``element_sizes``            int e       each element's number of vertices
===========================  ==========  ==================================================

A device's dual (``mesh --device ... --dual``) is version 5: the members above, whose
boundary is the domain's (the union of its boxes: every face met by one element, also
in a notch or a hole inside the bounding box), plus its parts per region, its contacts
and its interfaces (manifest: ``region_names``, ``region_materials``,
``contact_names``, ``contact_regions`` (region indices), ``contact_boxes`` (exact
texts, device units), ``region_boxes`` (per region its boxes: the domain),
``origin`` (the bounding box's low corner, where the grid starts),
``interface_regions`` (per interface its two regions ``[a, b]``, ``a < b``; named
``"a|b"``) and the four part denominators)::

    element_region                   int e     each element's region
    volume_part_vertex, _region      int p     one row per (vertex, region), sorted
    volume_part_exact, volume_part   iU/f8 p   over volume_part_denominator, times
                                               sqrt(volume_factor_squared): its part
                                               of the vertex's control volume
    coupling_part_edge, _region      int q     one row per (edge, region), sorted
    coupling_part_exact, coupling_part         over coupling_part_denominator, times
                                               sqrt(volume_factor_squared): its part
                                               of the edge's coefficient
    contact_face_nodes               int f x w each contact face (polygon, -1 padded)
    contact_face_contact             int f     its contact
    contact_part_vertex, _contact    int r     one row per (vertex, contact), sorted
    contact_part_exact, contact_part iU/f8 r   over contact_part_denominator (device
                                               units): its part of the contact's area
    interface_face_nodes             int g x w each interface face (polygon, -1 padded,
                                               counter-clockwise seen from region a)
    interface_face_interface         int g     its interface
    interface_part_vertex, _interface int s    one row per (vertex, interface), sorted
    interface_part_exact,            iU/f8 s   over interface_part_denominator (device
    interface_part                             units): its part of the interface's area

The parts of a vertex or an edge sum to its total exactly, a region's volume parts
to its volume, a contact's area parts to its rectangle's area, an interface's to the
area where its two regions touch.  A one-box mesh (one region) writes version 3, byte
for byte as before.  Version 4 (a device's dual before version 5) lacks the interface
members and counts the boundary in the bounding box's sides only; all three are read,
and :func:`verify_dual` computes a version 4 or 5 file's parts again from its
elements, their regions and its contact faces (version 5: its boundary and interfaces
from the faces its elements meet once and those between two regions), and proves the
elements a mesh of the union of boxes.

The reader refuses, with one line, a file that is not such a zip, lacks or adds a
member, has an array of the wrong kind or shape, fails a checksum (a truncated or
tampered file), has edges that name no vertex, or elements that are not lists of
distinct vertices.  Versions 1 (no exact boundary areas) and 2 (no elements) are
refused with their version named.

A checksum is no proof: whoever changes a member can renew it.  So
:func:`verify_dual` (``cospherical check``) computes the dual again from the
vertices and elements the file holds and compares every edge, coefficient, control
volume and boundary area with the file's, exactly, and every float with the one the
exact value gives.  A change that keeps the sums (one coefficient ``+k``, another
``-k``) is refused with the first edge it changed.  The cost is that of computing
the dual from its elements (their shapes found by sorting, each shape measured once):
0.5 CPU-s in all, reading and the proof below included, for the 50,912 elements of the
21,512-leaf example of the results page, 4.6 CPU-s for the 799,984 of the README's level-8 tree.
Sums cannot see elements that
overlap and leave a hole of the same volume, so the elements are also proved a mesh
of the domain: every face shared by exactly two elements in opposite orientations, or
by one in the domain's boundary (the mesher's own conformity rule, its memory bounded
before the faces are made).  Elements whose distinct shapes
would need more exact hull work than their number justifies (a small file of many
different 64-vertex shapes would take hours) are refused before any hull is computed.
The circumcentres
(``element_circumcenter``, floats for display) are not compared.
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
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from ..core.configuration import Box
from ..errors import FormatError, InputError, shown
from ..files.yamlio import atomic_open, machine_memory, parse_json
from ..mesh.device import NAME
from ..mesh.device import DeviceLayout
from ..mesh.dual import Dual, InterfaceParts, RegionParts
from .deflated import deflate_workers, write_zip

__all__ = ["DUAL_FORMAT_VERSION", "domain_sums", "dual_layout", "read_dual", "verify_dual", "write_dual"]

DUAL_FORMAT_VERSION = 5
# Version 3 is version 5 without the region and interface members: a one-box mesh (one region) still
# writes it, byte for byte as before.  Version 4 (a device's dual before version 5) has the region
# members but no interfaces, and its boundary figures are the bounding box's sides; all three are read
# (a version 4 dual read and written again stays version 4).
_VERSIONS = (3, 4, 5)
_MAX_DUAL_FILE = 16 * 1024**3
# member -> (dtype kind, columns or None, which count: n vertices, m edges, e elements)
_MEMBERS = {
    "grid_vertices": ("i", 3, "n"), "vertices": ("f", 3, "n"), "edges": ("i", 2, "m"), "length": ("f", None, "m"),
    "area": ("f", None, "m"), "coefficient": ("f", None, "m"), "coefficient_exact": ("iU", None, "m"),
    "control_volume": ("f", None, "n"), "volume_exact": ("iU", None, "n"), "boundary": ("b", None, "n"),
    "boundary_area": ("f", None, "n"), "boundary_area_exact": ("iU", 3, "n"), "element_circumcenter": ("f", 3, "e"),
    "element_nodes": ("i", "w", "e"), "element_sizes": ("i", None, "e"),
}
# a device's members (versions 4 and 5): p control-volume parts, q coupling parts, f contact faces, r contact area parts
_REGION_MEMBERS = {
    "element_region": ("i", None, "e"),
    "volume_part_vertex": ("i", None, "p"), "volume_part_region": ("i", None, "p"),
    "volume_part_exact": ("iU", None, "p"), "volume_part": ("f", None, "p"),
    "coupling_part_edge": ("i", None, "q"), "coupling_part_region": ("i", None, "q"),
    "coupling_part_exact": ("iU", None, "q"), "coupling_part": ("f", None, "q"),
    "contact_face_nodes": ("i", "w", "f"), "contact_face_contact": ("i", None, "f"),
    "contact_part_vertex": ("i", None, "r"), "contact_part_contact": ("i", None, "r"),
    "contact_part_exact": ("iU", None, "r"), "contact_part": ("f", None, "r"),
}
# a device's interfaces (version 5): g interface faces, s interface area parts
_INTERFACE_MEMBERS = {
    "interface_face_nodes": ("i", "w", "g"), "interface_face_interface": ("i", None, "g"),
    "interface_part_vertex": ("i", None, "s"), "interface_part_interface": ("i", None, "s"),
    "interface_part_exact": ("iU", None, "s"), "interface_part": ("f", None, "s"),
}
_MAX_NAMES = 64
# the most vertices an element may list: a leaf's 26 points, or a cell of the global mode (co-spherical
# grid points); bounds the exact hull computed per distinct element shape when the dual is verified
_MAX_ELEMENT_NODES = 64
# The exact work of verifying: a hull per distinct element shape, which tries every triple of its
# vertices (about 2 microseconds a triple; 0.1 CPU-s at 64 vertices). A file of many distinct large
# shapes would take hours, so their triples are bounded before any hull: a fixed allowance (about 2
# CPU-s) and so many per element (our meshes need a few: the results page's 50,912 elements are 363
# shapes of at most 8 vertices, 3,660 triples), which keeps the hulls within a few times the rest.
_TRIPLES_ALLOWED = 1_000_000
_TRIPLES_PER_ELEMENT = 100
# Every member is deflated at zlib's fastest level: on the README's level-8 tree (172 MB of arrays) level 6 took
# 3.0 CPU-s for a file of 18.2 MB, level 1 0.6 CPU-s for 22.8 MB (1.26 times larger); a whole `mesh --out` run
# without the dual takes about 1.5 CPU-s.  Each member still shrinks 4 to 100 times at level 1, so none is stored
# uncompressed.  The deflating runs in blocks on every core (formats.deflated): 0.4 s of wall time on 2 cores.
_DEFLATE_LEVEL = 1
# Exact integers too wide for int64 are written as decimal text, at least this wide (a wider column only
# where a value needs it: the files of earlier versions keep their bytes)
_TEXT_WIDTH = 200
# the manifest's exact numbers as written: plain integers and fractions of bounded length, so that a
# hostile text such as "1e999999999" never reaches Fraction (which would compute 10**999999999)
# the manifest's exact numbers, and the members' written as text: under Python's own bound on decimal text
# (sys.int_max_str_digits, 4300 by default); a 1e-12 x 1 x 3e9 box's coefficients need 1049 digits at level 4
_MAX_TEXT_DIGITS = 4000
_INTEGER = re.compile(r"-?[0-9]{1,%d}" % _MAX_TEXT_DIGITS)
_POSITIVE = re.compile(r"[1-9][0-9]{0,%d}" % (_MAX_TEXT_DIGITS - 1))
_POSITIVE_FRACTION = re.compile(r"[1-9][0-9]{0,%d}(/[1-9][0-9]{0,%d})?" % (_MAX_TEXT_DIGITS - 1, _MAX_TEXT_DIGITS - 1))
_MAX_GRID = 1 << 40
_FRACTION = re.compile(r"-?[0-9]{1,%d}(/[1-9][0-9]{0,%d})?" % (_MAX_TEXT_DIGITS - 1, _MAX_TEXT_DIGITS - 1))


def _npy(array: np.ndarray) -> tuple[bytes, memoryview]:
    """The ``.npy`` file of ``array`` (what ``numpy.save`` writes: a version 1.0 header, the C-order data) as its
    header and its data, the data a view of the array's bytes (no copy when the array is contiguous)."""
    array = np.ascontiguousarray(array)
    if array.dtype.hasobject:
        raise ValueError("dual.npz holds no pickles: an object array must be written as text")
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, np.lib.format.header_data_from_array_1_0(array))
    return header.getvalue(), array.reshape(-1).view(np.uint8).data


def _exact(array: np.ndarray) -> np.ndarray:
    if array.dtype != object:
        return array
    # Python integers as decimal text (str of each, in one cast), never cut: a cast to a narrower text
    # column drops the last digits without a word (lengths of 37-digit fractions need 220)
    text = array.astype(str)
    width = text.dtype.itemsize // np.dtype("U1").itemsize
    if width > _MAX_TEXT_DIGITS:
        raise InputError(f"the dual's exact values need {width} digits, more than dual.npz holds "
                         f"({_MAX_TEXT_DIGITS}): give the domain's lengths with fewer digits")
    return text.astype(f"U{max(width, _TEXT_WIDTH)}")


def write_dual(dual: Dual, path: str | Path) -> None:
    """Write ``dual`` as ``dual.npz`` (see the module), atomically and deterministically."""
    arrays = {name: getattr(dual, name) for name in _MEMBERS}
    arrays["coefficient_exact"] = _exact(arrays["coefficient_exact"])
    arrays["volume_exact"] = _exact(arrays["volume_exact"])
    arrays["boundary_area_exact"] = _exact(arrays["boundary_area_exact"])
    parts = dual.regions
    extra = {}
    if parts is not None:
        arrays.update({
            "element_region": parts.element_region.astype(np.int32),
            "volume_part_vertex": parts.volume_vertex, "volume_part_region": parts.volume_region.astype(np.int32),
            "volume_part_exact": _exact(parts.volume_exact), "volume_part": parts.volume_part,
            "coupling_part_edge": parts.coupling_edge, "coupling_part_region": parts.coupling_region.astype(np.int32),
            "coupling_part_exact": _exact(parts.coupling_exact), "coupling_part": parts.coupling_part,
            "contact_face_nodes": _face_rows(parts.contact_face_nodes),
            "contact_face_contact": parts.contact_face_contact.astype(np.int32),
            "contact_part_vertex": parts.contact_vertex, "contact_part_contact": parts.contact_contact.astype(np.int32),
            "contact_part_exact": _exact(parts.contact_exact), "contact_part": parts.contact_part})
        extra = {"region_names": list(parts.names), "region_materials": list(parts.materials),
                 "contact_names": list(parts.contact_names), "contact_regions": [int(r) for r in parts.contact_regions],
                 "contact_boxes": [list(b) for b in parts.contact_boxes],
                 "volume_part_denominator": str(parts.volume_denominator),
                 "coupling_part_denominator": str(parts.coupling_denominator),
                 "contact_part_denominator": str(parts.contact_denominator),
                 "origin": [str(x) for x in parts.origin],
                 "region_boxes": [[list(box) for box in boxes] for boxes in parts.boxes]}
    interfaces = parts.interfaces if parts is not None else None
    if interfaces is not None:
        arrays.update({
            "interface_face_nodes": _face_rows(interfaces.face_nodes),
            "interface_face_interface": interfaces.face_interface.astype(np.int32),
            "interface_part_vertex": interfaces.vertex, "interface_part_interface": interfaces.interface.astype(np.int32),
            "interface_part_exact": _exact(interfaces.exact), "interface_part": interfaces.part})
        extra.update({"interface_regions": [[int(a), int(b)] for a, b in interfaces.regions.tolist()],
                      "interface_part_denominator": str(interfaces.denominator)})
    members = {name: _npy(array) for name, array in arrays.items()}
    version = 3 if parts is None else 4 if interfaces is None else DUAL_FORMAT_VERSION
    with ThreadPoolExecutor(deflate_workers(), thread_name_prefix="dual.npz") as pool:
        # the checksums first (the manifest, the first member, holds them), on every core, then every member
        # deflated in blocks on every core and written in order as it comes (formats.deflated)
        digests = {name: pool.submit(_sha256, *member) for name, member in members.items()}
        manifest = {
            "format": "cospherical-dual", "version": version, **extra,
            "domain": list(dual.box.texts),
            "grid": int(dual.grid), "coefficient_denominator": str(dual.coefficient_denominator),
            "volume_denominator": str(dual.volume_denominator),
            "volume_factor_squared": str(dual.volume_factor_squared),
            "boundary_area_denominator": str(dual.boundary_area_denominator),
            "boundary_factors_squared": [str(f) for f in dual.boundary_factors_squared],
            "sha256": {name: digest.result() for name, digest in digests.items()},
        }
        members = {"manifest": _npy(np.frombuffer(json.dumps(manifest, sort_keys=True).encode(), dtype=np.uint8)),
                   **members}
        # straight into the file (no copy of the zip in memory), in place only once whole
        with atomic_open(path, binary=True) as handle:
            write_zip(handle, [(f"{name}.npy", member) for name, member in members.items()], _DEFLATE_LEVEL, pool)


def _sha256(header: bytes, data: memoryview) -> str:
    digest = hashlib.sha256(header)
    digest.update(data)
    return digest.hexdigest()


def _face_rows(faces: np.ndarray) -> np.ndarray:
    """Contact polygons as rows of at least 4 columns (-1 padded): the element rule of the reader."""
    faces = faces.reshape(len(faces), -1) if len(faces) else np.zeros((0, 4), dtype=np.int32)
    if faces.shape[1] < 4:
        faces = np.pad(faces, ((0, 0), (0, 4 - faces.shape[1])), constant_values=-1)
    return faces.astype(np.int32)


def _regular(path: Path) -> None:
    try:
        info = os.stat(path)
    except OSError as error:
        raise FormatError(f"{path}: cannot read: {error.strerror or error}") from None
    if not stat.S_ISREG(info.st_mode):
        raise FormatError(f"{path}: cannot read: not a regular file")
    if info.st_size > _MAX_DUAL_FILE:
        raise FormatError(f"{path}: cannot read: too large ({info.st_size} bytes; at most {_MAX_DUAL_FILE})")


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


def _check_headers(archive: zipfile.ZipFile, path: Path, members: dict[str, tuple[str, int | str | None, str]]) -> None:
    """Every member's type and shape from its .npy header, checked against the others and against
    this machine's memory before any member's data is read.

    A file of 2 MB whose one member inflated to 2 GB of zeros took 4 GB and 13 CPU-seconds
    to refuse (after it was read, as a checksum mismatch); re-signed, it would have been read
    whole. The headers are a few hundred bytes; a member whose data is not what its header
    says is damaged.
    """
    headers = {}
    for name in members:
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
    for name, count in (("volume_part_vertex", "p"), ("coupling_part_edge", "q"), ("contact_face_contact", "f"),
                        ("contact_part_vertex", "r"), ("interface_face_interface", "g"),
                        ("interface_part_vertex", "s")):
        if name in headers:
            counts[count] = headers[name][1][:1]
    for name, (kinds, columns, count) in members.items():
        dtype, shape = headers[name]
        if columns == "w":  # any width from 4 to _MAX_ELEMENT_NODES
            columns = shape[1] if len(shape) == 2 and 4 <= shape[1] <= _MAX_ELEMENT_NODES else "4..64"
        expected = counts[count] + (() if columns is None else (columns,))
        if dtype.kind not in kinds or shape != expected:
            raise FormatError(f"{path}: member {name}: {dtype} {shape}, expected {'/'.join(kinds)} {expected}")
    needed = 2 * sum(archive.getinfo(f"{name}.npy").file_size for name in members)  # the data and its array
    if needed > machine_memory() // 2:
        raise FormatError(f"{path}: cannot read: its members need {needed:,} bytes, more than half this "
                          f"machine's memory ({machine_memory() // 2:,})")


def read_dual(path: str | Path) -> Dual:
    """Read a ``dual.npz``; a malformed, truncated or tampered file raises :class:`FormatError` (one line).

    Tampered: a member whose bytes its manifest's SHA-256 does not vouch for. What is read is
    bounded and consistent in shape and index (no pickle, no index outside its array), but a
    file forged and signed again can hold values its elements do not give (a float column
    that is not its exact column, a coefficient moved between edges): :func:`verify_dual`
    (``cospherical check``) computes the dual again from the elements and refuses those.
    """
    path = Path(path)
    _regular(path)
    size = os.stat(path).st_size
    try:
        with zipfile.ZipFile(path) as archive:
            names = sorted(archive.namelist())
            twice = next((a for a, b in zip(names, names[1:]) if a == b), None)
            if twice is not None:  # zipfile reads the last of them: which one a reader takes is not ours to guess
                raise FormatError(f"{path}: not a cospherical dual: member {shown(twice)} appears twice")
            members = _MEMBERS
            if "element_region.npy" in names:
                members = {**_MEMBERS, **_REGION_MEMBERS}
                if "interface_face_nodes.npy" in names:
                    members = {**members, **_INTERFACE_MEMBERS}
            expected = sorted(f"{name}.npy" for name in ("manifest", *members))
            if names != expected:
                extra = sorted(set(names) ^ set(expected))
                raise FormatError(f"{path}: not a cospherical dual: member {extra[0] if extra else '?'} "
                                  f"{'unexpected' if extra and extra[0] in names else 'missing'}")
            # deflate's best ratio is about 1000; a member stored uncompressed (some other writer's) is at most
            # the file: either way no member is larger than this
            limit = max(size * 1100, 1 << 20)
            _, raw = _member(archive, "manifest", path, 1 << 20)
            manifest = _manifest(raw, path)
            expected_members = {3: len(_MEMBERS), 4: len(_MEMBERS) + len(_REGION_MEMBERS),
                                5: len(_MEMBERS) + len(_REGION_MEMBERS) + len(_INTERFACE_MEMBERS)}
            if expected_members[manifest["version"]] != len(members):
                raise FormatError(f"{path}: dual format version {manifest['version']} with the members of "
                                  f"another version ({'with' if 'element_region' in members else 'without'} the "
                                  f"region members, {'with' if 'interface_face_nodes' in members else 'without'} "
                                  "the interface members)")
            _check_headers(archive, path, members)
            arrays = {}
            for name in members:
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


def _manifest(raw: np.ndarray, path: Path) -> dict[str, Any]:
    try:
        text = raw.astype(np.uint8).tobytes().decode()
    except (ValueError, UnicodeDecodeError):
        raise FormatError(f"{path}: member manifest: not JSON") from None
    # the readers' one JSON parser: bounded nesting (100,000 brackets were a RecursionError
    # traceback), no repeated key, no number of thousands of digits
    manifest = parse_json(text, f"{path}: member manifest", max_digits=_MAX_TEXT_DIGITS)
    if not isinstance(manifest, dict) or manifest.get("format") != "cospherical-dual":
        raise FormatError(f"{path}: not a cospherical dual (its manifest names no format cospherical-dual)")
    version = manifest.get("version")
    if type(version) is not int or version not in _VERSIONS:  # 5.0 and True are not versions the writer writes
        raise FormatError(f"{path}: dual format version {shown(version)}; this reads "
                          f"{', '.join(map(str, _VERSIONS[:-1]))} and {_VERSIONS[-1]} (write it again with "
                          "cospherical mesh --dual)")
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
        raise FormatError(f"{path}: member {name}: not integers of at most {_MAX_TEXT_DIGITS} digits")
    return np.array([int(x) for x in text], dtype=object).reshape(array.shape)


def _dual(arrays: dict[str, np.ndarray], manifest: dict[str, Any], path: Path) -> Dual:
    edges = arrays["edges"]
    if len(edges) and (edges.min() < 0 or edges.max() >= len(arrays["grid_vertices"]) or np.any(edges[:, 0] >= edges[:, 1])):
        raise FormatError(f"{path}: member edges: a pair that is not two vertices i < j")
    factors = manifest["boundary_factors_squared"]
    if len(factors) != 3 or not all(isinstance(f, str) and _POSITIVE_FRACTION.fullmatch(f) for f in factors):
        raise FormatError(f"{path}: manifest: boundary_factors_squared is not three positive fractions of at most "
                          f"{_MAX_TEXT_DIGITS} digits")
    for key, pattern in (("coefficient_denominator", _POSITIVE), ("volume_denominator", _POSITIVE),
                         ("volume_factor_squared", _POSITIVE_FRACTION), ("boundary_area_denominator", _POSITIVE)):
        if not pattern.fullmatch(manifest[key]):
            raise FormatError(f"{path}: manifest: {key} is not a positive integer or fraction of at most {_MAX_TEXT_DIGITS} digits")
    if not 0 < manifest["grid"] <= _MAX_GRID:
        raise FormatError(f"{path}: manifest: grid {shown(manifest['grid'])} is not in 1..{_MAX_GRID}")
    try:
        box = Box.parse(manifest["domain"])
        grid = int(manifest["grid"])
        cden, vden = int(manifest["coefficient_denominator"]), int(manifest["volume_denominator"])
        bden = int(manifest["boundary_area_denominator"])
        factor_squared = Fraction(manifest["volume_factor_squared"])
        factor = math.sqrt(factor_squared)
        plane_squared = (Fraction(factors[0]), Fraction(factors[1]), Fraction(factors[2]))
    except (ValueError, TypeError, ZeroDivisionError, OverflowError) as error:
        raise FormatError(f"{path}: manifest: {error}") from None
    vertices = arrays["grid_vertices"]
    if len(vertices) and (vertices.min() < 0 or vertices.max() > grid):
        raise FormatError(f"{path}: member grid_vertices: a vertex outside the grid of {grid} intervals per side")
    nodes, sizes = _elements(arrays["element_nodes"], arrays["element_sizes"], len(vertices), path)
    squared = tuple(Fraction(x) for x in box.squared)
    if plane_squared != tuple(squared[(k + 1) % 3] * squared[(k + 2) % 3] for k in range(3)):
        raise FormatError(f"{path}: manifest: boundary_factors_squared are not the domain's (b^2 c^2, a^2 c^2, a^2 b^2)")
    # a polyhedron of k vertices has at most 2k - 4 faces: the most contact faces the elements can hold
    regions = _region_parts(arrays, manifest, len(vertices), len(edges), len(nodes), path, factor,
                            2 * int(sizes.astype(np.int64).sum())) \
        if "element_region" in arrays else None
    return Dual(box=box, grid=grid, grid_vertices=arrays["grid_vertices"].astype(np.int64),
                vertices=arrays["vertices"], edges=edges.astype(np.int64), length=arrays["length"],
                area=arrays["area"], coefficient=arrays["coefficient"], control_volume=arrays["control_volume"],
                boundary=arrays["boundary"], boundary_area=arrays["boundary_area"],
                coefficient_exact=_integers(arrays["coefficient_exact"], "coefficient_exact", path),
                coefficient_denominator=cden, volume_exact=_integers(arrays["volume_exact"], "volume_exact", path),
                volume_denominator=vden, volume_factor=factor, volume_factor_squared=factor_squared,
                boundary_area_exact=_integers(arrays["boundary_area_exact"], "boundary_area_exact", path),
                boundary_area_denominator=bden, boundary_factors_squared=plane_squared,
                element_circumcenter=arrays["element_circumcenter"], element_nodes=nodes, element_sizes=sizes,
                regions=regions)


def _region_parts(arrays: dict[str, np.ndarray], manifest: dict[str, Any], n_vertices: int, n_edges: int, n_elements: int, path: Path,
                  factor: float, n_face_bound: int) -> RegionParts:
    """A version 4 or 5 file's region members, checked: names, indices in range, denominators (before any geometry)."""
    # JSON values, their types checked below
    names: Any = manifest.get("region_names")
    materials: Any = manifest.get("region_materials")
    contacts: Any = manifest.get("contact_names")
    regions_of: Any = manifest.get("contact_regions")
    boxes: Any = manifest.get("contact_boxes")

    def texts(value: Any, count: int | None = None) -> bool:
        # the device file's rule for names (they go on to DEVSIM, Gmsh and VTU files as they are)
        return isinstance(value, list) and len(value) <= _MAX_NAMES and (count is None or len(value) == count) and \
            all(isinstance(x, str) and NAME.fullmatch(x) for x in value)

    if not texts(names) or not names or not texts(materials, len(names)) or len(set(names)) != len(names):
        raise FormatError(f"{path}: manifest: region_names and region_materials are not lists of up to "
                          f"{_MAX_NAMES} names (1 to 64 of A-Z a-z 0-9 _ . + -), the region names distinct")
    if not texts(contacts) or len(set(contacts)) != len(contacts) or not isinstance(regions_of, list) or \
            len(regions_of) != len(contacts) or \
            not all(type(r) is int and 0 <= r < len(names) for r in regions_of) or \
            not isinstance(boxes, list) or len(boxes) != len(contacts) or \
            not all(isinstance(b, list) and len(b) == 6 and all(isinstance(x, str) and _FRACTION.fullmatch(x)
                                                               for x in b) for b in boxes):
        raise FormatError(f"{path}: manifest: contact_names, contact_regions and contact_boxes do not agree")
    denominators = []
    for key in ("volume_part_denominator", "coupling_part_denominator", "contact_part_denominator"):
        if not isinstance(manifest.get(key), str) or not _POSITIVE.fullmatch(manifest[key]):
            raise FormatError(f"{path}: manifest: {key} is not a positive integer of at most {_MAX_TEXT_DIGITS} digits")
        denominators.append(int(manifest[key]))
    for name, bound in (("element_region", len(names)), ("volume_part_vertex", n_vertices),
                        ("volume_part_region", len(names)), ("coupling_part_edge", n_edges),
                        ("coupling_part_region", len(names)), ("contact_face_contact", len(contacts)),
                        ("contact_part_vertex", n_vertices), ("contact_part_contact", len(contacts))):
        values = arrays[name]
        if len(values) and (values.min() < 0 or values.max() >= bound):
            raise FormatError(f"{path}: member {name}: an index outside 0..{bound - 1}")
    faces = arrays["contact_face_nodes"]
    if np.any((faces < -1) | (faces >= n_vertices)) or np.any((faces[:, :3] < 0)):
        raise FormatError(f"{path}: member contact_face_nodes: a face that names no vertex")
    _distinct_faces(faces, n_face_bound, path)
    if len(arrays["element_region"]) != n_elements:
        raise FormatError(f"{path}: member element_region: not one region per element")
    origin: Any = manifest.get("origin")
    if not isinstance(origin, list) or len(origin) != 3 or not all(isinstance(x, str) and _FRACTION.fullmatch(x)
                                                                    for x in origin):
        raise FormatError(f"{path}: manifest: origin is not three exact numbers")
    region_boxes: Any = manifest.get("region_boxes")
    if not isinstance(region_boxes, list) or len(region_boxes) != len(names) or not all(
            isinstance(boxes, list) and 0 < len(boxes) <= 64 and all(
                isinstance(b, list) and len(b) == 6 and all(isinstance(x, str) and _FRACTION.fullmatch(x) for x in b)
                for b in boxes) for boxes in region_boxes):
        raise FormatError(f"{path}: manifest: region_boxes is not, per region, its boxes of six exact numbers")
    parts = RegionParts(
        tuple(names), tuple(materials), arrays["element_region"].astype(np.int32),
        arrays["volume_part_vertex"].astype(np.int64), arrays["volume_part_region"].astype(np.int32),
        _integers(arrays["volume_part_exact"], "volume_part_exact", path), denominators[0],
        arrays["coupling_part_edge"].astype(np.int64), arrays["coupling_part_region"].astype(np.int32),
        _integers(arrays["coupling_part_exact"], "coupling_part_exact", path), denominators[1],
        tuple(contacts), tuple(regions_of), tuple(tuple(b) for b in boxes), faces.astype(np.int32),
        arrays["contact_face_contact"].astype(np.int32), arrays["contact_part_vertex"].astype(np.int64),
        arrays["contact_part_contact"].astype(np.int32),
        _integers(arrays["contact_part_exact"], "contact_part_exact", path), denominators[2], factor,
        tuple(origin), tuple(tuple(tuple(b) for b in boxes) for boxes in region_boxes))
    if "interface_face_nodes" in arrays:
        parts.interfaces = _interface_parts(arrays, manifest, names, n_vertices, n_face_bound, path)
    floats: list[tuple[str, RegionParts | InterfaceParts, str]] = [
        (name, parts, name) for name in ("volume_part", "coupling_part", "contact_part")]
    if parts.interfaces is not None:
        floats.append(("interface_part", parts.interfaces, "part"))
    for name, holder, attribute in floats:  # the floats: what the exact values give
        try:
            given = getattr(holder, attribute)
        except OverflowError:  # a denominator of hundreds of digits: no float
            raise FormatError(f"{path}: manifest: {name}_denominator is too large for its parts to be floats") from None
        if not np.array_equal(arrays[name], given):
            raise FormatError(f"{path}: member {name}: not what the exact values give")
    return parts


def _interface_parts(arrays: dict[str, np.ndarray], manifest: dict[str, Any], names: list[str], n_vertices: int, n_face_bound: int,
                     path: Path) -> InterfaceParts:
    """A version 5 file's interface members, checked: region pairs, indices in range, faces of distinct
    vertices, the denominator (before any geometry)."""
    pairs = manifest.get("interface_regions")
    if not isinstance(pairs, list) or len(pairs) > _MAX_NAMES * (_MAX_NAMES - 1) // 2 or not all(
            isinstance(p, list) and len(p) == 2 and all(type(r) is int for r in p) and 0 <= p[0] < p[1] < len(names)
            for p in pairs) or len({tuple(p) for p in pairs}) != len(pairs):
        raise FormatError(f"{path}: manifest: interface_regions is not a list of distinct region pairs [a, b], a < b")
    denominator = manifest.get("interface_part_denominator")
    if not isinstance(denominator, str) or not _POSITIVE.fullmatch(denominator):
        raise FormatError(f"{path}: manifest: interface_part_denominator is not a positive integer of at most {_MAX_TEXT_DIGITS} "
                          "digits")
    for name, bound in (("interface_face_interface", len(pairs)), ("interface_part_vertex", n_vertices),
                        ("interface_part_interface", len(pairs))):
        values = arrays[name]
        if len(values) and (values.min() < 0 or values.max() >= bound):
            raise FormatError(f"{path}: member {name}: an index outside 0..{bound - 1}")
    faces = arrays["interface_face_nodes"]
    if np.any((faces < -1) | (faces >= n_vertices)) or np.any((faces[:, :3] < 0)):
        raise FormatError(f"{path}: member interface_face_nodes: a face that names no vertex")
    if len(faces) > n_face_bound:
        raise FormatError(f"{path}: member interface_face_nodes: {len(faces):,} faces, more than its elements have "
                          f"({n_face_bound:,})")
    _distinct_rows(faces, faces >= 0, path, "interface_face_nodes", "face")
    regions = np.array(pairs, dtype=np.int32).reshape(-1, 2)
    return InterfaceParts(regions, tuple(f"{names[a]}|{names[b]}" for a, b in regions.tolist()), faces.astype(np.int32),
                          arrays["interface_face_interface"].astype(np.int32),
                          arrays["interface_part_vertex"].astype(np.int64),
                          arrays["interface_part_interface"].astype(np.int32),
                          _integers(arrays["interface_part_exact"], "interface_part_exact", path), int(denominator))


def _distinct_faces(faces: np.ndarray, most: int, path: Path) -> None:
    """Contact faces: each of distinct vertices, no two of the same vertices, and no more than the elements
    have faces (``most``), refused in bulk before check walks them one by one (a face repeated three million
    times deflates to 115 kB and took 48 CPU-s)."""
    if len(faces) > most:
        raise FormatError(f"{path}: member contact_face_nodes: {len(faces):,} faces, more than its elements have "
                          f"({most:,})")
    _distinct_rows(faces, faces >= 0, path, "contact_face_nodes", "face")


def _distinct_rows(nodes: np.ndarray, used: np.ndarray, path: Path, member: str, row: str) -> None:
    """Refuse a row of ``nodes`` (its ``used`` entries; the rest padding) naming a vertex twice, or two rows
    of the same vertices: in bulk, with the first offending row named, before any geometry."""
    width = nodes.shape[1]
    ordered = np.sort(np.where(used, nodes, -1 - np.arange(width)[None, :]), axis=1)
    twice = np.any(ordered[:, 1:] == ordered[:, :-1], axis=1)
    if twice.any():
        raise FormatError(f"{path}: member {member}: {row} {int(np.flatnonzero(twice)[0])} names a vertex twice")
    if len(ordered) > 1 and _distinct_by_hash(ordered):
        return
    if len(ordered) > 1:  # a repeated row (or a hash collision): found, and the first pair named, by sorting rows
        order = np.lexsort(ordered.T[::-1])
        same = np.flatnonzero(np.all(ordered[order[1:]] == ordered[order[:-1]], axis=1))
        if len(same):
            first, second = sorted((int(order[same[0]]), int(order[same[0] + 1])))
            raise FormatError(f"{path}: member {member}: {row}s {first} and {second} have the same vertices")


def _distinct_by_hash(rows: np.ndarray) -> bool:
    """Whether the rows are all different, proved by sorting one hash per row and comparing the rows whose hashes
    are equal (``False``: some are equal, or two different rows share a hash)."""
    from ..mesh.dual.shapes import row_hashes

    hashed = np.sort(row_hashes(rows))
    return not np.any(hashed[1:] == hashed[:-1])


def _elements(nodes: np.ndarray, sizes: np.ndarray, n_vertices: int, path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The elements, checked: each 4 or more distinct vertex ids, then -1 padding (before any geometry)."""
    sizes = sizes.astype(np.int64)
    width = nodes.shape[1]
    if len(sizes) and (sizes.min() < 4 or sizes.max() > width):
        raise FormatError(f"{path}: member element_sizes: an element of {int(sizes.min() if sizes.min() < 4 else sizes.max())} "
                          f"vertices (4 to {width})")
    used = np.arange(width)[None, :] < sizes[:, None]
    if np.any(nodes[~used] != -1) or np.any(nodes[used] < 0) or np.any(nodes[used] >= n_vertices):
        raise FormatError(f"{path}: member element_nodes: an element names no vertex, or its padding is not -1")
    # Two elements of the same vertices: refused here, in bulk, because check's recomputation walks the
    # elements one by one in Python: ten million copies of one element deflate to a file of 225 kB
    # and took minutes before the edge comparison found them.
    _distinct_rows(nodes, used, path, "element_nodes", "element")
    return nodes.astype(np.int32), sizes.astype(np.int8)


@dataclass(frozen=True)
class _Vertices:
    """What :func:`~cospherical.mesh.dual.mesh_dual` reads of a mesh when it is given the elements."""

    box: Box
    grid: int
    vertices: np.ndarray


def _distinct_vertices(vertices: np.ndarray, path: str | Path) -> None:
    """Refuse two vertices at one grid point: an element holding both has an edge of length 0,
    which no dual has (its coefficient would divide by it)."""
    order = np.lexsort(vertices.T[::-1])
    same = np.flatnonzero(np.all(vertices[order[1:]] == vertices[order[:-1]], axis=1))
    if len(same):
        i, j = sorted(int(v) for v in order[same[0]:same[0] + 2])
        raise FormatError(f"{path}: member grid_vertices: vertices {i} and {j} are one grid point "
                          f"{vertices[i].tolist()}")


def _element_shapes(dual: Dual, path: str | Path) -> np.ndarray:
    """Each element's shape: a number equal for elements whose vertices, node for node, are translates of
    each other; from the vertex ids alone.  Elements whose distinct shapes need more exact hull work than
    :data:`_TRIPLES_ALLOWED` and :data:`_TRIPLES_PER_ELEMENT` allow (see there) are refused first.

    Shapes are told apart up to translation, finer than the dual's grouping (which also divides out
    a power of two), so the work counted is never less than the work done.
    """
    nodes, vertices = dual.element_nodes, dual.grid_vertices
    allowed = _TRIPLES_ALLOWED + _TRIPLES_PER_ELEMENT * len(nodes)
    seen: dict[bytes, int] = {}
    shape = np.empty(len(nodes), dtype=np.int64)
    triples = 0
    step = max(1, (1 << 17) // nodes.shape[1])  # elements per block: 3 MB of coordinates (24 bytes a vertex)
    for start in range(0, len(nodes), step):
        block = nodes[start:start + step].astype(np.int64)
        used = block >= 0
        coords = vertices[np.where(used, block, 0)]
        low = np.where(used[..., None], coords, np.iinfo(np.int64).max).min(axis=1)
        relative = np.where(used[..., None], coords - low[:, None, :], -1).reshape(len(block), -1)
        rows = np.ascontiguousarray(relative).view(np.dtype((np.void, relative.shape[1] * 8))).ravel()
        distinct, inverse = np.unique(rows, return_inverse=True)  # as raw bytes: ten times faster than axis=0
        numbers = np.empty(len(distinct), dtype=np.int64)
        for k, row in enumerate(distinct):
            key = row.tobytes()
            if key not in seen:
                seen[key] = len(seen)
                triples += math.comb(int((np.frombuffer(key, dtype=np.int64)[::3] >= 0).sum()), 3)
                if triples > allowed:
                    raise FormatError(f"{path}: member element_nodes: {len(seen):,} distinct element shapes whose "
                                      f"exact hulls are more work than {len(nodes):,} elements may need "
                                      f"({triples:,} vertex triples, at most {allowed:,})")
            numbers[k] = seen[key]
        shape[start:start + len(block)] = numbers[inverse.reshape(-1)]
    return shape


def _check_mesh(dual: Dual, shape: np.ndarray, path: str | Path, layout: DeviceLayout | None = None,
                element_region: np.ndarray | None = None) -> tuple[Any, ...] | None:
    """The elements are a mesh of the domain: every face met by exactly two elements, in opposite
    orientations, or by one in the domain's boundary
    (:func:`~cospherical.mesh.checks.pair_faces`, the mesher's own conformity rule).

    With positive volumes (every element is the hull of its vertices: not flat) and volumes
    adding up to the domain's (the control volumes, recomputed from the elements, sum to it),
    this proves that the elements tile the domain: crossing a face met from both sides keeps
    the number of elements over a point, so that number is the same all over the domain, and
    the volumes make it one.  Volume sums alone cannot see elements that overlap and leave a
    hole of the same volume.

    With ``element_region`` (a version 5 device), returns the faces paired by
    :func:`~cospherical.mesh.regions.face_sets` (the boundary's and the interfaces'), else ``None``.
    """
    from ..mesh.checks import element_faces, pair_faces
    from ..mesh.regions import face_sets

    owners: dict[int, list[np.ndarray]] | None = {} if element_region is not None else None
    try:
        faces = element_faces(dual.grid_vertices, dual.element_nodes, dual.element_sizes, shape, dual.box.squared,
                              machine_memory() // 2, owners=owners)
    except InputError as error:
        raise FormatError(f"{path}: member element_nodes: {error}") from None
    sets = None
    if owners is not None and element_region is not None:
        sizes = list(faces)
        sets = face_sets(np.concatenate([m for size in sizes for m in owners[size]]),
                         [f for size in sizes for f in faces[size]], element_region)
    found = pair_faces(faces, dual.grid_vertices, dual.grid, examples=1, layout=layout)
    if found.nonconforming_faces:
        corners = [[round(x * dual.grid) for x in corner] for corner in found.nonconforming_examples[0]]
        raise FormatError(f"{path}: member element_nodes: the elements are not a mesh: {found.nonconforming_faces:,} "
                          "faces are neither shared by two elements in opposite orientations nor in the domain's "
                          f"boundary, e.g. the face of grid points {', '.join(map(str, corners[:6]))}"
                          f"{', ...' if len(corners) > 6 else ''}")
    return sets


def verify_dual(dual: Dual, path: str | Path) -> None:
    """Compute ``dual`` again from its vertices and elements and compare, exactly (see the module).

    Raises :class:`FormatError` (one line) at the first difference: an edge, a vertex, or a
    float member that is not what its exact value gives.
    """
    from ..mesh.dual import as_floats, boundary_areas, mesh_dual
    from ..mesh.surfaces import set_domain_boundary

    _distinct_vertices(dual.grid_vertices, path)
    shape = _element_shapes(dual, path)
    layout = dual_layout(dual, path)
    interfaces = dual.regions.interfaces if dual.regions is not None else None
    if layout is not None and dual.regions is not None:
        _check_element_regions(dual, dual.regions, layout, path)
    sets = _check_mesh(dual, shape, path, layout,
                       dual.regions.element_region if dual.regions is not None and interfaces is not None else None)
    try:
        again = mesh_dual(_Vertices(dual.box, dual.grid, dual.grid_vertices), (dual.element_nodes, dual.element_sizes))
    except InputError as error:  # an element that is flat or not co-spherical has no dual
        raise FormatError(f"{path}: member element_nodes: {error}") from None
    if sets is not None:  # a version 5 device: its boundary is the faces met once (4: the bounding box's sides)
        _verify_interfaces(dual, sets, path)
        _, face, ones, _, _, _ = sets
        set_domain_boundary(again, face[ones])
    if not np.array_equal(again.edges, dual.edges):
        raise FormatError(f"{path}: member edges: not the edges of its elements ({len(dual.edges)} edges, "
                          f"its elements have {len(again.edges)})")
    g = dual.grid_vertices

    def first(where: np.ndarray) -> int:
        return int(np.flatnonzero(where)[0])

    def different(ours: np.ndarray, our_denominator: int, theirs: np.ndarray, their_denominator: int) -> np.ndarray:
        # a / d == b / e  <=>  a e == b d: Python integers, no overflow; over one denominator (the file's
        # are what a recomputation gives, unless altered) int64 numerators are compared as they are
        if our_denominator == their_denominator and ours.dtype == theirs.dtype == np.int64:
            left, right = ours, theirs
        else:
            left = ours.astype(object) * their_denominator
            right = theirs.astype(object) * our_denominator
        unequal: np.ndarray = np.asarray(np.asarray(left != right).reshape(len(ours), -1).any(axis=1))
        return unequal

    wrong = different(again.coefficient_exact, again.coefficient_denominator, dual.coefficient_exact,
                      dual.coefficient_denominator)
    if wrong.any():
        i, j = dual.edges[first(wrong)]
        raise FormatError(f"{path}: member coefficient_exact: edge {i}-{j} (grid points {g[i].tolist()}, "
                          f"{g[j].tolist()}) is not the coefficient its elements give")
    for name, ours, theirs in (("volume_exact", (again.volume_exact, again.volume_denominator),
                                (dual.volume_exact, dual.volume_denominator)),
                               ("boundary_area_exact", (again.boundary_area_exact, again.boundary_area_denominator),
                                (dual.boundary_area_exact, dual.boundary_area_denominator))):
        wrong = different(*ours, *theirs)
        if wrong.any():
            v = first(wrong)
            raise FormatError(f"{path}: member {name}: vertex {v} (grid point {g[v].tolist()}) is not what its "
                              "elements give")
    # the floats: what the writer computes from the file's own exact values, bit for bit
    lengths = np.array(dual.box.to_float())
    real = g * (lengths / dual.grid)
    edge_vectors = real[dual.edges[:, 1]] - real[dual.edges[:, 0]]
    length = np.sqrt((edge_vectors ** 2).sum(axis=1))
    coefficient = as_floats(dual.coefficient_exact, dual.coefficient_denominator, dual.volume_factor)
    expected = {"vertices": real, "length": length, "coefficient": coefficient, "area": coefficient * length,
                "control_volume": as_floats(dual.volume_exact, dual.volume_denominator, dual.volume_factor),
                "boundary": again.boundary,
                "boundary_area": boundary_areas(dual.boundary_area_exact, dual.boundary_area_denominator,
                                                dual.boundary_factors_squared)}
    for name, value in expected.items():
        wrong = np.asarray(np.asarray(getattr(dual, name) != value).reshape(len(value), -1).any(axis=1))
        if wrong.any():
            k = first(wrong)
            what = f"edge {dual.edges[k, 0]}-{dual.edges[k, 1]}" if len(value) == len(dual.edges) and name in (
                "length", "coefficient", "area") else f"vertex {k}"
            raise FormatError(f"{path}: member {name}: {what} is not what the exact values give")
    if dual.regions is not None:
        _verify_regions(dual, dual.regions, path)
    if sets is not None:
        dual.boundary_edge = again.boundary_edge  # verified: the edges in the boundary, which the file does not hold


def _check_element_regions(dual: Dual, parts: RegionParts, layout: DeviceLayout, path: str | Path) -> None:
    """Each element's region is the region of the box it lies in: the owner of the block holding its vertex
    centroid (an interior point; decided in integers, the centroid times the element's size against the block
    planes).  The parts check recomputes from ``element_region``; this proves ``element_region`` itself."""
    nodes, sizes = dual.element_nodes.astype(np.int64), dual.element_sizes.astype(np.int64)
    factor = dual.grid // layout.steps  # grid steps per step of the resolving level
    sums = np.where((nodes >= 0)[..., None], dual.grid_vertices[np.maximum(nodes, 0)], 0).sum(axis=1)
    owner = np.empty(len(nodes), dtype=np.int64)
    for size in np.unique(sizes).tolist():
        rows = np.flatnonzero(sizes == size)
        index = tuple(np.clip(np.searchsorted(layout.planes[a] * factor * size, sums[rows, a], "right") - 1, 0,
                              len(layout.planes[a]) - 2) for a in range(3))
        owner[rows] = layout.owner[index]
    wrong = np.flatnonzero(owner != parts.element_region)
    if len(wrong):
        e = int(wrong[0])
        names = parts.names
        lies = f"in a box of region {shown(names[owner[e]])}" if owner[e] >= 0 else "outside every region's box"
        raise FormatError(f"{path}: member element_region: element {e} is given region "
                          f"{shown(names[parts.element_region[e]])} but lies {lies}")


def dual_layout(dual: Dual, path: str | Path) -> DeviceLayout | None:
    """A version 4 or 5 file's device geometry (its regions' boxes and its contacts) checked again and cut into
    blocks (:class:`~cospherical.mesh.device.DeviceLayout`), or ``None`` for a one-box dual; its bounding box
    must be the file's domain, its low corner the file's origin."""
    from ..mesh.device import Contact, Device, Region, device_layout

    parts = dual.regions
    if parts is None:
        return None
    try:
        regions = tuple(Region(name, material, tuple(_six(box) for box in boxes))
                        for name, material, boxes in zip(parts.names, parts.materials, parts.boxes))
        contacts = tuple(Contact(name, parts.names[r], _six(box))
                         for name, r, box in zip(parts.contact_names, parts.contact_regions, parts.contact_boxes))
        device = Device("dual", regions, contacts, (), 0)
        layout = device_layout(device)
    except (InputError, ValueError, ZeroDivisionError) as error:
        raise FormatError(f"{path}: manifest: the device's boxes: {str(error)[:200]}") from None
    if tuple(str(high - low) for low, high in device.bounds) != tuple(dual.box.texts) or \
            tuple(device.origin) != tuple(Fraction(x) for x in parts.origin):
        raise FormatError(f"{path}: manifest: the device's boxes do not span its domain from its origin")
    return layout


def _six(texts: tuple[str, ...]) -> tuple[Fraction, Fraction, Fraction, Fraction, Fraction, Fraction]:
    """A box's six exact texts (low corner, high corner) as fractions; ValueError unless six numbers."""
    x0, y0, z0, x1, y1, z1 = (Fraction(x) for x in texts)
    return x0, y0, z0, x1, y1, z1


def domain_sums(layout: DeviceLayout, whole: bool = True) -> tuple[Fraction, tuple[Fraction, Fraction, Fraction]]:
    """What a device's control volumes and boundary areas sum to: its volume as a fraction of the bounding
    box's, and per axis the area of its boundary normal to it as a fraction of one side of the bounding
    box (``whole=False``: only the boundary in the bounding box's two sides, as a version 4 file counts it)."""
    steps = [np.diff(p) for p in layout.planes]
    inside = layout.owner >= 0
    volume = Fraction(int((inside * steps[0][:, None, None] * steps[1][None, :, None]
                           * steps[2][None, None, :]).sum()), layout.steps ** 3)
    sides = []
    for axis in range(3):
        b, c = [a for a in range(3) if a != axis]
        area = np.outer(steps[b], steps[c])
        layers = np.moveaxis(inside, axis, 0)
        if whole:  # a block face with the domain on one side only, at every plane
            padded = np.pad(layers, ((1, 1), (0, 0), (0, 0)))
            faces = padded[1:] != padded[:-1]
        else:
            faces = np.stack([layers[0], layers[-1]])
        sides.append(Fraction(int((faces * area).sum()), layout.steps ** 2))
    return volume, (sides[0], sides[1], sides[2])


def _verify_regions(dual: Dual, parts: RegionParts, path: str | Path) -> None:
    """A version 4 or 5 file's region parts computed again from its elements, their regions and its contact faces,
    and compared exactly; each contact's faces lie in its rectangle and cover its area exactly."""
    from ..mesh.regions import region_parts

    boxes = [tuple(Fraction(x) for x in box) for box in parts.contact_boxes]
    try:
        length_a, length_b, length_c = (Fraction(text) for text in dual.box.texts)
        lengths = (length_a, length_b, length_c)
    except ValueError:
        raise FormatError(f"{path}: manifest: a device's domain lengths must be rational") from None
    axes = []
    for c, box in enumerate(boxes):
        flat = [a for a in range(3) if box[a] == box[a + 3]]
        if len(flat) != 1:
            raise FormatError(f"{path}: manifest: contact {c}'s box is not a rectangle")
        axes.append(flat[0])
    contacts = tuple((name, region, tuple(box), axis) for name, region, box, axis in
                     zip(parts.contact_names, parts.contact_regions, parts.contact_boxes, axes))
    try:
        again = region_parts(dual.box, dual.grid, dual.grid_vertices, dual, parts.element_region, parts.names,
                             parts.materials, contacts, parts.contact_face_nodes, parts.contact_face_contact, lengths,
                             parts.origin)
    except InputError as error:  # a face off the coordinate planes, or whose first three vertices are on a line
        raise FormatError(f"{path}: member contact_face_nodes: a contact face is no polygon in a coordinate "
                          f"plane ({error})") from None

    def rows_differ(name: str, ours: tuple[tuple[np.ndarray, ...], np.ndarray, int],
                    theirs: tuple[tuple[np.ndarray, ...], np.ndarray, int]) -> None:
        (a_index, a_values, a_den), (b_index, b_values, b_den) = ours, theirs
        if len(a_index[0]) != len(b_index[0]) or any(not np.array_equal(x, y) for x, y in zip(a_index, b_index)):
            raise FormatError(f"{path}: member {name}: not the rows its elements give ({len(b_index[0])} rows, "
                              f"its elements give {len(a_index[0])})")
        left = a_values.astype(object) * b_den
        right = b_values.astype(object) * a_den
        wrong = np.flatnonzero(np.asarray(left != right).reshape(-1))
        if len(wrong):
            k = int(wrong[0])
            raise FormatError(f"{path}: member {name}_exact: row {k} ({' '.join(str(int(i[k])) for i in a_index)}) "
                              "is not the part its elements give")

    rows_differ("volume_part", ((again.volume_vertex, again.volume_region), again.volume_exact,
                                again.volume_denominator),
                ((parts.volume_vertex, parts.volume_region), parts.volume_exact, parts.volume_denominator))
    rows_differ("coupling_part", ((again.coupling_edge, again.coupling_region), again.coupling_exact,
                                  again.coupling_denominator),
                ((parts.coupling_edge, parts.coupling_region), parts.coupling_exact, parts.coupling_denominator))
    rows_differ("contact_part", ((again.contact_vertex, again.contact_contact), again.contact_exact,
                                 again.contact_denominator),
                ((parts.contact_vertex, parts.contact_contact), parts.contact_exact, parts.contact_denominator))
    # each contact: its faces in its rectangle, their areas the rectangle's (exact, on the grid)
    g = dual.grid_vertices
    origin = [Fraction(x) for x in parts.origin]
    for c, (box, axis) in enumerate(zip(boxes, axes)):
        b, d = (axis + 1) % 3, (axis + 2) % 3
        rectangle = [(box[i] - origin[i % 3]) / lengths[i % 3] * dual.grid for i in range(6)]
        twice = 0
        for face in parts.contact_face_nodes[parts.contact_face_contact == c]:
            p = g[face[face >= 0]].astype(np.int64)
            if not all(rectangle[a] <= int(v) <= rectangle[a + 3] for a in range(3) for v in p[:, a]):
                raise FormatError(f"{path}: member contact_face_nodes: a face of contact "
                                  f"{shown(parts.contact_names[c])} leaves its rectangle")
            x, y = p[:, b], p[:, d]
            twice += abs(int((x * np.roll(y, -1) - np.roll(x, -1) * y).sum()))
        area = Fraction(twice, 2 * dual.grid ** 2) * lengths[b] * lengths[d]
        if area != (box[b + 3] - box[b]) * (box[d + 3] - box[d]):
            raise FormatError(f"{path}: contact {shown(parts.contact_names[c])}: its faces' area {area} is not its "
                              "rectangle's")
    _contact_faces_on_elements(dual, parts, path)


def _contact_faces_on_elements(dual: Dual, parts: RegionParts, path: str | Path) -> None:
    """Each contact face lies on an element of its contact's region: its vertices are that element's (in the
    contact's flat rectangle, checked before, they are the element's face there).  A polygon of the file's own
    (one quad over a whole contact) or a contact naming a region that does not touch it is refused."""
    nodes = dual.element_nodes.astype(np.int64)
    owner = np.repeat(np.arange(len(nodes)), nodes.shape[1])  # vertex -> elements, through one sort
    flat = nodes.reshape(-1)
    order = np.argsort(flat, kind="stable")
    keys, owners = flat[order], owner[order]
    for k, (face, c) in enumerate(zip(parts.contact_face_nodes.tolist(), parts.contact_face_contact.tolist())):
        ids = [v for v in face if v >= 0]
        low, high = np.searchsorted(keys, ids[0], "left"), np.searchsorted(keys, ids[0], "right")
        candidates = owners[low:high]
        candidates = candidates[parts.element_region[candidates] == parts.contact_regions[c]]
        if not any(set(ids) <= set(nodes[e].tolist()) for e in candidates.tolist()):
            raise FormatError(f"{path}: member contact_face_nodes: face {k} of contact "
                              f"{shown(parts.contact_names[c])} is no face of an element of its region "
                              f"{shown(parts.names[parts.contact_regions[c]])}")



def _verify_interfaces(dual: Dual, sets: tuple[np.ndarray, ...], path: str | Path) -> None:
    """A version 5 file's interfaces computed again from its elements and their regions and compared exactly:
    the region pairs, the faces between elements of two regions (each oriented out of the lower region's
    element), each face's interface, and every (vertex, interface) area part."""
    from ..mesh.surfaces import interface_parts

    _, face, _, pair, pairs, which = sets
    parts = dual.regions
    given = parts.interfaces if parts is not None else None
    if parts is None or given is None:
        raise ValueError("_verify_interfaces: a dual without interfaces")
    try:
        a, b, c = (Fraction(text) for text in dual.box.texts)
    except ValueError:
        raise FormatError(f"{path}: manifest: a device's domain lengths must be rational") from None
    lengths = (a, b, c)
    again = interface_parts(dual.grid_vertices, dual.grid, lengths, parts.names, pairs, face[pair[:, 0]], which)
    if not np.array_equal(again.regions, given.regions):
        raise FormatError(f"{path}: manifest: interface_regions {given.regions.tolist()[:8]} are not the region pairs "
                          f"whose elements meet ({again.regions.tolist()[:8]})")
    ours, theirs = _oriented(again.face_nodes, again.face_interface), _oriented(given.face_nodes, given.face_interface)
    if ours.shape != theirs.shape or not np.array_equal(ours, theirs):
        raise FormatError(f"{path}: member interface_face_nodes: not the faces between elements of two regions, "
                          f"each oriented out of the lower region's ({len(theirs)} faces, its elements have "
                          f"{len(ours)})")
    if not (np.array_equal(again.vertex, given.vertex) and np.array_equal(again.interface, given.interface)):
        raise FormatError(f"{path}: member interface_part_vertex: not the rows its interface faces give "
                          f"({len(given.vertex)} rows, they give {len(again.vertex)})")
    wrong = np.flatnonzero(np.asarray(again.exact.astype(object) * given.denominator
                                      != given.exact.astype(object) * again.denominator).reshape(-1))
    if len(wrong):
        k = int(wrong[0])
        raise FormatError(f"{path}: member interface_part_exact: row {k} (vertex {int(given.vertex[k])}, interface "
                          f"{shown(given.names[given.interface[k]])}) is not the part its faces give")


def _oriented(faces: np.ndarray, which: np.ndarray) -> np.ndarray:
    """Polygons (-1 padded) each turned to start at its smallest vertex, orientation kept, with their set in the
    last column, rows sorted: equal for the same oriented faces in any order and from any first corner."""
    width = max(faces.shape[1] if faces.ndim == 2 else 0, 4)
    rows = []
    for polygon, w in zip(faces.tolist(), which.tolist()):
        ids = [v for v in polygon if v >= 0]
        k = ids.index(min(ids))
        rows.append(ids[k:] + ids[:k] + [-1] * (width - len(ids)) + [w])
    table = np.array(rows, dtype=np.int64).reshape(-1, width + 1)
    return table[np.lexsort(table.T[::-1])] if len(table) else table
