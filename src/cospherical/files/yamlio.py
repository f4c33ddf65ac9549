"""YAML in and out: safe loading only, atomic writes, JSON Schema validation."""

from __future__ import annotations

import json
import os
import tempfile
from contextlib import contextmanager
from functools import lru_cache
from pathlib import Path

import yaml

from ..errors import FormatError
from .data import data_path

__all__ = ["FormatError", "atomic_write", "dump_yaml", "load_yaml", "parse_yaml", "validate", "yaml_float"]

_Dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)


class _Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
    """Safe loading that refuses a mapping with a repeated key (YAML would keep the last)."""

    def construct_mapping(self, node, deep=False):
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
        return super().construct_mapping(node, deep)


@contextmanager
def atomic_open(path: str | Path, binary: bool = False):
    """A file to write, in place at ``path`` only when the block ends without an error.

    It is a temporary file in the same folder, renamed at the end: never a
    half-written file, and no temporary file left behind.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with (os.fdopen(fd, "wb") if binary else os.fdopen(fd, "w", encoding="utf-8", newline="\n")) as handle:
            yield handle
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the file ordinary permissions
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write(path: str | Path, text: str | bytes) -> None:
    """Write text (UTF-8) or bytes atomically (see :func:`atomic_open`)."""
    with atomic_open(path, binary=isinstance(text, bytes)) as handle:
        handle.write(text)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def yaml_text(data) -> str:
    return yaml.dump(data, Dumper=_Dumper, sort_keys=False, default_flow_style=None, width=100, allow_unicode=True)


def dump_yaml(data, path: str | Path) -> None:
    atomic_write(path, yaml_text(data))


def yaml_float(x: float) -> str:
    """A float as YAML 1.1 reads it back as a float (PyYAML needs a dot before an exponent)."""
    text = repr(float(x))
    mantissa, e, exponent = text.partition("e")
    if e and "." not in mantissa:
        text = f"{mantissa}.0e{exponent if exponent[0] in '+-' else '+' + exponent}"
    return text


def load_yaml(path: str | Path):
    """Read a YAML file with safe loading; a missing, unreadable or malformed file raises FormatError."""
    return parse_yaml(read_text(path), str(path))


def read_text(path: str | Path) -> str:
    """A file's text (UTF-8); a missing or unreadable file raises FormatError."""
    path = Path(path)
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise FormatError(f"{path}: cannot read: {getattr(error, 'strerror', None) or error}") from None


def parse_yaml(text: str, name: str):
    try:
        return yaml.load(text, Loader=_Loader)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" line {mark.line + 1}" if mark else ""
        problem = getattr(error, "problem", None) or "not valid YAML"
        raise FormatError(f"{name}:{where}: {problem}") from None


@lru_cache(maxsize=None)
def _validator(name: str):
    # fastjsonschema compiles the schema to Python: a 4096-configuration pattern
    # table validates in a fraction of a second instead of seconds.
    import fastjsonschema

    schema = json.loads(data_path(f"schemas/{name}.schema.json").read_text(encoding="utf-8"))
    return fastjsonschema.compile(schema)


def validate(data, schema: str, path: str | Path) -> None:
    """Check data against one of the package's JSON Schemas; the error names the place."""
    import fastjsonschema

    try:
        _validator(schema)(data)
    except fastjsonschema.JsonSchemaValueException as error:
        where = ".".join(str(p) for p in error.path[1:]) if error.path else "top level"
        raise FormatError(f"{path}: {schema} format: at {where or 'top level'}: {error.message.replace(error.name, 'value', 1)[:200]}") from None
