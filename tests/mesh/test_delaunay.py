"""The global Delaunay mode against the Delaunay subdivision computed another way, on whole octrees.

The oracle triangulates all mesh vertices at once with scipy's Qhull and merges
its tetrahedra with an exact integer in-sphere test across shared faces (no
clusters, no leaf tables, no circumcenters): the cells of the global mode must be
its cells, as sets of vertex sets.
"""

from __future__ import annotations

import json
from fractions import Fraction

import numpy as np
import pytest
import vtk
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cospherical.cli import main
from cospherical.core.configuration import Box
from cospherical.mesh.assembly import assemble
from cospherical.mesh.checks import check_circumcenters, check_conformity, check_delaunay, check_volume
from cospherical.mesh.delaunay import global_delaunay
from cospherical.mesh.octree import build_octree, parse_shape
from oracle import oracle_cells
from vtk.util.numpy_support import vtk_to_numpy


def mesh_cells(mesh) -> set[frozenset[int]]:
    conn, sizes = mesh.connectivity()
    return {frozenset(row[:n].tolist()) for row, n in zip(conn, sizes)}


def whole(mesh) -> dict:
    found = {**check_volume(mesh).figures(), **check_conformity(mesh).figures(), **check_delaunay(mesh).figures()}
    return {k: found[k] for k in ("volume_ok", "nonconforming_faces", "delaunay_violations", "delaunay_ties")}


WHOLE = {"volume_ok": True, "nonconforming_faces": 0, "delaunay_violations": 0, "delaunay_ties": 0}

CASES = [
    (["1", "2", "4"], 4, ["sphere:0.5,1,2,0.6"], "vertex"),
    (["1", "2", "4"], 4, ["plane:1,1,1,3"], "edge"),
    (["1", "2", "4"], 5, ["point:0.3,0.61,0.77"], "vertex"),
    (["1", "1", "4"], 4, ["sphere:0.5,0.5,2,0.4"], "edge"),
    (["1", "1", "4"], 4, ["point:0.2,0.7,3.1"], "vertex"),
    (["1", "sqrt(2)", "sqrt(2)"], 4, ["point:0.3,0.61,0.77"], "vertex"),
    (["1", "sqrt(2)", "sqrt(2)"], 3, ["box:0.1,0.2,0.3,0.4,0.5,0.6"], "edge"),
    (["1", "1", "1"], 4, ["sphere:0.5,0.5,0.5,0.3"], "vertex"),
]


@pytest.mark.oracle_qhull
@pytest.mark.parametrize("domain, levels, shapes, balance", CASES)
def test_global_mode_equals_qhull_merged_exactly(domain, levels, shapes, balance):
    box = Box.parse(domain)
    leaf = assemble(build_octree(box, levels, [parse_shape(s) for s in shapes], balance))
    mesh = global_delaunay(leaf)
    expected = oracle_cells(leaf)
    assert mesh_cells(mesh) == expected
    assert whole(mesh) == WHOLE
    if domain == ["1", "1", "1"]:
        assert mesh is leaf and mesh.cells is None  # cube octrees: already Delaunay, untouched
    elif check_delaunay(leaf).violations:
        assert mesh_cells(leaf) != expected and mesh.cells is not None and mesh.cells.clusters >= 1
    # every leaf element kept is a cell; the replaced leaves hold none of the mesh's leaf elements
    assert mesh_cells(leaf) & expected <= mesh_cells(mesh)
    circumcenters = check_circumcenters(mesh)
    assert circumcenters.elements_not_cospherical == 0


def _box(values):
    return Box.parse([str(Fraction(p, q)) for p, q in values])


@pytest.mark.oracle_qhull
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(st.integers(1, 7), st.integers(1, 5)), min_size=3, max_size=3),
       st.integers(2, 3), st.tuples(*[st.fractions(0, 1, max_denominator=16)] * 3),
       st.sampled_from(["vertex", "edge"]))
def test_random_trees_on_random_rational_boxes(lengths, levels, where, balance):
    box = _box(lengths)
    point = ",".join(str(float(x) * float(length)) for x, length in zip(where, box.lengths))
    leaf = assemble(build_octree(box, levels, [parse_shape(f"point:{point}")], balance))
    mesh = global_delaunay(leaf)
    assert mesh_cells(mesh) == oracle_cells(leaf)
    assert whole(mesh) == WHOLE


