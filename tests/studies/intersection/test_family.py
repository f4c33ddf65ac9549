"""The intersection family (paper, section 5): the midpoint scheme's positions, its codes, orbits, orders."""

from __future__ import annotations

import numpy as np
import pytest

from cospherical.choices import INSERTION_ORDERS
from cospherical.studies.intersection import all_configurations, intersection_codes, orbits, set_patterns


@pytest.mark.parametrize("order", INSERTION_ORDERS)
def test_enumeration_counts(order):
    # which edges of a set of four carry a point, and their order with ties: 150 per set
    assert [len(set_patterns(r, order)) for r in (2, 4, 8, 16)] == [16, 66, 126, 150]
    assert len(intersection_codes(16, order)) == 150**3 == 3_375_000 != 187**3 + 1
    assert all(d % (16 // 4) == 0 for p in set_patterns(4, order) for d in p)


def test_insertion_orders_differ_and_follow_the_midpoint_scheme():
    edge, rank, reverse = (set(set_patterns(16, o)) for o in INSERTION_ORDERS)
    assert edge != rank != reverse
    # two levels on edges 0 and 1: the first inserted goes to 1/2, the other halfway to an end
    assert (8, 12, 0, 0) in rank and (4, 8, 0, 0) in reverse
    assert (8, 12, 0, 0) in edge and (8, 4, 0, 0) in edge and (4, 8, 0, 0) not in edge


def test_rank_and_reverse_are_mirror_families():
    # t -> 1 - t turns the scheme inserting from the lowest level into the one inserting
    # from the highest: the two families are reflections, so their statistics agree.
    reflected = {tuple(16 - d if d else 0 for d in p) for p in set_patterns(16, "rank")}
    assert reflected == set(set_patterns(16, "reverse"))
    # t -> 1 - t on every edge at once is the box's central inversion, one of its symmetries: each rank
    # configuration's image is a reverse configuration of the same orbit. So the two families have the
    # same orbits, each as large, and a study (run_intersection tessellates one representative per orbit,
    # counted as often as its orbit has members) gives both the same statistics. The families themselves
    # differ (not the same configurations). At R = 4 (0.4 CPU-s; the two R = 4 studies run side by side took
    # 7.5; R = 8, 275,488 orbits each, 4 more).
    assert not np.array_equal(np.sort(all_configurations(4, "rank")), np.sort(all_configurations(4, "reverse")))
    (rank, rank_sizes, rank_count), (reverse, reverse_sizes, reverse_count) = (
        orbits(4, order) for order in ("rank", "reverse"))
    assert rank_count == reverse_count and len(rank) == len(reverse)
    by_rank, by_reverse = np.argsort(rank), np.argsort(reverse)
    assert np.array_equal(rank[by_rank], reverse[by_reverse])
    assert np.array_equal(rank_sizes[by_rank], reverse_sizes[by_reverse])
