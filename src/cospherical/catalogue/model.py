"""The element catalogue as an object: its types, looked up by id or canonical code, and its kept sets.

A catalogue file (``catalogue/catalogue.yaml``) is read and validated by
:func:`cospherical.catalogue.load_catalogue`, built from studies by
:func:`cospherical.catalogue.build_catalogue`; either gives a :class:`Catalogue`.
Whatever names element types, splits them by a criterion or checks a pattern
table against the catalogue is given this object and asks it what it needs:
``catalogue[type_id]``, ``type_id in catalogue``, ``catalogue.name_of(code)``,
``catalogue.kept(criterion)``.  The document it was made from is kept whole
(:meth:`Catalogue.to_dict`), so that a catalogue is written back byte for byte.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Any, Iterator, Mapping

__all__ = ["Catalogue", "CatalogueType", "Example", "ReferenceFace", "SplitPiece"]


@dataclass(frozen=True)
class ReferenceFace:
    """A face of a type's reference form: positions in its node order, counter-clockwise seen from
    outside, and the face's kind (``triangle``, ``rectangle``, ``quadrilateral``...)."""

    nodes: tuple[int, ...]
    kind: str


@dataclass(frozen=True)
class SplitPiece:
    """A piece of a split: its type id and its nodes as positions in the parent's reference order."""

    type: str
    nodes: tuple[int, ...]


@dataclass(frozen=True)
class Example:
    """Where a type was met: the configuration code, base element, box and point policy, the
    element's node ids there and their coordinates (floats, in the box)."""

    configuration: str | None
    element: str
    box: tuple[str, str, str]
    face_points: str
    nodes: tuple[int, ...]
    coordinates: tuple[tuple[float, ...], ...]


@dataclass(frozen=True)
class CatalogueType:
    """One element type of the catalogue (one entry of its ``types``).

    ``aliases`` holds the paper's class name first when the paper has the type
    (:attr:`paper_class`); ``vtk`` is the VTK cell for the standard shapes, else
    ``None``; ``splits`` maps a criterion to the splits the studies used, each a
    tuple of :class:`SplitPiece`.
    """

    id: str
    name: str
    aliases: tuple[str, ...]
    code: str
    vertices: int
    edges: int
    faces: int
    face_kinds: Mapping[str, int]
    vtk: str | None
    chiral: bool
    reference_faces: tuple[ReferenceFace, ...]
    example: Example
    studies: tuple[str, ...]
    splits: Mapping[str, tuple[tuple[SplitPiece, ...], ...]]

    @property
    def paper_class(self) -> str | None:
        """The paper's name of the type's class, if the paper has it (the first alias)."""
        return self.aliases[0] if self.aliases else None

    @classmethod
    def from_dict(cls, entry: Mapping[str, Any]) -> CatalogueType:
        """An entry of a validated catalogue document (the schema's fields and types)."""
        example = entry["example"]
        box = example["box"]
        return cls(
            id=entry["id"], name=entry["name"], aliases=tuple(entry["aliases"]), code=entry["code"],
            vertices=entry["vertices"], edges=entry["edges"], faces=entry["faces"],
            face_kinds=dict(entry["face_kinds"]), vtk=entry.get("vtk"), chiral=bool(entry.get("chiral", False)),
            reference_faces=tuple(ReferenceFace(tuple(face["nodes"]), face["kind"])
                                  for face in entry["reference_faces"]),
            example=Example(example["configuration"], example.get("element", "cuboid"), (box[0], box[1], box[2]),
                            example["face_points"], tuple(example["nodes"]),
                            tuple(tuple(point) for point in example["coordinates"])),
            studies=tuple(entry.get("studies", ())),
            splits={criterion: tuple(tuple(SplitPiece(piece["type"], tuple(piece["nodes"])) for piece in split)
                                     for split in splits)
                    for criterion, splits in entry.get("splits", {}).items()},
        )


@dataclass(frozen=True, eq=False)
class Catalogue:
    """The element catalogue: every type met, by id and by canonical code, and per criterion the
    kept types (what :func:`cospherical.catalogue.apply_catalogue_criterion` splits into).

    Made from a validated document (:meth:`from_dict`); immutable; two catalogues are the
    same object or different ones (compare :attr:`version`, or :meth:`to_dict`, for contents).

    Examples
    --------
    >>> from cospherical.catalogue import shipped_catalogue
    >>> catalogue = shipped_catalogue()
    >>> tetra = next(t for t in catalogue if t.vertices == 4)
    >>> tetra.name, tetra.vtk, tetra.id in catalogue, catalogue[tetra.id] is tetra
    ('Tetrahedron', 'tetra', True, True)
    >>> catalogue.name_of(tetra.code)
    'Tetrahedron'
    """

    schema_version: int
    version: str
    generator: str | None
    types: tuple[CatalogueType, ...]
    criteria: Mapping[str, frozenset[str]]  # criterion -> the type ids it keeps
    _document: Mapping[str, Any] = field(repr=False)
    _by_id: Mapping[str, CatalogueType] = field(init=False, repr=False)
    _by_code: Mapping[str, CatalogueType] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_by_id", {t.id: t for t in self.types})
        object.__setattr__(self, "_by_code", {t.code: t for t in self.types})

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Catalogue:
        """The catalogue of a document that fits the catalogue's JSON Schema (as read, or as built)."""
        return cls(schema_version=data["schema_version"], version=data["version"], generator=data.get("generator"),
                   types=tuple(CatalogueType.from_dict(entry) for entry in data["types"]),
                   criteria={criterion: frozenset(entry.get("kept", ()))
                             for criterion, entry in data.get("criteria", {}).items()},
                   _document=data)

    @classmethod
    def empty(cls, schema_version: int) -> Catalogue:
        """A catalogue without types (what a checkout without a catalogue file has)."""
        return cls.from_dict({"schema_version": schema_version, "version": "none", "types": []})

    def to_dict(self) -> dict[str, Any]:
        """The document (a copy): what :func:`cospherical.formats.catalogue_file.write_catalogue`
        writes and ``diff`` compares."""
        return copy.deepcopy(dict(self._document))

    def __len__(self) -> int:
        return len(self.types)

    def __iter__(self) -> Iterator[CatalogueType]:
        return iter(self.types)

    def __contains__(self, type_id: object) -> bool:
        return type_id in self._by_id

    def __getitem__(self, type_id: str) -> CatalogueType:
        """The type of id ``type_id`` (``KeyError`` if the catalogue lacks it)."""
        return self._by_id[type_id]

    def get(self, type_id: str) -> CatalogueType | None:
        """The type of id ``type_id``, or ``None``."""
        return self._by_id.get(type_id)

    def by_code(self, code: str) -> CatalogueType | None:
        """The type of canonical code ``code``, or ``None``."""
        return self._by_code.get(code)

    def name_of(self, code: str) -> str | None:
        """The catalogue's name of the type of canonical code ``code``, if it has that type."""
        found = self._by_code.get(code)
        return found.name if found is not None else None

    def kept(self, criterion: str) -> frozenset[str]:
        """The type ids kept under a splitting criterion (empty when the catalogue has none for it)."""
        return self.criteria.get(criterion, frozenset())

    def names(self) -> dict[str, tuple[str, list[str]]]:
        """Type id -> (name, aliases), as :func:`cospherical.catalogue.type_names` gives them."""
        return {t.id: (t.name, list(t.aliases)) for t in self.types}
