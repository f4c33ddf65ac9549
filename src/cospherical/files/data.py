"""Package data, found in one way: the catalogue, JSON Schemas, LaTeX templates, the paper's figures.

``cospherical/data/`` holds the schemas and the paper's figures.  The catalogue
and the templates live in the repository's top-level ``catalogue/`` and
``templates/`` (where the design card puts them, and where ``reproduce`` writes
the catalogue); the wheel copies both into ``cospherical/data/``.  So a file is
looked up in the package first and, in a source checkout, in its top-level home.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["data_path"]

_PACKAGE_DATA = Path(__file__).resolve().parent.parent / "data"
_CHECKOUT = Path(__file__).resolve().parents[3]
_TOP_LEVEL_HOME = {"catalogue.yaml": "catalogue/catalogue.yaml", "templates": "templates"}


def data_path(name: str) -> Path:
    """The path of a data file or folder of the package.

    Parameters
    ----------
    name : str
        Its name inside ``cospherical/data/``, e.g. ``"schemas/patterns.schema.json"``.

    Returns
    -------
    Path
        The packaged file when it exists, else its top-level home in a source
        checkout (which may not exist yet, e.g. a catalogue not yet generated).

    Examples
    --------
    >>> data_path("paper.yaml").name
    'paper.yaml'
    >>> data_path("templates").is_dir()
    True
    """
    packaged = _PACKAGE_DATA / name
    if packaged.exists() or name not in _TOP_LEVEL_HOME:
        return packaged
    return _CHECKOUT / _TOP_LEVEL_HOME[name]
