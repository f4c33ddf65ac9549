"""Every cache of the package, in one place, each bounded.

A cache keeps what a pure function returned for arguments it will meet again:
the same element in many configurations, a study's symmetries, a schema
compiled once.  Each is declared with :func:`cached` and a size, so that a
long-running process (a mesher, a notebook, a server) holds at most that many
results per cache; :func:`caches` lists them (those of the modules imported so
far) and :func:`clear_caches` empties them all.

Examples
--------
>>> from cospherical.core import canonical
>>> ("cospherical.core.canonical._canonical_form", 65536) in [(name, size) for name, size, _ in caches()]
True
"""

from __future__ import annotations

from functools import _lru_cache_wrapper, lru_cache
from typing import Any, Callable, TypeVar, cast

__all__ = ["cached", "caches", "clear_caches"]

F = TypeVar("F", bound=Callable[..., Any])

_CACHES: list[_lru_cache_wrapper[Any]] = []  # every function declared with cached(), in import order


def cached(maxsize: int) -> Callable[[F], F]:
    """Decorate a pure function with an LRU cache of at most ``maxsize`` results, and list it here."""
    if isinstance(maxsize, bool) or not isinstance(maxsize, int) or maxsize < 1:
        raise ValueError(f"cache size {maxsize!r}: a cache here is bounded, by a positive integer")

    def decorate(function: F) -> F:
        wrapped = lru_cache(maxsize=maxsize)(function)
        _CACHES.append(wrapped)
        return cast(F, wrapped)  # the same calls, plus cache_info and cache_clear

    return decorate


def caches() -> list[tuple[str, int | None, int]]:
    """(module.function, most results kept, results kept now) of every cache declared so far."""
    return [(f"{c.__module__}.{c.__qualname__}", c.cache_info().maxsize, c.cache_info().currsize) for c in _CACHES]


def clear_caches() -> None:
    """Empty every cache (for a process that changes what the package reads, such as a test
    that points the catalogue at another file)."""
    for c in _CACHES:
        c.cache_clear()
