"""Files of ``cospherical mesh``: the leaf list; pattern tables of orbit representatives looked up for every
configuration of an orbit; the mesh VTU read back by VTK (ParaView's reader) and meshio, cell for cell, exact
data alongside, written atomically."""

from __future__ import annotations

import json
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from fractions import Fraction

import numpy as np
import pytest
import vtk
from hypothesis import given, settings
from hypothesis import strategies as st
from vtk.util.numpy_support import vtk_to_numpy

from cospherical.cli import main
from cospherical.core.configuration import Box
from cospherical.formats import vtu
from cospherical.formats.mesh import read_leaves, table_lookup, write_vtu
from cospherical.formats.patterns import load
from cospherical.mesh.assembly import assemble
from cospherical.mesh.octree import build_octree, parse_shape
from tests.formats.test_check import BROKEN, broken_table, leaf_entries, leaf_table
from tests.mesh.test_assembly import OCTANT

CUBE = Box.parse(["1", "1", "1"])
# 253 leaves, 449 elements of six types: two of them have no VTK cell (polyhedra)
MIXED = ("plane:1,2,3,2", 3)


def mixed_mesh(box=CUBE):
    shape, levels = MIXED
    return assemble(build_octree(box, levels, [parse_shape(shape)]))


def read_vtk(path):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def cell_array(grid, name):
    return vtk_to_numpy(grid.GetCellData().GetArray(name))


def field_text(grid, name) -> str:
    return bytes(vtk_to_numpy(grid.GetFieldData().GetArray(name))).decode()


@pytest.mark.oracle_vtk
def test_vtk_reads_the_same_cells_node_orders_and_data(tmp_path):
    mesh = mixed_mesh()
    fvm = np.arange(len(mesh)) % 3 == 0  # any per-element data comes back with its element
    write_vtu(mesh, tmp_path / "mesh.vtu", point_data={"label": np.arange(len(mesh.vertices)) * 7},
              cell_data={"mark": fvm.astype(np.int8)})
    grid = read_vtk(tmp_path / "mesh.vtu")
    assert (grid.GetNumberOfPoints(), grid.GetNumberOfCells()) == (len(mesh.vertices), len(mesh))
    element = cell_array(grid, "element")
    assert sorted(element.tolist()) == list(range(len(mesh)))
    types = vtk_to_numpy(grid.GetCellTypes())
    kinds = set(types.tolist())
    assert {vtk.VTK_TETRA, vtk.VTK_HEXAHEDRON, vtk.VTK_POLYHEDRON} <= kinds
    # the type names come back from the field data, and say which cell each element is
    ids = field_text(grid, "type_ids").split("\n")
    names = field_text(grid, "type_names").split("\n")
    assert len(ids) == len(names) == len(mesh.types)
    expected = {"tetra": vtk.VTK_TETRA, "pyramid": vtk.VTK_PYRAMID, "wedge": vtk.VTK_WEDGE,
                "hexahedron": vtk.VTK_HEXAHEDRON, None: vtk.VTK_POLYHEDRON}
    assert [expected[mesh.types[ids[t]].vtk] for t in cell_array(grid, "type")] == types.tolist()
    conn, sizes = mesh.connectivity()
    stream = vtk.vtkIdList()
    for c in range(len(mesh)):
        e = int(element[c])
        points = vtk.vtkIdList()
        grid.GetCellPoints(c, points)
        assert [points.GetId(i) for i in range(points.GetNumberOfIds())] == conn[e, :sizes[e]].tolist()
        if types[c] == vtk.VTK_POLYHEDRON:  # its faces, counter-clockwise from outside, as the element's
            grid.GetFaceStream(c, stream)
            got = [stream.GetId(i) for i in range(stream.GetNumberOfIds())]
            leaf, local = int(mesh.element_leaf[e]), int(mesh.element_local[e])
            faces = mesh.tessellations[mesh.leaf_tessellation[leaf]].elements[local].faces
            want = [len(faces)] + [x for f in faces for x in (len(f), *mesh.slots[leaf, list(f)].tolist())]
            assert got == want
    assert (cell_array(grid, "leaf") == mesh.element_leaf[element]).all()
    assert (cell_array(grid, "fvm") == mesh.element_fvm()[element]).all()
    assert (cell_array(grid, "mark") == fvm[element]).all()
    assert (vtk_to_numpy(grid.GetPointData().GetArray("label")) == np.arange(len(mesh.vertices)) * 7).all()
    # exact coordinates alongside the floats
    exact = vtk_to_numpy(grid.GetPointData().GetArray("grid_coordinates"))
    assert (exact == mesh.vertices).all()
    intervals = int(vtk_to_numpy(grid.GetFieldData().GetArray("grid_intervals"))[0])
    assert intervals == mesh.grid
    assert [Fraction(s) for s in field_text(grid, "domain_squared").split()] == list(mesh.box.squared)
    points = vtk_to_numpy(grid.GetPoints().GetData())
    assert (points == exact / intervals).all()  # dyadic: the floats are exact too


