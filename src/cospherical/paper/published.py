"""The paper's element classes, published figures and notes (package data, reference only)."""

from __future__ import annotations

from typing import Any

from ..caches import cached
from ..core.element_types import ElementType
from ..files.data import data_path
from ..files.yamlio import load_yaml

__all__ = ["paper_class", "paper_classes", "paper_notes", "paper_studies"]


@cached(maxsize=1)
def _data() -> dict[str, Any]:
    # the package's reader: the C parser, 5x faster than yaml.safe_load
    data: dict[str, Any] = load_yaml(data_path("paper.yaml"))
    return data


def paper_classes() -> list[dict[str, Any]]:
    """The paper's element classes: name, short name, V/E/F counts, the face kinds they admit."""
    classes: list[dict[str, Any]] = _data()["classes"]
    return classes


def paper_studies() -> dict[str, Any]:
    """The paper's studies by key (``bisection_A``, ...): box, configurations, published counts."""
    studies: dict[str, Any] = _data()["studies"]
    return studies


def paper_notes() -> dict[str, str]:
    """Why a published figure and ours differ, by key; each comparison cites the ones that apply."""
    notes: dict[str, str] = _data()["notes"]
    return notes


def paper_class(etype: ElementType) -> dict[str, Any] | None:
    """The paper's class of an element type: same V/E/F and face kinds, or ``None``.

    Examples
    --------
    >>> from cospherical import Configuration, tessellate
    >>> paper_class(tessellate(Configuration.from_code("800000000000")).elements[0].type)["name"]
    'Quadrilateral Pyramid'
    """
    kinds = dict(etype.face_kinds)
    for entry in paper_classes():
        if list(entry["counts"]) == [etype.vertices, etype.edges, etype.faces] and kinds in entry["face_kinds"]:
            return entry
    return None
