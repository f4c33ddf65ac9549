"""Splits under the internal-face and internal-edge criteria, and the minimal kept sets."""

from __future__ import annotations

from collections import Counter
from fractions import Fraction

import numpy as np
import pytest
from scipy.optimize import Bounds, LinearConstraint, milp

from cospherical import Box
from cospherical.catalogue import element_options, minimal_kept_sets
from cospherical.paper import paper_class
from cospherical.studies.engine import bisection_codes, run_study

BOXES = {"A": ("1", "1", "1"), "B": ("1", "2", "4"), "C": ("1", "1.4142", "1.4142")}


@pytest.fixture(scope="module")
def studies(paper_studies):
    """Boxes A, B, C: the session's studies (conftest.py), shared with paper/test_comparison.py."""
    assert {key: study.box.texts for key, study in paper_studies.items()} == BOXES
    return paper_studies


def squared_distance(p, q, squared):
    return sum(w * (x - y) ** 2 for w, x, y in zip(squared, p, q))


def sphere_of(points, squared):
    """Exact circumcenter of points on one sphere, by Fractions (independent of the library)."""
    p0 = points[0]
    rows, rhs = [], []
    for p in points[1:]:
        rows.append([2 * w * (x - x0) for w, x, x0 in zip(squared, p, p0)])
        rhs.append(sum(w * (x * x - x0 * x0) for w, x, x0 in zip(squared, p, p0)))
    # Gaussian elimination over the rationals on the (possibly over-determined) system.
    m = [list(map(Fraction, r)) + [Fraction(b)] for r, b in zip(rows, rhs)]
    pivots = []
    row = 0
    for col in range(3):
        pivot = next((r for r in range(row, len(m)) if m[r][col] != 0), None)
        if pivot is None:
            continue
        m[row], m[pivot] = m[pivot], m[row]
        for r in range(len(m)):
            if r != row and m[r][col] != 0:
                f = m[r][col] / m[row][col]
                m[r] = [a - f * b for a, b in zip(m[r], m[row])]
        pivots.append(col)
        row += 1
    assert pivots == [0, 1, 2], "points do not span 3D"
    assert all(r[3] == 0 for r in m[3:]), "points are not co-spherical"
    return tuple(m[i][3] / m[i][i] for i in range(3))


def check_split(tess, parent, pieces, criterion):
    parent_faces = {frozenset(f) for f in parent.polyhedron.faces}
    parent_edges = {frozenset(e) for e in parent.polyhedron.edges}
    assert sum(p.polyhedron.unit_volume for p in pieces) == parent.polyhedron.unit_volume
    assert set().union(*(set(p.polyhedron.nodes) for p in pieces)) <= set(parent.polyhedron.nodes), "new vertex"
    uses = Counter(frozenset(f) for p in pieces for f in p.polyhedron.faces)
    for face, count in uses.items():
        if count == 1:
            assert face in parent_faces, f"piece face {sorted(face)} is neither shared nor a whole parent face"
        else:
            assert count == 2 and face not in parent_faces
    assert parent_faces <= set(uses), "a boundary face of the parent was cut"
    for p in pieces:
        for edge in map(frozenset, p.polyhedron.edges):
            if criterion == "internal_faces":
                assert edge in parent_edges, f"new edge {sorted(edge)} under internal_faces"
            elif edge not in parent_edges:
                assert not any(edge <= face for face in parent_faces), "new edge on a boundary face"


@pytest.mark.parametrize("criterion", ["internal_faces", "internal_edges_and_faces"])
@pytest.mark.parametrize("box", [("1", "1", "1"), ("1", "sqrt(2)", "sqrt(2)")])
def test_every_split_tiles_its_parent(box, criterion):
    study = run_study("bisection", Box.parse(box), bisection_codes(), criteria=("optimal",))
    seen = set()
    for tess in study.tessellations.values():
        for element in tess.elements:
            key = tuple((n, tess.nodes[n]) for n in element.polyhedron.nodes)
            if key in seen:
                continue
            seen.add(key)
            options = element_options(tess, element, criterion)
            assert options[0] == (element,) or any(o == (element,) for o in options)
            for pieces in options:
                check_split(tess, element, pieces, criterion)


