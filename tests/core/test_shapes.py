"""Other base elements (prism, pyramid, tetrahedron, any convex polyhedron): exact tessellations,
checked against Qhull's merged regions and by invariants on random Steiner positions."""

from __future__ import annotations

from collections import Counter, defaultdict
from fractions import Fraction

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from oracle import qhull_regions
from strategies import LENGTHS, PARAMETERS
from tests.core.test_delaunay import check_canonical_codes

from cospherical import Configuration, InputError, Shape, standard_shape, tessellate
from cospherical.core.geometry import Frame
from cospherical.core.shapes import EDGES, STANDARD_SHAPES, mask_codes
from cospherical.core.symmetry import orbit_representatives, shape_symmetries

SHAPES = sorted(set(STANDARD_SHAPES) - {"cuboid"})  # the shapes besides the cuboid, whose tests are their own
BOXES = {"cube": ("1", "1", "1"), "aspect4": ("1", "2", "4"), "sqrt2-exact": ("1", "sqrt(2)", "sqrt(2)")}


@pytest.mark.oracle_networkx
@pytest.mark.oracle_qhull
@pytest.mark.parametrize("name", SHAPES)
def test_every_bisection_configuration_matches_qhull(name):
    """Every edge mask with midpoints (512, 256, 64 configurations) on the cube against
    ``qdelaunay Qz Fv``, and same canonical code <=> isomorphic face graphs."""
    shape = standard_shape(name)
    samples: dict[str, list] = defaultdict(list)
    for code in mask_codes(len(shape.edges)):
        cfg = Configuration.from_code(code, shape=shape)
        tess = tessellate(cfg)
        assert {frozenset(e.nodes) for e in tess.elements} == qhull_regions(cfg.real_nodes()), code
        for e in tess.elements:
            if len(samples[e.type.code]) < 3:
                samples[e.type.code].append((e.polyhedron.faces, e.polyhedron.face_kinds))
    check_canonical_codes(samples)


@pytest.mark.oracle_qhull
@pytest.mark.parametrize("box", ["aspect4", "sqrt2-exact"])
def test_other_boxes_match_qhull(box):
    for name in SHAPES:
        shape = standard_shape(name, BOXES[box])
        for code in mask_codes(len(shape.edges))[::7]:
            cfg = Configuration.from_code(code, shape=shape)
            assert {frozenset(e.nodes) for e in tessellate(cfg).elements} == qhull_regions(cfg.real_nodes())


@st.composite
def shape_configurations(draw):
    shape = standard_shape(draw(st.sampled_from(SHAPES)), [draw(LENGTHS) for _ in range(3)])
    steiner = {k: draw(PARAMETERS) for k in range(len(shape.edges)) if draw(st.booleans())}
    if draw(st.booleans()):  # equal parameters where faces can carry points
        t = draw(PARAMETERS)
        steiner = {k: t for k in range(len(shape.edges)) if draw(st.booleans()) or k in steiner}
    return Configuration.from_steiner(None, steiner, draw(st.sampled_from(["octree", "none"])), shape=shape)


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(shape_configurations())
def test_invariants_on_random_steiner_positions(cfg):
    """Volumes add up to the element's exactly, elements meet face to face (an inner face in two
    elements, a boundary face in one, on the element's boundary), and every sphere is empty."""
    shape = cfg.shape
    tess = tessellate(cfg)
    assert sum(e.polyhedron.unit_volume for e in tess.elements) == shape.unit_volume
    nodes = tess.nodes
    frame = Frame.build(nodes, cfg.box.squared)
    index = {n: i for i, n in enumerate(frame.ids)}
    faces = Counter(frozenset(f) for e in tess.elements for f in e.polyhedron.faces)
    for face, count in faces.items():
        on_boundary = any(all(sum(a * x for a, x in zip(normal, nodes[v])) == offset for v in face)
                          for normal, offset in shape.planes)
        assert count == (1 if on_boundary else 2), sorted(face)
    for e in tess.elements:
        a, b, c, d = (index[v] for v in e.nodes[:4])
        members = [index[v] for v in e.nodes]
        sphere = next(s for s in (frame.sphere(*q) for q in _quadruples(members)) if s is not None)
        sides = [sphere.side(p) for p in frame.lifted]
        assert min(sides) == 0 and all(sides[m] == 0 for m in members)
        assert sum(1 for s in sides if s == 0) == len(members)  # the cell is every point on its sphere


