"""Pattern tables: per configuration code, the elements a mesh generator puts there.

A table is YAML: a header (schema_version, generator and catalogue versions,
study, box, point policy, scheme, criteria) and, for every configuration code,
``fvm_adequate`` and per criterion the list of elements, each with its type id,
node ids in the type's reference order (see the catalogue) and circumcenter.
Where a criterion gives the same elements as an earlier one, the entry is that
criterion's name (``internal_faces: optimal``) instead of a copy.
A mesh generator looks a configuration up like this::

    table = cospherical.load_patterns("patterns/bisection-1x1x1.yaml")
    for element in table.elements("800000000000"):
        print(element["type"], element["nodes"])
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator, Protocol, Sequence

from ..caches import cached
from ..choices import FacePointSource, POINT_POLICIES
from ..core.configuration import Box
from ..core.shapes import ELEMENTS
from ..core.tessellation import Element, Tessellation, element_entry
from ..errors import FormatError, InputError, shown
from ..files.data import data_path
from ..files.flowyaml import decode_entry, flow, mapping_text, split_section
from ..files.yamlio import atomic_write, parse_yaml, read_text, validate, yaml_text
from ..version import __version__
from .sqlite_store import is_store, open_store

__all__ = ["Entries", "PatternTable", "SCHEMA_VERSION", "configuration_line", "element_entry",
           "entry_elements", "load", "pattern_name", "patterns_text", "table_from_data", "table_from_text",
           "write_patterns"]

SCHEMA_VERSION = 1
_SCHEMES = {
    "bisection": "midpoints: every Steiner point at t = 1/2",
    "leaves": "octree leaves: midpoints at t = 1/2, the centre of every face whose neighbour is refined "
    "(any set of faces with four split edges), never a body point; keys are whole-point-set codes",
}


def pattern_name(study: str, box_texts: Sequence[str], face_points: str = "octree", element: str = "cuboid") -> str:
    """File stem for a study's outputs, e.g. ``bisection-1x1.4142x1.4142``: a lossless name of the box.

    Another base element than the cuboid is named after the study:
    ``bisection-prism-1x1x1``.  The box's canonical texts (digits, ``.``, ``/`` and
    ``sqrt(...)``) are written with ``/`` as ``_`` and ``sqrt(R)`` as ``sqrtR``, so
    different boxes never share a name (``1/3`` is ``1_3``, ``13`` is ``13``).
    Names read from a file are checked against the known ones: never a path.

    >>> pattern_name("bisection", ["1/3", "sqrt(2/3)", "2*sqrt(2)"], "none")
    'bisection-1_3xsqrt2_3xsqrt8-none'
    """
    if study not in _SCHEMES and study != "intersection" or face_points not in (*POINT_POLICIES, "explicit") \
            or element not in ELEMENTS:
        raise InputError(f"study {study!r} of a {element!r} with face points {face_points!r}: not a known study")
    texts = Box.parse(box_texts).texts
    box = "x".join(text.replace("/", "_").replace("sqrt(", "sqrt").replace(")", "") for text in texts)
    # explicit points are named by the codes inside the table, not by its file name
    return f"{study}-{'' if element == 'cuboid' else element + '-'}{box}" + (
        "" if face_points in ("octree", "explicit") else f"-{face_points}")


class _StudyTable(Protocol):
    """What a pattern table is written from: a study's result (:class:`cospherical.studies.engine.Study`)."""

    # read-only: a study is frozen, and its criteria are a property
    @property
    def name(self) -> str: ...
    @property
    def element(self) -> str: ...
    @property
    def box(self) -> Box: ...
    @property
    def face_points(self) -> FacePointSource: ...
    @property
    def criteria(self) -> tuple[str, ...]: ...


    def rows(self) -> Iterable[tuple[str, bool, Mapping[str, Tessellation], Callable[[Tessellation], Tessellation]]]:
        """Per configuration, in code order: its code, ``fvm_adequate``, the tessellations per
        criterion, and the map from those onto the configuration (see :func:`configuration_line`)."""


