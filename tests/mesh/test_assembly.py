"""Assembly of a mesh from an octree's leaves: by hand, from pattern tables, whole under every criterion and
balance, and broken tables caught by the checks."""

from __future__ import annotations

import numpy as np
import pytest

from cospherical.core.configuration import Box, Configuration
from cospherical.core.tessellation import tessellate
from cospherical.files.yamlio import atomic_write, yaml_text
from cospherical.formats.mesh import table_lookup
from cospherical.formats.patterns import configuration_line, load
from cospherical.mesh.assembly import assemble
from cospherical.mesh.checks import check_circumcenters, check_conformity, check_delaunay, check_volume
from cospherical.mesh.octree import build_octree, leaves_octree, parse_shape

CUBE = Box.parse(["1", "1", "1"])
BRICK = Box.parse(["1", "2", "4"])

# One octant of the root refined: 7 leaves of level 1 and 8 of level 2.
OCTANT = [(1, i, j, k) for i in (0, 1) for j in (0, 1) for k in (0, 1) if (i, j, k) != (0, 0, 0)] + \
         [(2, i, j, k) for i in (0, 1) for j in (0, 1) for k in (0, 1)]


def octant_tree(box=CUBE):
    return leaves_octree(box, [leaf[0] for leaf in OCTANT], [leaf[1:] for leaf in OCTANT])


def checks(mesh) -> dict:
    return {**check_volume(mesh).figures(), **check_conformity(mesh).figures(), **check_circumcenters(mesh).figures(),
            **check_delaunay(mesh).figures()}


def small_table(path, box, codes):
    """A pattern table of some bare (octree-policy) codes, in the shipped tables' format."""
    header = {"schema_version": 1, "generator": "test", "catalogue_version": "test", "study": "bisection",
              "box": list(box.texts), "face_points": "octree", "scheme": "test", "criteria": ["optimal"]}
    lines = [yaml_text(header).rstrip("\n"), "configurations:"]
    for code in sorted(codes):
        tess = tessellate(Configuration.from_code(code, box))
        lines.append(configuration_line(code, tess.fvm_adequate, {"optimal": tess}).rstrip("\n"))
    atomic_write(path, "\n".join(lines) + "\n")
    return load(path)


def bare_codes(mesh) -> set[str]:
    return {p.code.split("+")[0] for p in mesh.tessellations}


def test_one_leaf():
    mesh = assemble(build_octree(CUBE, 0, []))
    assert (len(mesh.tree), len(mesh.vertices), len(mesh)) == (1, 8, 1)
    assert mesh.tessellations[0].code == "000000000000+f"
    found = checks(mesh)
    assert found["volume_ok"] and found["nonconforming_faces"] == 0 and found["boundary_faces"] == 6
    assert found["delaunay_violations"] == 0 and found["leaves_not_fvm_adequate"] == 0


def test_one_refined_octant_by_hand():
    mesh = assemble(octant_tree())
    # 27 points of the level-1 grid, and the octant's own 27 points of which its 8 corners are shared
    assert (len(mesh.tree), len(mesh.vertices)) == (15, 46)
    codes = sorted(p.code for p in mesh.tessellations)
    # the three face neighbours see a face point and four edge points, the three edge neighbours one edge point,
    # the corner neighbour and the small leaves nothing
    assert "000000000000+f" in codes and len(codes) == 1 + 3 + 3
    face_leaf = [p for p in mesh.tessellations if "+f" in p.code and p.code.endswith(tuple("012345"))]
    assert len(face_leaf) == 3 and all(p.code.count("8") == 4 for p in face_leaf)
    found = checks(mesh)
    assert found["volume_ok"] and found["volume"] == "1"
    assert found["nonconforming_faces"] == 0 and found["delaunay_violations"] == 0
    # the same tree by refinement: a point, a small box, a small sphere inside the first octant
    for shape in ("point:0.25,0.25,0.25", "box:0.1,0.1,0.1,0.2,0.2,0.2", "sphere:0.2,0.2,0.2,0.1"):
        again = build_octree(CUBE, 2, [parse_shape(shape)])
        assert sorted(zip(again.levels.tolist(), map(tuple, again.positions.tolist()))) == \
            sorted((leaf[0], leaf[1:]) for leaf in OCTANT), shape


def test_table_equals_tessellating_every_leaf(tmp_path):
    tree = build_octree(BRICK, 3, [parse_shape("sphere:0.5,1,2,0.6")])
    fly = assemble(tree)
    table = small_table(tmp_path / "t.yaml", BRICK, bare_codes(fly))
    mesh = assemble(tree, table_lookup(table, "optimal", BRICK))
    assert not any(p.on_the_fly for p in mesh.tessellations) and all(p.on_the_fly for p in fly.tessellations)
    assert np.array_equal(mesh.connectivity()[0], fly.connectivity()[0])
    assert mesh.element_types()[0] == fly.element_types()[0]
    assert np.array_equal(mesh.element_types()[1], fly.element_types()[1])
    assert checks(mesh) == checks(fly)


def test_missing_configurations_are_tessellated_and_counted(tmp_path):
    tree = octant_tree()
    fly = assemble(tree)
    codes = sorted(bare_codes(fly))
    table = small_table(tmp_path / "t.yaml", CUBE, codes[:2])
    mesh = assemble(tree, table_lookup(table, "optimal", CUBE))
    assert sum(p.on_the_fly for p in mesh.tessellations) == len(fly.tessellations) - 2


