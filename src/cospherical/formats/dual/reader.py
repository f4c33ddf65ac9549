"""Reading ``dual.npz``: every member's kind and shape from its header before its data, the checksums, the
manifest's exact numbers, edges, elements and faces checked, all before any geometry."""

from __future__ import annotations

import hashlib
import io
import math
import os
import stat
import zipfile
import zlib
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from ...core.configuration import Box
from ...errors import FormatError, shown
from ...files.yamlio import machine_memory, parse_json
from ...mesh.device import NAME
from ...mesh.dual import Dual, InterfaceParts, RegionParts
from .members import _FRACTION, _INTEGER, _INTERFACE_MEMBERS, _MAX_DUAL_FILE, _MAX_ELEMENT_NODES, _MAX_GRID, _MAX_NAMES, _MAX_TEXT_DIGITS, _MEMBERS, _POSITIVE, _POSITIVE_FRACTION, _REGION_MEMBERS, _VERSIONS

__all__ = ["read_dual"]


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
    _indices_within(arrays, (("element_region", len(names)), ("volume_part_vertex", n_vertices),
                             ("volume_part_region", len(names)), ("coupling_part_edge", n_edges),
                             ("coupling_part_region", len(names)), ("contact_face_contact", len(contacts)),
                             ("contact_part_vertex", n_vertices), ("contact_part_contact", len(contacts))), path)
    faces = _face_nodes(arrays, "contact_face_nodes", n_vertices, n_face_bound, path)
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
    _indices_within(arrays, (("interface_face_interface", len(pairs)), ("interface_part_vertex", n_vertices),
                             ("interface_part_interface", len(pairs))), path)
    faces = _face_nodes(arrays, "interface_face_nodes", n_vertices, n_face_bound, path)
    regions = np.array(pairs, dtype=np.int32).reshape(-1, 2)
    return InterfaceParts(regions, tuple(f"{names[a]}|{names[b]}" for a, b in regions.tolist()), faces.astype(np.int32),
                          arrays["interface_face_interface"].astype(np.int32),
                          arrays["interface_part_vertex"].astype(np.int64),
                          arrays["interface_part_interface"].astype(np.int32),
                          _integers(arrays["interface_part_exact"], "interface_part_exact", path), int(denominator))


def _indices_within(arrays: dict[str, np.ndarray], bounds: tuple[tuple[str, int], ...], path: Path) -> None:
    """Refuse a member of index arrays (``bounds``: its name, the count it indexes) with an index outside
    ``0..count - 1``."""
    for name, bound in bounds:
        values = arrays[name]
        if len(values) and (values.min() < 0 or values.max() >= bound):
            raise FormatError(f"{path}: member {name}: an index outside 0..{bound - 1}")


def _face_nodes(arrays: dict[str, np.ndarray], member: str, n_vertices: int, most: int, path: Path) -> np.ndarray:
    """A member of faces (contact or interface faces, rows of vertex ids padded with -1), checked: every face
    names at least three vertices, each of distinct vertices, no two of the same vertices, and no more faces
    than the elements have (``most``); refused in bulk before check walks them one by one (a face repeated
    three million times deflates to 115 kB and took 48 CPU-s)."""
    faces = arrays[member]
    if np.any((faces < -1) | (faces >= n_vertices)) or np.any((faces[:, :3] < 0)):
        raise FormatError(f"{path}: member {member}: a face that names no vertex")
    if len(faces) > most:
        raise FormatError(f"{path}: member {member}: {len(faces):,} faces, more than its elements have ({most:,})")
    _distinct_rows(faces, faces >= 0, path, member, "face")
    return faces


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
    from ...mesh.dual.shapes import row_hashes

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
