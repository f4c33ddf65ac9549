"""cospherical mesh: octrees, assembly from pattern tables, the exact whole-mesh checks, outputs and refusals."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cospherical.cli import main
from cospherical.core.configuration import Box, Configuration
from cospherical.core.tessellation import tessellate
from cospherical.files.yamlio import atomic_write, yaml_text
from cospherical.formats.mesh import read_leaves, table_lookup
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
    found = {**check_volume(mesh), **check_conformity(mesh), **check_circumcenters(mesh), **check_delaunay(mesh)}
    found.pop("_leaves")
    found.pop("_elements")
    found.pop("_not_cells")
    return found


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
    return {p.code.split("+")[0] for p in mesh.patterns}


def test_one_leaf():
    mesh = assemble(build_octree(CUBE, 0, []))
    assert (len(mesh.tree), len(mesh.vertices), len(mesh)) == (1, 8, 1)
    assert mesh.patterns[0].code == "000000000000+f"
    found = checks(mesh)
    assert found["volume_ok"] and found["nonconforming_faces"] == 0 and found["boundary_faces"] == 6
    assert found["delaunay_violations"] == 0 and found["leaves_not_fvm_adequate"] == 0


def test_one_refined_octant_by_hand():
    mesh = assemble(octant_tree())
    # 27 points of the level-1 grid, and the octant's own 27 points of which its 8 corners are shared
    assert (len(mesh.tree), len(mesh.vertices)) == (15, 46)
    codes = sorted(p.code for p in mesh.patterns)
    # the three face neighbours see a face point and four edge points, the three edge neighbours one edge point,
    # the corner neighbour and the small leaves nothing
    assert "000000000000+f" in codes and len(codes) == 1 + 3 + 3
    face_leaf = [p for p in mesh.patterns if "+f" in p.code and p.code.endswith(tuple("012345"))]
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
    assert not any(p.on_the_fly for p in mesh.patterns) and all(p.on_the_fly for p in fly.patterns)
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
    assert sum(p.on_the_fly for p in mesh.patterns) == len(fly.patterns) - 2


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


def test_global_delaunay_equals_brute_force_on_a_brick():
    """The 1x2x4 octree is not globally Delaunay; the exact check agrees with brute force over all vertices."""
    mesh = assemble(build_octree(BRICK, 4, [parse_shape("sphere:0.5,1,2,0.6")]))
    found = check_delaunay(mesh)
    conn, sizes = mesh.connectivity()
    points = mesh.vertices * (np.array(BRICK.to_float()) / mesh.grid)
    pairs = elements = 0
    for e in range(len(mesh)):
        nodes = conn[e, :sizes[e]]
        x = points[nodes]
        centre = np.linalg.lstsq(2 * (x[1:] - x[0]), (x[1:] ** 2).sum(1) - (x[0] ** 2).sum(), rcond=None)[0]
        d2 = ((points - centre) ** 2).sum(1)
        d2[nodes] = np.inf
        inside = int((d2 < ((x[0] - centre) ** 2).sum() * (1 - 1e-9)).sum())
        pairs, elements = pairs + inside, elements + (inside > 0)
    assert (found["delaunay_violating_pairs"], found["delaunay_violations"]) == (pairs, elements)
    assert found["delaunay_violations"] > 0
    assert check_circumcenters(mesh)["leaves_not_fvm_adequate"] > 0


def test_cli_report_and_outputs(tmp_path, capsys):
    leaves = tmp_path / "leaves.json"
    leaves.write_text(json.dumps({"leaves": [list(leaf) for leaf in OCTANT]}))
    assert main(["mesh", "--domain", "1", "1", "1", "--leaves", str(leaves), "--out", str(tmp_path / "out"),
                 "--format", "json", "--no-uniform"]) == 0
    report = json.loads(capsys.readouterr().out)
    for key in ("leaves", "vertices", "elements", "types", "volume_ok", "nonconforming_faces",
                "leaves_not_fvm_adequate", "delaunay_violations", "configurations", "tessellated_on_the_fly"):
        assert key in report
    assert (report["leaves"], report["vertices"], report["configurations"], report["tessellated_on_the_fly"]) == \
        (15, 46, 7, 7)
    assert json.loads((tmp_path / "out" / "report.json").read_text()) == report
    assert (tmp_path / "out" / "mesh.png").stat().st_size > 1000
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [".cospherical-manifest.json", "mesh.png", "mesh.vtu",
                                                                    "report.json"]


def test_text_leaf_list(tmp_path):
    path = tmp_path / "leaves.txt"
    path.write_text("# octant\n" + "\n".join(" ".join(map(str, leaf)) for leaf in OCTANT) + "\n")
    levels, positions = read_leaves(path)
    assert len(levels) == 15 and positions.shape == (15, 3)


UNBALANCED = [(1, i, j, k) for i in (0, 1) for j in (0, 1) for k in (0, 1) if (i, j, k) != (0, 0, 0)] + \
             [(2, i, j, k) for i in (0, 1) for j in (0, 1) for k in (0, 1) if (i, j, k) != (1, 1, 1)] + \
             [(3, 2 + i, 2 + j, 2 + k) for i in (0, 1) for j in (0, 1) for k in (0, 1)]


@pytest.mark.parametrize("argv, needle", [
    (["--levels", "3", "--refine", "cone:1,2"], "unknown kind 'cone'"),
    (["--levels", "3", "--refine", "sphere:0.5,0.5,0.5"], "sphere needs 4 numbers"),
    (["--levels", "3", "--refine", "sphere:0.5,0.5,0.5,-1"], "radius must be positive"),
    (["--levels", "3", "--refine", "box:1,0,0,0,1,1"], "X0 <= X1"),
    (["--levels", "3", "--refine", "point:a,0,0"], "point:a,0,0"),
    (["--levels", "17", "--refine", "point:0,0,0"], "--levels '17'"),
    (["--levels", "x", "--refine", "point:0,0,0"], "--levels 'x'"),
    (["--refine", "point:0,0,0"], "needs --levels"),
    (["--levels", "2", "--refine", "point:0,0,0", "--balance", "face"], "invalid choice: 'face'"),
    (["--leaves", "{tmp}/overlap.txt"], "leaf 1 repeats leaf 0"),
    (["--leaves", "{tmp}/gap.txt"], "no leaf covers the cell at level 1, position 1 1 1"),
    (["--leaves", "{tmp}/unbalanced.txt"], "leaf 0 (level 1, position 0 0 1) touches leaves of level 3"),
    (["--leaves", "{tmp}/outside.txt"], "leaf 0: position 2 0 0 is outside the domain"),
    (["--leaves", "{tmp}/garbage.txt"], "line 2: 'one two' is not 'level i j k'"),
    (["--leaves", "{tmp}/missing.txt"], "cannot read"),
    (["--leaves", "{tmp}/missing.txt", "--cut", "2"], "--cut 2: must be a fraction"),
    (["--levels", "2", "--refine", "point:0,0,0", "--cut", "1/2"], "only --out DIR without --partitions draws"),
])
def test_bad_input_is_refused_with_one_line(tmp_path, capsys, argv, needle):
    (tmp_path / "overlap.txt").write_text("0 0 0 0\n0 0 0 0\n")
    (tmp_path / "gap.txt").write_text("\n".join(" ".join(map(str, leaf)) for leaf in OCTANT[:6] + OCTANT[7:]))
    (tmp_path / "unbalanced.txt").write_text("\n".join(" ".join(map(str, leaf)) for leaf in UNBALANCED))
    (tmp_path / "outside.txt").write_text("1 2 0 0\n")
    (tmp_path / "garbage.txt").write_text("0 0 0 0\none two\n")
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    assert main(["mesh", "--domain", "1", "1", "1", *argv]) == 2
    err = capsys.readouterr().err
    assert needle in err and err.count("\n") == 1, err


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


def test_vertex_balance_is_never_coarser_than_edge_balance():
    shapes = [parse_shape("point:0.3,0.61,0.77")]
    assert len(build_octree(CUBE, 6, shapes, "vertex")) >= len(build_octree(CUBE, 6, shapes, "edge"))


@pytest.fixture(scope="module")
def representatives_store(tmp_path_factory):
    """The R = 2 intersection store: one configuration per orbit of the cube's 48 symmetries."""
    from cospherical.catalogue import shipped_catalogue
    from cospherical.formats.intersection_table import write_pattern_table
    from cospherical.studies.intersection.table import TableRun
    from cospherical.studies.intersection import run_intersection

    path = tmp_path_factory.mktemp("store") / "intersection-r2.sqlite"
    write_pattern_table(TableRun(run_intersection(2, jobs=1), jobs=1), shipped_catalogue()["version"], store=path)
    return path