@pytest.mark.oracle_vtk
def test_cli_reports_both_modes(capsys, tmp_path):
    argv = ["mesh", "--domain", "1", "2", "4", "--levels", "3", "--refine", "point:0.1,0.1,0.1", "--format", "json",
            "--no-uniform", "--dual"]
    reports = {}
    for mode in ("global", "leaf"):
        assert main(argv + ["--delaunay", mode, "--out", str(tmp_path / mode)]) == 0
        reports[mode] = json.loads(capsys.readouterr().out)
        # VTK reads every cell, polyhedra too, and its own cell volumes fill the 1 x 2 x 4 domain
        reader = vtk.vtkXMLUnstructuredGridReader()
        reader.SetFileName(str(tmp_path / mode / "mesh.vtu"))
        reader.Update()
        sizes = vtk.vtkCellSizeFilter()
        sizes.SetInputData(reader.GetOutput())
        sizes.Update()
        volumes = vtk_to_numpy(sizes.GetOutput().GetCellData().GetArray("Volume"))
        assert len(volumes) == reports[mode]["elements"] and abs(volumes.sum() - 8) < 1e-9 and volumes.min() > 0
    g, leaf = reports["global"], reports["leaf"]
    assert (g["delaunay_mode"], leaf["delaunay_mode"]) == ("global", "leaf")
    assert leaf["delaunay_violations"] > 0 and g["delaunay_violations"] == 0 and g["delaunay_ties"] == 0
    assert g["leaf_mesh"]["delaunay_violations"] == leaf["delaunay_violations"]
    assert g["regions_retessellated"] >= 1 and g["largest_region_vertices"] > 8
    assert leaf["regions_retessellated"] == 0 and leaf["leaf_mesh"] is None
    assert g["volume_ok"] and g["nonconforming_faces"] == 0
    assert g["negative_coefficients"]["interior"] == 0
    for report in (g, leaf):
        assert sum(t["count"] for t in report["type_frequencies"]) == report["elements"]
        assert sum(c["leaves"] for c in report["configuration_frequencies"]) == report["leaves"]
    assert main(argv + ["--criterion", "internal_faces", "--delaunay", "global"]) == 2
    assert "--delaunay leaf" in capsys.readouterr().err


def test_python_integers_give_the_same_cells(monkeypatch):
    # large boxes or weights take the exact merge to Python integers: the same cells
    from functools import partial

    import cospherical.mesh.merged_cells as merged_cells
    import cospherical.mesh.proposal as proposal

    leaf = assemble(build_octree(Box.parse(["1", "2", "4"]), 4, [parse_shape("plane:1,1,1,3")], "edge"))
    fast = mesh_cells(global_delaunay(leaf))
    for module, name in ((proposal, "six_volumes"), (merged_cells, "circumcenters"), (proposal, "sphere_sides")):
        monkeypatch.setattr(module, name, partial(getattr(module, name), python_integers=True))
    assert mesh_cells(global_delaunay(leaf)) == fast


def test_the_final_check_skips_only_what_the_leaf_check_proved():
    # kept leaf elements and proven cells are not tested again: they must be leaf elements that passed,
    # and testing every cell again must find nothing the shorter check missed
    import dataclasses

    leaf = assemble(build_octree(Box.parse(["1", "2", "4"]), 4, [parse_shape("sphere:0.5,1,2,0.6")]))
    found = check_delaunay(leaf)
    mesh = global_delaunay(leaf, found)
    cells = mesh.cells
    conn, sizes = leaf.connectivity()
    failed = {frozenset(conn[e, :sizes[e]].tolist()) for e in found.not_cells}
    proven = {frozenset(row[row >= 0].tolist()) for row in cells.nodes[cells.proven]}
    assert proven and not proven & failed and proven <= mesh_cells(leaf)
    assert not cells.proven.all()
    again = dataclasses.replace(mesh, cells=dataclasses.replace(cells, proven=np.zeros(len(cells), dtype=bool)),
                                _groups=None)
    short, full = check_delaunay(mesh), check_delaunay(again)
    assert (full.violations, full.ties) == (short.violations, short.ties) == (0, 0)


def _count_exact(monkeypatch) -> list:
    """Record the clusters the exact engine tetrahedralises (their vertex counts)."""
    import cospherical.mesh.proposal as proposal

    calls: list = []
    engine = proposal.delaunay_tetrahedra
    monkeypatch.setattr(proposal, "delaunay_tetrahedra", lambda coords, weights: calls.append(len(coords))
                        or engine(coords, weights))
    return calls


@pytest.mark.parametrize("domain, levels, shapes, balance", [CASES[0], CASES[4],
                                                            (["1", "sqrt(2)", "3"], 4, ["point:0.3,0.61,0.77"], "vertex")])
def test_exact_engine_gives_the_qhull_paths_cells(domain, levels, shapes, balance, monkeypatch):
    leaf = assemble(build_octree(Box.parse(domain), levels, [parse_shape(s) for s in shapes], balance))
    calls = _count_exact(monkeypatch)
    proposed = mesh_cells(global_delaunay(leaf))
    assert calls == []  # ordinary boxes: Qhull's proposal passes the exact check, no fallback
    exact = global_delaunay(leaf, engine="exact")
    assert calls and mesh_cells(exact) == proposed and whole(exact) == WHOLE
    with pytest.raises(ValueError, match="engine"):
        global_delaunay(leaf, engine="cgal")


