"""The element catalogue: every element type met, named, with an example geometry.

The catalogue is versioned data (``catalogue/catalogue.yaml``, shipped in the
wheel as ``cospherical/data/catalogue.yaml``; built from studies by
:mod:`cospherical.catalogue.build`).  Names follow one rule, applied
when the catalogue is built: a type's structural name (tetrahedron, pyramids,
bipyramids, Triangular Prism, Cuboid) if it has one; else its paper class's name
when the class is not structural (numbered variants when several types share
it); else a systematic name.  The paper class is kept as an alias, which is
what comparisons with the paper use.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Iterable

from ..caches import cached
from ..core.element_types import ElementType, systematic_name
from ..files.data import data_path
from ..files.flowyaml import decode_entry, split_section
from ..files.yamlio import parse_yaml, read_text, validate, validated_data
from ..paper import paper_class
from .model import Catalogue

__all__ = ["SCHEMA_VERSION", "catalogue_from_text", "catalogue_path", "known_name", "load_catalogue",
           "shipped_catalogue", "type_name", "type_names"]

SCHEMA_VERSION = 1


def catalogue_path() -> Path:
    """The shipped catalogue: package data in a wheel, ``catalogue/`` in a checkout."""
    return data_path("catalogue.yaml")


@cached(maxsize=1)  # the shipped file does not change while a process runs
def shipped_catalogue() -> Catalogue:
    """The shipped catalogue, read and validated once per process (empty if there is none).

    Whatever works with another catalogue (``reproduce`` builds one from
    nothing, whatever state the file is in) is given it as an argument.

    Examples
    --------
    >>> shipped_catalogue().schema_version
    1
    """
    path = catalogue_path()
    if not path.exists():
        return Catalogue.empty(SCHEMA_VERSION)
    # the same text every run: its validated data kept as the validators are (load_catalogue's verdicts)
    return Catalogue.from_dict(validated_data(read_text(path), "catalogue", str(path), _catalogue_data))


def known_name(code: str, catalogue: Catalogue | None = None) -> str | None:
    """The name of a canonical code in ``catalogue`` (default: the shipped one), if it has it."""
    return (shipped_catalogue() if catalogue is None else catalogue).name_of(code)


def type_name(etype: ElementType, catalogue: Catalogue | None = None) -> str:
    """The name of an element type: the catalogue's (default: the shipped one), else its structural
    or systematic name.

    Examples
    --------
    >>> from cospherical import Configuration, tessellate
    >>> type_name(tessellate(Configuration.from_code("000000000000")).elements[0].type)
    'Cuboid'
    """
    return known_name(etype.code, catalogue) or etype.name


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


def load_catalogue(path: str | Path) -> Catalogue:
    """Read a catalogue file and validate it against its JSON Schema.

    Parameters
    ----------
    path : str or Path
        A catalogue YAML file, such as ``catalogue/catalogue.yaml``.

    Returns
    -------
    Catalogue
        Its ``version``, its types (one :class:`~cospherical.catalogue.model.CatalogueType`
        each: id, name, code, faces, splits...) by id and by code, and the kept type ids
        per criterion.

    Raises
    ------
    FormatError
        The file cannot be read, is not YAML, or does not fit the schema; the
        message names the file and the place.

    Examples
    --------
    >>> catalogue = load_catalogue(catalogue_path())
    >>> next(t.name for t in catalogue.types if t.vertices == 4)
    'Tetrahedron'
    """
    return catalogue_from_text(read_text(path), str(path))


def catalogue_from_text(text: str, name: str) -> Catalogue:
    """A catalogue's text, validated; a bad catalogue raises :class:`FormatError`.

    A catalogue as this package writes it (one type per line, JSON flow style)
    has its types decoded as JSON and only its header parsed as YAML; any other
    YAML spelling is read by the YAML parser.
    """
    data = _catalogue_data(text, name)
    validate(data, "catalogue", name)
    return Catalogue.from_dict(data)


def _catalogue_data(text: str, name: str) -> Any:
    """A catalogue's text parsed (not yet validated): see :func:`catalogue_from_text`."""
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
    return data
