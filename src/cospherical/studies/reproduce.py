"""The paper's studies as ``reproduce`` runs them: which boxes, policies and base elements.

The computation only; :func:`cospherical.outputs.reproduce.reproduce` writes
the catalogue, pattern tables and results from it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ..choices import POINT_POLICIES
from ..core.configuration import Box
from .engine import Study, bisection_codes, run_study
from .leaves import leaf_codes, run_leaves

__all__ = ["LEAF_BOXES", "PAPER_BOXES", "SHAPE_BOX", "SHAPE_ELEMENTS", "PaperStudies", "paper_studies_total",
           "run_paper_studies"]

# The paper's test cases A, B and C (C as the paper computed it, at 1.4142), and C at exactly sqrt 2.
PAPER_BOXES = (("1", "1", "1"), ("1", "2", "4"), ("1", "1.4142", "1.4142"), ("1", "sqrt(2)", "sqrt(2)"))
# The octree-leaf family, on the cube and on test case B, beside their octree-policy studies.
LEAF_BOXES = (("1", "1", "1"), ("1", "2", "4"))
# The paper's future work: the other base elements of the mesher, in the unit box.
SHAPE_ELEMENTS = ("prism", "pyramid", "tetrahedron")
SHAPE_BOX = ("1", "1", "1")


@dataclass(frozen=True)
class PaperStudies:
    """The bisection studies of every paper box under both point policies, the leaf studies, the shapes'."""

    bisection: list[Study]
    leaves: list[Study]
    shapes: list[Study]


def paper_studies_total() -> int:
    """The configurations :func:`run_paper_studies` tessellates or maps, for a progress bar."""
    return (len(PAPER_BOXES) * len(POINT_POLICIES) * len(bisection_codes()) + len(LEAF_BOXES) * len(leaf_codes())
            + sum(len(bisection_codes(element)) for element in SHAPE_ELEMENTS))


def run_paper_studies(progress: Callable[[int], None] | None = None) -> PaperStudies:
    """Run every study of ``reproduce``; ``progress(n)`` as configurations are done."""
    codes = bisection_codes()
    bisection: list[Study] = []
    for box in PAPER_BOXES:
        for policy in POINT_POLICIES:  # the first policy's tessellations are the others' where the points agree
            bisection.append(run_study("bisection", Box.parse(box), codes, policy, progress=progress,
                                       known=[s for s in bisection if s.box == Box.parse(box)]))
    # most leaf configurations are a bisection configuration of one policy or the other
    leaves = [run_leaves(Box.parse(box), progress=progress, known=[s for s in bisection if s.box == Box.parse(box)])
              for box in LEAF_BOXES]
    shapes = [run_study("bisection", Box.parse(SHAPE_BOX), bisection_codes(element), progress=progress,
                        element=element) for element in SHAPE_ELEMENTS]
    return PaperStudies(bisection, leaves, shapes)
