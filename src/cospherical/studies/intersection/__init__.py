"""The intersection study (paper, section 5): Steiner points anywhere, at multiples of 1/R.

``family`` makes the configurations and their orbits, ``run`` computes them in
two checkpointed stages, ``backends`` says where the work runs (this process, a
process pool, Dask), and ``statistics`` counts what was found.
"""

from .backends import completed
from .family import INSERTION_ORDERS, PARALLEL_EDGES, all_configurations, intersection_codes, orbits, set_patterns
from .run import ElementEntry, cell_polyhedron, element_entries, run_intersection, tessellate_chunk
from .statistics import statistics

__all__ = ["INSERTION_ORDERS", "PARALLEL_EDGES", "ElementEntry", "all_configurations", "cell_polyhedron", "completed",
           "element_entries",
           "intersection_codes", "orbits", "run_intersection", "set_patterns", "statistics", "tessellate_chunk"]
