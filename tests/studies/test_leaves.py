"""The octree-leaf family: its configurations, each against Qhull."""

from __future__ import annotations

import pytest
from oracle import qhull_regions_by_orbit

from cospherical import Box, Configuration
from cospherical.core.symmetry import box_symmetries
from cospherical.studies.engine import bisection_codes
from cospherical.studies.leaves import leaf_codes, run_leaves

CUBE = ("1", "1", "1")


def test_the_leaf_family():
    codes = leaf_codes()
    assert len(codes) == len(set(codes)) == 6210 == sum(
        2 ** len(Configuration.from_code(code[:12]).admissible_faces) for code in bisection_codes())
    for code in codes[::11]:
        cfg = Configuration.from_code(code)
        assert cfg.code == code and not cfg.has_body_point and cfg.point_faces <= cfg.admissible_faces


@pytest.mark.oracle_qhull
@pytest.mark.parametrize("box", [CUBE, ("1", "2", "4")])
def test_every_leaf_configuration_matches_qhull(box):
    """Every configuration of the leaf family, as the study gives it (through its orbit's
    representative), against ``qdelaunay Qz Fv``.  A configuration whose point set is that
    of an octree- or none-policy bisection configuration (no face point, or exactly the
    admissible ones short of all six) is checked by core/test_delaunay.py for both boxes:
    here only that the point sets coincide."""
    study = run_leaves(Box.parse(box), criteria=("optimal",))
    new = []
    for code in study.codes:
        cfg = Configuration.from_code(code, box)
        if not cfg.point_faces:
            assert cfg.nodes() == Configuration.from_code(code[:12], box, face_points="none").nodes()
        elif cfg.point_faces == cfg.admissible_faces and len(cfg.point_faces) < 6:
            assert cfg.nodes() == Configuration.from_code(code[:12], box).nodes()
        else:
            new.append(cfg)
    assert len(new) == 921
    # Qhull once per orbit, its regions carried to each member by an isometry checked exactly
    for cfg, regions in zip(new, qhull_regions_by_orbit(new, box_symmetries(Box.parse(box)))):
        tess = study.tessellation(cfg.code)
        assert tess.nodes == cfg.nodes()
        assert {frozenset(e.nodes) for e in tess.elements} == regions, cfg.code
