"""``mesh --partitions N``: the pieces, read back by VTK's parallel reader and joined by global id, are the
mesh of one process element for element; the outputs land whole or not at all; bad input is one line."""

from __future__ import annotations

import json
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import vtk
from vtk.util.numpy_support import vtk_to_numpy

from cospherical.cli import main
from cospherical.core.configuration import Box
from cospherical.formats.mesh import table_lookup
from cospherical.formats.patterns import load
from cospherical.mesh.assembly import assemble
from cospherical.mesh.delaunay import _clusters, delaunay_mesh
from cospherical.mesh.octree import build_octree, parse_shape
from cospherical.mesh.partition import morton_pieces
from tests.test_outputs import _descendants

ROOT = Path(__file__).resolve().parents[2]
# A cube sphere tree (every element from the leaf table, no cluster to re-tessellate) and a 1 x 2 x 4 tree
# whose leaf mesh is not Delaunay: its one re-tessellated cluster lies across the pieces' seams.
SPHERE = ("--domain", "1", "1", "1", "--levels", "4", "--refine", "sphere:0.5,0.5,0.5,0.3",
          "--patterns", str(ROOT / "patterns" / "leaves-1x1x1.yaml"))
BRICK = ("--domain", "1", "2", "4", "--levels", "4", "--refine", "point:0.1,0.1,2")
# leaves whose spheres the tree's structure bounds, beside a cluster re-tessellated in one piece of four: the
# pieces left as they were must not add their leaf mesh's spheres to the report's count
TALL = ("--domain", "1", "1", "3", "--levels", "3", "--refine", "point:0.3,0.6,1.1")


def single_mesh(argv: tuple) -> object:
    """The mesh of one process, as the command makes it (global Delaunay mode)."""
    box = Box.parse(argv[1:4])
    tree = build_octree(box, int(argv[5]), [parse_shape(argv[7])])
    lookup = table_lookup(load(argv[9]), "optimal", box) if len(argv) > 8 else None
    return delaunay_mesh(assemble(tree, lookup), "global")[0]


def single_cells(mesh) -> list[tuple]:
    """Each element as (its vertices' grid points, sorted; its type id's hash), sorted."""
    ids, element_type = mesh.element_types()
    conn, sizes = mesh.connectivity()
    cells = []
    for row, size, kind in zip(conn, sizes, element_type):
        points = sorted(tuple(int(x) for x in mesh.vertices[v]) for v in row[:size])
        cells.append((tuple(points), int(ids[kind].rsplit("-", 1)[1], 16)))
    return sorted(cells)


def pieces_read_by_vtk(folder: Path) -> tuple[list[tuple], dict]:
    """The .pvtu read by VTK's parallel reader (ParaView's): cells joined through global_id, sorted as above."""
    reader = vtk.vtkXMLPUnstructuredGridReader()
    reader.SetFileName(str(folder / "mesh.pvtu"))
    reader.Update()
    grid = reader.GetOutput()
    global_id = vtk_to_numpy(grid.GetPointData().GetArray("global_id"))
    grid_points = vtk_to_numpy(grid.GetPointData().GetArray("grid_coordinates"))
    type_hash = vtk_to_numpy(grid.GetCellData().GetArray("type_hash"))
    point_of = {}
    for gid, point in zip(global_id.tolist(), grid_points.tolist()):
        assert point_of.setdefault(gid, tuple(point)) == tuple(point), "one global id, two grid points"
    cells = []
    for c in range(grid.GetNumberOfCells()):
        ids = vtk.vtkIdList()
        grid.GetCellPoints(c, ids)
        points = sorted(tuple(grid_points[ids.GetId(i)]) for i in range(ids.GetNumberOfIds()))
        cells.append((tuple(tuple(int(x) for x in p) for p in points), int(type_hash[c])))
    return sorted(cells), point_of


def run_pieces(argv: tuple, out: Path, *more: str) -> dict:
    assert main(["mesh", *argv, "--no-uniform", "--format", "json", "--out", str(out), *more]) == 0
    return json.loads((out / "report.json").read_text())


@pytest.fixture(scope="module")
def brick():
    mesh = single_mesh(BRICK)
    return mesh, single_cells(mesh)