def _quadruples(members):
    from itertools import combinations

    return combinations(members, 4)


def test_fvm_is_the_base_element():
    # The tetrahedron with every midpoint: the middle octahedron's center (1/4, 1/4, 1/4)... lies
    # inside; a long thin box moves circumcenters out of the element but not out of the box.
    tess = tessellate(Configuration.from_code("888888", shape=standard_shape("tetrahedron", ("1", "1", "8"))))
    centers = [e.polyhedron.center for e in tess.elements]
    assert all(all(0 <= x <= 1 for x in c) for c in centers)
    assert not tess.fvm_adequate


def test_every_element_takes_explicit_face_points_and_point_suffixes():
    """One configuration class: a prism's quadrilateral face carries an explicit point, named by a
    point suffix that round-trips and maps with the symmetries; a triangle or a body point is refused."""
    prism = standard_shape("prism")
    cfg = Configuration.from_code("888888888", faces=[2], shape=prism)
    assert cfg.code == cfg.point_set_code == "888888888+f2" and cfg.point_faces == {2}
    assert cfg.nodes()[6 + 9 + 0] == (Fraction(1, 2), 0, Fraction(1, 2))  # face 2 (y = 0) is quad face 0
    again = Configuration.from_code(cfg.code, shape=prism)
    assert again == cfg and again.nodes() == cfg.nodes()
    assert Configuration.from_code("888888888", shape=prism).point_set_code == "888888888+f234"
    swap = shape_symmetries(prism)[1]  # x <-> y takes face 2 (y = 0) to face 4 (x = 0)
    assert swap.code(cfg.code) == "888888888+f4" == swap.configuration(cfg).code
    for faces, body, message in (([0], False, "face 0 .* only a quadrilateral"), ([2, 3, 4], True, "body point")):
        with pytest.raises(InputError, match=message):
            Configuration.from_code("888888888", faces=faces, body=body, shape=prism)


@pytest.mark.oracle_qhull
def test_a_parallelepiped_has_a_body_point():
    # A sheared box: every face carrying its point (octree policy), the body point where the three
    # cut planes cross, node 26 as in the cuboid; the tessellation is Qhull's.
    corners = [(0, 0, 0), (1, 0, 0), (2, 1, 0), (1, 1, 0), (0, 0, 1), (1, 0, 1), (2, 1, 1), (1, 1, 1)]
    faces = [(0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7), (0, 1, 2, 3), (4, 5, 6, 7)]
    shape = Shape.from_vertices([[Fraction(x, 2) for x in p] for p in corners], EDGES, faces)  # the cuboid's edges
    cfg = Configuration.from_code("888888888888", shape=shape)
    assert cfg.point_faces == set(range(6)) and cfg.has_body_point
    assert cfg.nodes()[26] == (Fraction(1, 2), Fraction(1, 4), Fraction(1, 4))
    tess = tessellate(cfg)
    assert sum(e.polyhedron.unit_volume for e in tess.elements) == shape.unit_volume
    assert {frozenset(e.nodes) for e in tess.elements} == qhull_regions(cfg.real_nodes())


