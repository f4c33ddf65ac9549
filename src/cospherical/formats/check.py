"""Deep checks of catalogue and pattern-table files, beyond their JSON Schemas.

A pattern table's elements are checked against the catalogue (known type ids,
one node per vertex) and against geometry: every configuration's elements,
with the nodes its code and the table's base element, box and point policy
give, must tile the base element (exact volumes adding up to its volume, every
face shared by two elements or lying on its boundary).
"""

from __future__ import annotations

from collections import Counter
from fractions import Fraction
from math import lcm

from ..catalogue import catalogue_from_text
from ..core.base_element import base_element
from ..core.configuration import Box
from ..core.element_types import classify_faces
from ..core.geometry import Frame, six_volume
from ..core.polyhedron import face_kind, measure
from ..core.shapes import Shape
from ..errors import FormatError, InputError
from ..files.flowyaml import split_section
from ..files.yamlio import parse_yaml, read_text, validate
from .diff import document_kind
from .patterns import entry_elements, load, table_from_data, table_from_text
from .sqlite_store import is_store

__all__ = ["check_catalogue", "check_patterns", "document_data", "read_document", "read_document_file",
           "validated"]


def check_catalogue(data: dict, name: str) -> None:
    """Ids, codes and names unique; faces consistent with V/E/F; splits name known types."""
    ids = Counter(t["id"] for t in data["types"])
    _check_unique(data, name)
    for i, t in enumerate(data["types"]):
        where = f"{name}: types/{i} ({t['id']})"
        faces = [f["nodes"] for f in t["reference_faces"]]
        if len(faces) != t["faces"] or any(not 0 <= v < t["vertices"] for f in faces for v in f):
            raise FormatError(f"{where}: reference_faces do not match {t['vertices']} vertices and {t['faces']} faces")
        edges = {frozenset((f[k], f[(k + 1) % len(f)])) for f in faces for k in range(len(f))}
        if len(edges) != t["edges"] or t["vertices"] - t["edges"] + t["faces"] != 2:
            raise FormatError(f"{where}: V/E/F {t['vertices']}/{t['edges']}/{t['faces']} do not fit its faces")
        for criterion, splits in t.get("splits", {}).items():
            for split in splits:
                for piece in split:
                    if piece["type"] not in ids:
                        raise FormatError(f"{where}: splits/{criterion}: unknown type {piece['type']!r}")
    for criterion, entry in data.get("criteria", {}).items():
        unknown = [k for k in entry.get("kept", []) if k not in ids]
        if unknown:
            raise FormatError(f"{name}: criteria/{criterion}/kept: unknown type {unknown[0]!r}")


def _check_unique(data: dict, name: str) -> None:
    """Every type once: the same id, canonical code or name twice makes a catalogue ambiguous."""
    for field in ("id", "code", "name"):
        repeated = [k for k, n in Counter(t[field] for t in data["types"]).items() if n > 1]
        if repeated:
            raise FormatError(f"{name}: types: {field} {repeated[0]!r} appears more than once")


