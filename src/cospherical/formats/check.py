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

from ..core.configuration import Box
from ..core.geometry import Frame, six_volume
from ..errors import FormatError, InputError
from ..files.yamlio import validate
from ..studies.bisection import element_family
from .diff import document_kind
from .patterns import entry_elements

__all__ = ["check_catalogue", "check_patterns"]


def check_catalogue(data: dict, name: str) -> None:
    """Ids, codes and names unique; faces consistent with V/E/F; splits name known types."""
    ids = Counter(t["id"] for t in data["types"])
    for field in ("id", "code", "name"):
        repeated = [k for k, n in Counter(t[field] for t in data["types"]).items() if n > 1]
        if repeated:
            raise FormatError(f"{name}: types: {field} {repeated[0]!r} appears more than once")
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


def check_patterns(table, catalogue: dict | None, name: str, tiling: bool = True) -> None:
    """Check a loaded :class:`~cospherical.patterns.PatternTable` against the catalogue and geometry."""
    types = {t["id"]: t for t in catalogue["types"]} if catalogue else None
    header = table.header
    try:
        box = Box.parse(header["box"])
    except InputError as error:
        raise FormatError(f"{name}: box: {error}") from None
    family = element_family(header.get("element", "cuboid"), box, header["face_points"])
    for code, entry in table.configurations.items():
        try:
            cfg = family.configuration(code)
        except InputError as error:
            raise FormatError(f"{name}: configurations/{code}: {error}") from None
        nodes = cfg.nodes()
        frame = Frame.build(nodes, box.squared) if tiling and types else None
        for criterion in header["criteria"]:
            where = f"{name}: configurations/{code}/{criterion}"
            elements = entry_elements(entry, criterion)
            for k, element in enumerate(elements):
                missing = [n for n in element["nodes"] if n not in nodes]
                if missing:
                    raise FormatError(f"{where}/{k}: node {missing[0]} is not a point of this configuration")
                if len(set(element["nodes"])) != len(element["nodes"]):
                    raise FormatError(f"{where}/{k}: a node appears twice")
                if types is not None:
                    t = types.get(element["type"])
                    if t is None:
                        raise FormatError(f"{where}/{k}: unknown element type {element['type']!r}")
                    if len(element["nodes"]) != t["vertices"]:
                        raise FormatError(f"{where}/{k}: {len(element['nodes'])} nodes for a type with {t['vertices']} vertices")
            if frame is not None:
                _check_tiling(frame, elements, types, where, getattr(cfg, "shape", None))


def _check_tiling(frame: Frame, elements, types, where: str, shape=None) -> None:
    """The elements fill the box (or the ``shape``) exactly and meet face to face."""
    index = {node: i for i, node in enumerate(frame.ids)}
    coords = frame.coords
    total = 0
    faces: Counter = Counter()
    for k, element in enumerate(elements):
        nodes = element["nodes"]
        cycles = [[index[nodes[p]] for p in face["nodes"]] for face in types[element["type"]]["reference_faces"]]
        six = six_volume(coords, cycles)
        if element.get("mirror"):  # the mirror image: its reference faces run the other way round
            six = -six
        if six <= 0:
            raise FormatError(f"{where}/{k}: the nodes do not make a proper element of type {element['type']}")
        total += six
        faces.update(frozenset(frame.ids[v] for v in cycle) for cycle in cycles)
    volume = Fraction(total, 6 * frame.scale**3)
    if volume != (1 if shape is None else shape.unit_volume):
        raise FormatError(f"{where}: the elements do not fill the {'box' if shape is None else shape.name} "
                          f"(volume {volume} of {1 if shape is None else shape.unit_volume})")
    # A shape's face planes, in the frame's integer coordinates (x = coords / scale).
    planes = [] if shape is None else [(normal, offset * frame.scale) for normal, offset in shape.planes]
    for face, count in faces.items():
        points = [coords[index[v]] for v in face]
        if shape is None:
            on_boundary = any(len({p[axis] for p in points}) == 1 and points[0][axis] in (0, frame.scale)
                              for axis in range(3))
        else:
            on_boundary = any(all(sum(a * x for a, x in zip(normal, p)) == offset for p in points)
                              for normal, offset in planes)
        if count != (1 if on_boundary else 2):
            raise FormatError(f"{where}: face {sorted(face)} belongs to {count} elements: they do not meet face to face")


def validated(data, name: str) -> tuple[str, dict]:
    """The document's kind (``catalogue`` or ``patterns``), after schema validation."""
    kind = document_kind(data, name)
    validate(data, kind, name)
    return kind, data
