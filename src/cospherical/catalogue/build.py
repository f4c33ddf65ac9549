"""The catalogue built from studies: every element type met, named, with an example geometry and its splits.

:func:`build_catalogue` computes the catalogue's data (written by
:func:`cospherical.formats.catalogue_file.write_catalogue`); the intersection
studies' types come in as examples (:func:`intersection_examples`), each
rebuilt from its configuration and nodes.
"""

from __future__ import annotations

import hashlib
import json
from typing import Any, Mapping, Protocol, Sequence
from pathlib import Path

from ..core.canonical import canonical_form
from ..core.configuration import Box, Configuration
from ..core.delaunay import delaunay_cells
from ..core.element_types import ElementType
from ..core.geometry import Frame
from ..core.polyhedron import polyhedron
from ..choices import SPLIT_CRITERIA
from ..core.tessellation import Element
from ..errors import FormatError
from ..files.data import data_path
from ..files.flowyaml import decode_entry, split_section
from ..files.yamlio import read_text
from ..version import __version__
from .model import Catalogue
from .criteria import Choice, SplitPositions, option_types, split_options, split_positions
from .names import SCHEMA_VERSION, type_names

__all__ = ["StudyResult", "build_catalogue", "intersection_examples"]


def _chiral(element: Element) -> bool:
    """Whether the type differs from its mirror image (its canonical walks need one handedness)."""
    mirror = [tuple(reversed(face)) for face in element.polyhedron.faces]
    return canonical_form(mirror, element.polyhedron.face_kinds).mirrored != element.mirrored


class StudyResult(Protocol):
    """What the catalogue reads of a study: a :class:`cospherical.studies.engine.Study` (a layer above) is one."""

    @property
    def name(self) -> str: ...
    @property
    def box(self) -> Box: ...
    @property
    def face_points(self) -> str: ...
    @property
    def element(self) -> str: ...
    @property
    def choices(self) -> Mapping[str, Choice]: ...


def _study_label(study: StudyResult) -> str:
    element = "" if study.element == "cuboid" else f" {study.element}"
    return f"{study.name}{element} {'x'.join(study.box.texts)} {study.face_points}"


def intersection_examples(path: str | Path | None = None) -> list[dict[str, Any]]:
    """The examples of the intersection studies' types (``scripts/intersection_examples.py`` writes them),
    each rebuilt as an element: dicts with ``configuration``, ``element``, ``studies`` and ``splits``
    (per criterion, the splits the studies used, as (piece type, positions in the element's
    reference order) tuples).

    A type is rebuilt from its configuration code (the cube, octree points) and node ids: the
    points are co-spherical, so their Delaunay subdivision is the element itself.  A file whose
    example no longer gives its type (the classification changed) raises :class:`FormatError`.
    """
    path = Path(path) if path else data_path("intersection-examples.yaml")
    if not path.exists():
        return []
    split = split_section(read_text(path), "types")
    if split is None or not isinstance(split[1], list):
        raise FormatError(f"{path}: not a list of examples, one per line")
    found = []
    for i, text in enumerate(split[1]):
        example = decode_entry(text, f"{path}: types/{i}")
        configuration = Configuration.from_code(example["configuration"])
        nodes = configuration.nodes()
        points = {n: nodes[n] for n in example["nodes"]}
        frame = Frame.build(points, configuration.box.squared)
        (cell,) = delaunay_cells(frame)
        poly = polyhedron(frame, cell)
        element = Element.from_polyhedron(poly)
        if element.type.id != example["type"]:
            raise FormatError(f"{path}: types/{i}: the example gives type {element.type.id}, not {example['type']}: "
                              "run scripts/intersection_examples.py again")
        splits = {}
        for criterion, used in example["splits"].items():
            options = split_options(tuple(sorted(points.items())), configuration.box.squared, poly, criterion)
            splits[criterion] = {split_positions(element, option) for option in options
                                 if sorted(option_types(option)) in used}
        found.append({"configuration": configuration, "element": element, "studies": example["studies"],
                      "splits": splits})
    return found


