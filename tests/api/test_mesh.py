"""The library's one call: ``cospherical.build_mesh`` as the docs write it, its object, and the CLI on top of it."""

from __future__ import annotations

import hashlib
import json

import numpy as np
import pytest

import cospherical
from cospherical.cli import main
from cospherical.errors import InputError
from cospherical.files.yamlio import validate
from cospherical.mesh.report import MeshReport


def _digests(folder) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir())}


def test_the_snippet_runs_as_written():
    m = cospherical.build_mesh(domain=(1, 2, 4), levels=5,
                               refine=["sphere:0.5,1,2,0.3"])
    r = m.report
    assert (r.leaves, r.volume_ok, r.nonconforming_faces, r.delaunay_violations) == (2024, True, 0, 0)
    assert m.vertices.shape == (r.vertices, 3) and m.vertices.dtype == np.float64
    exact = m.exact_vertices
    # the floats are the exact grid points scaled: x = g * a / intervals
    assert np.array_equal(m.vertices, exact.coordinates * (np.array([1.0, 2.0, 4.0]) / exact.intervals))
    assert len(m.elements) == r.elements and len(m.elements.offsets) == r.elements + 1
    assert m.elements.sizes().min() >= 4 and m.elements.connectivity.max() == r.vertices - 1
    assert sorted(m.elements.type_ids) == sorted(t.id for t in r.type_frequencies if t.count)
    # the dual, computed on first use: control volumes tile the domain exactly, a linear function is harmonic
    dual = m.dual
    assert dual.volume_sum() == 1
    K = dual.laplacian()
    interior = ~dual.boundary
    assert np.abs((K @ m.vertices[:, 0])[interior]).max() < 1e-9
    assert m.report.dual is None  # asked for after the build: the report stays as built


def test_report_round_trip_and_schema():
    m = cospherical.build_mesh(domain=(1, 1, 1), levels=2, refine="point:0.1,0.1,0.1", uniform=False, dual=True)
    data = m.report.to_dict()
    validate(data, "mesh-report", "mesh report")
    assert MeshReport.from_dict(data) == m.report
    assert MeshReport.from_dict(json.loads(json.dumps(data))).to_dict() == data
    assert "timings" not in data and {"assembly", "volume", "dual"} <= set(m.report.timings)
    assert m.report.dual.tetrahedral is None  # the outside mesher runs only when asked (tetrahedral_counts)
    data["leaves"] = -1  # a copy: the report does not change
    assert m.report.leaves == 15
    with pytest.raises(AttributeError):
        m.report.leaves = 3  # frozen


@pytest.mark.parametrize("argv, kwargs", [
    (["--domain", "1", "2", "4", "--levels", "3", "--refine", "sphere:0.5,1,2,0.6", "--patterns",
      "patterns/leaves-1x2x4.yaml", "--dual", "--tetrahedral-counts", "--no-uniform"],
     dict(domain=(1, 2, 4), levels=3, refine=["sphere:0.5,1,2,0.6"], patterns="patterns/leaves-1x2x4.yaml",
          dual=True, tetrahedral_counts=True, uniform=False)),
    (["--domain", "1", "1", "1", "--leaves", "examples/leaves.txt", "--delaunay", "leaf", "--no-delaunay"],
     dict(domain=("1", "1", "1"), leaves="examples/leaves.txt", delaunay="leaf", check_delaunay=False)),
])
def test_the_cli_writes_what_write_writes(tmp_path, capsys, argv, kwargs):
    assert main(["mesh", *argv, "--out", str(tmp_path / "cli")]) == 0
    capsys.readouterr()
    cospherical.build_mesh(**kwargs).write(tmp_path / "api")
    cli, api = _digests(tmp_path / "cli"), _digests(tmp_path / "api")
    assert set(cli) == {".cospherical-manifest.json", "mesh.vtu", "report.json", "mesh.png"} | (
        {"dual.npz"} if kwargs.get("dual") else set())
    assert cli == api
    if kwargs.get("tetrahedral_counts"):
        counts = json.loads((tmp_path / "cli" / "report.json").read_text())["dual"]["tetrahedral"]
        assert counts["tool"] == "tetgen" and counts["elements"] > 0


