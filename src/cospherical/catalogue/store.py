"""The element catalogue: every element type met, named, with an example geometry.

The catalogue is versioned data (``catalogue/catalogue.yaml``, shipped in the
wheel as ``cospherical/data/catalogue.yaml``; built from studies by
:mod:`cospherical.formats.catalogue_file`).  Names follow one rule, applied
when the catalogue is built: a type's structural name (tetrahedron, pyramids,
bipyramids, Triangular Prism, Cuboid) if it has one; else its paper class's name
when the class is not structural (numbered variants when several types share
it); else a systematic name.  The paper class is kept as an alias, which is
what comparisons with the paper use.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path
from typing import Iterable

from ..core.element_types import ElementType, systematic_name
from ..files.data import data_path
from ..files.flowyaml import decode_entry, split_section
from ..files.yamlio import parse_yaml, read_text, validate
from ..paper import paper_class

__all__ = ["SCHEMA_VERSION", "catalogue_from_text", "catalogue_path", "known_name", "load_catalogue", "shipped_catalogue",
           "type_name", "use_catalogue",
           "type_names"]

SCHEMA_VERSION = 1


def catalogue_path() -> Path:
    """The shipped catalogue: package data in a wheel, ``catalogue/`` in a checkout."""
    return data_path("catalogue.yaml")


_in_use: list[dict] = []  # set by use_catalogue(): the catalogue this process works with instead of the file


def shipped_catalogue() -> dict:
    """The shipped catalogue, read and validated once per process (empty if there is none).

    Examples
    --------
    >>> shipped_catalogue()["schema_version"]
    1
    """
    return _in_use[0] if _in_use else _read_shipped()


@lru_cache(maxsize=None)
def _read_shipped() -> dict:
    path = catalogue_path()
    if not path.exists():
        return {"schema_version": SCHEMA_VERSION, "version": "none", "types": []}
    return load_catalogue(path)


def use_catalogue(catalogue: dict | None) -> None:
    """Work with ``catalogue`` (names, kept sets) instead of the shipped file; ``None``: the file again.

    ``reproduce`` regenerates the catalogue from nothing: it starts from an empty
    one, whatever state the file is in (missing, stale, corrupt), and then names
    everything by the catalogue it has just built, so one run gives the final bytes.
    """
    _in_use[:] = [catalogue] if catalogue is not None else []
    _known_names.cache_clear()


@lru_cache(maxsize=None)
def _known_names() -> dict[str, str]:
    return {entry["code"]: entry["name"] for entry in shipped_catalogue()["types"]}


def known_name(code: str) -> str | None:
    """The catalogue's name of a canonical code, if the shipped catalogue has it."""
    return _known_names().get(code)


def type_name(etype: ElementType) -> str:
    """The name of an element type: the shipped catalogue's, else its structural or systematic name.

    Examples
    --------
    >>> from cospherical import Configuration, tessellate
    >>> type_name(tessellate(Configuration.from_code("000000000000")).elements[0].type)
    'Cuboid'
    """
    return known_name(etype.code) or etype.name


def type_names(types: Iterable[ElementType]) -> dict[str, tuple[str, list[str]]]:
    """Type id -> (name, aliases) by the catalogue's naming rule; names are unique."""
    types = sorted(types, key=lambda t: t.id)
    base = {}
    aliases = {}
    for t in types:
        cls = paper_class(t)
        aliases[t.id] = [cls["name"]] if cls else []
        if t.structural:
            base[t.id] = t.structural
        elif cls and not cls.get("structural"):
            base[t.id] = cls["name"]
        else:
            base[t.id] = systematic_name(t.vertices, t.face_summary)
    names = {}
    for t in types:
        sharing = [u.id for u in types if base[u.id] == base[t.id]]
        suffix = f" (variant {sharing.index(t.id) + 1})" if len(sharing) > 1 else ""
        names[t.id] = (base[t.id] + suffix, aliases[t.id])
    return names


def load_catalogue(path: str | Path) -> dict:
    """Read a catalogue file and validate it against its JSON Schema.

    Parameters
    ----------
    path : str or Path
        A catalogue YAML file, such as ``catalogue/catalogue.yaml``.

    Returns
    -------
    dict
        ``schema_version``, ``version``, ``criteria`` (kept type ids per criterion)
        and ``types`` (one entry per element type: id, name, code, faces, splits...).

    Raises
    ------
    FormatError
        The file cannot be read, is not YAML, or does not fit the schema; the
        message names the file and the place.

    Examples
    --------
    >>> catalogue = load_catalogue(catalogue_path())
    >>> next(t["name"] for t in catalogue["types"] if t["vertices"] == 4)
    'Tetrahedron'
    """
    return catalogue_from_text(read_text(path), str(path))


def catalogue_from_text(text: str, name: str) -> dict:
    """A catalogue's text as validated data; a bad catalogue raises :class:`FormatError`.

    A catalogue as this package writes it (one type per line, JSON flow style)
    has its types decoded as JSON and only its header parsed as YAML; any other
    YAML spelling is read by the YAML parser.
    """
    split = split_section(text, "types")
    data = None
    if split is not None and isinstance(split[1], list):
        data = parse_yaml(split[0], name)
        if isinstance(data, dict) and "types" not in data and "configurations" not in data:
            data["types"] = [decode_entry(item, f"{name}: types/{i}") for i, item in enumerate(split[1])]
        else:
            data = None
    if data is None:
        data = parse_yaml(text, name)
    validate(data, "catalogue", name)
    return data
