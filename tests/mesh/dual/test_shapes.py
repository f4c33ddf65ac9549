"""The pieces grouped per configuration or element shape (cospherical.mesh.dual.shapes): every path, one dual."""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from cospherical.core.configuration import Box
from cospherical.mesh.assembly import assemble
from cospherical.mesh.dual import mesh_dual
from cospherical.mesh.octree import build_octree, parse_shape

from ..test_dual import CACHES


def test_element_list_path_equals_the_configuration_path():
    """The connectivity path (any element list) gives the leaf path's numbers, exactly."""
    box = Box.parse(["1", "2", "4"])
    mesh = assemble(build_octree(box, 2, [parse_shape("point:1/3,1/5,1/7")]),
                    cache=CACHES.setdefault(box.texts, {}))
    fast, generic = mesh_dual(mesh), mesh_dual(mesh, mesh.connectivity())
    assert np.array_equal(fast.edges, generic.edges)
    assert all(Fraction(int(x), fast.coefficient_denominator) == Fraction(int(y), generic.coefficient_denominator)
               for x, y in zip(fast.coefficient_exact, generic.coefficient_exact))
    assert all(Fraction(int(x), fast.volume_denominator) == Fraction(int(y), generic.volume_denominator)
               for x, y in zip(fast.volume_exact, generic.volume_exact))
    assert all(Fraction(int(x), fast.boundary_area_denominator) == Fraction(int(y), generic.boundary_area_denominator)
               for x, y in zip(fast.boundary_area_exact.reshape(-1), generic.boundary_area_exact.reshape(-1)))
    assert np.array_equal(fast.element_circumcenter, generic.element_circumcenter)



def _same(a, b):
    """Two ShapePieces are the same: node ids, edges, planes, numerators and denominators (each the least common
    one of fractions in lowest terms, so equal fractions are equal numbers)."""
    return all(np.array_equal(getattr(a, name), getattr(b, name)) if name in ("edges", "volume_nodes")
               else getattr(a, name) == getattr(b, name) for name in a.__slots__)


def test_pieces_remembered_per_shape_are_each_elements_own():
    """A configuration's pieces, carried over from another configuration of its class (equal up to the box's
    symmetries), or its elements measured once per class of shapes up to translation and the box's symmetries
    and mapped and moved back, are the pieces of each element measured where it lies, exactly: boundary planes,
    node ids and all (a cube, whose configurations repeat at other corners and in mirror images, a
    1 x sqrt 2 x sqrt 2 box, whose last two axes may be swapped, and a 1 x 2 x 4 box, only mirrored)."""
    from cospherical.mesh.dual import shapes
    from cospherical.mesh.dual.pieces import element_pieces

    for texts, shape in ((["1", "1", "1"], "sphere:0.5,0.5,0.5,0.3"), (["1", "sqrt(2)", "sqrt(2)"], "point:0.3,0.4,0.5"),
                         (["1", "2", "4"], "point:1/3,1/5,1/7")):
        box = Box.parse(texts)
        mesh = assemble(build_octree(box, 3, [parse_shape(shape)]), cache=CACHES.setdefault(box.texts, {}))
        squared = tuple(Fraction(x) for x in box.squared)
        for per_configuration in (False, True):  # element shapes mapped (each configuration its own class), or both
            shapes._REMEMBERED.clear()
            shapes._SHAPES.clear()
            shapes._CLASSES.clear()
            shapes._CONFIGURATIONS.clear()
            elements = configurations = 0
            for _, tessellation, _ in mesh.groups():
                points = tessellation.configuration.nodes()
                direct = shapes.ShapePieces.summed([
                    element_pieces({n: points[n] for n in e.nodes}, e.faces, e.center, squared)
                    for e in tessellation.elements])
                if not per_configuration:
                    shapes._CONFIGURATIONS.clear()
                remembered = shapes._tessellation_pieces(tessellation, squared)
                assert _same(direct, remembered)
                elements += len(tessellation.elements)
                configurations += 1
            if per_configuration:  # measured once per class of configurations, carried over to the others
                assert len(shapes._CONFIGURATIONS) < configurations
            else:
                assert len(shapes._SHAPES) < elements or texts[1] != "1"  # the cube's shapes were met again
                assert len(shapes._CLASSES) < len(shapes._SHAPES)  # and mapped: measured once per class


def test_element_shapes_are_classed_exactly_even_when_their_hashes_collide(monkeypatch):
    """Equal rows (an element's offsets) share a class, different rows never do: with every hash made equal,
    the classes come from the rows themselves, and the dual of an element list is the same."""
    from cospherical.mesh.dual import shapes

    rows = np.random.default_rng(5).integers(0, 3, size=(200, 6))
    first, which = shapes._equal_rows(rows)
    assert np.array_equal(rows[first][which], rows) and len(first) == len(np.unique(rows, axis=0))
    box = Box.parse(["1", "2", "4"])
    mesh = assemble(build_octree(box, 2, [parse_shape("point:1/3,1/5,1/7")]), cache=CACHES.setdefault(box.texts, {}))
    hashed = mesh_dual(mesh, mesh.connectivity())
    monkeypatch.setattr(shapes, "_ROW_HASH", np.zeros_like(shapes._ROW_HASH))  # every row collides
    collided = shapes._equal_rows(rows)
    assert np.array_equal(rows[collided[0]][collided[1]], rows) and len(collided[0]) == len(first)
    again = mesh_dual(mesh, mesh.connectivity())
    for name in ("edges", "coefficient_exact", "volume_exact", "boundary_area_exact", "element_circumcenter"):
        assert np.array_equal(getattr(hashed, name), getattr(again, name))


def test_a_configuration_tessellated_otherwise_is_not_carried_over():
    """The cube cut into two prisms along x = y, and along x + y = 1: one point set, tessellations that are mirror
    images but not the same, so that each is measured on its own (never one carried over to the other)."""
    from cospherical.core.configuration import Configuration
    from cospherical.mesh.assembly import local_tessellation
    from cospherical.mesh.dual import shapes
    from cospherical.mesh.dual.pieces import element_pieces

    cube = Configuration.from_code("000000000000", faces=[])
    points = cube.nodes()
    squared = (Fraction(1), Fraction(1), Fraction(1))
    shapes._CONFIGURATIONS.clear()
    for cut in (lambda p: p[0] - p[1], lambda p: p[0] + p[1] - 1):
        halves = [[n for n, p in points.items() if side * cut(p) >= 0] for side in (1, -1)]
        tessellation = local_tessellation(cube, [("prism", half) for half in halves])
        direct = shapes.ShapePieces.summed([element_pieces({n: points[n] for n in e.nodes}, e.faces, e.center,
                                                           squared) for e in tessellation.elements])
        pieces = shapes._tessellation_pieces(tessellation, squared)
        assert _same(direct, pieces)
    assert len(shapes._CONFIGURATIONS) == 2
