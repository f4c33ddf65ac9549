"""``cospherical mesh`` from the command line: its report and outputs, its refusals, the leaf numbers of its cells."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from cospherical.cli import main
from cospherical.core.configuration import Box
from cospherical.mesh.octree import build_octree, parse_shape
from tests.mesh.test_assembly import OCTANT


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
    (["--leaves", "leaves.txt", "--balance", "edge"], "--balance goes with --refine"),  # was ignored
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


@pytest.mark.oracle_vtk
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


def test_a_refine_shape_outside_the_domain_is_one_warning_line(capsys):
    argv = ["mesh", "--domain", "1", "2", "4", "--levels", "2", "--no-uniform", "--refine", "point:0.5,0.5,0.5",
            "--refine", "point:0.5,0.5,4.5", "--refine", "sphere:0.5,1,2,0.1", "--refine", "plane:0,0,1,5\n"]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert err.splitlines() == [  # one line each, the shape's text named as written
        "cospherical: warning: refine shape 'point:0.5,0.5,4.5' does not meet the domain: it refines nothing",
        "cospherical: warning: refine shape 'plane:0,0,1,5\\n' does not meet the domain: it refines nothing"], err


def test_mesh_out_imports_only_what_it_uses(tmp_path):
    # A default `mesh --out` of a cube (its uniform study shipped) with the committed leaf table in a fresh
    # process: what only other options use is not imported; each of these cost a `mesh` run 3-30 ms of its
    # fixed ~0.4 s.
    import subprocess
    import sys

    table = str(Path(__file__).parents[2] / "patterns" / "leaves-1x1x1.yaml")
    script = ("import sys\nfrom cospherical.cli import main\n"
              f"assert main(['mesh', '--domain', '1', '1', '1', '--levels', '2', '--refine', 'point:0.1,0.1,0.1', "
              f"'--patterns', {table!r}, '--out', {str(tmp_path / 'out')!r}]) == 0\n"
              "print(' '.join(sorted(sys.modules)))")
    loaded = set(subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                                check=True).stdout.split("\n")[-2].split())
    assert "cospherical.outputs.mesh_picture" in loaded  # it ran, and drew mesh.png
    unused = {"cospherical.mesh.partition", "cospherical.execution.backends",  # --partitions
              "cospherical.mesh.dual", "cospherical.formats.dual", "cospherical.mesh.regions",  # --dual, --device
              "cospherical.mesh.tetrahedra",  # --gmsh, --tets
              "cospherical.studies.engine",  # the uniform study of a shipped shape is read, not run
              "cospherical.mesh.device",  # --device
              "cospherical.formats.check",  # a committed table's entries are proven by its digest
              "PIL.JpegImagePlugin", "PIL.PngImagePlugin",  # mesh.png encoded by png_bytes, not Pillow's plugins
              "PIL.ImageFile",  # nor their base module (and logging with it): the pixels read by the raw encoder
              "numpy.ma",  # numpy 2.4's unique() without counts or indices imports it to test for a mask
              "scipy"}
    assert not unused & loaded, unused & loaded