def patterns_text(study: _StudyTable, catalogue_version: str) -> str:
    """The pattern table of a study as YAML text (deterministic)."""
    header = {
        "schema_version": SCHEMA_VERSION,
        "generator": f"cospherical {__version__}",
        "catalogue_version": catalogue_version,
        "study": study.name,
        **({"element": study.element} if study.element != "cuboid" else {}),
        "box": list(study.box.texts),
        "face_points": study.face_points,
        "scheme": _SCHEMES.get(study.name, study.name),
        "criteria": list(study.criteria),
    }
    lines = [yaml_text(header), "configurations:\n"]
    texts: ElementTexts = {}  # one table's element texts: an element repeats in thousands of configurations
    lines.extend(configuration_line(*row, texts=texts) for row in study.rows())
    return "".join(lines)


# The element texts one table's lines share: (the element object's id, the box's scale) -> (the element, its
# text), the element kept so that its id stays its own.
ElementTexts = dict[tuple[int, tuple[float, float, float]], tuple[Element, str]]


def configuration_line(code: str, fvm_adequate: bool, tessellations: Mapping[str, Tessellation],
                       image: Callable[[Tessellation], Tessellation] = lambda tess: tess,
                       texts: ElementTexts | None = None) -> str:
    """One configuration's entry in a pattern table, every table's: one line of YAML (a JSON flow mapping).

    ``tessellations``: per criterion, in the table's order.  Where a criterion
    gives the same elements as an earlier one (most configurations need no
    split), the entry names that criterion instead of a copy.  ``image`` maps a
    tessellation to the configuration ``code`` (a study keeps one per orbit).
    One line per entry is what lets :func:`load` hand each to a JSON parser
    (:mod:`cospherical.files.flowyaml`).  ``texts``: a dict the lines of one table
    share, where each element object's text is kept once written (with the object,
    so that its id stays its own); an image that returns the same object for an
    equal element (a study's rows do) is written once per table.
    The line is :func:`~cospherical.files.flowyaml.mapping_line` of the entry
    ``{"fvm_adequate": ..., criterion: elements or the earlier criterion's name}``.
    """
    if texts is None:
        texts = {}
    parts = [f'"fvm_adequate": {flow(fvm_adequate)}']
    written: dict[tuple[tuple[int, ...], ...], str] = {}
    for criterion, tess in tessellations.items():
        key = tuple(e.polyhedron.nodes for e in tess.elements)
        if key in written:
            parts.append(f"{flow(criterion)}: {flow(written[key])}")
            continue
        written[key] = criterion
        mapped = image(tess)
        scale = mapped.configuration.box.to_float()
        elements = []
        for element in mapped.elements:
            known = texts.get((id(element), scale))
            if known is None:
                known = texts[id(element), scale] = (element, flow(element_entry(element, scale)))
            elements.append(known[1])
        parts.append(f"{flow(criterion)}: [{', '.join(elements)}]")
    return mapping_text(code, "{" + ", ".join(parts) + "}")


def write_patterns(study: _StudyTable, path: str | Path, catalogue_version: str) -> None:
    atomic_write(path, patterns_text(study, catalogue_version))


