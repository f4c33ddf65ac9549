"""Every cache of the package is bounded, listed, and emptied by one call."""

from __future__ import annotations

import pytest

from cospherical.caches import cached, caches, clear_caches


@pytest.mark.parametrize("size", [0, -1, None, True, 2.5])
def test_a_cache_must_be_bounded(size):
    with pytest.raises(ValueError, match="bounded"):
        cached(size)


def test_a_declared_cache_keeps_at_most_its_size_and_is_listed_and_cleared():
    calls = []

    @cached(maxsize=2)
    def square(x):
        calls.append(x)
        return x * x

    assert [square(x) for x in (1, 2, 2, 3, 1)] == [1, 4, 4, 9, 1]
    assert calls == [1, 2, 3, 1]  # 2 met again from the cache; 3 pushed 1 out: two results at most
    name = f"{__name__}.test_a_declared_cache_keeps_at_most_its_size_and_is_listed_and_cleared.<locals>.square"
    assert (name, 2, 2) in caches()
    import cospherical.core.canonical  # noqa: F401  (the package's own caches are listed as they are imported)

    assert any(listed.startswith("cospherical.core.canonical.") for listed, _, _ in caches())
    clear_caches()
    assert (name, 2, 0) in caches() and all(now == 0 for _, _, now in caches())
