"""Studies: every configuration of a family tessellated, one per symmetry orbit, with statistics.

The engine (:mod:`cospherical.studies.engine`) runs any family of codes; the families are the
bisection codes (there), the octree leaves, the intersection study (its own package, run on a
process pool or Dask), and the aspect-ratio sweeps.  Nothing is re-exported here: the public
names are those of each module's ``__all__``.
"""

__all__: list[str] = []
