"""The device file: a versioned YAML description of a device (reading only).

Schema (``schemas/device.schema.json``; the documentation page shows it whole)::

    version: 1                      # optional; the only version so far
    device: NAME                    # names: 1-64 of A-Z a-z 0-9 _ . + -
    regions:                        # 1 to 64 regions
      - name: NAME
        material: NAME
        boxes: [[x0, y0, z0, x1, y1, z1], ...]      # 1 to 64 boxes in all
    contacts:                       # optional, at most 64
      - name: NAME
        region: NAME                # the region whose boundary holds it
        box: [x0, y0, z0, x1, y1, z1]               # flat along one axis
    refine:                         # optional, at most 64 shapes
      - plane: [nx, ny, nz, d]      # or point: [x, y, z], sphere: [x, y, z, r],
                                    # box: [x0, y0, z0, x1, y1, z1]
    levels: 5                       # how deep the shapes refine (0..16; default 0)
    balance: vertex                 # or edge (default vertex)

Numbers are exact: ``0.75`` is read as the decimal text it is (3/4), never as a
binary float; ``"1/3"`` (quoted) is a fraction.  Names are data: they are
written into outputs, never used as paths.  The file is bounded (64 kB, and the
counts above) before anything is computed from it.
"""

from __future__ import annotations

import re
from dataclasses import replace
from fractions import Fraction
from pathlib import Path
from typing import Any

import yaml

from ..core.exact import parse_rational
from ..errors import FormatError, InputError
from ..files.yamlio import check_nesting, load_document, read_text, validate
from ..mesh.device import Contact, Coordinates, Device, Region
from ..mesh.octree import Shape, parse_shape

__all__ = ["DEVICE_FILE_VERSION", "MAX_DEVICE_BYTES", "parse_device", "read_device"]

DEVICE_FILE_VERSION = 1
MAX_DEVICE_BYTES = 64 * 1024


class _ExactLoader(yaml.SafeLoader):
    """Safe loading that keeps a YAML float as its text (so ``0.1`` stays the decimal 1/10) and refuses repeated keys."""

    def compose_node(self, parent: yaml.Node | None, index: int) -> yaml.Node | None:
        # an alias can make a small text a huge tree (a "billion laughs"): a device file needs none
        if self.check_event(yaml.AliasEvent):
            raise yaml.composer.ComposerError(None, None, "an alias (*name): not allowed in a device file",
                                              self.peek_event().start_mark)  # type: ignore[no-untyped-call]
        return super().compose_node(parent, index)

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        keys = [self.construct_object(k, deep=deep) for k, _ in node.value]
        for i, key in enumerate(keys):
            if not isinstance(key, str) or key in keys[:i]:
                raise yaml.constructor.ConstructorError(None, None, f"repeated or unusable key {str(key)[:40]!r}",
                                                        node.start_mark)
        return super().construct_mapping(node, deep)


def _float_text(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> str:
    """A YAML float as its text: exact, read by :func:`~cospherical.core.exact.parse_rational`."""
    return str(loader.construct_scalar(node))


_ExactLoader.add_constructor("tag:yaml.org,2002:float", _float_text)

# YAML 1.1 integers that are not what they look like: 010 is 8 (octal), 1:30 is 90 (base 60), 0x10 is 16
_DECIMAL_INTEGER = re.compile(r"[-+]?(0|[1-9][0-9]*)")


def _decimal_integer(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> int:
    """An integer written in decimal digits; YAML 1.1's other forms are refused rather than read as another number."""
    text = loader.construct_scalar(node)
    if not _DECIMAL_INTEGER.fullmatch(text):
        raise yaml.constructor.ConstructorError(None, None, f"{text[:40]!r} is not a decimal integer (YAML reads 010 "
                                                "as 8, 1:30 as 90, 0x10 as 16): write its decimal digits, without "
                                                "leading zeros", node.start_mark)
    return int(text)


_ExactLoader.add_constructor("tag:yaml.org,2002:int", _decimal_integer)


def read_device(path: str | Path) -> Device:
    """Read and check a device file (see the module); any fault raises one line naming the file and the place."""
    name = Path(path).name
    return replace(parse_device(read_text(path, MAX_DEVICE_BYTES), name), source=name)


def parse_device(text: str, name: str = "device file") -> Device:
    """A device from the text of a device file.

    Examples
    --------
    >>> device = parse_device('''
    ... device: bar
    ... regions:
    ...   - {name: si, material: Si, boxes: [[0, 0, 0, 2, 1, 0.5]]}
    ... ''')
    >>> device.regions[0].boxes[0][5], device.levels
    (Fraction(1, 2), 0)
    """
    if len(text) > MAX_DEVICE_BYTES:
        raise FormatError(f"{name}: {len(text):,} characters, above the {MAX_DEVICE_BYTES:,} a device file may have")
    check_nesting(text, name)
    data = load_document(text, name, _ExactLoader)
    if not isinstance(data, dict):
        raise FormatError(f"{name}: a device file is a mapping with 'device' and 'regions'")
    validate(data, "device", name)

    def numbers(values: list[Any], what: str) -> Coordinates:
        x0, y0, z0, x1, y1, z1 = (Fraction(parse_rational(str(v) if not isinstance(v, int) else v, f"{name}: {what}"))
                                  for v in values)
        return (x0, y0, z0, x1, y1, z1)

    regions = tuple(Region(r["name"], r["material"],
                           tuple(numbers(box, f"region {r['name']!r} box {k}") for k, box in enumerate(r["boxes"])))
                    for r in data["regions"])
    contacts = tuple(Contact(c["name"], c["region"], numbers(c["box"], f"contact {c['name']!r}"))
                     for c in data.get("contacts", []))
    refine: list[Shape] = []
    for k, entry in enumerate(data.get("refine", [])):
        kind, values = next(iter(entry.items()))
        text = f"{kind}:" + ",".join(str(v) for v in values)
        try:
            refine.append(parse_shape(text))
        except InputError as error:
            raise FormatError(f"{name}: refine {k}: {error}") from None
    return Device(data["device"], regions, contacts, tuple(refine), data.get("levels", 0),
                  data.get("balance", "vertex"))
