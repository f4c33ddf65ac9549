"""The library's front door: a whole mesh in one call, and its conversions to other libraries.

:func:`~cospherical.api.mesh.build_mesh` runs the mesher's one pipeline and returns an
:class:`~cospherical.api.mesh.OctreeMesh` (vertices, elements, the exact report, the
dual, its files).  It sits above the formats and the pictures it writes, and below the
command line, which is this call with argument parsing, progress bars and exit codes.
"""

__all__: list[str] = []  # nothing re-exported: cospherical's own __init__ names the public API
