"""What the studies are shown as: text reports, LaTeX tables, figures, the mesh picture, and the
``reproduce`` pipeline that regenerates ``catalogue/``, ``patterns/`` and ``results/``.

Nothing is re-exported here: the public names are those of each module's ``__all__``.
"""

__all__: list[str] = []
