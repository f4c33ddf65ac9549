"""The paper's element classes and published figures (package data, reference only)."""

from __future__ import annotations

from functools import lru_cache
from importlib import resources

import yaml

from .element_types import ElementType

__all__ = ["paper_class", "paper_classes", "paper_studies"]


@lru_cache(maxsize=None)
def _data() -> dict:
    return yaml.safe_load(resources.files("cospherical").joinpath("data/paper.yaml").read_text())


def paper_classes() -> list[dict]:
    return _data()["classes"]


def paper_studies() -> dict:
    return _data()["studies"]


def paper_class(etype: ElementType) -> dict | None:
    """The paper's class of an element type: same V/E/F and face kinds, or ``None``."""
    kinds = dict(etype.face_kinds)
    for entry in paper_classes():
        if list(entry["counts"]) == [etype.vertices, etype.edges, etype.faces] and kinds in entry["face_kinds"]:
            return entry
    return None