def check_patterns(table, catalogue: dict | None, name: str, tiling: bool = True) -> None:
    """Check a loaded :class:`~cospherical.formats.patterns.PatternTable` against the catalogue and geometry."""
    types = {t["id"]: t for t in catalogue["types"]} if catalogue else None
    header = table.header
    try:
        box = Box.parse(header["box"])
    except InputError as error:
        raise FormatError(f"{name}: box: {error}") from None
    family = base_element(header.get("element", "cuboid"), box, header["face_points"])
    # The same element (type, nodes, node positions) recurs in many configurations
    # and criteria of a table: its volume and faces are computed once.
    geometry: dict[tuple, tuple | None] = {}
    recomputed: dict[tuple, tuple | None] = {}
    for code, entry in table.configurations.items():
        try:
            cfg = family.configuration(code)
        except InputError as error:
            raise FormatError(f"{name}: configurations/{code}: {error}") from None
        nodes = cfg.nodes()
        # Positions as integer pairs: they key the geometry cache, and hashing
        # Fractions would be most of the check's time.
        positions = {n: tuple((x.numerator, x.denominator) for x in point) for n, point in nodes.items()}
        checked = []
        for criterion in header["criteria"]:
            where = f"{name}: configurations/{code}/{criterion}"
            elements = entry_elements(entry, criterion)
            if any(elements is other for other in checked):  # a reference to an earlier criterion's elements
                continue
            checked.append(elements)
            for k, element in enumerate(elements):
                missing = [n for n in element["nodes"] if n not in nodes]
                if missing:
                    raise FormatError(f"{where}/{k}: node {missing[0]} is not a point of this configuration")
                if types is not None:
                    t = types.get(element["type"])
                    if t is None:
                        raise FormatError(f"{where}/{k}: unknown element type {element['type']!r}")
            if tiling and types:
                _check_tiling(nodes, positions, box.squared, elements, types, geometry, where, cfg.shape)
        if tiling and types:
            _check_recomputed(cfg, positions, box.squared, entry, header["criteria"], f"{name}: configurations/{code}",
                              recomputed)


def _check_recomputed(cfg, positions: dict, squared, entry: dict, criteria, where: str, cache: dict) -> None:
    """Recompute and compare exactly, element by element: the type label and mirror flag (from the
    convex hull of the element's points), the circumcenter (the stored float must be the float of the
    exact one), and ``fvm_adequate`` (every circumcenter of the optimal elements in the closed box;
    in the base element for another element than the cuboid).  Elements recur across a table, so
    each distinct one (its points) is computed once."""
    scale = cfg.box.to_float()
    centers = []
    for c, criterion in enumerate(criteria):
        for k, element in enumerate(entry_elements(entry, criterion)):
            points = tuple(positions[n] for n in element["nodes"])
            if points not in cache:
                # with the float circumcenter: float() of a Fraction is slow, and the scale is the
                # table's box, the same for every configuration that shares this cache
                found = _recompute(points, squared)
                cache[points] = found and (*found, [float(x) * s for x, s in zip(found[2], scale)])
            if cache[points] is None:
                raise FormatError(f"{where}/{criterion}/{k}: its nodes are not the vertices of a convex element on one sphere")
            type_id, mirrored, center, real = cache[points]
            if element["type"] != type_id:
                raise FormatError(f"{where}/{criterion}/{k}: type {element['type']}, recomputed {type_id}")
            if bool(element.get("mirror", False)) != mirrored:
                raise FormatError(f"{where}/{criterion}/{k}: mirror is {bool(element.get('mirror', False))}, recomputed {mirrored}")
            if [float(x) for x in element["circumcenter"]] != real:
                raise FormatError(f"{where}/{criterion}/{k}: circumcenter {element['circumcenter']}, recomputed {real}")
            if c == 0:
                centers.append(center)
    adequate = all(cfg.contains(center) for center in centers)
    if entry["fvm_adequate"] != adequate:
        raise FormatError(f"{where}: fvm_adequate is {entry['fvm_adequate']}, recomputed {adequate}")


def _recompute(points: tuple, squared) -> tuple | None:
    """(type id, mirrored, exact circumcenter in unit coordinates) of the element with these
    points, or ``None`` if they are not the vertices of a convex polyhedron on one sphere."""

    unit = {i: tuple(Fraction(n, d) for n, d in point) for i, point in enumerate(points)}
    frame = Frame.build(unit, squared)
    element = measure(frame, range(len(points)))
    cycles = sorted(element.cycles)
    if {i for cycle in cycles for i in cycle} != set(range(len(points))):
        return None
    etype, _, mirrored = classify_faces(tuple(cycles), tuple(face_kind(frame, cycle) for cycle in cycles))
    if element.sphere is None:
        return None
    return etype.id, mirrored, element.center