class Entries(Mapping[str, dict[str, Any]]):
    """A table's configurations, code -> entry, each decoded and validated when first asked for.

    A mesher looks up a few configurations of a table of thousands (millions at
    R = 16): decoding all of them up front is what made loading slow.  Iterating
    visits every entry, so ``check`` still validates the whole table.
    """

    def __init__(self, texts: Mapping[str, str], header: dict[str, Any], name: str) -> None:
        self._texts = texts
        self._header = header
        self._name = name
        self._decoded: dict[str, dict[str, Any]] = {}

    def __getitem__(self, code: str) -> dict[str, Any]:
        entry = self._decoded.get(code)
        if entry is None:
            entry = decode_entry(self._texts[code], f"{self._name}: configurations/{code}")
            _check_entries({**self._header, "configurations": {code: entry}}, self._name, header_checked=True)
            self._decoded[code] = entry
        return entry

    def items(self, chunk: int = 4096) -> Iterator[tuple[str, dict[str, Any]]]:  # type: ignore[override]  # streamed, not a view
        """Every (code, entry) in file order, decoded and validated a chunk at a time.

        One schema validation per chunk costs a quarter of one per entry; entries
        not looked up before are not kept, so a table of millions of
        configurations is checked in bounded memory.
        """
        return ((code, entry) for code, entry, _ in self.items_with_texts(chunk))

    def items_with_texts(self, chunk: int = 4096,
                         skip: Callable[[str, str], bool] | None = None) -> Iterator[tuple[str, dict[str, Any], str]]:
        """Every (code, entry, entry's text as written), as :meth:`items`; ``skip(code, text)``: true
        for an entry to pass over, neither decoded nor validated (one checked before)."""
        # An indexed store streams its rows; a dict of lines is read in place.
        pairs = self._texts.texts() if hasattr(self._texts, "texts") else self._texts.items()
        batch: dict[str, dict[str, Any]] = {}
        texts: dict[str, str] = {}
        for code, text in pairs:
            self._check_code(code)
            if skip is not None and skip(code, text):
                continue
            entry = self._decoded.get(code)
            batch[code] = entry if entry is not None else decode_entry(text, f"{self._name}: configurations/{code}")
            texts[code] = text
            if len(batch) == chunk:
                _check_entries({**self._header, "configurations": batch}, self._name, header_checked=True)
                yield from ((code, entry, texts[code]) for code, entry in batch.items())
                batch, texts = {}, {}
        _check_entries({**self._header, "configurations": batch}, self._name, header_checked=True)
        yield from ((code, entry, texts[code]) for code, entry in batch.items())

    def values(self) -> Iterator[dict[str, Any]]:  # type: ignore[override]  # streamed, not a view
        return (entry for _, entry in self.items())

    def text(self, code: str) -> str:
        """An entry as written (its JSON text): equal texts are equal entries, which ``diff`` skips."""
        return self._texts[code]

    def __contains__(self, code: object) -> bool:
        return code in self._texts

    def __iter__(self) -> Iterator[str]:
        for code in self._texts:
            self._check_code(code)
            yield code

    def _check_code(self, code: object) -> None:
        # Codes are names read from the file, reported by check and diff: each must have
        # the schema's syntax, matched whole (a store's keys are any text, newlines too,
        # and the schema's "$" lets a trailing newline through).
        if not isinstance(code, str) or not _code_syntax().fullmatch(code):
            raise FormatError(f"{self._name}: configurations: {shown(str(code))} is not a configuration code")

    def __len__(self) -> int:
        return len(self._texts)


@cached(maxsize=1)
def _code_syntax() -> re.Pattern[str]:
    """The schema's pattern of configuration codes (its one home), to match whole."""
    schema = json.loads(data_path("schemas/patterns.schema.json").read_text(encoding="utf-8"))
    pattern = schema["properties"]["configurations"]["propertyNames"]["pattern"]
    return re.compile(pattern.removeprefix("^").removesuffix("$"))


@dataclass(frozen=True)
class PatternTable:
    """A loaded pattern table: its header and its configurations, validated against the JSON Schema."""

    header: dict[str, Any]
    configurations: Mapping[str, dict[str, Any]]

    def elements(self, code: str, criterion: str = "optimal") -> list[dict[str, Any]] | None:
        """The elements of one configuration: dicts with ``type``, ``nodes``, ``circumcenter``.

        A code the table does not hold, or that is not a string, raises :class:`KeyError`
        naming it, whether the table is YAML or an indexed store.

        Examples
        --------
        >>> from cospherical.files.flowyaml import mapping_line
        >>> text = ("schema_version: 1\\ngenerator: g\\ncatalogue_version: c\\nstudy: s\\nbox: ['1', '1', '1']\\n"
        ...         "face_points: octree\\nscheme: s\\ncriteria: [optimal]\\nconfigurations:\\n"
        ...         + mapping_line("000000000000", {"fvm_adequate": True, "optimal": [
        ...             {"type": "v8f6-c3cb81", "nodes": [0, 1, 2, 3, 4, 5, 6, 7], "circumcenter": [0.5, 0.5, 0.5]}]}))
        >>> table = table_from_text(text, "demo.yaml")
        >>> table.elements("000000000000")[0]["nodes"]
        [0, 1, 2, 3, 4, 5, 6, 7]
        """
        if not isinstance(code, str) or code not in self.configurations:
            raise KeyError(f"configuration {code!r} is not in this table")
        if criterion not in self.header["criteria"]:
            raise KeyError(f"criterion {criterion!r} is not in this table: {', '.join(self.header['criteria'])}")
        return entry_elements(self.configurations[code], criterion)