@pytest.mark.oracle_vtk
def test_vtk_finds_every_cell_valid_and_the_volumes_exact(tmp_path):
    """VTK's own validity test (orientation, convexity, faces) and its cell volumes against the exact ones."""
    mesh = mixed_mesh()
    write_vtu(mesh, tmp_path / "mesh.vtu")
    grid = read_vtk(tmp_path / "mesh.vtu")
    validator = vtk.vtkCellValidator()
    validator.SetInputData(grid)
    validator.Update()
    assert (vtk_to_numpy(validator.GetOutput().GetCellData().GetArray("ValidityState")) == 0).all()
    sizes = vtk.vtkCellSizeFilter()
    sizes.SetInputData(grid)
    sizes.Update()
    volume = vtk_to_numpy(sizes.GetOutput().GetCellData().GetArray("Volume"))
    element = cell_array(grid, "element")
    leaf = mesh.element_leaf[element]
    exact = [float(mesh.tessellations[mesh.leaf_tessellation[i]].elements[j].unit_volume
                   / 8 ** int(mesh.tree.levels[i]))
             for i, j in zip(leaf.tolist(), mesh.element_local[element].tolist())]
    assert np.allclose(volume, exact, rtol=1e-12, atol=0)
    assert abs(volume.sum() - 1) < 1e-12


@pytest.mark.oracle_meshio
def test_meshio_reads_it(tmp_path):
    """meshio reads a grid of standard cells (its VTU reader refuses polyhedra mixed with other cells)."""
    import meshio

    mesh = assemble(build_octree(CUBE, 3, [parse_shape("point:0.3,0.4,0.45")]))
    assert all(info.vtk for info in mesh.types.values())
    write_vtu(mesh, tmp_path / "mesh.vtu")
    back = meshio.read(tmp_path / "mesh.vtu")
    assert (back.points == mesh.vertices / mesh.grid).all()
    element = np.concatenate(back.cell_data["element"])
    assert sorted(element.tolist()) == list(range(len(mesh)))
    assert len(back.cells) == len({info.vtk for info in mesh.types.values()})  # one block per cell type
    conn, _ = mesh.connectivity()
    ids = bytes(back.field_data["type_ids"]).decode().split("\n")
    types = np.concatenate(back.cell_data["type"])
    at = 0
    for block in back.cells:
        rows = element[at:at + len(block.data)]
        assert (block.data == conn[rows, :block.data.shape[1]]).all()
        assert {mesh.types[ids[t]].vtk for t in types[at:at + len(block.data)]} == {block.type}
        at += len(block.data)
    assert (back.point_data["grid_coordinates"] == mesh.vertices).all()