def _element_geometry(element: dict, points: tuple, squared, types, shape: Shape) -> tuple | None:
    """(unit volume, faces as (node set, on the boundary of the base element ``shape``)) of an element,
    or ``None`` if its nodes do not make a proper element of its type."""
    frame = Frame.build(dict(enumerate(points)), squared)  # frame index = position in the element's node list
    cycles = [face["nodes"] for face in types[element["type"]]["reference_faces"]]
    six = six_volume(frame.coords, cycles)
    if element.get("mirror"):  # the mirror image: its reference faces run the other way round
        six = -six
    if six <= 0:
        return None
    nodes, coords, scale = element["nodes"], frame.coords, frame.scale
    # The shape's face planes, in the frame's integer coordinates (x = coords / scale), with
    # integer normals: the test runs on integers, as the box's did.
    planes = []
    for normal, offset in shape.planes:
        common = lcm(*(x.denominator for x in normal))
        planes.append((tuple(int(x * common) for x in normal), offset * scale * common))
    faces = []
    for cycle in cycles:
        on_boundary = any(all(sum(a * x for a, x in zip(normal, coords[p])) == offset for p in cycle)
                          for normal, offset in planes)
        faces.append((frozenset(nodes[p] for p in cycle), on_boundary))
    return Fraction(six, 6 * scale**3), tuple(faces)


def _check_tiling(nodes: dict, positions: dict, squared, elements, types, geometry: dict, where: str,
                  shape: Shape) -> None:
    """The elements fill the base element ``shape`` exactly and meet face to face."""
    total = Fraction(0)
    faces: Counter = Counter()
    for k, element in enumerate(elements):
        key = (element["type"], tuple(element["nodes"]), bool(element.get("mirror")),
               tuple(positions[n] for n in element["nodes"]))
        found = geometry.get(key, False)
        if found is False:
            points = tuple(nodes[n] for n in element["nodes"])
            found = geometry[key] = _element_geometry(element, points, squared, types, shape)
        if found is None:
            raise FormatError(f"{where}/{k}: the nodes do not make a proper element of type {element['type']}")
        volume, element_faces = found
        total += volume
        faces.update(element_faces)
    if total != shape.unit_volume:
        raise FormatError(f"{where}: the elements do not fill the {'box' if shape.name == 'cuboid' else shape.name} "
                          f"(volume {total} of {shape.unit_volume})")
    for (face, on_boundary), count in faces.items():
        if count != (1 if on_boundary else 2):
            raise FormatError(f"{where}: face {sorted(face)} belongs to {count} elements: they do not meet face to face")


def read_document(text: str, name: str):
    """A catalogue's or pattern table's text: ``("catalogue", data)`` or ``("patterns", PatternTable)``, validated.

    Files as this package writes them take the fast path of each reader (one
    JSON entry per line, see :mod:`cospherical.files.flowyaml`); anything else is
    parsed as YAML.  A pattern table's entries are validated as they are read.
    """
    section = split_section(text, "configurations")
    if section is not None and isinstance(section[1], dict):
        table = table_from_text(text, name)
        document_kind({**table.header, "configurations": {}}, name)
        return "patterns", table
    section = split_section(text, "types")
    if section is not None and isinstance(section[1], list):
        catalogue = catalogue_from_text(text, name)
        _check_unique(catalogue, name)
        return "catalogue", catalogue
    kind, data = validated(parse_yaml(text, name), name)
    return kind, (data if kind == "catalogue" else table_from_data(data, name))


def read_document_file(path) -> tuple[str, object]:
    """:func:`read_document` on a file: a catalogue, a pattern table, or a pattern table's indexed store."""
    if is_store(path):
        return "patterns", load(path)
    return read_document(read_text(path), str(path))


def document_data(document) -> dict:
    """A read document as one mapping (a pattern table's header with its configurations), as diff compares them."""
    if isinstance(document, dict):
        return document
    return {**document.header, "configurations": document.configurations}


def validated(data, name: str) -> tuple[str, dict]:
    """The document's kind (``catalogue`` or ``patterns``), after schema validation (and, for a
    catalogue, every type once)."""
    kind = document_kind(data, name)
    validate(data, kind, name)
    if kind == "catalogue":
        _check_unique(data, name)
    return kind, data
