"""The report's figures of a dual: negative coefficients, sums, and the mixed mesh beside a tetrahedral one."""

from __future__ import annotations

from typing import Any

from .arrays import Dual
from .tetrahedral import TETRAHEDRAL_LIMIT, tetrahedral_counts

__all__ = ["dual_summary"]


def dual_summary(dual: Dual, elements: int, faces: int, tetrahedral: bool = False) -> dict[str, Any]:
    """The report's figures of a dual: negative coefficients, sums, and the mixed mesh beside a tetrahedral one.

    ``elements`` and ``faces`` are the mixed mesh's (faces: interior plus boundary).
    ``tetrahedral`` runs the outside mesher (:func:`tetrahedral_counts`: TetGen on 450,000
    vertices costs several times the dual); without it, or above :data:`TETRAHEDRAL_LIMIT`
    vertices, the tetrahedral side is ``None``.
    """
    negative = dual.negative_coefficients()
    mixed = {"elements": int(elements), "edges": int(len(dual.edges)), "faces": int(faces),
             "nonzeros": int(len(dual.vertices) + 2 * len(dual.edges))}
    tets = tetrahedral_counts(dual.grid_vertices) if tetrahedral and len(dual.vertices) <= TETRAHEDRAL_LIMIT else None
    return {"negative_coefficients": negative, "dual": {
        "edges": mixed["edges"], "volume_sum": str(dual.volume_sum()),
        "coefficient_min": float(dual.coefficient.min()) if len(dual.edges) else None,
        "coefficient_max": float(dual.coefficient.max()) if len(dual.edges) else None,
        "boundary_vertices": int(dual.boundary.sum()), "mixed": mixed, "tetrahedral": tets}}
