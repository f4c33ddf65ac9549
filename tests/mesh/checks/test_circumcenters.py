"""The circumcenter checks: leaves not FVM-adequate counted against each configuration's own tessellation."""

from __future__ import annotations

from cospherical.core.configuration import Box
from cospherical.core.tessellation import tessellate
from cospherical.mesh.assembly import assemble
from cospherical.mesh.checks import check_circumcenters
from cospherical.mesh.octree import build_octree, parse_shape

BRICK = Box.parse(["1", "2", "4"])


def test_leaves_not_fvm_adequate_are_those_whose_tessellation_is_not():
    # the mesh's exact measure of each configuration's elements against the tessellation engine's own verdict
    mesh = assemble(build_octree(BRICK, 4, [parse_shape("sphere:0.5,1,2,0.6")]))
    found = check_circumcenters(mesh)
    inadequate = sum(len(leaves) for _, tessellation, leaves in mesh.groups()
                     if not tessellate(tessellation.configuration).fvm_adequate)
    assert found.leaves_not_fvm_adequate == inadequate > 0
    assert found.circumcenters_outside_leaf >= found.leaves_not_fvm_adequate
    assert found.elements_not_cospherical == 0
    # an element's circumcenter outside the closed box lies outside its leaf too
    assert 0 <= found.boundary_circumcenters_outside <= found.circumcenters_outside_leaf
