"""The symmetries of a box: group orders, maps of configurations and points, orbit representatives."""

from __future__ import annotations

import pytest

from cospherical import Box, Configuration
from cospherical.core.symmetry import box_symmetries, orbit_representatives
from cospherical.studies.engine import bisection_codes

CUBE = ("1", "1", "1")


@pytest.mark.parametrize("lengths, order", [(("1", "1", "1"), 48), (("1", "2", "2"), 16), (("1", "2", "4"), 8)])
def test_group_orders(lengths, order):
    symmetries = box_symmetries(Box.parse(lengths))
    assert len(symmetries) == order
    assert sum(s.proper for s in symmetries) == order // 2
    # closed under inverse, and each node map is a bijection of 0..26
    assert all(sorted(s.node_map) == list(range(27)) for s in symmetries)
    assert all(s.inverse() in symmetries for s in symmetries)


# That the study's tessellations, mapped through the symmetries, equal direct ones is
# checked for every bisection configuration of four boxes and both point policies in
# core/test_delaunay.py, where the direct tessellations are made anyway.


def test_symmetry_maps_configurations_and_points():
    box = Box.parse(("1", "1", "1"))
    cfg = Configuration.from_steiner(box, {0: "1/4", 9: "3/16", 4: "1/4", 2: "1/4", 6: "1/4"})
    for sym in box_symmetries(box):
        image = sym.configuration(cfg)
        assert image.code == sym.code(cfg.code)
        nodes, image_nodes = cfg.nodes(), image.nodes()
        assert {sym.node_map[i]: sym.point(p) for i, p in nodes.items()} == image_nodes


@pytest.mark.parametrize("lengths", [("1", "1", "1"), ("1", "2", "2"), ("1", "2", "4")])
def test_orbit_representatives_without_numpy_equal_numpy_ones(lengths):
    # The pure-Python backend (one orbit at a time, no numpy) against the numpy backend:
    # the same representatives and the same (first) symmetries.
    import random

    import numpy as np

    from cospherical.core import symmetry
    from cospherical.studies.leaves import leaf_codes

    symmetries = box_symmetries(Box.parse(lengths))
    group = symmetry._group(symmetries)
    assert group is not None and symmetry._group(symmetries[:5]) is None  # not a group: the numpy path
    rng = random.Random(15)
    scattered = ["".join(rng.choice("0123456789abcdefABCDEF") for _ in range(12)) for _ in range(500)]
    scattered += [code + rng.choice(["+f", "+f0", "+f13", "+fb", "+f245b", "+f012345"]) for code in scattered[:200]]
    for codes in (bisection_codes(), leaf_codes(), scattered):
        masks = [symmetry._point_mask(code) if "+" in code else 0 for code in codes]
        numpy_keys = symmetry.orbit_point_keys(symmetry.code_digits(codes), np.array(masks, dtype=np.int64),
                                               symmetries, backend="numpy")
        assert symmetry._orbit_keys_python(codes, masks, group) == tuple(a.tolist() for a in numpy_keys)


def test_symmetries_map_face_points():
    box = Box.parse(CUBE)
    cfg = Configuration.from_steiner(box, {0: "1/4", 2: "1/4", 1: "3/4", 3: "3/4", 4: "1/4", 8: "1/2", 9: "1/2"},
                                     faces=[0, 4])
    images = set()
    for sym in box_symmetries(box):
        image = sym.configuration(cfg)
        assert image.code == sym.code(cfg.code) and image.point_faces == {sym.face_map[0], sym.face_map[4]}
        assert {sym.node_map[i]: sym.point(p) for i, p in cfg.nodes().items()} == image.nodes()
        images.add(image.code)
    representative, _ = orbit_representatives([cfg.code], box_symmetries(box))
    assert representative[0] in images
