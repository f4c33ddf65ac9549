"""Our cells against Qhull's merged Delaunay regions, and the canonical codes of the elements met against networkx."""

from __future__ import annotations

import random
from collections import defaultdict
from fractions import Fraction

import pytest
from oracle import isomorphic, qhull_regions, qhull_regions_by_orbit
from strategies import random_configuration

from cospherical import Box, Configuration, tessellate
from cospherical.core.symmetry import box_symmetries
from cospherical.studies.engine import run_study

CUBE = ("1", "1", "1")
BOXES = {
    "cube": ("1", "1", "1"),
    "aspect4": ("1", "2", "4"),
    "sqrt2-rounded": ("1", "1.4142", "1.4142"),
    "sqrt2-exact": ("1", "sqrt(2)", "sqrt(2)"),
}


def bisection_codes():
    for mask in range(4096):
        yield "".join("8" if mask >> k & 1 else "0" for k in range(12))


def check_canonical_codes(samples: dict[str, list]) -> None:
    """Same code <=> isomorphic labelled face graphs (networkx), over every type met."""
    for code, polys in samples.items():
        for other in polys[1:]:
            assert isomorphic(polys[0], other), f"same code {code} but not isomorphic"
    codes = sorted(samples)
    for i, a in enumerate(codes):
        for b in codes[i + 1 :]:
            pa, pb = samples[a][0], samples[b][0]
            if len(pa[0]) == len(pb[0]) and sorted(pa[1]) == sorted(pb[1]):
                assert not isomorphic(pa, pb), f"codes {a} and {b} differ but graphs are isomorphic"


@pytest.mark.oracle_qhull
@pytest.mark.oracle_networkx
@pytest.mark.parametrize("policy", ["octree", "none"])
@pytest.mark.parametrize("box", sorted(BOXES))
def test_every_bisection_configuration_matches_qhull(box, policy, full):
    # Every configuration's tessellation in the study (its orbit's, carried by the study's
    # symmetry maps) is compared with Qhull's regions of its own point set; Qhull runs once
    # per orbit, its answer carried to the other members by an isometry checked exactly
    # (oracle.qhull_regions_by_orbit).  Every member's configuration in the study is the one
    # built here from its code; a representative's tessellation in the study is tessellate()
    # of that configuration (run_study without known=), so tessellating it again here would
    # repeat the same computation.  A seeded 1 in 16 of the other configurations (--full: all
    # 4096, representatives too, three times the CPU) are tessellated directly, which must
    # give the study's mapped tessellation: their cells are already held to Qhull above, this
    # adds their types and details (1 in 4 cost 8 cases x ~1 CPU-s more).
    lengths = Box.parse(BOXES[box])
    configurations = {(cfg := Configuration.from_code(code, lengths, policy)).code: cfg for code in bisection_codes()}
    study = run_study("bisection", lengths, list(configurations), policy, criteria=("optimal",))
    # each member's tessellation as a pattern table gets it (the rows' images: equal elements mapped once;
    # studies/test_engine.py holds them equal to Study.tessellation's), a quarter of the mapping's CPU
    members = {code: (tessellations["optimal"], image) for code, _, tessellations, image in study.rows()}
    samples: dict[str, list] = defaultdict(list)
    direct = random.Random(4096)
    regions_by_code = qhull_regions_by_orbit(configurations.values(), box_symmetries(lengths))
    for (code, cfg), regions in zip(configurations.items(), regions_by_code):
        representative, image = members[code]
        tess = image(representative)
        assert {frozenset(e.nodes) for e in tess.elements} == regions, f"{box} {policy} {code}"
        assert tess.configuration == cfg, f"{box} {policy} {code}"
        if full or (code not in study.tessellations and direct.random() < 1 / 16):
            assert tessellate(cfg) == tess, f"{box} {policy} {code}"
        for e in tess.elements:
            poly = e.polyhedron
            if len(samples[e.type.code]) < 3:
                samples[e.type.code].append((poly.faces, poly.face_kinds))
    check_canonical_codes(samples)


@pytest.mark.oracle_qhull
@pytest.mark.oracle_networkx
def test_random_configurations_match_qhull():
    rng = random.Random(20261123)
    samples: dict[str, list] = defaultdict(list)
    for _ in range(600):
        cfg = random_configuration(rng)
        tess = tessellate(cfg)
        ours = {frozenset(e.nodes) for e in tess.elements}
        assert ours == qhull_regions(cfg.real_nodes()), (cfg.box.texts, cfg.steiner, cfg.face_points)
        for e in tess.elements:
            if len(samples[e.type.code]) < 3:
                samples[e.type.code].append((e.polyhedron.faces, e.polyhedron.face_kinds))
    check_canonical_codes(samples)


@pytest.mark.oracle_qhull
@pytest.mark.parametrize("order", ["edge", "rank", "reverse"])
def test_random_intersection_configurations_match_qhull(order):
    from cospherical.studies.intersection import intersection_codes

    digits = intersection_codes(16, order)
    rng = random.Random(order)
    for index in rng.sample(range(len(digits)), 200):
        cfg = Configuration.from_code("".join("%x" % d for d in digits[index]))
        ours = {frozenset(e.nodes) for e in tessellate(cfg).elements}
        assert ours == qhull_regions(cfg.real_nodes()), cfg.code


@pytest.mark.oracle_qhull
def test_the_python_walk_matches_qhull():
    # The Python walk (tessellate()'s default, any frame) against the oracle; the
    # compiled walk is held to it in core/test_compiled.py.
    from cospherical.core.delaunay import delaunay_cells
    from cospherical.core.geometry import Frame

    rng = random.Random(11)
    for _ in range(150):
        cfg = random_configuration(rng)
        frame = Frame.build(cfg.nodes(), cfg.box.squared)
        ours = {frozenset(cell.nodes) for cell in delaunay_cells(frame, backend="python")}
        assert ours == qhull_regions(cfg.real_nodes()), (cfg.box.texts, cfg.steiner, cfg.face_points)


@pytest.mark.oracle_qhull
def test_random_face_subsets_at_sixteenths_match_qhull():
    rng = random.Random(1313)
    boxes = [CUBE, ("1", "2", "4"), ("1", "sqrt(2)", "sqrt(2)"), ("3", "1", "2")]
    checked = 0
    while checked < 300:
        steiner = {}
        for axis_edges in ((0, 2, 4, 6), (1, 3, 5, 7), (8, 9, 10, 11)):
            t = Fraction(rng.randint(1, 15), 16)
            for k in axis_edges:
                roll = rng.random()
                if roll < 0.6:
                    steiner[k] = t  # equal parameters on parallel edges: admissible faces
                elif roll < 0.8:
                    steiner[k] = Fraction(rng.randint(1, 15), 16)
        admissible = sorted(Configuration.from_steiner(CUBE, steiner).admissible_faces)
        if not admissible:
            continue
        faces = [f for f in admissible if rng.random() < 0.5]
        body = len(faces) == 6 and rng.random() < 0.5
        cfg = Configuration.from_steiner(rng.choice(boxes), steiner, faces=faces, body=body)
        ours = {frozenset(e.nodes) for e in tessellate(cfg).elements}
        assert ours == qhull_regions(cfg.real_nodes()), (cfg.box.texts, cfg.point_set_code)
        checked += 1
