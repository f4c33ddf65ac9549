"""The one mesh pipeline: trees from every source, progress as told, timings per stage, the report typed."""

from __future__ import annotations

from collections import defaultdict
from fractions import Fraction

import numpy as np
import pytest

from cospherical.core.configuration import Box
from cospherical.errors import InputError
from cospherical.mesh.assembly import assemble
from cospherical.mesh.octree import build_octree, parse_shape
from cospherical.formats.device_file import parse_device
from cospherical.mesh.pipeline import (delaunay_mode, run_pipeline, tree_from_device, tree_from_leaves,
                                       tree_from_octree, tree_from_refine)
from cospherical.mesh.report import MeshReport, TreeSummary, mesh_report

BOX = Box.parse([1, 2, 4])


def _faces(report: MeshReport) -> int:
    """Every element face, as the conformity check met them: twice each interior one, once the rest."""
    return 2 * report.interior_faces + report.boundary_faces + report.nonconforming_faces


def test_progress_adds_up_to_each_stage_total_and_timings_follow_the_stages():
    told = defaultdict(list)
    source = tree_from_refine(BOX, 3, ["sphere:0.5,1,2,0.6"])
    result = run_pipeline(source, uniform=False, dual=True,
                          progress=lambda stage, total, n: told[stage].append((total, n)))
    # the final check is the global step's own, not run again; the faces paired have no total known before
    assert set(told) == {"assembly", "regions", "conformity", "dual"}
    for stage, calls in told.items():
        totals = {total for total, _ in calls}
        assert len(totals) == 1 and sum(n for _, n in calls) == (totals.pop() or _faces(result.report)), stage
    assert told["assembly"][0][0] == len(source.tree)
    assert told["regions"][0][0] == result.report.leaf_mesh.elements
    assert list(result.report.timings) == ["assembly", "global Delaunay", "volume", "conformity", "circumcenters",
                                           "delaunay", "statistics", "dual"]
    assert all(seconds >= 0 for seconds in result.report.timings.values())
    assert result.dual is not None and result.report.dual.edges == len(result.dual.edges)


def test_a_device_tells_the_same_stages_with_their_own_totals():
    """A device's mesh is told as the one-box mesh is (assembly through the leaves, the leaf mesh's check through
    its elements), so the command line draws the same bars for it."""
    device = parse_device("device: cube\nregions:\n  - {name: si, material: Si, boxes: [[0, 0, 0, 1, 1, 1]]}\n"
                          "refine:\n  - point: [0.1, 0.2, 0.3]\nlevels: 3\n")
    told = defaultdict(list)
    source = tree_from_device(device)
    result = run_pipeline(source, uniform=False, progress=lambda stage, total, n: told[stage].append((total, n)))
    assert set(told) == {"assembly", "regions", "conformity"}
    assert sum(n for _, n in told["conformity"]) == _faces(result.report)
    assert told["assembly"][0][0] == len(source.tree) == sum(n for _, n in told["assembly"])
    assert told["regions"][0][0] == result.report.leaf_mesh.elements == sum(n for _, n in told["regions"])


def _far(x0: str, side: str, levels: int) -> str:
    return (f"device: far\nregions:\n  - {{name: si, material: Si, boxes: [[{x0}, 0, 0, {x0} + {side}, 1, 1]]}}\n"
            f"refine:\n  - point: [{Fraction(x0) + Fraction(side) / 3}, 0.4, 0.4]\nlevels: {levels}\n"
            ).replace(f"{x0} + {side}", str(Fraction(x0) + Fraction(side)))


@pytest.mark.parametrize("x0, side, levels", [
    ("100000000000000000000", "1", 2),    # every vertex rounded onto x = 1e20
    ("1000000000000", "1/1000", 3),        # a 1e-3 cube at 1e12: distinct floats, its volumes 2 % off
    ("1000", "1", 8),                      # 1000 sides off
    ("-7", "1/8", 6)])
def test_a_device_is_refused_where_float_coordinates_cannot_hold_its_leaves(x0, side, levels):
    # the premise from the floats themselves: every grid line's float, its step against the exact step
    exact = [Fraction(x0) + Fraction(side) * k / 2 ** levels for k in range(2 ** levels + 1)]
    steps = np.diff([float(x) for x in exact])
    fits = bool(np.all(np.abs(steps - float(exact[1] - exact[0])) <= float(exact[1] - exact[0]) / 2 ** 26))
    device = parse_device(_far(x0, side, levels))
    if fits:
        assert tree_from_device(device).tree.depth == levels
    else:
        with pytest.raises(InputError, match="float64 coordinates .* too coarse for its smallest leaves"):
            tree_from_device(device)
    assert fits == (x0 in ("1000", "-7"))


def test_the_pipeline_in_leaf_mode_is_the_steps_by_hand():
    tree = build_octree(BOX, 3, [parse_shape("point:0.2,0.3,0.4")])  # 22 leaves, 5 elements not Delaunay
    by_hand = mesh_report(assemble(tree), TreeSummary("leaves", depth=tree.depth), None, uniform=False)
    told = defaultdict(int)
    result = run_pipeline(tree_from_octree(tree), delaunay="leaf", uniform=False,
                          progress=lambda stage, total, n: told.__setitem__(stage, told[stage] + n))
    assert isinstance(result.report, MeshReport) and result.report == by_hand
    assert by_hand.delaunay_violations > 0 and len(result.violating) == by_hand.delaunay_violations
    assert dict(told) == {"assembly": len(tree), "delaunay": len(result.mesh), "conformity": _faces(result.report)}


def test_a_leaf_list_keeps_its_numbering():
    tree = build_octree(BOX, 2, [parse_shape("point:0.2,0.3,0.4")])
    shuffled = np.random.default_rng(3).permutation(len(tree))
    source = tree_from_leaves(BOX, tree.levels[shuffled], tree.positions[shuffled], file="mine.txt")
    assert np.array_equal(shuffled[source.leaf_order], np.arange(len(tree)))  # tree's leaf i is listed at leaf_order[i]
    assert source.described.to_dict() == {"source": "leaves", "file": "mine.txt", "depth": 2}


@pytest.mark.parametrize("criterion, delaunay, expected", [
    ("optimal", None, "global"), ("internal_faces", None, "leaf"), ("optimal", "leaf", "leaf")])
def test_the_delaunay_mode_follows_the_criterion(criterion, delaunay, expected):
    assert delaunay_mode(criterion, delaunay) == expected


def test_a_contradiction_is_refused():
    with pytest.raises(InputError, match="use --delaunay leaf"):
        delaunay_mode("internal_edges_and_faces", "global")
    with pytest.raises(InputError, match="write global or leaf"):
        delaunay_mode("optimal", "both")


def test_a_tree_given_keeps_its_vertex_balance_only_where_its_leaves_bear_it_out():
    """The Delaunay check bounds where vertices lie by the tree's vertex balance: a tree a caller brings keeps
    that claim when it holds, and loses it when its leaves are only balanced across faces and edges (the
    check then searches every sphere, and finds what it must)."""
    from dataclasses import replace

    shapes = [parse_shape("point:0.1,0.1,0.1"), parse_shape("point:0.55,0.55,0.55")]
    balanced = build_octree(BOX, 4, shapes)
    assert tree_from_octree(balanced).tree.vertex_balanced
    edges_only = build_octree(BOX, 4, shapes, "edge")
    assert len(edges_only) < len(balanced)  # some leaves meet at a corner two levels apart
    claimed = tree_from_octree(replace(edges_only, vertex_balanced=True)).tree
    assert not claimed.vertex_balanced and np.array_equal(claimed.levels, edges_only.levels)
