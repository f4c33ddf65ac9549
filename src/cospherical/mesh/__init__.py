"""The mesher: a 1-irregular octree meshed from the pattern tables.

Above the studies it uses (the leaf family, the catalogue's criteria) and below the
formats that read and write its results: ``octree`` builds or reads the tree,
``assembly`` meshes its leaves, ``checks`` decides conformity, volume and the Delaunay
property exactly, ``dual`` gives its finite-volume dual (control volumes, coupling
coefficients, the box method's matrix), ``tetrahedra`` splits the elements into conforming
tetrahedra for solvers that read only simplices, ``statistics`` and ``report`` summarise the mesh, and ``pipeline`` runs them in order:
the one pipeline that :func:`cospherical.build_mesh` and ``cospherical mesh`` both call.
"""

__all__: list[str] = []  # nothing re-exported: the public names are each module's __all__