def entry_elements(entry: dict[str, Any], criterion: str) -> list[dict[str, Any]] | None:
    """The elements of a configuration's entry under a criterion, following a reference to the
    criterion with the same elements (``internal_faces: optimal``); ``None`` where there are none.

    >>> entry_elements({"optimal": [{"type": "v4f4-8f0284"}], "internal_faces": "optimal"}, "internal_faces")
    [{'type': 'v4f4-8f0284'}]
    """
    elements = entry.get(criterion)
    for _ in range(len(entry)):  # a chain of references is never longer than the entry; a cycle ends here
        if not isinstance(elements, str):
            return elements
        elements = entry.get(elements)
    return None


def load(path: str | Path) -> PatternTable:
    """Read a pattern table and validate it (JSON Schema, criterion references).

    Parameters
    ----------
    path : str or Path
        A pattern table, such as ``patterns/bisection-1x1x1.yaml``.

    Returns
    -------
    PatternTable
        ``header`` and, through :meth:`PatternTable.elements`, each configuration's
        elements per criterion.

    Raises
    ------
    FormatError
        The file cannot be read or does not have the format; the message names the place.

    A table as this package writes it (one line per configuration) is indexed
    line by line and each entry decoded, as JSON, and validated when it is first
    used; any other YAML spelling of a table is read whole by the YAML parser.  An
    indexed store (:mod:`cospherical.formats.sqlite_store`, an SQLite file) is opened and
    queried one configuration at a time.
    The documentation's "Pattern tables for a mesher" has an example, run by the tests.
    """
    if is_store(path):
        header, texts = open_store(path)
        _check_entries({**header, "configurations": {}}, str(path))
        return PatternTable(header, Entries(texts, header, str(path)))
    return table_from_text(read_text(path), str(path))


def table_from_text(text: str, name: str) -> PatternTable:
    """:func:`load` on the file's text."""
    split = split_section(text, "configurations")
    if split is None:
        return table_from_data(parse_yaml(text, name), name)
    header_text, texts = split
    header = parse_yaml(header_text, name)
    if not isinstance(header, dict) or not isinstance(texts, dict):
        return table_from_data(parse_yaml(text, name), name)
    _check_entries({**header, "configurations": {}}, name)
    return PatternTable(header, Entries(texts, header, name))


def table_from_data(data: dict[str, Any], name: str) -> PatternTable:
    """A :class:`PatternTable` from parsed YAML, validated (schema, criteria references)."""
    _check_entries(data, name)
    header = {k: v for k, v in data.items() if k != "configurations"}
    return PatternTable(header, data["configurations"])


def _check_entries(data: dict[str, Any], name: str, header_checked: bool = False) -> None:
    # The one validation of entries, for every reader (check, mesh, load_patterns; YAML
    # or store), before any geometry: the schema (node ids 0..26, each once, at most 27),
    # then what it cannot say: every criterion present, references only to earlier
    # criteria, as many nodes as the type id's vertex count (v<V>f<F>-...).
    if not _plainly_valid(data, name, header_checked):
        validate(data, "patterns", name)  # the schema's own verdict, and its message
    criteria = data["criteria"]
    for code, entry in data["configurations"].items():
        for i, criterion in enumerate(criteria):
            if criterion not in entry:
                raise FormatError(f"{name}: configuration {code}: no {criterion!r} elements")
            same = entry[criterion]
            if isinstance(same, str):
                if same not in criteria[:i]:
                    raise FormatError(f"{name}: configuration {code}: {criterion} refers to {same!r}, "
                                      "which is not an earlier criterion of the table")
                continue
            for k, element in enumerate(same):
                vertices = int(element["type"][1:element["type"].index("f")])
                if len(element["nodes"]) != vertices:
                    raise FormatError(f"{name}: configurations/{code}/{criterion}/{k}: {len(element['nodes'])} "
                                      f"nodes for a type of {vertices} vertices ({element['type']})")


