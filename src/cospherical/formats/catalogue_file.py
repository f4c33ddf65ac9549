"""The catalogue file, built from studies: every element type met, named, with an example geometry."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from ..catalogue import SCHEMA_VERSION, type_names
from ..core.canonical import canonical_form
from ..core.element_types import ElementType
from ..core.split import SPLIT_CRITERIA
from ..files.yamlio import dump_yaml
from ..version import __version__

__all__ = ["build_catalogue", "write_catalogue"]


def _chiral(element) -> bool:
    """Whether the type differs from its mirror image (its canonical walks need one handedness)."""
    mirror = [tuple(reversed(face)) for face in element.polyhedron.faces]
    return canonical_form(mirror, element.polyhedron.face_kinds).mirrored != element.mirrored


def _study_label(study) -> str:
    element = "" if study.element == "cuboid" else f" {study.element}"
    return f"{study.name}{element} {'x'.join(study.box.texts)} {study.face_points}"


def build_catalogue(studies) -> dict:
    """The catalogue of every element type met in the studies, as YAML-ready data."""
    examples: dict[str, tuple] = {}
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
                    examples.setdefault(t.id, (study, reps[rep], element))
                    if label not in appears.setdefault(t.id, []):
                        appears[t.id].append(label)
    names = type_names(types.values())
    splits: dict[str, dict[str, set]] = {}
    kept: dict[str, set[str]] = {}
    for study in studies:
        for criterion, choice in study.choices.items():
            if criterion == "optimal":
                continue
            kept.setdefault(criterion, set()).update(choice.kept)
            for type_id, used in choice.splits.items():
                splits.setdefault(type_id, {}).setdefault(criterion, set()).update(used)
    entries = []
    for type_id in sorted(types, key=lambda i: (types[i].vertices, types[i].faces, i)):
        t = types[type_id]
        study, tess, element = examples[type_id]
        position = {v: i for i, v in enumerate(element.nodes)}
        real = tess.configuration.real_nodes()
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
                    "configuration": tess.configuration.code,
                    **({"element": study.element} if study.element != "cuboid" else {}),
                    "box": list(study.box.texts),
                    "face_points": study.face_points,
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
    return {
        "schema_version": SCHEMA_VERSION,
        "version": digest,
        "generator": f"cospherical {__version__}",
        "criteria": {criterion: {"kept": sorted(ids)} for criterion, ids in sorted(kept.items())},
        "types": entries,
    }


def write_catalogue(catalogue: dict, path: str | Path) -> None:
    dump_yaml(catalogue, path)
