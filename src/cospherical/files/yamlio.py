"""YAML in and out: safe loading only, atomic writes (:mod:`.outputs`), JSON Schema validation."""

from __future__ import annotations

import itertools
import json
import os
import re
import stat
import sys
from collections.abc import Callable, Hashable
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

from ..caches import cached
from ..errors import FormatError
from .data import data_path
from .outputs import atomic_open, atomic_path, atomic_write

__all__ = ["MAX_INTEGER_DIGITS", "FormatError", "atomic_open", "atomic_path", "atomic_write", "check_nesting", "read_bytes", "read_text", "utf8_text", "validated_data", "dump_yaml", "load_document", "load_yaml", "parse_json", "parse_yaml", "validate", "yaml_float"]

if TYPE_CHECKING:
    import yaml


@cached(maxsize=1)
def _loader() -> type:
    """The loader of :func:`parse_yaml`, made on first use: PyYAML's import (~10 ms, a regex compiled at
    import) is paid by the commands that parse YAML, not by a mesh whose inputs need none."""
    import yaml

    class _Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):  # type: ignore[misc]  # the C loader where libyaml is there: the same API
        """Safe loading that refuses a mapping with a repeated key (YAML would keep the last).

        Timestamps are not resolved: a date stays a string (an impossible date such as
        2001-13-14 would otherwise raise from deep inside the loader), and the schemas
        say which strings are allowed.
        """

        yaml_implicit_resolvers = {
            first: [(tag, regexp) for tag, regexp in resolvers if tag != "tag:yaml.org,2002:timestamp"]
            for first, resolvers in getattr(yaml, "CSafeLoader", yaml.SafeLoader).yaml_implicit_resolvers.items()
        }

        def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Hashable, Any]:
            seen = set()
            for key_node, _ in node.value:
                key = self.construct_object(key_node, deep=deep)
                try:
                    repeated = key in seen
                    seen.add(key)
                except TypeError:
                    raise yaml.constructor.ConstructorError(None, None, "a mapping key that is not a plain value",
                                                            key_node.start_mark) from None
                if repeated:
                    raise yaml.constructor.ConstructorError(None, None, f"repeated key {key!r}", key_node.start_mark)
            mapping: dict[Hashable, Any] = super().construct_mapping(node, deep)
            return mapping

    return _Loader


# Reading: our files are at most a few MB (a pattern table at R = 4 is 69 MB); a
# larger file, or one nested deeper than any we write, is refused before parsing
# (deep nesting overflows the C parser's stack).
MAX_INPUT_BYTES = 512 * 2**20
# The full YAML parser builds about 60-100 bytes of nodes and objects per byte of block-style
# text (an 8.8 MB table: 0.5 GB; 100 MB: 9.4 GB): it takes at most this much, so that its peak
# stays below ~1.5 GB.  The files we write (one JSON line per entry) are split before it and
# have no such bound.
MAX_YAML_PARSE = 16 * 2**20
_MAX_DEPTH = 64
_MAX_INDENT = 256


def machine_memory() -> int:
    """This machine's physical memory in bytes (8 GiB where the system does not say): what the
    readers and the mesher measure their bounds against, so that a small hostile file that
    claims gigabytes is refused before they are allocated."""
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return 8 * 1024**3


def yaml_text(data: object) -> str:
    import yaml

    dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)
    return yaml.dump(data, Dumper=dumper, sort_keys=False, default_flow_style=None, width=100, allow_unicode=True)


def dump_yaml(data: object, path: str | Path) -> None:
    atomic_write(path, yaml_text(data))


def yaml_float(x: float) -> str:
    """A float as YAML 1.1 reads it back as a float (PyYAML needs a dot before an exponent)."""
    text = repr(float(x))
    mantissa, e, exponent = text.partition("e")
    if e and "." not in mantissa:
        text = f"{mantissa}.0e{exponent if exponent[0] in '+-' else '+' + exponent}"
    return text


def load_yaml(path: str | Path) -> Any:
    """Read a YAML file with safe loading; a missing, unreadable or malformed file raises FormatError."""
    return parse_yaml(read_text(path), str(path))