class Broken:
    """A pattern table with one configuration's elements edited."""

    def __init__(self, edit):
        self.edit = edit

    def __call__(self, configuration):
        tess = tessellate(configuration)
        elements = [{"type": e.type.id, "nodes": list(e.nodes)} for e in tess.elements]
        return self.edit(elements) if len(elements) > 1 else elements


@pytest.mark.parametrize("edit, volume", [
    (lambda elements: elements[:-1], "less"),             # an element missing: a hole
    (lambda elements: elements + elements[:1], "more"),  # an element twice: an overlap
])
def test_checks_catch_a_broken_table(edit, volume):
    mesh = assemble(octant_tree(), Broken(edit))
    found = checks(mesh)
    assert not found["volume_ok"]
    share = eval(found["volume"].replace("/", "/ "))  # noqa: S307 (a fraction written by us)
    assert (share < 1) if volume == "less" else (share > 1)
    assert found["nonconforming_faces"] > 0 and found["nonconforming_examples"]


def test_split_criteria_keep_the_mesh_whole():
    """Splits add internal faces and edges only: the split mesh still fills the domain and conforms."""
    tree = build_octree(CUBE, 4, [parse_shape("sphere:0.5,0.5,0.5,0.3")])
    optimal = assemble(tree)
    split = assemble(tree, criterion="internal_edges_and_faces")
    assert len(split) > len(optimal)
    found = checks(split)
    assert found["volume_ok"] and found["nonconforming_faces"] == 0 and found["delaunay_violations"] == 0


@pytest.mark.parametrize("balance", ["edge", "vertex"])
def test_both_balances_give_whole_meshes(balance):
    """Edge balance lets leaves touching only at a corner differ by two levels: still 1-irregular, still whole."""
    tree = build_octree(CUBE, 5, [parse_shape("point:0.3,0.61,0.77"), parse_shape("plane:1,1,1,1.2")], balance)
    found = checks(assemble(tree))
    assert found["volume_ok"] and found["nonconforming_faces"] == 0 and found["delaunay_violations"] == 0
    again = leaves_octree(CUBE, tree.levels, tree.positions)  # the leaf-list check accepts it
    assert np.array_equal(again.positions, tree.positions)


def test_a_part_of_a_tree_sees_the_whole_trees_points_on_its_leaves():
    """A part of a tree (a partition piece, a device's region) assembled with the whole tree's vertices gives
    its leaves the whole tree's slots: a leaf at the part's finest level can still have the corners of smaller
    leaves of the whole tree on its edges and faces (the part's depth is not the grid's)."""
    from cospherical.mesh.assembly import vertex_keys
    from cospherical.mesh.octree import Octree

    tree = build_octree(Box.parse([1, 1, 1]), 4, [parse_shape("point:0.1,0.1,0.1")])
    whole = assemble(tree)
    part = np.flatnonzero(tree.levels <= 2)
    sub = assemble(Octree(tree.box, tree.levels[part], tree.positions[part], tree.vertex_balanced),
                   vertices=vertex_keys(tree))
    assert tree.depth == 4 and sub.tree.depth == 2
    hanging = (whole.slots[part, 8:26] >= 0).any(axis=1) & (tree.levels[part] == 2)
    assert hanging.any()  # leaves at the part's finest level with points of smaller leaves on them
    assert np.array_equal(sub.slots, whole.slots[part])


def test_configurations_sharing_an_element_measure_it_once():
    # assemble measures each element at given node ids and points once for all the configurations
    # that have it: every configuration's elements are what a measure of its own gives
    from cospherical.mesh.assembly import local_tessellation

    mesh = assemble(build_octree(CUBE, 3, [parse_shape("sphere:0.5,0.5,0.5,0.3")]))
    measured: dict = {}
    elements = 0
    for tessellation in mesh.tessellations:
        listed = [(e.type_id, e.nodes) for e in tessellation.elements]
        shared = local_tessellation(tessellation.configuration, listed, on_the_fly=True, measured=measured)
        assert shared == tessellation == local_tessellation(tessellation.configuration, listed, on_the_fly=True)
        elements += len(listed)
    assert len(mesh.tessellations) == 21 and len(measured) < elements  # some shared, each measured once


def test_connectivity_is_the_blocks_vertex_ids():
    """connectivity() (one gather per configuration) gives every element the vertex ids its block gives it, padded
    with -1, with leaves and cells that replace leaves (a brick's sphere tree has both)."""
    import cospherical

    mesh = cospherical.build_mesh(domain=(1, 2, 4), levels=4, refine=["sphere:0.5,1,2,0.3"]).assembled  # 168 cells
    assert mesh.cells is not None and mesh.leaf_elements > 0
    conn, sizes = mesh.connectivity()
    seen = np.zeros(len(mesh), dtype=bool)
    for rows, nodes, _, _ in mesh.blocks():
        assert np.array_equal(conn[rows, :nodes.shape[1]], nodes) and (conn[rows, nodes.shape[1]:] == -1).all()
        assert (sizes[rows] == nodes.shape[1]).all() and not seen[rows].any()
        seen[rows] = True
    assert seen.all() and conn.dtype == np.int32 and sizes.dtype == np.int8
