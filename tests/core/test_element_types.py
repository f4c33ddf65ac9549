"""The element types: their VTK node orders, stable ids, and classification."""

import pytest

from cospherical import Configuration, tessellate
from cospherical.core.element_types import type_id


def orientation(points):
    (p0, p1, p2, p3) = points
    u, v, w = ([b - a for a, b in zip(p0, q)] for q in (p1, p2, p3))
    return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]))


@pytest.mark.parametrize("code", ["000000000000", "800000000000", "888888888888", "880080000000", "8888a0000808", "123456789abc"])
@pytest.mark.parametrize("box", [("1", "1", "1"), ("1", "2", "4"), ("1", "sqrt(2)", "sqrt(2)")])
def test_vtk_orders_have_the_first_face_normal_pointing_inside(code, box):
    tess = tessellate(Configuration.from_code(code, box))
    xyz = {i: tuple(float(x) for x in p) for i, p in tess.nodes.items()}  # unit frame: same signs
    for e in tess.elements:
        n = e.nodes
        vtk = e.type.vtk
        if vtk == "tetra":
            assert orientation([xyz[i] for i in n]) > 0
        elif vtk == "pyramid":
            assert orientation([xyz[n[0]], xyz[n[1]], xyz[n[2]], xyz[n[4]]]) > 0
        elif vtk == "wedge":
            assert orientation([xyz[n[0]], xyz[n[1]], xyz[n[2]], xyz[n[3]]]) > 0
            edges = set(map(frozenset, e.polyhedron.edges))
            assert all(frozenset((n[i], n[i + 3])) in edges for i in range(3))
        elif vtk == "hexahedron":
            assert orientation([xyz[n[0]], xyz[n[1]], xyz[n[3]], xyz[n[4]]]) > 0
            edges = set(map(frozenset, e.polyhedron.edges))
            assert all(frozenset((n[i], n[i + 4])) in edges for i in range(4))


def test_type_ids_are_stable():
    assert type_id("v4:1t2t3t/0t3t2t/0t1t3t/0t2t1t", 4, 4) == "v4f4-8f0284"
    tess = tessellate(Configuration.from_code("000000000000"))
    assert tess.elements[0].type.id.startswith("v8f6-")


def test_classification_on_id_ranks_is_the_classification_on_ids():
    # classify works on the ranks of the node ids and maps the answer back (a cache
    # shared by cells whose ids come in the same order): the same as on the ids.
    from cospherical.core.element_types import _classify_ranks, classify
    from cospherical.studies.engine import bisection_codes

    seen = set()
    for box in (("1", "1", "1"), ("1", "2", "3")):
        for code in bisection_codes()[::7]:
            for element in tessellate(Configuration.from_code(code, box)).elements:
                poly = element.polyhedron
                if (poly.faces, poly.face_kinds) in seen:
                    continue
                seen.add((poly.faces, poly.face_kinds))
                assert classify(poly) == _classify_ranks.__wrapped__(poly.faces, poly.face_kinds)
    assert len(seen) > 500