def element_sets(mesh):
    conn, sizes = mesh.connectivity()
    ids, types = mesh.element_types()
    return sorted((ids[types[e]], tuple(sorted(conn[e, :sizes[e]].tolist()))) for e in range(len(mesh)))


def test_a_table_of_orbit_representatives_serves_every_configuration_of_an_orbit(representatives_store, tmp_path):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    from cospherical.formats.mesh import write_vtu

    table = load(representatives_store)
    tree = build_octree(CUBE, 3, [parse_shape("plane:1,2,3,2")])  # standard cells and polyhedra
    mesh = assemble(tree, table_lookup(table, "optimal", CUBE))
    mapped = [p for p in mesh.patterns if p.mapped_from is not None]
    assert mapped and not any(p.on_the_fly for p in mesh.patterns)
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


@pytest.mark.parametrize("pieces", [None, "2"])
def test_leaf_cell_data_numbers_the_leaves_as_the_leaves_file_lists_them(tmp_path, pieces):
    """With --leaves, each cell's ``leaf`` is a line of the file, and the cell lies inside that line's leaf."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    tree = build_octree(Box.parse(["1", "1", "1"]), 2, [parse_shape("point:0.3,0.6,0.2")])
    listed = np.random.default_rng(5).permutation(len(tree))  # the file's order is not the tree's
    rows = np.column_stack([tree.levels, tree.positions])[listed]
    path = tmp_path / "leaves.txt"
    path.write_text("".join(" ".join(map(str, row)) + "\n" for row in rows.tolist()))
    argv = ["mesh", "--domain", "1", "1", "1", "--leaves", str(path), "--delaunay", "leaf", "--no-uniform",
            "--out", str(tmp_path / "out"), "--format", "json"]
    assert main(argv + (["--partitions", pieces, "--jobs", "1"] if pieces else [])) == 0
    reader = vtk.vtkXMLPUnstructuredGridReader() if pieces else vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(tmp_path / "out" / ("mesh.pvtu" if pieces else "mesh.vtu")))
    reader.Update()
    grid = reader.GetOutput()
    leaf = vtk_to_numpy(grid.GetCellData().GetArray("leaf"))
    points = vtk_to_numpy(grid.GetPoints().GetData())
    assert sorted(set(leaf.tolist())) == list(range(len(tree)))  # every line of the file, by its index
    size = 0.5 ** rows[:, 0]
    for c in range(grid.GetNumberOfCells()):
        ids = [grid.GetCell(c).GetPointId(k) for k in range(grid.GetCell(c).GetNumberOfPoints())]
        low = rows[leaf[c], 1:] * size[leaf[c]]
        assert np.all(points[ids] >= low - 1e-12) and np.all(points[ids] <= low + size[leaf[c]] + 1e-12)
