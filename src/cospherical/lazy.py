"""Names a module exports but imports where first asked for (a module ``__getattr__``, PEP 562).

A command pays at start-up for every module it imports; a name that only some commands use (the
package's API, a file format's reader, the report sections of ``--dual``) is imported the first time
it is asked for, and is an ordinary attribute of the module from then on.

Examples
--------
>>> namespace = {"__name__": "example"}
>>> attribute = on_first_use(namespace, {"Fraction": "fractions", "half": ("fractions", "Fraction")})
>>> attribute("Fraction")(1, 2), "Fraction" in namespace, "half" in namespace
(Fraction(1, 2), True, False)
>>> attribute("nothing")
Traceback (most recent call last):
    ...
AttributeError: module 'example' has no attribute 'nothing'
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["on_first_use"]


def on_first_use(namespace: dict[str, Any], where: Mapping[str, str | tuple[str, str]]) -> Callable[[str], Any]:
    """The ``__getattr__`` of the module whose globals are ``namespace``: a name of ``where`` is imported from its
    module (an absolute name; ``(module, attribute)`` where the module calls it otherwise) and kept in ``namespace``;
    any other name raises :class:`AttributeError`, as a module without it would."""
    module_name = namespace["__name__"]

    def __getattr__(name: str) -> Any:
        found = where.get(name)
        if found is None:
            raise AttributeError(f"module {module_name!r} has no attribute {name!r}")
        module, attribute = found if isinstance(found, tuple) else (found, name)
        value = getattr(importlib.import_module(module), attribute)
        namespace[name] = value  # once loaded, an ordinary attribute
        return value

    return __getattr__
