"""The intersection study (paper, section 5): Steiner points anywhere, at multiples of 1/R.

``family`` makes the configurations and their orbits, ``run`` computes them in
two checkpointed stages (where the work runs: :mod:`cospherical.execution`), and
``statistics`` counts what was found.
"""

from .family import PARALLEL_EDGES, all_configurations, intersection_codes, orbits, set_patterns
from .run import cell_polyhedron, element_entries, run_intersection, tessellate_chunk
from .statistics import ElementEntry, statistics

__all__ = ["PARALLEL_EDGES", "ElementEntry", "all_configurations", "cell_polyhedron",
           "element_entries",
           "intersection_codes", "orbits", "run_intersection", "set_patterns", "statistics", "tessellate_chunk"]