def test_a_leaf_list_in_memory_is_numbered_as_listed():
    rows = [[1, i >> 2, (i >> 1) & 1, i & 1] for i in range(8)][::-1]
    m = cospherical.build_mesh(domain=(1, 1, 1), leaves=rows, uniform=False)
    # every element lies in the leaf its number names
    low = np.array(rows)[m.elements.leaf, 1:] * 0.5
    for e in range(len(m.elements)):
        points = m.vertices[m.elements.nodes(e)]
        assert np.all(points >= low[e] - 1e-12) and np.all(points <= low[e] + 0.5 + 1e-12)
    assert m.report.tree == cospherical.TreeSummary("leaves", depth=1)


@pytest.mark.parametrize("kwargs, needle", [
    (dict(domain=(1, 1, 1), levels=2), "give the tree one way"),
    (dict(domain=(1, 1, 1), refine=["point:0,0,0"]), "refine= needs levels="),
    (dict(domain=(1, 1, 1), levels=2, refine=["point:0,0,0"], leaves=[[0, 0, 0, 0]]), "not refine and leaves"),
    (dict(domain=(1, 0.5, 1), levels=2, refine=["point:0,0,0"]), "not a float"),
    (dict(domain=(1, 1), levels=2, refine=["point:0,0,0"]), "three lengths"),
    (dict(domain=(1, 1, 1), leaves=[[0, 0, 0]]), "rows of four integers"),
    (dict(domain=(1, 1, 1), leaves=[[0, 0.5, 0, 0]]), "rows of four integers"),  # never truncated to 0
    (dict(domain=(1, 1, 1), leaves=[[0, 2**70, 0, 0]]), "rows of four integers"),
    (dict(domain=(1, 1, 1), leaves=[["0", "0", "0", "0"]]), "rows of four integers"),
    (dict(domain=(1, 1, 1), leaves=[[0, 0, 0, 0]] * 3, max_leaves=2), "above the bound of 2"),
    (dict(domain=(1, 1, 1), leaves=iter([[0, 0, 0, 0]])), "not list_iterator"),
    (dict(domain=(1, 1, 1), leaves=[[1, 0, 0, 0]]), "no leaf covers"),
    (dict(domain=(1, 1, 1), levels=1, refine=["point:0,0,0"], criterion="internal_faces", delaunay="global"),
     "use --delaunay leaf"),
    (dict(domain=(1, 1, 1), levels=1, refine=["point:0,0,0"], device="d.yaml"), "not domain="),
    # keywords of a type build_mesh cannot use: one line naming the keyword, never a TypeError from inside
    (dict(domain=5, levels=1, refine=["point:0,0,0"]), "domain=5"),
    (dict(domain=iter([1, 1, 1]), levels=1, refine=["point:0,0,0"]), "domain=<list_iterator"),
    (dict(domain=(1, 1, 1), levels=1, refine=5), "refine=5"),
    (dict(domain=(1, 1, 1), levels=1, refine={"point:0,0,0"}), "refine={"),  # a set: hash order
    (dict(domain=(1, 1, 1), tree=5), "tree=5"),
    (dict(domain=(1, 1, 1), levels=1, refine=["point:0,0,0"], patterns=5), "patterns=5"),
    (dict(domain=(1, 1, 1), levels=1, refine=["point:0,0,0"], criterion="x"), "criterion='x'"),
    (dict(domain=(1, 1, 1), levels=1, refine=["point:0,0,0"], criterion=["optimal"]), "criterion=['optimal']"),
    (dict(domain=(1, 1, 1), levels=1, refine=["point:0,0,0"], delaunay=[]), "delaunay=[]"),
    (dict(domain=(1, 1, 1), levels=1, refine=["point:0,0,0"], dual="no"), "dual='no'"),
    (dict(domain=(1, 1, 1), levels=1, refine=["point:0,0,0"], dual=True, tetrahedral_counts=1),
     "tetrahedral_counts=1"),
    (dict(domain=(1, 1, 1), levels=1, refine=["point:0,0,0"], tetrahedral_counts=True), "give dual=True too"),
    (dict(domain=(1, 1, 1), levels=1, refine=["point:0,0,0"], max_leaves="8"), "max_leaves='8'"),
    (dict(domain=(1, 1, 1), levels=1, refine=["point:0,0,0"], max_leaves=1.5), "max_leaves=1.5"),
    (dict(domain=(1, 1, 1), levels=1, refine=["point:0,0,0"], progress=5), "progress=5"),
    (dict(domain=(1, 1, 1), levels=1, refine=["point:0,0,0"], checks="some"), "checks='some'"),
    (dict(device=5), "device=5"),
    (dict(device=""), "device=''"),
    (dict(device="d.yaml", balance="edge"), "not balance="),  # the file says its balance: was ignored
])
def test_bad_calls_raise_one_input_error(kwargs, needle):
    with pytest.raises(InputError, match=None) as raised:
        cospherical.build_mesh(**kwargs)
    assert needle in str(raised.value) and "\n" not in str(raised.value)