@pytest.mark.parametrize("key", ["A", "B", "C"])
def test_every_criterion_tiles_the_box_with_empty_spheres(studies, key):
    study = studies[key]
    squared = study.box.squared
    # The criteria share most elements: each element of a configuration is checked once, and the
    # sphere of the same points (in another configuration) is solved once.
    spheres, checked = {}, set()
    for criterion in study.criteria:
        for code, tess in study.choices[criterion].tessellations.items():
            assert sum(e.polyhedron.unit_volume for e in tess.elements) == 1
            for element in tess.elements:
                if (code, element.polyhedron.nodes) in checked:
                    continue
                checked.add((code, element.polyhedron.nodes))
                points = tuple(tess.nodes[n] for n in element.polyhedron.nodes)
                if points not in spheres:
                    center = sphere_of(points, squared)
                    spheres[points] = center, squared_distance(points[0], center, squared)
                center, r2 = spheres[points]
                assert all(squared_distance(p, center, squared) >= r2 for p in tess.nodes.values())
    # every configuration, through the symmetry maps: still a tiling of the box
    for criterion in ("internal_faces", "internal_edges_and_faces"):
        for code in study.codes[::5]:
            assert sum(e.polyhedron.unit_volume for e in study.tessellation(code, criterion).elements) == 1


def milp_minimum(instances) -> int:
    """The smallest kept set by integer programming (HiGHS), independent of our search."""
    types = sorted({t for options in instances for o in options for t in o})
    index = {t: i for i, t in enumerate(types)}
    columns = [(i, o) for i, options in enumerate(instances) for o in sorted(options, key=sorted)]
    n = len(types) + len(columns)
    rows, lower, upper = [], [], []
    for j, (_, option) in enumerate(columns):  # choosing an option needs each of its types kept
        for t in option:
            row = np.zeros(n)
            row[len(types) + j] = 1
            row[index[t]] = -1
            rows.append(row), lower.append(-np.inf), upper.append(0)
    for i in range(len(instances)):  # every instance picks an option
        row = np.zeros(n)
        for j, (owner, _) in enumerate(columns):
            if owner == i:
                row[len(types) + j] = 1
        rows.append(row), lower.append(1), upper.append(np.inf)
    cost = np.concatenate([np.ones(len(types)), np.zeros(len(columns))])
    result = milp(cost, constraints=LinearConstraint(np.array(rows), lower, upper),
                  integrality=np.ones(n), bounds=Bounds(0, 1))
    assert result.success
    return round(result.fun)


@pytest.mark.oracle_highs
@pytest.mark.parametrize("key", ["A", "B", "C"])
@pytest.mark.parametrize("criterion", ["internal_faces", "internal_edges_and_faces"])
def test_kept_sets_are_minimal(studies, key, criterion):
    study = studies[key]
    instances = [
        {frozenset(p.type.id for p in o) for o in element_options(tess, e, criterion)}
        for tess in study.tessellations.values()
        for e in tess.elements
    ]
    distinct = [set(s) for s in {frozenset(i) for i in instances}]
    size, solutions = minimal_kept_sets(distinct)
    assert size == len(study.choices[criterion].kept) == milp_minimum(distinct)
    assert study.choices[criterion].kept in solutions
    for kept in solutions:
        assert all(any(o <= kept for o in options) for options in distinct)


def names(options):
    return [sorted((paper_class(p.type) or {"name": p.type.name})["name"] for p in o) for o in options]


def test_paper_worked_examples(studies):
    found = {}
    for tess in studies["A"].tessellations.values():
        for e in tess.elements:
            cls = (paper_class(e.type) or {}).get("name")
            if cls in ("Triangular Bipyramid", "Triangular Biprism", "Generic #9", "Generic #6") and cls not in found:
                found[cls] = (tess, e)
    tess, e = found["Triangular Bipyramid"]
    assert ["Tetrahedron", "Tetrahedron"] in names(element_options(tess, e, "internal_faces"))
    tess, e = found["Triangular Biprism"]
    assert ["Triangular Prism", "Triangular Prism"] in names(element_options(tess, e, "internal_faces"))
    tess, e = found["Generic #9"]
    assert ["Cuboid", "Quadrilateral Pyramid"] in names(element_options(tess, e, "internal_faces"))
    tess, e = found["Generic #6"]  # one inner edge: two tetrahedra and a tetrahedron complement
    assert names(element_options(tess, e, "internal_faces")) == [["Generic #6"]]
    assert ["Tetrahedron", "Tetrahedron", "Tetrahedron Complement"] in names(
        element_options(tess, e, "internal_edges_and_faces"))
