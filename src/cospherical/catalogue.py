"""The element catalogue: every element type met, named, with an example geometry.

The catalogue is versioned data (``catalogue/catalogue.yaml``, shipped in the
wheel as ``cospherical/data/catalogue.yaml``).  Names follow one rule, applied
when the catalogue is built: a type's structural name (tetrahedron, pyramids,
bipyramids, triangular prism, cuboid) if it has one; else its paper class's name
when the class is not structural (numbered variants when several types share
it); else a systematic name.  The paper class is kept as an alias, which is
what comparisons with the paper use.
"""

from __future__ import annotations

import hashlib
import json
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Iterable

from . import __version__
from .element_types import ElementType, systematic_name
from .split import SPLIT_CRITERIA
from .paper import paper_class
from .yamlio import dump_yaml, load_yaml, validate

__all__ = ["SCHEMA_VERSION", "build_catalogue", "catalogue_path", "known_name", "load_catalogue", "shipped_catalogue", "type_names"]

SCHEMA_VERSION = 1


def catalogue_path() -> Path:
    """The shipped catalogue: package data in a wheel, ``catalogue/`` in a checkout."""
    packaged = Path(str(resources.files("cospherical").joinpath("data/catalogue.yaml")))
    if packaged.exists():
        return packaged
    return Path(__file__).resolve().parents[2] / "catalogue" / "catalogue.yaml"


@lru_cache(maxsize=None)
def shipped_catalogue() -> dict:
    """The shipped catalogue, read and validated once per process (empty if there is none)."""
    path = catalogue_path()
    if not path.exists():
        return {"schema_version": SCHEMA_VERSION, "version": "none", "types": []}
    return load_catalogue(path)


@lru_cache(maxsize=None)
def _known_names() -> dict[str, str]:
    return {entry["code"]: entry["name"] for entry in shipped_catalogue()["types"]}


def known_name(code: str) -> str | None:
    """The catalogue's name of a canonical code, if the shipped catalogue has it."""
    return _known_names().get(code)


def type_names(types: Iterable[ElementType]) -> dict[str, tuple[str, list[str]]]:
    """Type id -> (name, aliases) by the catalogue's naming rule; names are unique."""
    types = sorted(types, key=lambda t: t.id)
    base = {}
    aliases = {}
    for t in types:
        cls = paper_class(t)
        aliases[t.id] = [cls["name"]] if cls else []
        if t.structural:
            base[t.id] = t.structural
        elif cls and not cls.get("structural"):
            base[t.id] = cls["name"]
        else:
            base[t.id] = systematic_name(t.vertices, t.face_summary)
    names = {}
    for t in types:
        sharing = [u.id for u in types if base[u.id] == base[t.id]]
        suffix = f" (variant {sharing.index(t.id) + 1})" if len(sharing) > 1 else ""
        names[t.id] = (base[t.id] + suffix, aliases[t.id])
    return names


def _chiral(element) -> bool:
    """Whether the type differs from its mirror image (its canonical walks need one handedness)."""
    from .canonical import canonical_form

    mirror = [tuple(reversed(face)) for face in element.polyhedron.faces]
    return canonical_form(mirror, element.polyhedron.face_kinds).mirrored != element.mirrored


def _study_label(study) -> str:
    return f"{study.name} {'x'.join(study.box.texts)} {study.face_points}"


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


def load_catalogue(path: str | Path) -> dict:
    """Read and validate a catalogue file."""
    data = load_yaml(path)
    validate(data, "catalogue", path)
    return data


def write_catalogue(catalogue: dict, path: str | Path) -> None:
    dump_yaml(catalogue, path)
