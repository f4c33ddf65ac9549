"""Reading and writing files, independent of the geometry: YAML and JSON read strictly, the
one-entry-per-line YAML of the catalogue and tables, outputs written whole or not at all, git
revisions and the package's data files.

Nothing is re-exported here: the public names are those of each module's ``__all__``.
"""

__all__: list[str] = []
