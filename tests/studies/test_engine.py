"""The study engine: a bisection study without numpy; on each shape, orbit statistics equal tessellating every
configuration."""

from __future__ import annotations

import subprocess
import sys
from collections import Counter

import pytest

from cospherical import Configuration, standard_shape, tessellate
from tests.core.test_shapes import SHAPES


def test_a_bisection_study_loads_no_numpy():
    # numpy takes a tenth of a second to import: the bisection study and its command do without it.
    script = ("import sys; from cospherical.cli import main; main(['study', 'bisection', '--format', 'json']); "
              "sys.exit('numpy' in sys.modules)")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


@pytest.fixture(scope="module")
def shape_studies():
    from cospherical.studies.engine import bisection_codes, run_study

    return {name: run_study("bisection", standard_shape(name).box, bisection_codes(name), element=name)
            for name in SHAPES}


@pytest.mark.parametrize("name", SHAPES)
def test_study_counts_equal_direct_counts(shape_studies, name):
    """Orbit statistics (one tessellation per orbit, weighted by orbit sizes) equal tessellating
    every configuration, and every member's mapped tessellation is its direct one."""
    study = shape_studies[name]
    shape = standard_shape(name)
    rows = {code: (adequate, tessellations, image) for code, adequate, tessellations, image in study.rows()}
    counts, fvm, fvm_open = Counter(), 0, 0
    for code in study.codes:
        cfg = Configuration.from_code(code, shape=shape)
        tess = tessellate(cfg)
        counts.update(e.type.id for e in tess.elements)
        fvm += tess.fvm_adequate
        fvm_open += tess.fvm_adequate_open
        # The FVM verdicts against float circumcenters and a tolerance (the unit box: no scaling).
        margin = min(_float_margin(shape, [cfg.real_nodes()[v] for v in e.nodes]) for e in tess.elements)
        assert (tess.fvm_adequate, tess.fvm_adequate_open) == (margin > -1e-9, margin > 1e-9), code
        mapped = study.tessellation(code)
        assert [(e.type.id, e.nodes, e.mirrored) for e in mapped.elements] == \
            [(e.type.id, e.nodes, e.mirrored) for e in tess.elements], code
        # what a pattern table writes: the rows' images (equal elements mapped once, shared) are the same
        adequate, tessellations, image = rows[code]
        assert adequate == tess.fvm_adequate
        assert [(e.type.id, e.nodes, e.mirrored, e.polyhedron) for e in image(tessellations["optimal"]).elements] == \
            [(e.type.id, e.nodes, e.mirrored, e.polyhedron) for e in mapped.elements], code
    assert {t.type.id: t.count for t in study.type_counts()} == dict(counts)
    assert (study.fvm_adequate, study.fvm_adequate_open) == (fvm, fvm_open)
    assert study.configurations == 1 << len(shape.edges)


def _float_margin(shape, points) -> float:
    """The least distance of the points' circumcenter inside the shape's face planes (negative: outside)."""
    import numpy as np

    p = np.array(points)
    center = np.linalg.lstsq(2 * (p[1:] - p[0]), (p[1:] ** 2).sum(1) - (p[0] ** 2).sum(), rcond=None)[0]
    margins = []
    for normal, offset in shape.planes:
        n = np.array([float(x) for x in normal])
        margins.append((float(offset) - n @ center) / np.linalg.norm(n))
    return min(margins)


def test_a_study_takes_another_policys_tessellations_only_where_the_points_agree(shape_studies):
    # the prism's none-policy study, alone and taking the octree study's tessellations: the same study
    from cospherical.studies.engine import bisection_codes, run_study

    octree = shape_studies["prism"]
    box, codes = standard_shape("prism").box, bisection_codes("prism")
    alone = run_study("bisection", box, codes, "none", element="prism")
    taking = run_study("bisection", box, codes, "none", element="prism", known=[octree])
    assert taking.tessellations == alone.tessellations and taking.choices == alone.choices
    taken = [rep for rep, tess in taking.tessellations.items() if tess.elements is octree.tessellations[rep].elements]
    with_face_points = [rep for rep, tess in octree.tessellations.items() if tess.configuration.point_faces]
    assert taken and with_face_points and not set(taken) & set(with_face_points)
    assert len(taken) + len(with_face_points) == octree.orbits