@pytest.mark.oracle_vtk
@settings(max_examples=8, deadline=None)
@given(st.tuples(*[st.integers(1, 15)] * 3), st.integers(1, 3))
def test_the_same_mesh_gives_the_same_bytes_and_vtk_the_whole_volume(tmp_path_factory, point, levels):
    folder = tmp_path_factory.mktemp("vtu")
    shape = parse_shape("point:" + ",".join(f"{x / 16}" for x in point))
    mesh = assemble(build_octree(CUBE, levels, [shape]))
    write_vtu(mesh, folder / "a.vtu")
    write_vtu(assemble(build_octree(CUBE, levels, [shape])), folder / "b.vtu")
    assert (folder / "a.vtu").read_bytes() == (folder / "b.vtu").read_bytes()
    sizes = vtk.vtkCellSizeFilter()
    sizes.SetInputData(read_vtk(folder / "a.vtu"))
    sizes.Update()
    assert abs(vtk_to_numpy(sizes.GetOutput().GetCellData().GetArray("Volume")).sum() - 1) < 1e-12


@pytest.mark.oracle_vtk
def test_blocks_deflated_on_threads_give_one_threads_bytes_and_vtk_reads_them(tmp_path, monkeypatch):
    mesh = mixed_mesh()
    data = {"point_data": {"label": np.arange(len(mesh.vertices)) * 7}, "cell_data": {"mark": np.arange(len(mesh)) % 5}}
    write_vtu(mesh, tmp_path / "whole.vtu", **data)  # one block an array: compressed without threads
    monkeypatch.setattr(vtu, "BLOCK", 256)  # up to 46 blocks an array (VTK's layout lets each be compressed alone)
    with ThreadPoolExecutor(1) as one, ThreadPoolExecutor(4) as four:
        write_vtu(mesh, tmp_path / "one.vtu", pool=one, **data)
        write_vtu(mesh, tmp_path / "four.vtu", pool=four, **data)
    write_vtu(mesh, tmp_path / "own.vtu", **data)  # the writer's own threads
    blocks = (tmp_path / "one.vtu").read_bytes()
    assert blocks == (tmp_path / "four.vtu").read_bytes() == (tmp_path / "own.vtu").read_bytes()
    assert blocks != (tmp_path / "whole.vtu").read_bytes()
    whole, cut = read_vtk(tmp_path / "whole.vtu"), read_vtk(tmp_path / "own.vtu")
    for part in (lambda grid: grid.GetCells().GetConnectivityArray(), lambda grid: grid.GetCells().GetOffsetsArray(),
                 lambda grid: grid.GetCellTypes(), lambda grid: grid.GetPoints().GetData(),
                 lambda grid: grid.GetPolyhedronFaces().GetConnectivityArray(),
                 *(lambda grid, name=name: grid.GetCellData().GetArray(name) for name in ("element", "mark", "leaf")),
                 lambda grid: grid.GetPointData().GetArray("label")):
        assert (vtk_to_numpy(part(cut)) == vtk_to_numpy(part(whole))).all()
    assert (vtk_to_numpy(cut.GetPointData().GetArray("label")) == data["point_data"]["label"]).all()


def test_a_full_disk_leaves_the_old_file(tmp_path):
    """A write that fails part way (a file size limit: the kernel refuses the bytes) leaves the old file, no temporary."""
    path = tmp_path / "mesh.vtu"
    path.write_bytes(b"old")
    program = (
        "import resource, signal, sys\n"
        "from cospherical.core.configuration import Box\n"
        "from cospherical.formats.mesh import write_vtu\n"
        "from cospherical.mesh.assembly import assemble\n"
        "from cospherical.mesh.octree import build_octree, parse_shape\n"
        f"mesh = assemble(build_octree(Box.parse([1, 1, 1]), {MIXED[1]}, [parse_shape({MIXED[0]!r})]))\n"
        "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
        "resource.setrlimit(resource.RLIMIT_FSIZE, (2000, 2000))\n"
        "from cospherical.errors import InputError\n"
        "try:\n"
        f"    write_vtu(mesh, {str(path)!r})\n"
        "except InputError as error:\n"
        "    sys.exit(str(error))\n")
    result = subprocess.run([sys.executable, "-c", program], check=False, capture_output=True, text=True, timeout=120)
    assert result.returncode == 1 and "cannot write" in result.stderr and "Traceback" not in result.stderr
    assert path.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["mesh.vtu"]