@pytest.mark.oracle_vtk
@pytest.mark.parametrize("argv, pieces", [(SPHERE, 2), (SPHERE, 4), (BRICK, 2), (BRICK, 4), (TALL, 4)])
def test_the_pieces_are_the_mesh_of_one_process(argv, pieces, tmp_path, capsys):
    mesh = single_mesh(argv)
    report = run_pieces(argv, tmp_path, "--partitions", str(pieces), "--jobs", "2")
    capsys.readouterr()
    assert main(["mesh", *argv, "--no-uniform", "--format", "json"]) == 0
    assert report == json.loads(capsys.readouterr().out)  # every figure, the seams' faces and spheres included
    cells, point_of = pieces_read_by_vtk(tmp_path)
    assert cells == single_cells(mesh)
    # a vertex's global id is its index in the mesh of one process, in every piece that holds it
    assert point_of == {v: tuple(int(x) for x in mesh.vertices[v]) for v in point_of}
    assert len(point_of) == len(mesh.vertices)
    assert sorted(p.name for p in tmp_path.glob("mesh*")) == sorted(["mesh.pvtu"] + [f"mesh-{k}.vtu" for k in range(pieces)])
    assert report["nonconforming_faces"] == 0 and report["delaunay_violations"] == 0 and report["volume_ok"]


def test_the_brick_cluster_crosses_the_seams(brick):
    """The test above is meant to see re-tessellated cells whose cluster lies in several pieces."""
    mesh, _ = brick
    assert mesh.cells is not None and len(mesh.cells)
    fresh = ~mesh.cells.proven  # the re-tessellated cells, in parts through shared vertices
    cluster, count = _clusters(mesh.cells.nodes[fresh], len(mesh.vertices))
    first = mesh.cells.leaf[fresh]
    assert count >= 1
    for pieces in (2, 4):
        piece_of = np.empty(len(mesh.tree), dtype=np.int64)
        for k, leaves in enumerate(morton_pieces(mesh.tree, pieces)):
            piece_of[leaves] = k
        assert any(len(np.unique(piece_of[first[cluster == r]])) > 1 for r in range(count)), pieces


def test_same_input_same_bytes(tmp_path, capsys):
    for run in ("a", "b"):
        run_pieces(BRICK, tmp_path / run, "--partitions", "2", "--jobs", "1")
    names = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert names == sorted(p.name for p in (tmp_path / "b").iterdir())
    assert all((tmp_path / "a" / n).read_bytes() == (tmp_path / "b" / n).read_bytes() for n in names)


@pytest.mark.oracle_vtk
def test_on_a_local_dask_cluster(brick, tmp_path, capsys):
    import socket
    import warnings

    # the scheduler's HTTP port held by someone else (another cluster): dask moves to a free port
    # and warned in four lines on stderr, beside the command's one
    with socket.socket() as held, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            held.bind(("127.0.0.1", 8787))
        except OSError:
            pass  # already held, by another process: the same case
        run_pieces(BRICK, tmp_path, "--partitions", "2", "--dask-workers", "2")
    assert not [w for w in caught if "already in use" in str(w.message)], [str(w.message) for w in caught]
    assert pieces_read_by_vtk(tmp_path)[0] == brick[1]


def _limited(limit: int):
    def start() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return start


def test_a_full_disk_leaves_no_piece(tmp_path):
    """A piece that cannot be written (the kernel refuses its bytes): no mesh-*.vtu, no .pvtu, the old files kept."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "mesh.pvtu").write_text("an older run's")
    result = subprocess.run([sys.executable, "-m", "cospherical", "mesh", *BRICK, "--partitions", "2", "--out",
                             str(out)], check=False, capture_output=True, text=True, timeout=300,
                            preexec_fn=_limited(2000))
    assert result.returncode == 2 and len(result.stderr.splitlines()) == 1 and "cannot write" in result.stderr
    assert sorted(p.name for p in out.iterdir()) == ["mesh.pvtu"] and (out / "mesh.pvtu").read_text() == "an older run's"


def _start(out: Path, *more: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "cospherical", "mesh", "--domain", "1", "1", "1", "--levels", "6",
                             "--refine", "sphere:0.5,0.5,0.5,0.3", "--partitions", "2", "--out", str(out), *more],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


def test_a_kill_after_a_piece_is_written_leaves_none_in_place(tmp_path, capsys):
    """SIGKILL once the first piece is written (the pieces one after another): nothing in the folder but the
    run's hidden staging folder, which the next run removes."""
    out = tmp_path / "out"
    process = _start(out, "--jobs", "1")
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and process.poll() is None:
        if list(out.glob(".cospherical-staging.*/mesh-0.vtu")):
            break
        time.sleep(0.02)
    assert process.poll() is None, "the run ended before it was killed"
    process.kill()
    process.communicate(timeout=60)
    assert [p.name for p in out.iterdir() if not p.name.startswith(".cospherical-staging.")] == []
    assert main(["mesh", *BRICK, "--out", str(out), "--partitions", "2", "--jobs", "1"]) == 0
    assert not list(out.glob(".cospherical-staging.*"))