@pytest.mark.parametrize("domain, shape", [(["1e-12", "1", "3e9"], "point:0,0.3,1e9"),
                                           (["sqrt(2)", "1e-12", "1"], "point:0.5,0,0.7")])
def test_extreme_boxes_mesh_exactly(domain, shape, monkeypatch, capsys, tmp_path):
    # Qhull's float triangulation fails on these clusters; the exact engine takes them; the dual's
    # numbers pass float's range and the picture's section is one pixel wide: every output is written
    calls = _count_exact(monkeypatch)
    argv = ["mesh", "--domain", *domain, "--levels", "4", "--refine", shape, "--format", "json", "--no-uniform",
            "--dual", "--out", str(tmp_path)]
    assert main(argv) == 0
    report = json.loads(capsys.readouterr().out)
    assert {"dual.npz", "mesh.png", "mesh.vtu", "report.json"} <= {p.name for p in tmp_path.iterdir()}
    assert report["negative_coefficients"]["interior"] == 0
    assert calls and report["regions_retessellated"] >= 1 and report["leaf_mesh"]["delaunay_violations"] > 0
    assert {k: report[k] for k in WHOLE} == WHOLE and report["elements"] > report["leaves"]


@pytest.mark.oracle_qhull
@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(st.integers(1, 9), st.integers(1, 9)), min_size=3, max_size=3), st.booleans(),
       st.tuples(*[st.fractions(0, 1, max_denominator=8)] * 3))
def test_exact_engine_on_random_trees_and_boxes(lengths, root, where):
    # rational boxes, or the first length a square root (the sqrt(2) family of the paper's case C)
    box = _box(lengths)
    if root:
        box = Box.parse([f"sqrt({Fraction(*lengths[0])})", *[str(Fraction(p, q)) for p, q in lengths[1:]]])
    point = ",".join(str(float(x) * float(length)) for x, length in zip(where, box.lengths))
    leaf = assemble(build_octree(box, 3, [parse_shape(f"point:{point}")], "vertex"))
    mesh = global_delaunay(leaf, engine="exact")
    assert mesh_cells(mesh) == oracle_cells(leaf)
    assert whole(mesh) == WHOLE


def test_a_wrong_float_proposal_is_caught(monkeypatch):
    # Qhull on points stretched 5x along z: a valid tiling, but not the Delaunay one of the true box
    import scipy.spatial

    leaf = assemble(build_octree(Box.parse(["1", "1", "4"]), 4, [parse_shape("point:0.2,0.7,3.1")], "vertex"))
    expected = mesh_cells(global_delaunay(leaf))
    qhull = scipy.spatial.Delaunay
    monkeypatch.setattr(scipy.spatial, "Delaunay", lambda points, **options: qhull(points * [1, 1, 5], **options))
    calls = _count_exact(monkeypatch)
    assert mesh_cells(global_delaunay(leaf)) == expected and calls


@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.integers(-12, 12), min_size=3, max_size=3), st.tuples(*[st.fractions(0, 1, max_denominator=8)] * 3))
def test_random_extreme_boxes_mesh_exactly(exponents, where):
    # aspect ratios up to 1e24, where Qhull's floats fail: the exact checks alone decide (Qhull is no oracle here)
    box = Box.parse([f"1e{k}" for k in exponents])
    point = ",".join(str(float(x) * float(length)) for x, length in zip(where, box.lengths))
    leaf = assemble(build_octree(box, 3, [parse_shape(f"point:{point}")], "vertex"))
    assert whole(global_delaunay(leaf)) == WHOLE


def _tampered(change):
    """A proposal: Qhull's triangulation with its simplices changed by ``change(qhull)`` (a row mask and extra
    rows); the faces next to a dropped or added simplex lose their neighbour, so the local check sees nothing."""
    from types import SimpleNamespace

    from scipy.spatial import Delaunay

    def proposal(points):
        qhull = Delaunay(points, qhull_options="Qbb Qc Qz Q12 Qt")
        keep, extra = change(qhull)
        renumber = np.where(keep, np.cumsum(keep) - 1, -1)
        neighbors = np.where(qhull.neighbors >= 0, renumber[qhull.neighbors], -1)[keep]
        return SimpleNamespace(simplices=np.r_[qhull.simplices[keep], extra],
                               neighbors=np.r_[neighbors, np.full((len(extra), 4), -1)], coplanar=qhull.coplanar)
    return proposal


def _missing(qhull):
    return np.arange(len(qhull.simplices)) % 3 != 0, np.zeros((0, 4), dtype=np.int64)


