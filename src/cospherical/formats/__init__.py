"""The project's file formats, read and written: the catalogue, pattern tables (YAML and the
indexed SQLite store), tessellations, meshes (VTU and the leaf lists), the finite-volume dual, and
the checks and diffs of these files.  What it writes is computed below it and handed over.

Nothing is re-exported here: the public names are those of each module's ``__all__``; the pattern
table's reader is also :func:`cospherical.load_patterns`.
"""

__all__: list[str] = []