def test_sigterm_stops_the_workers_and_leaves_nothing(tmp_path):
    out = tmp_path / "out"
    process = _start(out)
    deadline = time.monotonic() + 60
    workers: list[int] = []
    while time.monotonic() < deadline and len(workers) < 2 and process.poll() is None:
        workers = _descendants(process.pid)
        time.sleep(0.02)
    # at once: on a quiet machine the run ends about 0.5 s after its workers start, and a SIGTERM that
    # reaches the interpreter's exit (its handlers already put back) kills it without a word
    assert process.poll() is None, "the run ended before it was stopped"
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode != 0 and stderr.strip() == "cospherical: terminated"
    assert not out.exists() or [p.name for p in out.iterdir()] == []
    time.sleep(0.5)
    assert not any(Path(f"/proc/{pid}").exists() and "zombie" not in Path(f"/proc/{pid}/status").read_text()
                   for pid in workers)


@pytest.mark.parametrize("more, needle", [
    (("--partitions", "0"), "--partitions '0': must be an integer from 1 to 4,096"),
    (("--partitions", "99999999999"), "must be an integer from 1 to 4,096"),
    (("--partitions", "1e3"), "must be an integer"),
    (("--partitions", "4096"), "--partitions 4096: from 1 to the tree's 50 leaves"),
    (("--partitions", "2", "--scheduler", "localhost"), "give tcp://HOST:PORT"),
    (("--partitions", "2", "--scheduler", "tcp://127.0.0.1:9", "--scheduler-timeout", "0.5"), "cannot connect"),
    (("--partitions", "2", "--dask-workers", "0"), "--dask-workers 0: must be an integer from 1 to 256"),
    (("--partitions", "2", "--dask-workers", "100000"), "--dask-workers 100000: must be an integer from 1 to 256"),
    (("--partitions", "2", "--jobs", "257"), "--jobs '257': must be an integer from 1 to 256"),
    # dask makes a timedelta of it: inf was a KeyError traceback, 1e308 a connection that never gave up
    (("--partitions", "2", "--scheduler", "tcp://127.0.0.1:9", "--scheduler-timeout", "inf"),
     "--scheduler-timeout inf: must be more than 0 seconds and at most 86,400"),
    (("--partitions", "2", "--scheduler", "tcp://127.0.0.1:9", "--scheduler-timeout", "1e308"),
     "at most 86,400"),
    (("--scheduler", "tcp://127.0.0.1:9"), "--scheduler runs the pieces of --partitions N"),
    (("--partitions", "2", "--dual"), "--dual needs the whole mesh"),
])
def test_bad_partitions_are_one_line(more, needle, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["mesh", *BRICK, "--out", str(out), *more]) == 2
    err = capsys.readouterr().err
    assert needle in err and len(err.splitlines()) == 1, err
    assert not out.exists()


def test_progress_is_told_as_each_piece_finishes():
    # the CLI's bars (cli/mesh.py) draw these: every piece, then the second round of the brick's seams
    from cospherical.mesh.partition import mesh_in_pieces
    from cospherical.mesh.report import TreeSummary

    told = []
    box = Box.parse(BRICK[1:4])
    mesh_in_pieces(build_octree(box, int(BRICK[5]), [parse_shape(BRICK[7])]), 2, None, "optimal", "global",
                   TreeSummary("refine"), None,
                   uniform=False, progress=lambda *call: told.append(call))
    first = [call for call in told if call[0] == "pieces"]
    assert first == [("pieces", 2, 0), ("pieces", 2, 1), ("pieces", 2, 1)]
    again = [call for call in told if call[0] == "again"]
    assert again[0][2] == 0 and len(again) == 1 + again[0][1] >= 2 and told == first + again
