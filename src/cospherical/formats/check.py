"""Deep checks of catalogue and pattern-table files, beyond their JSON Schemas.

A pattern table's elements are checked against the catalogue (known type ids,
one node per vertex) and against geometry (:class:`EntryCheck`, one entry at a
time: ``check`` runs it on every entry, the mesher on each entry it uses): every
element, measured from the points its code and the table's base element, box and
point policy give, must be what its entry says (type id, mirror flag,
circumcenter) in its type's node order (its faces counter-clockwise seen from
outside), and every configuration's elements must tile the base element (exact
volumes adding up to its volume, every face met once from each side or once on
its boundary).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from fractions import Fraction
from math import lcm
from pathlib import Path
from typing import Any

from ..caches import cached
from ..catalogue import Catalogue, CatalogueType, catalogue_from_text
from ..core.base_element import base_element
from ..core.configuration import Box
from ..core.element_types import classify_faces
from ..core.geometry import Frame
from ..core.polyhedron import face_kind, measure
from ..core.shapes import Shape
from ..errors import FormatError, InputError
from ..files.flowyaml import split_section
from ..files.yamlio import parse_yaml, read_text, validate
from .diff import document_kind
from .patterns import entry_elements, load, table_from_data, table_from_text
from .sqlite_store import is_store

__all__ = ["EntryCheck", "check_catalogue", "check_patterns", "document_data", "read_document", "read_document_file",
           "validated"]


def check_catalogue(catalogue: Catalogue, name: str) -> None:
    """Ids, codes and names unique; faces consistent with V/E/F; splits name known types."""
    _check_unique(catalogue, name)
    for i, t in enumerate(catalogue.types):
        where = f"{name}: types/{i} ({t.id})"
        faces = [f.nodes for f in t.reference_faces]
        if len(faces) != t.faces or any(not 0 <= v < t.vertices for f in faces for v in f):
            raise FormatError(f"{where}: reference_faces do not match {t.vertices} vertices and {t.faces} faces")
        edges = {frozenset((f[k], f[(k + 1) % len(f)])) for f in faces for k in range(len(f))}
        if len(edges) != t.edges or t.vertices - t.edges + t.faces != 2:
            raise FormatError(f"{where}: V/E/F {t.vertices}/{t.edges}/{t.faces} do not fit its faces")
        for criterion, splits in t.splits.items():
            for split in splits:
                for piece in split:
                    if piece.type not in catalogue:
                        raise FormatError(f"{where}: splits/{criterion}: unknown type {piece.type!r}")
    for criterion, kept in catalogue.criteria.items():
        unknown = sorted(k for k in kept if k not in catalogue)
        if unknown:
            raise FormatError(f"{name}: criteria/{criterion}/kept: unknown type {unknown[0]!r}")


def _check_unique(catalogue: Catalogue, name: str) -> None:
    """Every type once: the same id, canonical code or name twice makes a catalogue ambiguous."""
    for field in ("id", "code", "name"):
        repeated = [k for k, n in Counter(getattr(t, field) for t in catalogue.types).items() if n > 1]
        if repeated:
            raise FormatError(f"{name}: types: {field} {repeated[0]!r} appears more than once")


def check_patterns(table, catalogue: Catalogue | None, name: str, tiling: bool = True, measured: dict | None = None) -> None:
    """Check a loaded :class:`~cospherical.formats.patterns.PatternTable` against the catalogue and geometry.

    ``measured``: a dict the checks of several tables share (against one catalogue), so that an
    element that recurs across tables of the same box and base element is measured once."""
    check = EntryCheck(table.header, catalogue, name, tiling, measured)
    for code, entry in table.configurations.items():
        check(code, entry)


class EntryCheck:
    """The deep check of a pattern table, one configuration's entry at a time: ``check(code, entry)``.

    ``check`` calls it on every entry of a table; the mesher on each entry it uses, the
    first time it uses it, so that a table it reads is held to the same rules.  An entry
    passes when, for every criterion, each element's nodes are points of the
    configuration and its type is in the catalogue (``catalogue``; without one, only
    this), and (``geometry``) each element, measured exactly from its points, is a
    convex polyhedron on one sphere whose recomputed type id, mirror flag and
    circumcenter are the entry's and whose type's reference faces, through its node
    list, are its faces counter-clockwise seen from outside (a VTK cell's positive
    orientation: a hexahedron listed mirrored or upside down, a pyramid with its base
    clockwise, is refused), and the elements tile the base element: their volumes add
    up to its volume and every face is met once from each side, or once on the base
    element's boundary; ``fvm_adequate`` is recomputed too.  The first failure raises
    :class:`FormatError` naming the table, the configuration and the element.

    An element (its type, mirror flag and points) recurs across a table's configurations
    and criteria: it is measured once (once across tables too, given one ``measured`` dict
    for the checks of several tables against the same catalogue).
    """

    def __init__(self, header: dict, catalogue: Catalogue | None, name: str, geometry: bool = True,
                 measured: dict | None = None):
        self._types = catalogue if catalogue is not None and len(catalogue) else None
        self._name = name
        self._geometry = geometry and bool(self._types)
        try:
            box = Box.parse(header["box"])
        except InputError as error:
            raise FormatError(f"{name}: box: {error}") from None
        self._squared = box.squared
        self._scale = box.to_float()
        self._criteria = header["criteria"]
        self._family = base_element(header.get("element", "cuboid"), box, header["face_points"])
        # what an element's measure depends on besides its type, mirror flag and points
        measured = {} if measured is None else measured
        self._measured: dict[tuple, _Measured | str] = measured.setdefault(
            (self._squared, self._family.shape, self._scale), {})
        self._placed: dict[tuple, _Placed | str] = {}

    def __call__(self, code: str, entry: dict) -> None:
        where = f"{self._name}: configurations/{code}"
        try:
            cfg = self._family.configuration(code)
        except InputError as error:
            raise FormatError(f"{where}: {error}") from None
        nodes = cfg.nodes()
        # Positions as integer pairs: they key the cache of measured elements, and hashing
        # Fractions would be most of the check's time.
        positions = {n: tuple((x.numerator, x.denominator) for x in point) for n, point in nodes.items()}
        checked: list = []
        inside = True
        for c, criterion in enumerate(self._criteria):
            elements = entry_elements(entry, criterion)
            if any(elements is other for other in checked):  # a reference to an earlier criterion's elements
                continue
            checked.append(elements)
            measured = self._elements(elements, positions, cfg.shape, f"{where}/{criterion}")
            if c == 0:
                inside = all(m.inside for m in measured)
        if self._geometry:
            if entry["fvm_adequate"] != inside:
                raise FormatError(f"{where}: fvm_adequate is {entry['fvm_adequate']}, recomputed {inside}")

    def _elements(self, elements: list, positions: dict, shape: Shape, where: str) -> list[_Placed]:
        """Check one criterion's elements (see the class); returns them measured."""
        measured = []
        total = Fraction(0)
        faces: Counter = Counter()  # (oriented face, on the boundary) -> the elements that have it
        across: dict = {}  # a face inside the base element -> the same face seen from its other side
        where_is = positions.get
        for k, element in enumerate(elements):
            nodes = element["nodes"]
            points = tuple(map(where_is, nodes))
            if None in points:
                missing = [n for n in nodes if n not in positions]
                raise FormatError(f"{where}/{k}: node {missing[0]} is not a point of this configuration")
            if self._types is not None and element["type"] not in self._types:
                raise FormatError(f"{where}/{k}: unknown element type {element['type']!r}")
            if not self._geometry:
                continue
            found = self._place(element, tuple(nodes), points, shape)
            if isinstance(found, str):
                raise FormatError(f"{where}/{k}: {found}")
            if element["circumcenter"] != found.real_center:  # numbers (the schema): 1 == 1.0, as float() made them
                raise FormatError(f"{where}/{k}: circumcenter {element['circumcenter']}, recomputed "
                                  f"{found.real_center}")
            total += found.volume
            # Every element has a positive volume: past the base element's, the rest cannot tile it
            # (and a hostile entry of thousands of elements is refused after a few).
            if total > shape.unit_volume:
                raise FormatError(f"{where}: the elements do not fill the {_shape_name(shape)}: the first {k + 1} "
                                  f"already have volume {total} of {shape.unit_volume}")
            faces.update(found.faces)
            across.update(found.across)
            measured.append(found)
        if not self._geometry:
            return measured
        if total != shape.unit_volume:
            raise FormatError(f"{where}: the elements do not fill the {_shape_name(shape)} "
                              f"(volume {total} of {shape.unit_volume})")
        _check_faces(faces, across, where)
        return measured

    def _place(self, element: dict, nodes: tuple, points: tuple, shape: Shape) -> _Placed | str:
        """The element measured (once per type, mirror flag and points) and its faces in node ids
        (once per node list at those points: the same nodes recur across a table's configurations)."""
        mirror = bool(element.get("mirror"))
        key = (element["type"], mirror, nodes, points)
        placed = self._placed.get(key)
        if placed is None:
            found = self._measure(element, points, shape)
            placed = self._placed[key] = found if isinstance(found, str) else _Placed.of(found, nodes, shape)
        return placed

    def _measure(self, element: dict, points: tuple, shape: Shape) -> _Measured | str:
        key = (element["type"], bool(element.get("mirror")), points)
        found = self._measured.get(key)
        if found is None:
            found = self._measured[key] = _measure_element(element["type"], key[1], points, self._squared,
                                                           self._types[element["type"]], self._scale, shape)
        return found