def build_catalogue(studies: Sequence[StudyResult], extra: Sequence[dict[str, Any]] = ()) -> Catalogue:
    """The catalogue of every element type met in the studies (written by
    :func:`cospherical.formats.catalogue_file.write_catalogue`).

    ``extra``: examples of further types (:func:`intersection_examples`), after the studies'.
    """
    examples: dict[str, tuple[Sequence[str], str, Configuration, Element, str]] = {}
    appears: dict[str, list[str]] = {}
    types: dict[str, ElementType] = {}
    # Optimal elements first, so that a type's example is an unsplit element where
    # it has one; pieces of splits are element types too.
    for criterion in ("optimal", *SPLIT_CRITERIA):
        for study in studies:
            if criterion not in study.choices:
                continue
            label = _study_label(study) + ("" if criterion == "optimal" else f" ({criterion})")
            reps = study.choices[criterion].tessellations
            for rep in sorted(reps):
                for element in reps[rep].elements:
                    t = element.type
                    types[t.id] = t
                    if t.id not in examples:  # (the box's texts cost more than the rest of this loop)
                        examples[t.id] = (study.box.texts, study.face_points, reps[rep].configuration, element,
                                          study.element)
                    if label not in appears.setdefault(t.id, []):
                        appears[t.id].append(label)
    for example in extra:
        element = example["element"]
        types.setdefault(element.type.id, element.type)
        examples.setdefault(element.type.id, (("1", "1", "1"), "octree", example["configuration"], element, "cuboid"))
        appears.setdefault(element.type.id, []).extend(example["studies"])
    names = type_names(types.values())
    splits: dict[str, dict[str, set[SplitPositions]]] = {}
    kept: dict[str, set[str]] = {}
    for study in studies:
        for criterion, choice in study.choices.items():
            if criterion == "optimal":
                continue
            kept.setdefault(criterion, set()).update(choice.kept)
            for type_id, used in choice.splits.items():
                splits.setdefault(type_id, {}).setdefault(criterion, set()).update(used)
    for example in extra:
        for criterion, used in example["splits"].items():
            splits.setdefault(example["element"].type.id, {}).setdefault(criterion, set()).update(used)
    entries = []
    for type_id in sorted(types, key=lambda i: (types[i].vertices, types[i].faces, i)):
        t = types[type_id]
        box_texts, face_points, configuration, element, shape = examples[type_id]
        position = {v: i for i, v in enumerate(element.nodes)}
        real = configuration.real_nodes()
        # Faces of the type's direct form, counter-clockwise seen from outside: an
        # example that is the mirror image gives them the other way round.
        faces = sorted(
            ([position[v] for v in (reversed(face) if element.mirrored else face)], kind)
            for face, kind in zip(element.polyhedron.faces, element.polyhedron.face_kinds)
        )
        faces = [(nodes[nodes.index(min(nodes)):] + nodes[: nodes.index(min(nodes))], kind) for nodes, kind in faces]
        faces.sort()
        entries.append(
            {
                "id": t.id,
                "name": names[type_id][0],
                "aliases": names[type_id][1],
                "code": t.code,
                "vertices": t.vertices,
                "edges": t.edges,
                "faces": t.faces,
                "face_kinds": dict(t.face_kinds),
                "vtk": t.vtk,
                "chiral": t.vtk is None and _chiral(element),
                "reference_faces": [{"nodes": nodes, "kind": kind} for nodes, kind in faces],
                "example": {
                    "configuration": configuration.code,
                    **({"element": shape} if shape != "cuboid" else {}),
                    "box": list(box_texts),
                    "face_points": face_points,
                    "nodes": list(element.nodes),
                    "coordinates": [list(real[v]) for v in element.nodes],
                },
                "studies": appears[type_id],
                "splits": {
                    criterion: [
                        [{"type": piece_type, "nodes": list(positions)} for piece_type, positions in split]
                        for split in sorted(found)
                    ]
                    for criterion, found in sorted(splits.get(type_id, {}).items())
                },
            }
        )
    digest = hashlib.sha256(json.dumps([entries, sorted(kept.items())], sort_keys=True, default=sorted).encode()).hexdigest()[:12]
    return Catalogue.from_dict({
        "schema_version": SCHEMA_VERSION,
        "version": digest,
        "generator": f"cospherical {__version__}",
        "criteria": {criterion: {"kept": sorted(ids)} for criterion, ids in sorted(kept.items())},
        "types": entries,
    })
