"""Canonical codes of labelled face graphs: the same code exactly when the graphs are isomorphic."""

from __future__ import annotations

import itertools
import random

import pytest
from oracle import isomorphic

from cospherical import Configuration, tessellate
from cospherical.core.canonical import canonical_form

TETRA = [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)]
PYRAMID = [(0, 3, 2, 1), (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)]
PRISM = [(0, 2, 1), (3, 4, 5), (0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5)]
CUBE = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
# face graphs with their face kinds: the same graph under other labels is another polyhedron type
POLYHEDRA = {
    "tetrahedron": (TETRA, ["triangle"] * 4),
    "square pyramid": (PYRAMID, ["rectangle"] + ["triangle"] * 4),
    "pyramid on a quadrilateral": (PYRAMID, ["quadrilateral"] + ["triangle"] * 4),
    "wedge": (PRISM, ["triangle", "triangle", "rectangle", "rectangle", "rectangle"]),
    "wedge, one side a quadrilateral": (PRISM, ["triangle", "triangle", "quadrilateral", "rectangle", "rectangle"]),
    "wedge, another side a quadrilateral": (PRISM, ["triangle", "triangle", "rectangle", "quadrilateral", "rectangle"]),
    "cuboid": (CUBE, ["rectangle"] * 6),
    "cube, one face a quadrilateral": (CUBE, ["quadrilateral"] + ["rectangle"] * 5),
    "cube, two opposite quadrilaterals": (CUBE, ["quadrilateral"] * 2 + ["rectangle"] * 4),
    "cube, two adjacent quadrilaterals": (CUBE, ["quadrilateral", "rectangle", "quadrilateral"] + ["rectangle"] * 3),
}


@pytest.mark.oracle_networkx
def test_equal_codes_exactly_for_isomorphic_labelled_graphs():
    codes = {name: canonical_form(*shape).code for name, shape in POLYHEDRA.items()}
    for (a, shape_a), (b, shape_b) in itertools.combinations(POLYHEDRA.items(), 2):
        assert (codes[a] == codes[b]) == isomorphic(shape_a, shape_b), (a, b)
    # the two wedges with one quadrilateral side are one type: the sides are alike by symmetry
    assert codes["wedge, one side a quadrilateral"] == codes["wedge, another side a quadrilateral"]
    assert len(set(codes.values())) == len(codes) - 1


def _relabelled(faces, kinds, order) -> set:
    """The faces renamed by each vertex's place in ``order``, as cycles from their smallest vertex, with kinds."""
    rank = {v: i for i, v in enumerate(order)}
    out = set()
    for face, kind in zip(faces, kinds):
        cycle = [rank[v] for v in face]
        start = cycle.index(min(cycle))
        out.add((tuple(cycle[start:] + cycle[:start]), kind))
    return out


def test_the_reference_order_is_canonical():
    # renamed by its reference order, a polyhedron is the same labelled map whatever its first labels
    # and face order were: what lets a pattern table say which node plays which role
    rng = random.Random(3)
    for name, (faces, kinds) in POLYHEDRA.items():
        form = canonical_form(faces, kinds)
        assert sorted(form.order) == sorted({v for face in faces for v in face}), name
        relabel = dict(zip(form.order, rng.sample(range(10, 30), len(form.order))))
        order = rng.sample(range(len(faces)), len(faces))
        other = [tuple(relabel[v] for v in faces[i]) for i in order], [kinds[i] for i in order]
        again = canonical_form(*other)
        assert again.code == form.code and not form.mirrored and not again.mirrored, name
        assert _relabelled(*other, again.order) == _relabelled(faces, kinds, form.order), name


def test_code_is_invariant_under_relabelling_and_mirroring():
    rng = random.Random(7)
    tess = tessellate(Configuration.from_code("8888a0000808", ("1", "sqrt(2)", "sqrt(2)")))
    for e in tess.elements:
        faces, kinds = e.polyhedron.faces, e.polyhedron.face_kinds
        relabel = {v: 100 + i for i, v in enumerate(rng.sample(e.polyhedron.nodes, len(e.polyhedron.nodes)))}
        renamed = [tuple(relabel[v] for v in face) for face in faces]
        mirrored = [tuple(reversed(face)) for face in renamed]
        order = rng.sample(range(len(faces)), len(faces))
        shuffled = [mirrored[i] for i in order], [kinds[i] for i in order]
        assert canonical_form(renamed, kinds).code == e.type.code
        assert canonical_form(*shuffled).code == e.type.code
