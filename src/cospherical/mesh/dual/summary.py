"""The report's figures of a dual: negative coefficients, sums, and the mixed mesh beside a tetrahedral one."""

from __future__ import annotations

from typing import NamedTuple

from ..report_sections import DualSummary, MixedCounts, NegativeCoefficients
from .arrays import Dual
from .tetrahedral import TETRAHEDRAL_LIMIT, tetrahedral_counts

__all__ = ["DualFigures", "dual_summary"]


class DualFigures(NamedTuple):
    """The report's figures of a dual: its ``negative_coefficients`` and its ``dual`` section."""

    negative_coefficients: NegativeCoefficients
    dual: DualSummary


def dual_summary(dual: Dual, elements: int, faces: int, tetrahedral: bool = False) -> DualFigures:
    """The report's figures of a dual: negative coefficients, sums, and the mixed mesh beside a tetrahedral one.

    ``elements`` and ``faces`` are the mixed mesh's (faces: interior plus boundary).
    ``tetrahedral`` runs the outside mesher (:func:`tetrahedral_counts`: TetGen on 450,000
    vertices costs several times the dual); without it, or above :data:`TETRAHEDRAL_LIMIT`
    vertices, the tetrahedral side is ``None``.
    """
    mixed = MixedCounts(int(elements), int(len(dual.edges)), int(faces), int(len(dual.vertices) + 2 * len(dual.edges)))
    tets = tetrahedral_counts(dual.grid_vertices) if tetrahedral and len(dual.vertices) <= TETRAHEDRAL_LIMIT else None
    return DualFigures(dual.negative_coefficients(), DualSummary(
        mixed.edges, str(dual.volume_sum()),
        float(dual.coefficient.min()) if len(dual.edges) else None,
        float(dual.coefficient.max()) if len(dual.edges) else None,
        int(dual.boundary.sum()), mixed, tets))