def test_text_leaf_list(tmp_path):
    path = tmp_path / "leaves.txt"
    path.write_text("# octant\n" + "\n".join(" ".join(map(str, leaf)) for leaf in OCTANT) + "\n")
    levels, positions = read_leaves(path)
    assert len(levels) == 15 and positions.shape == (15, 3)


@pytest.fixture(scope="module")
def representatives_store(tmp_path_factory):
    """The R = 2 intersection store: one configuration per orbit of the cube's 48 symmetries."""
    from cospherical.catalogue import shipped_catalogue
    from cospherical.formats.intersection_table import write_pattern_table
    from cospherical.studies.intersection.table import TableRun
    from cospherical.studies.intersection import run_intersection

    path = tmp_path_factory.mktemp("store") / "intersection-r2.sqlite"
    write_pattern_table(TableRun(run_intersection(2, jobs=1), jobs=1), shipped_catalogue().version, store=path)
    return path


def element_sets(mesh):
    conn, sizes = mesh.connectivity()
    ids, types = mesh.element_types()
    return sorted((ids[types[e]], tuple(sorted(conn[e, :sizes[e]].tolist()))) for e in range(len(mesh)))


@pytest.mark.oracle_vtk
def test_a_table_of_orbit_representatives_serves_every_configuration_of_an_orbit(representatives_store, tmp_path):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    from cospherical.formats.mesh import write_vtu

    table = load(representatives_store)
    tree = build_octree(CUBE, 3, [parse_shape("plane:1,2,3,2")])  # standard cells and polyhedra
    mesh = assemble(tree, table_lookup(table, "optimal", CUBE))
    mapped = [p for p in mesh.tessellations if p.mapped_from is not None]
    assert mapped and not any(p.on_the_fly for p in mesh.tessellations)
    assert all(p.mapped_from.split("+")[0] in table.configurations for p in mapped)  # the bare code, its policy's
    # element for element what tessellating each configuration gives, and a valid mesh
    assert element_sets(mesh) == element_sets(assemble(tree))
    # a reflection turns a VTK cell inside out unless its nodes are reordered: VTK's own validity test
    write_vtu(mesh, tmp_path / "mesh.vtu")
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(tmp_path / "mesh.vtu"))
    validator = vtk.vtkCellValidator()
    validator.SetInputConnection(reader.GetOutputPort())
    validator.Update()
    assert (vtk_to_numpy(validator.GetOutput().GetCellData().GetArray("ValidityState")) == 0).all()
    # the store's header names functions that exist
    import importlib
    import re

    for name in re.findall(r"cospherical(?:\.\w+)+", table.header["symmetry"]):
        module, _, attribute = name.rpartition(".")
        assert hasattr(importlib.import_module(module), attribute), name


@settings(max_examples=6, deadline=None)
@given(st.tuples(*[st.integers(1, 15)] * 3), st.integers(2, 3))
def test_mapped_configurations_equal_tessellated_ones(representatives_store, point, levels):
    tree = build_octree(CUBE, levels, [parse_shape("point:" + ",".join(f"{x / 16}" for x in point))])
    mesh = assemble(tree, table_lookup(load(representatives_store), "optimal", CUBE))
    assert element_sets(mesh) == element_sets(assemble(tree))