@dataclass(frozen=True)
class _Measured:
    """An element measured from its points: its unit volume, its faces (cycles of positions in its
    node list, counter-clockwise seen from outside) and whether each lies on the base element's
    boundary, its exact and float circumcenters."""

    volume: Fraction
    faces: tuple[tuple[int, ...], ...]
    on_boundary: tuple[bool, ...]
    center: tuple[Fraction, Fraction, Fraction]
    real_center: list[float]


@dataclass(frozen=True)
class _Placed:
    """A measured element at its nodes: what an entry's check sums and counts, made once."""

    volume: Fraction
    real_center: list[float]
    inside: bool  # its exact circumcenter in the closed base element (the FVM test)
    faces: tuple[tuple[tuple[int, ...], bool], ...]  # (oriented face in node ids, on the boundary)
    across: dict  # each face inside the base element -> the same face from its other side

    @classmethod
    def of(cls, found: _Measured, nodes: tuple, shape: Shape) -> _Placed:
        faces = tuple((_turned(tuple(nodes[p] for p in cycle)), on_boundary)
                      for cycle, on_boundary in zip(found.faces, found.on_boundary))
        across = {face: (_turned(face[0][::-1]), False) for face in faces if not face[1]}
        return cls(found.volume, found.real_center, shape.contains(found.center), faces, across)