@pytest.mark.parametrize("box", BOXES.values())
def test_the_cuboid_is_a_standard_shape(box):
    """The standard cuboid is the box with the cuboid's numbering (VTK hexahedron: corners, edges,
    face f carrying node 20 + f), and its isometries are exactly the box's symmetries: the same
    node maps and edge maps (48, 16 or 8 of them)."""
    from cospherical.core.configuration import Box
    from cospherical.core.shapes import CORNERS, FACES
    from cospherical.core.symmetry import box_symmetries

    shape = standard_shape("cuboid", box)
    assert shape.corners == tuple(tuple(map(Fraction, c)) for c in CORNERS) and shape.edges == EDGES
    assert [set(face) for face in shape.faces] == [set(face) for face in FACES] and shape.quad_faces == tuple(range(6))
    assert shape.unit_volume == 1
    ours = {(tuple(s.node_map[n] for n in range(26)), s.edge_map) for s in shape_symmetries(shape)}
    theirs = {(s.node_map[:26], s.edge_map) for s in box_symmetries(Box.parse(box))}
    assert ours == theirs and len(ours) == {"1": 48, "2": 8, "sqrt(2)": 16}[box[1]]


def test_symmetry_groups_and_orbits():
    sizes = {name: len(shape_symmetries(standard_shape(name))) for name in SHAPES}
    assert sizes == {"prism": 4, "pyramid": 8, "tetrahedron": 6}
    assert len(shape_symmetries(standard_shape("tetrahedron", ("1", "2", "4")))) == 1
    assert len(shape_symmetries(standard_shape("pyramid", ("1", "1", "2")))) == 8
    for name in SHAPES:
        shape = standard_shape(name)
        codes = mask_codes(len(shape.edges))
        reps, index = orbit_representatives(codes, shape_symmetries(shape))
        for code, rep, i in zip(codes, reps, index):
            sym = shape_symmetries(shape)[i]
            assert sym.code(code) == rep
            assert sym.inverse().code(rep) == code
            # the image tessellation is the tessellation of the image
            ours = tessellate(Configuration.from_code(code, shape=shape))
            theirs = tessellate(Configuration.from_code(rep, shape=shape))
            assert sorted(sym.polyhedron(e.polyhedron).faces for e in ours.elements) == \
                sorted(e.polyhedron.faces for e in theirs.elements)


@pytest.mark.oracle_qhull
def test_general_quadrilateral_face_point():
    # A trapezoid face: the face point is where the two cut lines cross, not the corners' mean.
    corners = [(0, 0, 0), (4, 0, 0), (3, 2, 0), (1, 2, 0), (0, 0, 1), (4, 0, 1), (3, 2, 1), (1, 2, 1)]
    faces = [(0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    shape = Shape.from_vertices([[Fraction(x, 4) for x in p] for p in corners], EDGES, faces)  # the cuboid's edges
    cfg = Configuration.from_steiner(steiner={0: "1/2", 1: "1/2", 2: "1/2", 3: "1/2"}, shape=shape)
    assert cfg.point_faces == {0}
    assert cfg.nodes()[20 + 0] == (Fraction(1, 2), Fraction(1, 4), 0)
    tess = tessellate(cfg)
    assert sum(e.polyhedron.unit_volume for e in tess.elements) == shape.unit_volume
    assert {frozenset(e.nodes) for e in tess.elements} == qhull_regions(cfg.real_nodes())


def test_a_shape_pickled_by_another_process_hashes_as_here():
    # A study's pool moves shapes between processes, whose string hashes differ: an unpickled
    # shape must find its equal in a dict (the caches keyed by shapes) of this process.
    import os
    import pickle
    import subprocess
    import sys

    made = subprocess.run([sys.executable, "-c", "import pickle, sys; from cospherical import standard_shape; "
                           "s = standard_shape('prism'); hash(s); sys.stdout.buffer.write(pickle.dumps(s))"],
                          capture_output=True, env={**os.environ, "PYTHONHASHSEED": "1"}, check=True)
    there = pickle.loads(made.stdout)
    assert there == standard_shape("prism") and {standard_shape("prism"): "here"}[there] == "here"