def _overlapping(qhull):
    # Qhull's tetrahedra and, per pair on a face, one of the other split of their five points: it overlaps both
    # and has no neighbour (its sphere holds a point unless the five are co-spherical)
    simplices = qhull.simplices
    pair = np.flatnonzero(qhull.neighbors[:, 0] >= 0)
    neighbour = qhull.neighbors[pair, 0]
    far = simplices[neighbour, np.argmax(qhull.neighbors[neighbour] == pair[:, None], axis=1)]
    return np.ones(len(simplices), dtype=bool), np.c_[simplices[pair, 0], far, simplices[pair, 1:3]]


@pytest.mark.oracle_qhull
@pytest.mark.parametrize("change", [_missing, _overlapping])
def test_a_wrong_proposal_the_local_check_passes_is_redone_exactly(change, monkeypatch):
    leaf = assemble(build_octree(Box.parse(["1", "1", "4"]), 4, [parse_shape("point:0.2,0.7,3.1")], "vertex"))
    calls = _count_exact(monkeypatch)
    mesh = global_delaunay(leaf, proposal=_tampered(change))
    assert calls  # the proof failed on the proposal's cells: the exact engine redid those clusters
    assert mesh_cells(mesh) == oracle_cells(leaf)
    assert whole(mesh) == WHOLE


@pytest.mark.oracle_qhull
def test_a_table_element_that_is_not_cospherical_is_replaced_by_delaunay_cells():
    # A pattern table may hold an element that is no Delaunay element at all (here a whole
    # leaf with its edge and face points as one element): it has no sphere to test, so it
    # must count among the elements that are not cells, and the global mode replaces it.
    tree = build_octree(Box.parse(["1", "1", "1"]), 2, [parse_shape("point:0.1,0.1,0.1")])
    plain = assemble(tree)
    some_type = next(iter(plain.types))
    replaced = []

    def lookup(configuration):
        nodes = sorted(configuration.nodes())
        if len(nodes) > 8 and not replaced:
            replaced.append(configuration.code)
            return [{"type": some_type, "nodes": nodes}]
        return None

    mesh = assemble(tree, lookup)
    assert replaced and check_circumcenters(mesh).elements_not_cospherical == 1
    found = check_delaunay(mesh)
    assert len(found.not_cells) == 1
    result = global_delaunay(mesh, found)
    assert check_circumcenters(result).elements_not_cospherical == 0
    assert whole(result) == WHOLE
    assert mesh_cells(result) == oracle_cells(result)


@pytest.mark.oracle_qhull
def test_only_a_wrong_proposals_own_failure_sends_every_cluster_to_the_exact_engine(monkeypatch):
    # Tetrahedra of one centre that are not one cell (NotOneCell) are a proposal's fault: every cluster is
    # redone exactly.  Any other error on the way is a bug and must surface, not be taken for that one.
    import cospherical.mesh.merged_cells as merged_cells

    leaf = assemble(build_octree(Box.parse(["1", "1", "4"]), 4, [parse_shape("point:0.2,0.7,3.1")], "vertex"))
    shape = merged_cells.cell_shape
    for error, raised in ((merged_cells.NotOneCell, None), (ValueError, ValueError), (KeyError, KeyError)):
        failed: list = []

        def once(*args, error=error, failed=failed):
            if not failed:
                failed.append(True)
                raise error("planted")
            return shape(*args)
        monkeypatch.setattr(merged_cells, "cell_shape", once)
        calls = _count_exact(monkeypatch)
        if raised is None:
            mesh = global_delaunay(leaf)
            assert calls and mesh_cells(mesh) == oracle_cells(leaf)
        else:
            with pytest.raises(raised, match="planted"):
                global_delaunay(leaf)
        monkeypatch.undo()


def test_a_kept_element_found_again_is_a_bug_not_a_cluster(monkeypatch):
    # the final check tests only the fresh cells: a kept leaf element among its findings cannot be
    # attributed to a cluster (it was once read through a negative index), so it stops the run
    import dataclasses

    import cospherical.mesh.delaunay as delaunay

    leaf = assemble(build_octree(Box.parse(["1", "1", "4"]), 4, [parse_shape("point:0.2,0.7,3.1")], "vertex"))
    first = check_delaunay(leaf)
    check = delaunay.check_delaunay

    def planted(mesh, *args, **kwargs):
        found = check(mesh, *args, **kwargs)
        if mesh.cells is not None:
            found = dataclasses.replace(found, not_cells=np.r_[0, found.not_cells])
        return found
    monkeypatch.setattr(delaunay, "check_delaunay", planted)
    with pytest.raises(RuntimeError, match="not a fresh cell"):
        global_delaunay(leaf, first)
