"""cospherical: Delaunay tessellations of 1-irregular cuboids with co-spherical elements.

The public API, re-exported here from the layers that define it (read top to
bottom: ``core`` -> ``paper`` -> ``catalogue`` -> ``studies`` -> ``formats`` ->
``outputs`` -> ``cli``; each imports only from those before it).  The names load
on first use, so ``import cospherical`` stays cheap for the command line.

Examples
--------
>>> from cospherical import Configuration, tessellate
>>> tess = tessellate(Configuration.from_code("888888888888"))
>>> len(tess.elements), tess.elements[0].type.name
(8, 'Cuboid')
"""

from __future__ import annotations

import importlib

from .errors import CosphericalError, FormatError, InputError, UsageError
from .version import __version__

# name -> module that defines it
_API = {
    "Box": "cospherical.core.configuration",
    "Configuration": "cospherical.core.configuration",
    "Length": "cospherical.core.exact",
    "ElementType": "cospherical.core.element_types",
    "Element": "cospherical.core.tessellation",
    "Shape": "cospherical.core.shapes",
    "ShapeConfiguration": "cospherical.core.shapes",
    "standard_shape": "cospherical.core.shapes",
    "tessellate_shape": "cospherical.core.tessellation",
    "Tessellation": "cospherical.core.tessellation",
    "tessellate": "cospherical.core.tessellation",
    "load_catalogue": "cospherical.catalogue",
    "shipped_catalogue": "cospherical.catalogue",
    "type_name": "cospherical.catalogue",
    "PatternTable": "cospherical.formats.patterns",
    "load_patterns": ("cospherical.formats.patterns", "load"),
}

__all__ = ["CosphericalError", "FormatError", "InputError", "UsageError", "__version__", *_API]


def __getattr__(name: str):
    if name not in _API:
        raise AttributeError(f"module 'cospherical' has no attribute {name!r}")
    module, attribute = _API[name] if isinstance(_API[name], tuple) else (_API[name], name)
    value = getattr(importlib.import_module(module), attribute)
    globals()[name] = value  # once loaded, an ordinary attribute
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