def _measure_element(type_id: str, mirror: bool, points: tuple, squared, catalogued: CatalogueType, scale,
                     shape: Shape) -> _Measured | str:
    """An element of type ``type_id`` (``catalogued``, its catalogue entry) listed by ``points``
    (integer pairs of unit coordinates) in the base element ``shape`` of squared lengths ``squared``
    (``scale``: its lengths as floats), measured; or why it is not one (text)."""
    unit = {i: tuple(Fraction(n, d) for n, d in point) for i, point in enumerate(points)}
    frame = Frame.build(unit, squared)  # frame index = position in the element's node list
    element = measure(frame, range(len(points)))
    cycles = tuple(sorted(element.cycles))
    if element.sphere is None or {i for cycle in cycles for i in cycle} != set(range(len(points))):
        return "its nodes are not the vertices of a convex element on one sphere"
    etype, _, mirrored = classify_faces(cycles, tuple(face_kind(frame, cycle) for cycle in cycles))
    if type_id != etype.id:
        return f"type {type_id}, recomputed {etype.id}"
    if mirror != mirrored:
        return f"mirror is {mirror}, recomputed {mirrored}"
    # The type's faces through the node list, turned back for a mirror image, must be the hull's
    # as they run: the node order gives a positively oriented cell (VTK's order for its cells).
    reference = {_turned(face.nodes[::-1] if mirror else face.nodes) for face in catalogued.reference_faces}
    if reference != {_turned(cycle) for cycle in cycles}:
        return (f"the nodes are not in the reference order of type {type_id}: its faces do not run "
                "counter-clockwise seen from outside (a mirrored, upside-down or reordered element)")
    return _Measured(element.unit_volume, cycles, _on_boundary(frame, cycles, shape), element.center,
                     [float(x) * s for x, s in zip(element.center, scale)])


