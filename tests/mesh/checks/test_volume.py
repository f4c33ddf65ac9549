"""The volume check: the elements' volumes summed exactly against the domain's."""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from cospherical.core.configuration import Box
from cospherical.mesh.assembly import assemble
from cospherical.mesh.checks import check_volume
from cospherical.mesh.octree import Octree, build_octree, parse_shape

BRICK = Box.parse(["1", "2", "4"])


def test_the_volumes_sum_to_the_domains_and_a_missing_octant_shows():
    # the whole tree's elements fill the box; with the leaves of one octant dropped (and no device saying
    # the domain is the rest) they fill exactly 7/8 of it, and the check says the volume is wrong
    tree = build_octree(BRICK, 3, [parse_shape("sphere:0.5,1,2,0.6")])
    whole = check_volume(assemble(tree))
    assert (whole.volume, whole.flat_elements, whole.volume_ok) == (Fraction(1), 0, True)
    octant = ((tree.positions >> (tree.levels.astype(np.int64) - 1)[:, None]) == (1, 0, 0)).all(axis=1)
    part = check_volume(assemble(Octree(tree.box, tree.levels[~octant], tree.positions[~octant], tree.vertex_balanced)))
    assert (part.volume, part.flat_elements, part.volume_ok) == (Fraction(7, 8), 0, False)
    assert part.figures() == {"volume_ok": False, "volume": "7/8", "flat_elements": 0}