# The schema's rules for entries, written out for the common case: the generated validator
# spends most of a table's reading on them (0.4 ms an entry), these a tenth of it.  They only
# ever accept: whatever they do not plainly accept goes to the schema's validator, which
# decides and says why, so the verdict is always the schema's.
_CRITERION_REFERENCES = {"internal_faces": ("optimal",), "internal_edges_and_faces": ("optimal", "internal_faces")}
_ENTRY_KEYS = frozenset(("fvm_adequate", "optimal", "internal_faces", "internal_edges_and_faces"))
_ELEMENT_KEYS = frozenset(("type", "nodes", "circumcenter"))
_ELEMENT_KEYS_MIRROR = _ELEMENT_KEYS | {"mirror"}
_INTEGER = {int}  # exactly: a boolean is not a node id
_NUMBER = frozenset((int, float))
_NODE_IDS = frozenset(range(27))


@cached(maxsize=1)
def _type_syntax() -> re.Pattern[str]:
    """The schema's pattern of type ids, searched as the schema's validator searches it."""
    schema = json.loads(data_path("schemas/patterns.schema.json").read_text(encoding="utf-8"))
    return re.compile(schema["$defs"]["elements"]["items"]["properties"]["type"]["pattern"])


def _plainly_valid(data: dict[str, Any], name: str, header_checked: bool = False) -> bool:
    """Whether ``data`` (a table, its configurations a chunk of entries) plainly meets the schema: its
    header by the schema's validator (with no entries; not again when ``header_checked``: a loaded
    table's entries are checked with the header it was loaded with), every entry by the rules above."""
    if type(data) is not dict or type(data.get("configurations")) is not dict:
        return False
    codes, types = _code_syntax(), _type_syntax()
    known: set[str] = set()  # type ids seen to match the pattern (a table has a few dozen)
    for code, entry in data["configurations"].items():
        if type(code) is not str or not codes.fullmatch(code) or type(entry) is not dict \
                or not entry.keys() <= _ENTRY_KEYS or type(entry.get("fvm_adequate")) is not bool:
            return False
        for criterion, elements in entry.items():
            if criterion == "fvm_adequate":
                continue
            if type(elements) is str:
                if elements not in _CRITERION_REFERENCES.get(criterion, ()):
                    return False
                continue
            if type(elements) is not list or not elements:
                return False
            for element in elements:
                if type(element) is not dict:
                    return False
                keys = element.keys()
                if not (keys == _ELEMENT_KEYS or (keys == _ELEMENT_KEYS_MIRROR and type(element["mirror"]) is bool)):
                    return False
                nodes, center, type_id = element["nodes"], element["circumcenter"], element["type"]
                # the types first (a list among the node ids cannot go into a set), each test a C loop
                if type(nodes) is not list or not 4 <= len(nodes) <= 27 or set(map(type, nodes)) != _INTEGER:
                    return False
                ids = set(nodes)
                if len(ids) != len(nodes) or not ids <= _NODE_IDS:
                    return False
                if type(center) is not list or len(center) != 3 or not set(map(type, center)) <= _NUMBER:
                    return False
                if type(type_id) is not str:
                    return False
                if type_id not in known:
                    if not types.search(type_id):
                        return False
                    known.add(type_id)
    if header_checked:
        return True
    try:
        validate({**data, "configurations": {}}, "patterns", name)
    except FormatError:
        return False  # the whole table to the schema's validator, whose first complaint may be elsewhere
    return True