def test_the_report_says_where_each_configuration_came_from(representatives_store, capsys):
    assert main(["mesh", "--domain", "1", "1", "1", "--levels", "3", "--refine", "sphere:0.5,0.5,0.5,0.3",
                 "--patterns", str(representatives_store), "--format", "json", "--no-uniform", "--no-delaunay"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["configurations_mapped"] > 0 and report["tessellated_on_the_fly"] == 0
    assert report["configurations_from_table"] + report["configurations_mapped"] + report["tessellated_on_the_fly"] \
        == report["configurations"]


# 15 leaves: among their configurations the cube's and one edge point's, which the broken tables hold
SMALL_TREE = ("--domain", "1", "1", "1", "--levels", "2", "--refine", "point:0.1,0.1,0.1", "--no-uniform",
              "--no-delaunay")
BROKEN_FOR_THE_MESHER = {**BROKEN, "5,000 copies of the cube": (
    "000000000000+f", lambda e: {**e, "optimal": e["optimal"] * 5000}, "do not fill the box")}


@pytest.mark.parametrize("case", BROKEN_FOR_THE_MESHER)
def test_the_mesher_refuses_a_broken_table_entry_with_checks_line(tmp_path, capsys, case):
    """A table entry the mesh would use is held to check's rules: the same one line, exit 2, and no mesh."""
    code, broken, needle = BROKEN_FOR_THE_MESHER[case]
    path = broken_table(tmp_path / "broken.yaml", code, broken)
    assert main(["check", str(path)]) == 2
    line = capsys.readouterr().err
    assert needle in line and f"configurations/{code}" in line
    # the tree's leaves in one process, the default global mode; or in pieces, each piece's leaves from the table
    how = ["--partitions", "2", "--jobs", "1"] if "turned" in case else ["--delaunay", "leaf"]
    out = tmp_path / "out"
    assert main(["mesh", *SMALL_TREE, *how, "--patterns", str(path), "--out", str(out)]) == 2
    assert capsys.readouterr().err == line
    assert not out.exists() or not any(out.iterdir())


def test_the_mesher_checks_the_elements_of_its_criterion_and_check_all_every_criterion(tmp_path, capsys):
    """An entry's elements under another criterion never reach the mesh: the mesher holds only its own
    criterion's to check's rules (a third fewer elements measured on the leaf table), --check all every one."""
    entries = leaf_entries("000000000000+f", "800000000000+f")
    mirrored = {"type": entries["000000000000+f"]["optimal"][0]["type"], "nodes": [0, 3, 2, 1, 4, 7, 6, 5],
                "circumcenter": [0.5, 0.5, 0.5]}
    entries["000000000000+f"] = {**entries["000000000000+f"], "internal_faces": [mirrored]}  # optimal's intact
    path = leaf_table(tmp_path / "split-broken.yaml", entries)
    assert main(["check", str(path)]) == 2
    line = capsys.readouterr().err
    assert "configurations/000000000000+f/internal_faces/0" in line and "reference order" in line, line
    assert main(["mesh", *SMALL_TREE, "--delaunay", "leaf", "--patterns", str(path), "--format", "json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["configurations_from_table"] == 2 and report["volume_ok"] and report["nonconforming_faces"] == 0
    for more in (["--check", "all"], ["--criterion", "internal_faces"]):
        assert main(["mesh", *SMALL_TREE, "--delaunay", "leaf", "--patterns", str(path), *more]) == 2, more
        assert capsys.readouterr().err == line


def test_the_good_tables_entries_are_used(tmp_path, capsys):
    path = leaf_table(tmp_path / "good.yaml", leaf_entries("000000000000+f", "800000000000+f"))
    assert main(["mesh", *SMALL_TREE, "--delaunay", "leaf", "--patterns", str(path), "--format", "json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["configurations_from_table"] == 2 and report["volume_ok"] and report["nonconforming_faces"] == 0


def test_the_checked_tables_are_the_committed_tables_against_the_shipped_catalogue():
    """CHECKED_TABLES names each committed table by the SHA-256 of its bytes: a table regenerated or edited
    fails here until `cospherical check` passes it and its digest is written there."""
    import hashlib
    from pathlib import Path

    from cospherical.catalogue import shipped_catalogue
    from cospherical.formats.mesh import CHECKED_TABLES

    committed = {hashlib.sha256(path.read_bytes()).hexdigest(): path.name
                 for path in (Path(__file__).parents[2] / "patterns").glob("*.yaml")}
    assert {digest: name for digest, (name, _) in CHECKED_TABLES.items()} == committed, (
        "a committed table changed: run `cospherical check` on it, then write its bytes' SHA-256 (sha256sum) in "
        "cospherical.formats.mesh.CHECKED_TABLES")
    assert {version for _, version in CHECKED_TABLES.values()} == {shipped_catalogue().version}


def test_a_committed_table_read_by_its_sorted_lines_is_the_table_cut_into_entries():
    """Each committed table (the bytes load_table reads by bisection) has the header, the codes in their
    order and the entry texts that cutting its whole section gives, and lacks what that lacks."""
    from pathlib import Path

    from cospherical.formats.mesh import SortedLines, load_table
    from cospherical.formats.patterns import table_from_text

    for path in sorted((Path(__file__).parents[2] / "patterns").glob("*.yaml")):
        fast, _ = load_table(path)
        whole = table_from_text(path.read_text(encoding="utf-8"), str(path))
        assert isinstance(fast.configurations._texts, SortedLines) and fast.header == whole.header
        codes = list(whole.configurations)
        assert list(fast.configurations) == codes and len(fast.configurations) == len(codes)
        fresh, _ = load_table(path)  # looked up before anything iterates it
        for code in codes if path.name == "leaves-1x1x1.yaml" else codes[::7] + codes[-3:]:
            assert fresh.configurations.text(code) == whole.configurations.text(code), (path.name, code)
        assert fresh.elements(codes[-1]) == whole.elements(codes[-1])
        for absent in ("", "0", codes[0] + "0", codes[-1] + "0", codes[len(codes) // 2][:-1], "~", None):
            assert absent not in fresh.configurations and absent not in whole.configurations


def test_a_committed_tables_entries_are_proven_and_a_changed_copys_checked(tmp_path, capsys):
    """The committed leaf table's bytes: its entries are not checked again and the report says why; a copy
    with a comment line first (the same entries) is checked, and --check all checks the committed one."""
    from pathlib import Path

    committed = Path(__file__).parents[2] / "patterns" / "leaves-1x1x1.yaml"
    changed = tmp_path / "leaves-1x1x1.yaml"
    changed.write_bytes(b"# a copy\n" + committed.read_bytes())
    runs = {}
    for name, path, more in (("committed", committed, []), ("changed", changed, []),
                             ("all", committed, ["--check", "all"])):
        assert main(["mesh", *SMALL_TREE, "--patterns", str(path), "--format", "json", *more]) == 0
        runs[name] = json.loads(capsys.readouterr().out)
    proven = runs["committed"]["checks"]
    assert "table_entries" not in proven["run"] and "leaves-1x1x1.yaml (SHA-256 3fc551314021aaea" in \
        proven["not_run"]["table_entries"]
    for name in ("changed", "all"):
        assert runs[name]["checks"]["run"][0] == "table_entries" and "table_entries" not in \
            runs[name]["checks"]["not_run"], name
    # the same mesh either way
    figures = {name: {k: v for k, v in run.items() if k != "checks"} for name, run in runs.items()}
    assert figures["committed"] == figures["changed"] == figures["all"]


def test_a_store_whose_count_is_not_its_entries_is_refused_by_the_mesher(tmp_path, capsys):
    import sqlite3

    from cospherical.formats.sqlite_store import dictionary_of, pack, write_store

    good = load(leaf_table(tmp_path / "good.yaml", leaf_entries("000000000000+f", "800000000000+f")))
    texts = {code: good.configurations.text(code) for code in good.configurations}
    dictionary = dictionary_of(list(texts.values()))
    path = tmp_path / "leaves.sqlite"
    write_store(path, good.header, dictionary, [(code, pack(text, dictionary)) for code, text in sorted(texts.items())])
    assert main(["mesh", *SMALL_TREE, "--delaunay", "leaf", "--patterns", str(path)]) == 0  # the store as written
    capsys.readouterr()
    for count in (1, 3):  # an entry fewer, or one more, than the store holds
        connection = sqlite3.connect(path)
        connection.execute("UPDATE meta SET value = ? WHERE key = 'count'", (str(count),))
        connection.commit()
        connection.close()
        assert main(["check", str(path)]) == 2
        line = capsys.readouterr().err
        assert f"store damaged: 2 entries, but its count says {count}" in line, line
        assert main(["mesh", *SMALL_TREE, "--delaunay", "leaf", "--patterns", str(path)]) == 2
        assert capsys.readouterr().err == line