def test_an_error_past_a_device_files_parsing_names_the_file(tmp_path):
    # as its parse errors do: with several device files in a script, the line says which one
    from cospherical.formats.device_file import parse_device, read_device

    path = tmp_path / "stray-contact.yaml"
    path.write_text("device: d\nregions:\n  - {name: si, material: Si, boxes: [[0, 0, 0, 1, 1, 1]]}\n"
                    "contacts:\n  - {name: c, region: si, box: [0, 0, 0.5, 1, 1, 0.5]}\nlevels: 1\n")
    with pytest.raises(InputError, match="^stray-contact.yaml: .*contact 'c'"):
        cospherical.build_mesh(device=path)
    with pytest.raises(InputError, match="^stray-contact.yaml: .*contact 'c'"):  # the CLI's way: read first
        cospherical.build_mesh(device=read_device(path))
    with pytest.raises(InputError, match="^contact 'c'"):  # a Device made in memory has no file to name
        cospherical.build_mesh(device=parse_device(path.read_text()))


def test_a_devices_dual_asked_later_has_its_region_parts():
    """``m.dual`` on first use is the dual ``dual=True`` makes: for a device, split per region and contact too."""
    import dataclasses

    later = cospherical.build_mesh(device="examples/devices/mos-capacitor.yaml", uniform=False)
    now = cospherical.build_mesh(device="examples/devices/mos-capacitor.yaml", uniform=False, dual=True)
    assert later.report.dual is None and later.dual.regions is not None
    for a, b in ((later.dual.regions, now.dual.regions), (later.dual.regions.interfaces, now.dual.regions.interfaces)):
        for item in dataclasses.fields(b):
            ours, theirs = getattr(a, item.name), getattr(b, item.name)
            if item.name != "interfaces":
                assert np.array_equal(ours, theirs) if isinstance(ours, np.ndarray) else ours == theirs, item.name
    for name in ("boundary", "boundary_area_exact", "boundary_edge"):  # the domain's boundary, not the box's
        assert np.array_equal(getattr(later.dual, name), getattr(now.dual, name)), name
    assert later.dual.boundary_area_denominator == now.dual.boundary_area_denominator


def test_the_cli_writes_the_tetrahedra_and_gmsh_file_that_write_writes(tmp_path, capsys):
    """mesh --gmsh 4.1 --gmsh-binary --tets: mesh.msh and tets.vtu in the folder and its manifest, as write() makes
    them; Gmsh reads the device's regions, contacts and interface back by name."""
    import gmsh

    device = "examples/devices/mos-capacitor.yaml"
    assert main(["mesh", "--device", device, "--gmsh", "4.1", "--gmsh-binary", "--tets", "--no-uniform",
                 "--out", str(tmp_path / "cli")]) == 0
    capsys.readouterr()
    mesh = cospherical.build_mesh(device=device, uniform=False)
    mesh.write(tmp_path / "api", gmsh="4.1", binary=True, tets=True)
    cli, api = _digests(tmp_path / "cli"), _digests(tmp_path / "api")
    assert {"mesh.msh", "tets.vtu", ".cospherical-manifest.json"} <= set(cli) and cli == api
    manifest = json.loads((tmp_path / "cli" / ".cospherical-manifest.json").read_text())
    assert {"mesh.msh", "tets.vtu"} <= set(manifest["mesh"])
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(str(tmp_path / "cli" / "mesh.msh"))
        names = {(dim, gmsh.model.getPhysicalName(dim, tag)) for dim, tag in gmsh.model.getPhysicalGroups()}
    finally:
        gmsh.finalize()
    assert names == {(3, "substrate"), (3, "oxide"), (2, "bulk"), (2, "gate"), (2, "substrate|oxide")}
    import meshio  # tets.vtu read by an independent reader: tetrahedra only, positive, each with its parent and region

    back = meshio.read(tmp_path / "cli" / "tets.vtu")
    assert [block.type for block in back.cells] == ["tetra"]
    d = back.points[back.cells[0].data]
    assert (np.einsum("ij,ij->i", d[:, 1] - d[:, 0], np.cross(d[:, 2] - d[:, 0], d[:, 3] - d[:, 0])) > 0).all()
    element, region = back.cell_data["element"][0], back.cell_data["region"][0]
    assert set(np.unique(element)) == set(range(len(mesh.elements)))
    assert set(np.unique(region)) == {0, 1}