def _turned(cycle) -> tuple[int, ...]:
    """A face cycle started at its smallest node, in its own direction: equal for the same oriented face."""
    start = cycle.index(min(cycle))
    return tuple(cycle[start:]) + tuple(cycle[:start])


def _check_faces(faces: Counter, across: dict, where: str) -> None:
    """Elements that meet face to face: every face met once from each side, or once on the base
    element's boundary (``faces``: (oriented face, on the boundary) -> how many elements have it;
    ``across``: a face inside the base element -> the same face seen from its other side)."""
    for key, count in faces.items():
        face = key[0]
        if count > 1:
            raise FormatError(f"{where}: face {list(face)} belongs to {count} elements on the same side: they overlap")
        if not key[1] and faces.get(across[key]) != 1:
            raise FormatError(f"{where}: face {list(face)} has no element on its other side: the elements do not "
                              "meet face to face")


def _on_boundary(frame: Frame, cycles, shape: Shape) -> tuple[bool, ...]:
    """Per face cycle (frame indices): whether it lies in a face plane of the base element ``shape``."""
    coords = frame.coords
    return tuple(any(all(a * x + b * y + c * z == offset for x, y, z in (coords[p] for p in cycle))
                     for (a, b, c), offset in _integer_planes(shape, frame.scale)) for cycle in cycles)


@cached(maxsize=256)
def _integer_planes(shape: Shape, scale: int) -> tuple[tuple[tuple[int, int, int], int], ...]:
    """The face planes of ``shape`` in a frame's integer coordinates (``x = coords / scale``), as integer
    normals and offsets: the test of a point runs on integers."""
    planes = []
    for normal, offset in shape.planes:
        common = lcm(*(x.denominator for x in (*normal, offset * scale)))
        planes.append((tuple(int(x * common) for x in normal), int(offset * scale * common)))
    return tuple(planes)


def _shape_name(shape: Shape) -> str:
    return "box" if shape.name == "cuboid" else shape.name


def read_document(text: str, name: str):
    """A catalogue's or pattern table's text: ``("catalogue", Catalogue)`` or ``("patterns", PatternTable)``, validated.

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
    return kind, (Catalogue.from_dict(data) if kind == "catalogue" else table_from_data(data, name))


def read_document_file(path: str | Path) -> tuple[str, Any]:
    """:func:`read_document` on a file: a catalogue, a pattern table, or a pattern table's indexed store."""
    if is_store(path):
        return "patterns", load(path)
    return read_document(read_text(path), str(path))


def document_data(document) -> dict:
    """A read document as one mapping (a pattern table's header with its configurations), as diff compares them."""
    if isinstance(document, Catalogue):
        return document.to_dict()
    return {**document.header, "configurations": document.configurations}


def validated(data, name: str) -> tuple[str, dict]:
    """The document's kind (``catalogue`` or ``patterns``), after schema validation (and, for a
    catalogue, every type once)."""
    kind = document_kind(data, name)
    validate(data, kind, name)
    if kind == "catalogue":
        _check_unique(Catalogue.from_dict(data), name)
    return kind, data
