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

import hashlib
from collections import Counter
from dataclasses import dataclass
from fractions import Fraction
from math import lcm
from pathlib import Path
from typing import Any, Sequence, cast

from ..catalogue import Catalogue, CatalogueType, catalogue_from_text
from ..core.base_element import base_element
from ..core.configuration import Box
from ..core.element_types import classify_faces
from ..core.geometry import Frame, Rational
from ..core.polyhedron import face_kind, measure
from ..core.shapes import Shape
from ..errors import FormatError, InputError
from ..files.flowyaml import split_section
from ..files.yamlio import parse_yaml, read_text, validate
from .diff import document_kind
from .patterns import Entries, PatternTable, entry_elements, load, table_from_data, table_from_text
from .sqlite_store import is_store

__all__ = ["EntryCheck", "SharedChecks", "check_catalogue", "check_patterns", "document_data", "read_document", "read_document_file",
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


class SharedChecks:
    """What the checks of several tables against one catalogue share, so that each thing is done once.

    - an element (type, mirror flag, points) is measured once per box and base element;
    - a configuration's points are computed once per base element and point policy: they
      are unit coordinates, the same for every box; so is which face planes of the base
      element hold a point, and an element's hull and volume over the box's;
    - an entry (its text, for the same point set, box, base element and criteria) that
      passed once is not decoded or checked again: the leaf tables repeat most of the
      bisection tables' entries (4,095 of 6,210), and its verdict cannot differ.
    """

    def __init__(self) -> None:
        self.measured: dict[tuple[Any, ...], dict[tuple[Any, ...], _Measured | str]] = {}
        self.positions: dict[tuple[Any, ...], dict[str, tuple[tuple[tuple[int, int], ...], dict[int, int]]]] = {}
        self.points: dict[tuple[tuple[int, int], ...], int] = {}  # a point's integer pairs -> its id
        self.coordinates: list[tuple[Fraction, Fraction, Fraction]] = []  # id -> the point (unit coordinates)
        self.planes: dict[Shape, list[int]] = {}  # per shape, id -> bit mask of the face planes holding the point
        # points (ids, in an element's node order) -> its hull's cycles and unit volume, the same in every box
        self.hulls: dict[tuple[int, ...], tuple[tuple[tuple[int, ...], ...], Fraction]] = {}
        self.passed: set[tuple[Any, ...]] = set()  # (context, point-set code, digest of the entry's text)


def check_patterns(table: PatternTable, catalogue: Catalogue | None, name: str, tiling: bool = True,
                   shared: SharedChecks | None = None) -> None:
    """Check a loaded :class:`~cospherical.formats.patterns.PatternTable` against the catalogue and geometry.

    ``shared``: what the checks of several tables (against one catalogue) share
    (:class:`SharedChecks`), so that what recurs across them is done once."""
    check = EntryCheck(table.header, catalogue, name, tiling, shared)
    configurations = table.configurations
    if isinstance(configurations, Entries):
        # an entry that passed in an earlier table is neither decoded nor checked again
        for code, entry, text in configurations.items_with_texts(skip=check.passed_before):
            check(code, entry, text)
        return
    for code, entry in configurations.items():
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
    and criteria: it is measured once (once across tables too, given one
    :class:`SharedChecks` for the checks of several tables against the same catalogue).

    ``only``: the one criterion whose elements are checked (a mesher's: the other criteria's
    elements never reach its mesh, and ``fvm_adequate``, which the mesher recomputes from the
    elements it uses, is checked only when ``only`` is the table's first criterion, the one it
    describes); ``None``: every criterion, as ``check`` does.
    """

    def __init__(self, header: dict[str, Any], catalogue: Catalogue | None, name: str, geometry: bool = True,
                 shared: SharedChecks | None = None, only: str | None = None):
        self._types = catalogue if catalogue is not None and len(catalogue) else None
        self._known = frozenset(t.id for t in self._types) if self._types is not None else None
        self._name = name
        self._geometry = geometry and bool(self._types)
        try:
            box = Box.parse(header["box"])
        except InputError as error:
            raise FormatError(f"{name}: box: {error}") from None
        self._squared = box.squared
        self._scale = box.to_float()
        self._criteria = header["criteria"]
        if only is not None and only not in self._criteria:
            raise FormatError(f"{name}: no {only!r} elements (it has {', '.join(self._criteria)})")
        self._only = only
        self._family = base_element(header.get("element", "cuboid"), box, header["face_points"])
        shape = self._family.shape
        self._shared = shared = SharedChecks() if shared is None else shared
        # what an element's measure depends on besides its type, mirror flag and points
        self._measured = shared.measured.setdefault((self._squared, shape, self._scale), {})
        # a configuration's points depend on the shape in unit coordinates and the point policy, not on the box
        self._positions = shared.positions.setdefault(
            (shape.name, shape.corners, shape.edges, shape.faces, header["face_points"]), {})
        # what an entry's verdict depends on besides its text and its points
        self._context = (self._squared, shape, self._scale, tuple(self._criteria), self._geometry,
                         catalogue.version if catalogue is not None else None, only)
        self._placed: dict[tuple[str, bool, tuple[int, ...], tuple[int, ...]], _Placed | str] = {}
        unit = shape.unit_volume
        self._unit_volume = (unit.numerator, unit.denominator)

    def passed_before(self, code: str, text: str) -> bool:
        """Whether the entry ``text`` of ``code`` passed this check already (in this table's context)."""
        try:
            point_set, _ = self._points(code)
        except InputError:
            return False  # refused with its place when it is checked
        return (self._context, point_set, _digest(text)) in self._shared.passed

    def _points(self, code: str) -> tuple[tuple[tuple[int, int], ...], dict[int, int]]:
        """A configuration's points: node -> point id (:class:`SharedChecks`), and the same as a
        sorted tuple (the point set: what an entry's verdict depends on besides the table)."""
        found = self._positions.get(code)
        if found is None:
            cfg = self._family.configuration(code)
            ids, coordinates = self._shared.points, self._shared.coordinates
            positions = {}
            # Points interned as ids: they key the cache of measured elements, and hashing
            # Fractions would be most of the check's time.
            for n, point in cfg.nodes().items():
                pairs = tuple((x.numerator, x.denominator) for x in point)
                i = ids.get(pairs)
                if i is None:
                    i = ids[pairs] = len(coordinates)
                    coordinates.append((Fraction(point[0]), Fraction(point[1]), Fraction(point[2])))
                positions[n] = i
            found = self._positions[code] = (tuple(sorted(positions.items())), positions)
        return found

    def _plane_masks(self, points: tuple[int, ...], shape: Shape) -> list[int]:
        """Per point (ids), the bit mask of the base element's face planes it lies in, exactly."""
        masks = self._shared.planes.setdefault(shape, [])
        coordinates = self._shared.coordinates
        if len(masks) < len(coordinates):
            for point in coordinates[len(masks):]:
                masks.append(sum(1 << f for f, (normal, offset) in enumerate(shape.planes)
                                 if normal[0] * point[0] + normal[1] * point[1] + normal[2] * point[2] == offset))
        return [masks[p] for p in points]

    def __call__(self, code: str, entry: dict[str, Any], text: str | None = None) -> None:
        """Check ``entry``, the entry of ``code``; ``text``: the entry as written (remembered once it passes)."""
        where = f"{self._name}: configurations/{code}"
        try:
            point_set, positions = self._points(code)
        except InputError as error:
            raise FormatError(f"{where}: {error}") from None
        shape = self._family.shape
        checked: list[list[dict[str, Any]]] = []
        inside = True
        for c, criterion in enumerate(self._criteria):
            if self._only is not None and criterion != self._only:
                continue
            elements = entry_elements(entry, criterion)
            if elements is None:  # the schema, checked first, gives every criterion its elements
                raise FormatError(f"{where}/{criterion}: no elements")
            if any(elements is other for other in checked):  # a reference to an earlier criterion's elements
                continue
            checked.append(elements)
            all_inside = self._elements(elements, positions, shape, f"{where}/{criterion}")
            if c == 0:
                inside = all_inside
        if self._geometry and self._only in (None, self._criteria[0]):
            if entry["fvm_adequate"] != inside:
                raise FormatError(f"{where}: fvm_adequate is {entry['fvm_adequate']}, recomputed {inside}")
        if text is not None:
            self._shared.passed.add((self._context, point_set, _digest(text)))

    def _elements(self, elements: list[dict[str, Any]], positions: dict[int, int], shape: Shape, where: str) -> bool:
        """Check one criterion's elements (see the class); returns whether every circumcenter is inside."""
        placed_all: list[_Placed] = []
        unit_num, unit_den = self._unit_volume
        total, denominator = 0, 1  # the volume so far: total / denominator
        seen: set[_Face] = set()  # (oriented face, on the boundary) of the elements so far
        needed: set[_Face] = set()  # the faces inside the base element seen from their other side
        clash = False  # a face met twice from the same side: found again, with its message, below
        inside = True
        where_is = positions.get
        known = self._known
        geometry = self._geometry
        for k, element in enumerate(elements):
            nodes = element["nodes"]
            points = tuple(map(where_is, nodes))
            if None in points:
                missing = [n for n in nodes if n not in positions]
                raise FormatError(f"{where}/{k}: node {missing[0]} is not a point of this configuration")
            if known is not None and element["type"] not in known:
                raise FormatError(f"{where}/{k}: unknown element type {element['type']!r}")
            if not geometry:
                continue
            # no None among the points: refused just above
            found = self._place(element, tuple(nodes), cast("tuple[int, ...]", points), shape)
            if isinstance(found, str):
                raise FormatError(f"{where}/{k}: {found}")
            if element["circumcenter"] != found.real_center:  # numbers (the schema): 1 == 1.0, as float() made them
                raise FormatError(f"{where}/{k}: circumcenter {element['circumcenter']}, recomputed "
                                  f"{found.real_center}")
            num, den = found.volume_pair
            if denominator % den:
                common = lcm(denominator, den)
                total *= common // denominator
                denominator = common
            total += num * (denominator // den)
            # Every element has a positive volume: past the base element's, the rest cannot tile it
            # (and a hostile entry of thousands of elements is refused after a few).
            if total * unit_den > unit_num * denominator:
                raise FormatError(f"{where}: the elements do not fill the {_shape_name(shape)}: the first {k + 1} "
                                  f"already have volume {Fraction(total, denominator)} of {shape.unit_volume}")
            if not clash and not seen.isdisjoint(found.face_keys):
                clash = True
            seen |= found.face_keys
            needed |= found.opposites
            inside = inside and found.inside
            placed_all.append(found)
        if not geometry:
            return inside
        if total * unit_den != unit_num * denominator:
            raise FormatError(f"{where}: the elements do not fill the {_shape_name(shape)} "
                              f"(volume {Fraction(total, denominator)} of {shape.unit_volume})")
        if clash or not needed <= seen:
            faces: Counter[_Face] = Counter()  # (oriented face, on the boundary) -> the elements that have it
            across: dict[_Face, _Face] = {}  # a face inside the base element -> the same face seen from its other side
            for found in placed_all:
                faces.update(found.faces)
                across.update(found.across)
            _check_faces(faces, across, where)
        return inside

    def _place(self, element: dict[str, Any], nodes: tuple[int, ...], points: tuple[int, ...], shape: Shape) -> _Placed | str:
        """The element measured (once per type, mirror flag and points) and its faces in node ids
        (once per node list at those points: the same nodes recur across a table's configurations)."""
        mirror = bool(element.get("mirror"))
        key = (element["type"], mirror, nodes, points)
        placed = self._placed.get(key)
        if placed is None:
            found = self._measure(element["type"], mirror, points, shape)
            placed = self._placed[key] = found if isinstance(found, str) else _Placed.of(found, nodes, shape)
        return placed

    def _measure(self, type_id: str, mirror: bool, points: tuple[int, ...], shape: Shape) -> _Measured | str:
        key = (type_id, mirror, points)
        found = self._measured.get(key)
        if found is None:
            coordinates = self._shared.coordinates
            assert self._types is not None  # measured only with a catalogue (geometry)
            hulls = self._shared.hulls
            found = self._measured[key] = _measure_element(
                type_id, mirror, tuple(coordinates[p] for p in points), self._plane_masks(points, shape),
                self._squared, self._types[type_id], self._scale, hulls.get(points))
            if not isinstance(found, str):
                hulls.setdefault(points, (found.faces, found.volume))
        return found


def _digest(text: str) -> bytes:
    """An entry's text as :class:`SharedChecks` remembers it: a collision-resistant digest, not the text
    (the tables' texts would stay in memory)."""
    return hashlib.blake2b(text.encode(), digest_size=16).digest()


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


# A face of an element as placed: its cycle of node ids (started at the smallest), and whether it lies on the
# base element's boundary.
_Face = tuple[tuple[int, ...], bool]


@dataclass(frozen=True)
class _Placed:
    """A measured element at its nodes: what an entry's check sums and counts, made once."""

    volume_pair: tuple[int, int]  # its unit volume, numerator and denominator
    real_center: list[float]
    inside: bool  # its exact circumcenter in the closed base element (the FVM test)
    faces: tuple[_Face, ...]  # (oriented face in node ids, on the boundary)
    across: dict[_Face, _Face]  # each face inside the base element -> the same face from its other side
    face_keys: frozenset[_Face]  # the faces, as a set
    opposites: frozenset[_Face]  # the faces the neighbours across its inner faces must have

    @classmethod
    def of(cls, found: _Measured, nodes: tuple[int, ...], shape: Shape) -> _Placed:
        faces = tuple((_turned(tuple(nodes[p] for p in cycle)), on_boundary)
                      for cycle, on_boundary in zip(found.faces, found.on_boundary))
        across = {face: (_turned(face[0][::-1]), False) for face in faces if not face[1]}
        return cls((found.volume.numerator, found.volume.denominator), found.real_center,
                   shape.contains(found.center), faces, across, frozenset(faces), frozenset(across.values()))


def _measure_element(type_id: str, mirror: bool, points: tuple[tuple[Fraction, Fraction, Fraction], ...],
                     plane_masks: list[int], squared: Sequence[Rational], catalogued: CatalogueType, scale: Sequence[float],
                     hull: tuple[tuple[tuple[int, ...], ...], Fraction] | None = None) -> _Measured | str:
    """An element of type ``type_id`` (``catalogued``, its catalogue entry) listed by ``points``
    (unit coordinates; ``plane_masks``: per point, the face planes of the base element that hold it)
    in a base element of squared lengths ``squared`` (``scale``: its lengths as floats), measured; or
    why it is not one (text).  ``hull``: its cycles and unit volume measured before in another box
    (:func:`~cospherical.core.polyhedron.measure`)."""
    frame = Frame.build(dict(enumerate(points)), squared)  # frame index = position in the element's node list
    element = measure(frame, range(len(points)), hull)
    cycles = tuple(sorted(element.cycles))
    if element.sphere is None or element.center is None or {i for cycle in cycles for i in cycle} != set(range(len(points))):
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
    return _Measured(element.unit_volume, cycles, _on_boundary(cycles, plane_masks), element.center,
                     [float(x) * s for x, s in zip(element.center, scale)])


def _turned(cycle: Sequence[int]) -> tuple[int, ...]:
    """A face cycle started at its smallest node, in its own direction: equal for the same oriented face."""
    start = cycle.index(min(cycle))
    return tuple(cycle[start:]) + tuple(cycle[:start])


def _check_faces(faces: Counter[_Face], across: dict[_Face, _Face], where: str) -> None:
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


def _on_boundary(cycles: Sequence[Sequence[int]], plane_masks: list[int]) -> tuple[bool, ...]:
    """Per face cycle (positions in the node list): whether it lies in a face plane of the base element,
    i.e. one plane holds all its points (``plane_masks``: per point, the planes that hold it)."""
    found = []
    for cycle in cycles:
        common = -1
        for p in cycle:
            common &= plane_masks[p]
        found.append(common != 0)
    return tuple(found)


def _shape_name(shape: Shape) -> str:
    return "box" if shape.name == "cuboid" else shape.name


def read_document(text: str, name: str) -> tuple[str, Catalogue | PatternTable]:
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


def document_data(document: Catalogue | PatternTable) -> dict[str, Any]:
    """A read document as one mapping (a pattern table's header with its configurations), as diff compares them."""
    if isinstance(document, Catalogue):
        return document.to_dict()
    return {**document.header, "configurations": document.configurations}


def validated(data: object, name: str) -> tuple[str, dict[str, Any]]:
    """The document's kind (``catalogue`` or ``patterns``), after schema validation (and, for a
    catalogue, every type once)."""
    kind = document_kind(data, name)
    assert isinstance(data, dict)  # document_kind refuses anything else
    validate(data, kind, name)
    if kind == "catalogue":
        _check_unique(Catalogue.from_dict(data), name)
    return kind, data
