"""YAML that loads fast: one big collection written one JSON flow entry per line.

Our large files (pattern tables, the catalogue) are a small header and one
big collection: a mapping from configuration code to entry, or a list of
element types.  Each entry is written on one line as JSON, which is YAML flow
style, so the file stays YAML that any reader (PyYAML) reads, and diffs line by
line; but a reader that knows the shape hands each line to :mod:`json`
(C-accelerated, ~50x faster than PyYAML here) and parses only the header as
YAML.  A file not in that shape (hand-edited, an older version) is read by the
YAML parser as before: the fast path is an optimisation, never a second format.

Measured on ``patterns/bisection-1x1x1.yaml`` (4096 configurations, 5.7 MB):
PyYAML (C loader) 10-18 s and 450 MB; this reader, every entry decoded,
0.3 s and 60 MB; indexing the lines only (entries decoded when asked for)
0.05 s.

Examples
--------
>>> text = "study: demo\\nconfigurations:\\n" + mapping_line("000000000000", {"fvm_adequate": True, "x": [0.5]})
>>> text
'study: demo\\nconfigurations:\\n  \\'000000000000\\': {"fvm_adequate": true, "x": [0.5]}\\n'
>>> header, entries = split_section(text, "configurations")
>>> header, decode_entry(entries["000000000000"], "demo")
('study: demo\\n', {'fvm_adequate': True, 'x': [0.5]})
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from typing import Any, NoReturn

from ..errors import FormatError
from .yamlio import yaml_float

__all__ = ["decode_entry", "flow", "mapping_entries", "mapping_line", "mapping_text", "sequence_line", "split_section"]

# A mapping entry: two spaces, a single-quoted key without quotes in it, then a
# JSON object.  A sequence entry: "- " then a JSON object.
_MAPPING_LINE = re.compile(r"  '([^'\n]*)': (\{[^\n]*\})")
_SEQUENCE_LINE = re.compile(r"- (\{[^\n]*\})")
_MAPPING_LINES = re.compile(r"^  '([^'\n]*)': (\{[^\n]*\})$", re.M)
_SEQUENCE_LINES = re.compile(r"^- (\{[^\n]*\})$", re.M)
_TOP_LEVEL_LINE = re.compile(r"\n[^ \-\n#]")


# what json.dumps(text, ensure_ascii=False) writes, without a new encoder per call
_string = json.encoder.encode_basestring


def flow(value: object) -> str:
    """A value as one line of JSON that YAML 1.1 reads back as the same value.

    JSON is YAML flow style, except that YAML 1.1 (PyYAML) reads ``1e-05`` as a
    string: floats are written as :func:`~cospherical.files.yamlio.yaml_float`
    writes them (``1.0e-05``), which JSON reads too.

    >>> flow({"type": "v4f4-8f0284", "nodes": [0, 1], "circumcenter": [1e-05, 0.5], "mirror": True})
    '{"type": "v4f4-8f0284", "nodes": [0, 1], "circumcenter": [1.0e-05, 0.5], "mirror": true}'
    """
    # the exact types first: a pattern table writes millions of values
    if type(value) is str:
        return _string(value)
    if type(value) is float:
        return yaml_float(value)
    if type(value) is list or type(value) is tuple:
        if all(type(v) is int for v in value):  # node ids
            return "[" + ", ".join(map(str, value)) + "]"
        return "[" + ", ".join(map(flow, value)) + "]"
    if value is True:
        return "true"
    if value is False:
        return "false"
    if value is None:
        return "null"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return yaml_float(value)
    if isinstance(value, str):
        return _string(value)
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_string(str(k))}: {flow(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(flow(v) for v in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} as a flow value")


def mapping_line(key: str, entry: dict[str, Any]) -> str:
    """One entry of a block mapping at indent 2, its value as a JSON flow mapping (with a newline)."""
    return mapping_text(key, flow(entry))


def mapping_text(key: str, text: str) -> str:
    """:func:`mapping_line` of a value already written as one line of flow JSON."""
    return f"  '{key}': {text}\n"


def sequence_line(entry: dict[str, Any]) -> str:
    """One item of a block sequence at indent 0, as a JSON flow mapping (with a newline)."""
    return f"- {flow(entry)}\n"


def mapping_entries(text: str) -> Iterator[tuple[str, str]]:
    """The (key, JSON text) pairs of consecutive :func:`mapping_line` lines; another line raises FormatError."""
    for line in text.splitlines():
        found = _MAPPING_LINE.fullmatch(line)
        if found is None:
            raise FormatError(f"not an entry line: {line[:60]!r}")
        yield found.group(1), found.group(2)


def split_section(text: str, key: str) -> tuple[str, dict[str, str] | list[str]] | None:
    """The document without its top-level ``key`` section, and that section's entries as JSON texts.

    The section is a mapping of :func:`mapping_line` lines (returned as a dict,
    key -> JSON text) or a sequence of :func:`sequence_line` lines (a list); it
    runs to the next top-level key or the end.  ``None`` when the text is not in
    this shape (the caller then parses it as YAML), and when a key repeats: the
    YAML parser then says where.
    """
    start = text.find(f"\n{key}:\n")
    if start < 0:
        if not text.startswith(f"{key}:\n"):
            return None
        start = -1
    body_start = start + len(key) + 3
    # The section ends at the first line that starts a new top-level key (found from the newline before
    # it: a search for a newline runs at memchr's speed, one for a line start with re.M 16 times slower).
    match = _TOP_LEVEL_LINE.search(text, body_start - 1)
    end = match.start() + 1 if match else len(text)
    if end <= body_start:
        return None
    lines = text.count("\n", body_start, end) + (text[end - 1] != "\n")  # the final newline starts no line
    # One scan of the section in C, in place (a loop over its lines, a match each, took 0.1 s of a 9 MB
    # table): a match lies within one line and there is at most one per line, so as many matches as
    # lines is every line of the shape, and the matches are all the memory a hostile file costs.
    found: dict[str, str] | list[str]
    if text.startswith("- ", body_start):
        found = _SEQUENCE_LINES.findall(text, body_start, end)
        if len(found) != lines:
            return None
    else:
        pairs = _MAPPING_LINES.findall(text, body_start, end)
        found = dict(pairs)
        if len(pairs) != lines or len(found) != lines:  # a line of another shape, or a repeated key
            return None
    return text[: start + 1] + text[end:], found


def _refuse_repeats(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    entry = dict(pairs)
    if len(entry) != len(pairs):
        repeated = next(k for k in entry if sum(1 for p, _ in pairs if p == k) > 1)
        raise ValueError(f"repeated key {repeated!r}")
    return entry


def _refuse_constant(text: str) -> NoReturn:
    raise ValueError(f"{text} is not a YAML value")


def _yaml_float(text: str) -> float:
    """A JSON float that YAML 1.1 reads as a float too: with an exponent, only after a dot and signed
    (PyYAML reads 1e5 and 1.0e5 as strings; JSON takes all three)."""
    if "e" in text or "E" in text:  # (most floats have no exponent: a million a table, one test each)
        exponent = max(text.find("e"), text.find("E"))
        if "." not in text or text[exponent + 1] not in "+-":
            raise ValueError(f"{text[:exponent + 1]}...: not a YAML 1.1 float (write a dot and a signed exponent)")
    return float(text)


def _decode_counting(text: str) -> tuple[object, int]:
    """The text decoded, and how many keys its objects kept: fewer than the text writes means a
    repeated key was dropped.  A hook per object costs less than writing the value back to count;
    a decoder per call keeps the count to the call (threads may decode at once)."""
    kept = 0

    def count(value: dict[str, Any]) -> dict[str, Any]:
        nonlocal kept
        kept += len(value)
        return value

    value = json.JSONDecoder(parse_constant=_refuse_constant, parse_float=_yaml_float, object_hook=count).decode(text)
    return value, kept


# Decoding with a hook per key-value list (to catch a repeated key) costs 4x plain decoding:
# decode counting the keys, and only when a key was dropped, again with that hook.  Every key
# ends in a quote, JSON whitespace and a colon; a match inside a string only counts one more.
_KEY_END = re.compile(r'"[ \t\n\r]*:')
_STRICT = json.JSONDecoder(object_pairs_hook=_refuse_repeats, parse_constant=_refuse_constant,
                           parse_float=_yaml_float)


def decode_entry(text: str, where: str) -> Any:
    """One entry's JSON text as data; a malformed entry raises :class:`FormatError` naming ``where``.

    Refused like the YAML reader refuses them: a repeated key, and numbers that
    YAML 1.1 would read otherwise than JSON (``1e5``, ``NaN``).

    >>> decode_entry('{"a": [0.5, 1]}', "demo")
    {'a': [0.5, 1]}
    >>> decode_entry('{"a": 1, "a": 2}', "demo")
    Traceback (most recent call last):
    ...
    cospherical.errors.FormatError: demo: repeated key 'a'
    """
    try:
        value, kept = _decode_counting(text)
        # A dropped repeat shows as fewer keys kept than the text writes (a key's end inside
        # a string counts as one more written: decoded again, with the hook, to be sure).
        if kept != len(_KEY_END.findall(text)):
            value = _STRICT.decode(text)
        return value
    except (ValueError, RecursionError) as error:
        message = str(error).splitlines()[0][:120] if str(error) else "not valid"
        raise FormatError(f"{where}: {message}") from None