@pytest.mark.parametrize("argv, needle", [
    (["--gmsh-binary", "--gmsh", "2.2"], None),
    (["--gmsh-binary"], "give --gmsh VERSION too"),
    (["--gmsh", "3.0"], "invalid choice"),
    (["--tets", "--partitions", "2"], "not with --partitions"),
    (["--tetrahedral-counts"], "give --dual too"),
])
def test_gmsh_and_tets_options_refused_with_one_line(tmp_path, capsys, argv, needle):
    base = ["mesh", "--domain", "1", "1", "1", "--refine", "point:0.5,0.5,0.5", "--levels", "1", "--no-uniform"]
    if needle is None:  # without --out there is nowhere to write mesh.msh
        argv, needle = argv, "with --out"
    else:
        base += ["--out", str(tmp_path / "out")]
    assert main([*base, *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0] and not (tmp_path / "out").exists()


def test_write_refuses_an_empty_folder_and_a_cut_outside_the_domain(tmp_path, monkeypatch):
    # write("") wrote the files into the current folder; a NaN cut was a ValueError from the picture
    mesh = cospherical.build_mesh(domain=(1, 1, 1), levels=0, refine=["point:0,0,0"], uniform=False)
    monkeypatch.chdir(tmp_path)
    for kwargs, needle in ((dict(folder=""), "folder=''"), (dict(folder=None), "folder=None"),
                           (dict(folder="out", cut=float("nan")), "cut=nan"), (dict(folder="out", cut=2), "cut=2"),
                           (dict(folder="out", cut="x"), "cut='x'")):
        with pytest.raises(InputError) as raised:
            mesh.write(**kwargs)
        assert needle in str(raised.value) and "\n" not in str(raised.value)
    assert list(tmp_path.iterdir()) == []


def test_the_report_says_which_checks_ran_and_how():
    """The report's checks: each exact check run; the Delaunay spheres bounded by the tree's structure or,
    with checks="all", every one searched (the same findings); a check not asked for named with its reason."""
    common = dict(domain=(1, 1, 1), levels=2, refine=["sphere:0.5,0.5,0.5,0.3"], uniform=False)
    bounded, searched = (cospherical.build_mesh(**common, checks=c).report.to_dict() for c in ("default", "all"))
    assert bounded["checks"]["run"] == ["volume", "conformity", "circumcenters", "delaunay"]
    assert bounded["checks"]["delaunay_spheres"] == {"bounded_by_the_tree": bounded["elements"]}
    assert searched["checks"]["delaunay_spheres"] == {"bounded_by_the_tree": 0}
    assert {k: v for k, v in bounded.items() if k != "checks"} == {k: v for k, v in searched.items() if k != "checks"}
    skipped = cospherical.build_mesh(**common, check_delaunay=False).report.checks
    assert "delaunay" not in skipped.run and "--no-delaunay" in skipped.not_run["delaunay"]
    validate(bounded, "mesh-report", "report")


def test_writing_tells_progress_file_by_file(tmp_path):
    """The writers' bar (mesh --out on a large tree) advances once per file, to the count of the folder's names."""
    told: list = []
    m = cospherical.build_mesh(domain=(1, 1, 1), levels=1, refine=["point:0.5,0.5,0.5"], uniform=False, dual=True)
    m.write_files(lambda name: tmp_path / name, progress=lambda stage, total, n: told.append((stage, total, n)))
    assert {stage for stage, _, _ in told} == {"outputs"} and sum(n for _, _, n in told) == len(told) == 4
    assert {total for _, total, _ in told} == {4} and sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["mesh.vtu", "report.json", "mesh.png", "dual.npz"])
