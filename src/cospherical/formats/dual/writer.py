"""Writing ``dual.npz``: the members as ``.npy`` files, their checksums in the manifest, deflated (in threads
when the dual is large)."""

from __future__ import annotations

import hashlib
import io
import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ...errors import InputError
from ...files.yamlio import atomic_open
from ...mesh.dual import Dual
from ..deflated import InlinePool, deflating, in_threads, write_zip
from .members import DUAL_FORMAT_VERSION, _MAX_TEXT_DIGITS, _MEMBERS

if TYPE_CHECKING:
    from concurrent.futures import Executor

__all__ = ["threaded", "write_dual"]

# Every member is deflated at zlib's fastest level: on the README's level-8 tree (172 MB of arrays) level 6 took
# 3.0 CPU-s for a file of 18.2 MB, level 1 0.6 CPU-s for 22.8 MB (1.26 times larger); a whole `mesh --out` run
# without the dual takes about 1.5 CPU-s.  Each member still shrinks 4 to 100 times at level 1, so none is stored
# uncompressed.  The deflating runs in blocks on every core (formats.deflated): 0.4 s of wall time on 2 cores.
_DEFLATE_LEVEL = 1
# Exact integers too wide for int64 are written as decimal text, at least this wide (a wider column only
# where a value needs it: the files of earlier versions keep their bytes)
_TEXT_WIDTH = 200


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


def _dual_bytes(dual: Dual) -> int:
    """The bytes of ``dual``'s arrays, which decide whether ``dual.npz`` is hashed and deflated in threads
    (:func:`~cospherical.formats.deflated.deflating`)."""
    return sum(getattr(dual, name).nbytes for name in _MEMBERS)


def threaded(dual: Dual) -> bool:
    """Whether ``dual.npz`` is worth writing in threads (:func:`~cospherical.formats.deflated.in_threads` of
    :func:`_dual_bytes`): else :func:`write_dual` hashes and deflates in the caller's thread."""
    return in_threads(_dual_bytes(dual))


def write_dual(dual: Dual, path: str | Path, pool: Executor | InlinePool | None = None) -> None:
    """Write ``dual`` as ``dual.npz`` (see the module), atomically and deterministically; ``pool``: the threads
    that hash and deflate (default: threads of the call's own when :func:`threaded`, else none), the same bytes
    with any."""
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
    with deflating(_dual_bytes(dual), pool, "dual.npz") as workers:
        # the checksums first (the manifest, the first member, holds them), on every core, then every member
        # deflated in blocks on every core and written in order as it comes (formats.deflated)
        digests = {name: workers.submit(_sha256, *member) for name, member in members.items()}
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
            write_zip(handle, [(f"{name}.npy", member) for name, member in members.items()], _DEFLATE_LEVEL, workers)


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
