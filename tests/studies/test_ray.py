"""Exact thresholds along a ray of boxes, each checked against the direct studies of boxes on both sides and at itself
(:func:`~cospherical.studies.sweep.box_statistics` is the oracle)."""

from __future__ import annotations

from fractions import Fraction

import pytest

from cospherical.core.exact import Length, rational_text
from cospherical.errors import InputError
from cospherical.studies.ray import Ray, profile_summary, ray_profile
from cospherical.studies.sweep import box_statistics, grid_values

RANGES = {"1,r,r": (Fraction(1), Fraction(9, 5)), "1,1,r": (Fraction(3, 2), Fraction(2))}


@pytest.fixture(scope="module")
def profiles():
    return {ray: ray_profile(Ray.parse(ray), *RANGES[ray]) for ray in RANGES}


def box_of(ray: str, r_text: str) -> tuple[str, str, str]:
    return tuple(r_text if part == "r" else "1" for part in ray.split(","))


def rational_inside(lo: Fraction, hi: Fraction) -> Fraction:
    """A simple rational r with lo < r^2 < hi (u = r^2 bounds)."""
    target = (Length(lo).__float__() + Length(hi).__float__()) / 2
    for den in (10, 100, 1000, 10000, 100000):
        r = Fraction(round(target * den), den)
        if lo < r * r < hi:
            return r
    raise AssertionError("no rational found")


@pytest.mark.parametrize("ray", sorted(RANGES))
def test_each_threshold_holds_on_both_sides_and_at_itself(profiles, ray):
    steps = profiles[ray]
    assert len(steps) >= 3
    for step in steps:
        if step.lo == step.hi:
            probes = [Length(step.lo).text]  # exactly at the threshold: a sqrt box
        else:
            probes = [rational_text(rational_inside(step.lo, step.hi))]
        for probe in probes:
            direct = box_statistics(box_of(ray, probe))
            assert (direct["fvm_adequate"], direct["types"]) == (step.fvm_adequate, len(step.types)), (ray, probe)


def test_largest_fully_adequate_ratios(profiles):
    summary = profile_summary(Ray.parse("1,r,r"), *RANGES["1,r,r"], profiles["1,r,r"])  # the fixture's profile
    assert summary["largest_fully_adequate"] == {"r": "sqrt(2)", "attained": True}
    # just above sqrt 2 some configuration fails
    assert box_statistics(("1", "1.4143", "1.4143"))["fvm_adequate"] < 4096


def test_a_ray_is_written_as_three_lengths_each_1_or_r():
    assert Ray.parse(" 1, R ,r").text == "1,r,r" and Ray.parse("r,1,1").box(Fraction(4)).texts == ("2", "1", "1")
    for text in ("1,1,1", "1,r", "1,2,r", "r,r,r,r", ""):
        with pytest.raises(InputError, match="write three lengths, each 1 or r"):
            Ray.parse(text)


def test_grid_points_agree_with_the_ray(profiles):
    ray = "1,1,r"
    for c in grid_values("3/2:2:3"):
        direct = box_statistics(("1", "1", rational_text(c)))
        step = next(s for s in profiles[ray] if s.contains(c * c))
        assert (direct["fvm_adequate"], direct["types"]) == (step.fvm_adequate, len(step.types)), c
