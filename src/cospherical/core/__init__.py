"""The exact core: numbers, the geometry kernel (geometry.py: every exact predicate and construction,
which the rest of the project calls and never writes out), the Morton curve, configurations and
shapes, Delaunay cells, element types, tessellations, symmetries and splits (their layers, bottom to top, in pyproject.toml's import-linter contract).

Nothing is re-exported here: the public names are those of each module's ``__all__``, the most
used of them also at the top level (:mod:`cospherical`).
"""

__all__: list[str] = []