def read_text(path: str | Path, max_bytes: int = MAX_INPUT_BYTES) -> str:
    """The UTF-8 text of an input file: only a regular file (never a device or a FIFO), at most
    ``max_bytes`` of it; anything else raises FormatError with one line."""
    return utf8_text(read_bytes(path, max_bytes), path)


def utf8_text(data: bytes, path: str | Path) -> str:
    """An input file's bytes (:func:`read_bytes`) as UTF-8 text; anything else raises FormatError with one line."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise FormatError(f"{path}: cannot read: {error}") from None


def read_bytes(path: str | Path, max_bytes: int = MAX_INPUT_BYTES) -> bytes:
    """The bytes of an input file, as :func:`read_text` reads them (a regular file, at most ``max_bytes``):
    for a reader that also needs a digest of exactly what it parses."""
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)  # a FIFO must not block the open
        try:
            info = os.fstat(fd)
            if not stat.S_ISREG(info.st_mode):
                kind = "a folder" if stat.S_ISDIR(info.st_mode) else "a special file"
                raise FormatError(f"{path}: cannot read: {kind}, not a regular file")
            if info.st_size > max_bytes:
                raise FormatError(f"{path}: cannot read: too large ({info.st_size} bytes; at most {max_bytes})")
            with os.fdopen(os.dup(fd), "rb") as handle:
                data = handle.read(max_bytes + 1)
        finally:
            os.close(fd)
        if len(data) > max_bytes:
            raise FormatError(f"{path}: cannot read: too large (more than {max_bytes} bytes)")
        return data
    except OSError as error:
        raise FormatError(f"{path}: cannot read: {getattr(error, 'strerror', None) or error}") from None


def check_nesting(text: str, name: str) -> None:
    """Refuse nesting deeper than any file we write, before the parser recurses into it."""
    # Flow collections: brackets, counted also inside quoted strings (ours hold none, so this only over-counts).
    if len(text) < 1 << 20:
        # Small texts (the headers of our files, read at every start-up) without numpy,
        # whose import costs a third of a small command's start-up.
        flow = max(itertools.accumulate(1 if c in "[{" else -1 for c in re.findall(r"[\[\]{}]", text)), default=0)
    else:
        import numpy as np

        data = np.frombuffer(text.encode("utf-8"), dtype=np.uint8)
        steps = np.isin(data, (ord("["), ord("{"))).astype(np.int64) - np.isin(data, (ord("]"), ord("}")))
        flow = int(np.cumsum(steps).max()) if len(steps) else 0
    # Block collections: indentation and leading "- " / "? " indicators.
    block = max((len(m) for m in re.findall(r"^[ ?\-]+", text, re.M)), default=0)
    if flow > _MAX_DEPTH or block > _MAX_INDENT:
        raise FormatError(f"{name}: nested too deeply (more than {_MAX_DEPTH} levels)")


def _refuse_aliases(data: object, name: str) -> None:
    """Refuse YAML aliases: the tool never writes them, and they make small files expand without bound.

    An alias makes two places hold the same list or mapping object; a walk that
    meets one container twice has found one.
    """
    seen: set[int] = set()
    stack = [data]
    while stack:
        item = stack.pop()
        if isinstance(item, (dict, list)):
            if id(item) in seen:
                raise FormatError(f"{name}: a YAML alias (*name): not allowed in cospherical files")
            seen.add(id(item))
            stack.extend(item.values() if isinstance(item, dict) else item)


def _unique_pairs(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    mapping = dict(pairs)
    if len(mapping) != len(pairs):
        seen: set[str] = set()
        for key, _ in pairs:
            if key in seen:
                raise ValueError(f"repeated key {key!r}")
            seen.add(key)
    return mapping


# No number in our files has more digits than this; int() of thousands of digits is
# quadratic, and Python refuses more than 4,300 with an error of its own.
MAX_INTEGER_DIGITS = 40
_LONG_NUMBER = re.compile(rf"[0-9]{{{MAX_INTEGER_DIGITS + 1},}}")


def parse_json(text: str, name: str, max_digits: int = MAX_INTEGER_DIGITS) -> Any:
    """Parse JSON text as every reader of ours does: no repeated key, no nesting deeper than
    we write, no run of more than ``max_digits`` digits (:data:`MAX_INTEGER_DIGITS`, unless
    the format writes longer exact numbers, as text); errors as one-line :class:`FormatError`.

    >>> parse_json('{"a": 1, "a": 2}', "demo.json")
    Traceback (most recent call last):
    ...
    cospherical.errors.FormatError: demo.json: not valid JSON: repeated key 'a'
    """
    check_nesting(text, name)
    # a scan of the text (strings too: the cheap over-count): a hook per number costs more than the parse
    long = (_LONG_NUMBER if max_digits == MAX_INTEGER_DIGITS else re.compile(f"[0-9]{{{max_digits + 1},}}")).search(text)
    if long:
        raise FormatError(f"{name}: not valid JSON: a number of {len(long.group(0)):,} digits "
                          f"(at most {max_digits})")
    try:
        return json.loads(text, object_pairs_hook=_unique_pairs)
    except json.JSONDecodeError as error:
        raise FormatError(f"{name}: line {error.lineno}: not valid JSON: {error.msg}") from None
    except (ValueError, RecursionError) as error:
        raise FormatError(f"{name}: not valid JSON: {str(error).splitlines()[0][:120]}") from None


def _refuse_size(text: str, name: str) -> NoReturn:
    raise FormatError(f"{name}: {len(text):,} characters of YAML not in the form cospherical writes (one line "
                      f"per entry); the full YAML parser takes at most {MAX_YAML_PARSE:,}")


def load_document(text: str, name: str, loader: type) -> Any:
    """``text`` read by the YAML ``loader``, whatever goes wrong one :class:`FormatError` line naming ``name`` and the line.

    The one place a YAML parser's errors become a user's message: the reader of the
    project's own files and the device file's exact reader (its own loader) share it.
    """
    import yaml

    try:
        return yaml.load(text, Loader=loader)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" line {mark.line + 1}" if mark else ""
        problem = getattr(error, "problem", None) or "not valid YAML"
        raise FormatError(f"{name}:{where}: {problem}") from None
    except (ValueError, OverflowError, RecursionError) as error:
        if "integer string conversion" in str(error):  # Python's advice to a programmer is no user's message
            raise FormatError(f"{name}: an integer of more than {sys.get_int_max_str_digits():,} digits") from None
        raise FormatError(f"{name}: a value cannot be read: {str(error).splitlines()[0][:120]}") from None


def parse_yaml(text: str, name: str) -> Any:
    """Parse YAML text safely: no aliases, no deep nesting, no Python tags; errors as one-line FormatError."""
    json_like = text.lstrip().startswith("{")
    if len(text) > MAX_YAML_PARSE and not json_like:  # before the nesting scan, which takes seconds on it
        _refuse_size(text, name)
    check_nesting(text, name)
    if json_like:  # JSON (our summaries): read as JSON, where 4e-06 is a number
        try:
            return json.loads(text, object_pairs_hook=_unique_pairs)
        except ValueError:
            pass  # a YAML flow mapping, or broken: the YAML reader says where
    if len(text) > MAX_YAML_PARSE:
        _refuse_size(text, name)
    data = load_document(text, name, _loader())
    _refuse_aliases(data, name)
    return data


@cached(maxsize=16)
def _validator(name: str) -> Callable[[object], object]:
    # fastjsonschema compiles the schema to Python: a 4096-configuration pattern
    # table validates in a fraction of a second instead of seconds.
    text = data_path(f"schemas/{name}.schema.json").read_text(encoding="utf-8")
    return _compiled_validator(name, text, data_path("schemas") / "__pycache__")


def _compiled_validator(name: str, text: str, folder: Path) -> Callable[[object], object]:
    """fastjsonschema's validator of the schema ``text``, its bytecode kept as Python keeps a module's.

    Generating and compiling a validator costs 15-40 ms a schema (the mesh report's is
    180 kB of Python), paid by every command that reads or writes a file of that
    schema; the code object is kept in ``folder`` (the schemas' ``__pycache__``) under a digest of
    the schema, fastjsonschema's version and the interpreter's bytecode magic (any
    change makes a new one), and loaded in about a millisecond.  The same function,
    so the same verdicts and messages; a cache that cannot be read or written (a
    read-only install, ``PYTHONDONTWRITEBYTECODE``) only costs the compile again.
    """
    import hashlib
    import importlib.util
    import marshal
    import sys

    import fastjsonschema

    key = hashlib.sha256("\0".join((fastjsonschema.VERSION, importlib.util.MAGIC_NUMBER.hex(), text)).encode())
    path = folder / f"{name}.{key.hexdigest()[:16]}.marshal"
    try:
        function, code = marshal.loads(path.read_bytes())
        if not isinstance(function, str) or not isinstance(code, type(_compiled_validator.__code__)):
            raise ValueError("not a cached validator")
    except (OSError, ValueError, EOFError, TypeError):
        source = fastjsonschema.compile_to_code(json.loads(text))
        found = re.search(r"^def (\w+)\(", source, re.M)  # the schema's own function comes first
        if found is None:
            raise ValueError(f"fastjsonschema gave no validator for the {name} schema") from None
        function, code = found.group(1), compile(source, f"<{name} schema>", "exec")
        if not sys.dont_write_bytecode:
            _keep(folder, path, marshal.dumps((function, code)))
    namespace: dict[str, Any] = {}
    exec(code, namespace)
    validator: Callable[[object], object] = namespace[function]
    return validator


def _keep(folder: Path, path: Path, data: bytes) -> None:
    """Write a cached validator atomically beside the others, and drop those of the schema's earlier texts."""
    try:
        folder.mkdir(exist_ok=True)
        temporary = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        temporary.write_bytes(data)
        os.replace(temporary, path)
        for old in folder.glob(path.name.split(".", 1)[0] + ".*.marshal"):
            if old != path:
                old.unlink(missing_ok=True)
    except OSError:
        pass  # a read-only install: compiled again next time


def validated_data(text: str, schema: str, name: str, parse: Callable[[str, str], Any],
                   folder: Path | None = None) -> Any:
    """``parse(text, name)``, validated against ``schema`` (:func:`validate`), kept as the validators are.

    Parsing and validating the shipped catalogue costs ~15 ms of every ``mesh`` run, for the same text
    each time: the validated data is kept in the schemas' ``__pycache__`` (marshal) under a digest of
    the text, the schema, fastjsonschema's version and the interpreter's bytecode magic, so the data
    read back is exactly what that text gave and that schema passed; any other text is parsed and
    validated (and kept in its place: one per schema).  Data marshal cannot hold is not kept.
    ``folder``: where to keep it (default the schemas' ``__pycache__``).
    """
    import hashlib
    import importlib.util
    import marshal

    import fastjsonschema

    schema_text = data_path(f"schemas/{schema}.schema.json").read_text(encoding="utf-8")
    key = hashlib.sha256("\0".join((fastjsonschema.VERSION, importlib.util.MAGIC_NUMBER.hex(), schema_text,
                                    text)).encode())
    folder = data_path("schemas") / "__pycache__" if folder is None else folder
    path = folder / f"{schema}-data.{key.hexdigest()[:32]}.marshal"
    try:
        return marshal.loads(path.read_bytes())
    except (OSError, ValueError, EOFError, TypeError):
        pass
    data = parse(text, name)
    validate(data, schema, name)
    if not sys.dont_write_bytecode:
        try:
            kept = marshal.dumps(data)
        except ValueError:  # a type marshal does not write (a YAML date): parsed again next time
            return data
        _keep(folder, path, kept)
    return data


def validate(data: object, schema: str, path: str | Path) -> None:
    """Check data against one of the package's JSON Schemas; the error names the place."""
    import fastjsonschema

    try:
        _validator(schema)(data)
    except fastjsonschema.JsonSchemaValueException as error:
        where = ".".join(str(p) for p in error.path[1:]) if error.path else "top level"
        raise FormatError(f"{path}: {schema} format: at {where or 'top level'}: {error.message.replace(error.name or '', 'value', 1)[:200]}") from None
