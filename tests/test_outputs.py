"""Outputs and processes under attack: links, a user's files, two runs at once, failed runs, signals.

Every case asserts on the victims: a symbolic link's target keeps its bytes, a
file the user put in an output folder is still there, nothing of a failed run
is left, no worker process outlives the command.
"""

from __future__ import annotations

import errno
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cospherical.cli import main
from cospherical.files.outputs import MANIFEST, OutputFolder
from tests.files.test_outputs import listing, victim

ROOT = Path(__file__).resolve().parents[1]
SUMMARY = ROOT / "results" / "bisection-1x1x1.json"
MESH = ["mesh", "--domain", "1", "1", "1", "--refine", "point:0.5,0.5,0.5", "--levels", "1", "--no-uniform"]


def refused(capsys, *argv, needle: str = "") -> str:
    rc = main([str(a) for a in argv])
    _, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert rc == 2 and len(lines) == 1 and "Traceback" not in err, (rc, err)
    assert needle in lines[0], lines[0]
    return lines[0]


# --- the mechanism itself ----------------------------------------------------------------------------------------


def test_a_link_at_an_output_name_is_refused_and_its_target_untouched(tmp_path, capsys):
    target = victim(tmp_path)
    for name in ("mesh.vtu", "report.json", "mesh.png", MANIFEST):  # the manifest too: it is written last
        out = tmp_path / f"out-{name}"
        out.mkdir()
        (out / name).symlink_to(target)
        start = time.monotonic()
        refused(capsys, *MESH, "--out", out, needle="symbolic link")
        assert time.monotonic() - start < 5  # before the meshing, not after it
        assert target.read_text() == "the user's own file\n" and listing(out) == {name: str(target)}


def test_two_runs_into_one_folder_the_second_is_refused_at_once(tmp_path, capsys):
    out = tmp_path / "out"
    with OutputFolder(out, "mesh"):
        start = time.monotonic()
        refused(capsys, *MESH, "--out", out, needle="another cospherical run")
        refused(capsys, "render", "--summary", SUMMARY, "--out", out, needle="another cospherical run")
        refused(capsys, "study", "bisection", "--out", out, needle="another cospherical run")
        refused(capsys, "sweep", "--ray", "1,2,2", "--out", out, needle="another cospherical run")
        assert time.monotonic() - start < 5
        assert [p.name for p in out.iterdir() if not p.name.startswith(".cospherical-staging.")] == []
    assert main([*MESH, "--out", str(out)]) == 0
    capsys.readouterr()
    assert sorted(listing(out)) == [MANIFEST, "mesh.png", "mesh.vtu", "report.json"]


def test_a_mesh_whose_vtu_cannot_be_written_leaves_no_report(tmp_path, capsys, monkeypatch):
    import cospherical.formats.mesh

    def full_disk(mesh, path, *args, **kwargs):
        Path(path).write_bytes(b"<VTKFile half of it")
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(cospherical.formats.mesh, "write_vtu", full_disk)
    fresh = tmp_path / "fresh"
    refused(capsys, *MESH, "--out", fresh, needle="No space left")
    assert not fresh.exists()
    kept = tmp_path / "kept"
    kept.mkdir()
    (kept / "report.json").write_text("an older run's report")
    refused(capsys, *MESH, "--out", kept, needle="No space left")
    assert listing(kept) == {"report.json": b"an older run's report"}


@pytest.mark.parametrize("limit", [2048, 8192])
def test_a_full_disk_names_the_users_file_not_the_staging_one(tmp_path, limit):
    # a real write failure (a file-size limit: EFBIG, as ENOSPC would be) in whichever output is written
    # first past the limit: the line names that output in the folder the user gave, where it would go
    import resource

    out = tmp_path / "out"

    def limited():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    result = subprocess.run([sys.executable, "-m", "cospherical", *MESH, "--out", str(out)], capture_output=True,
                            text=True, timeout=300, preexec_fn=limited)
    lines = result.stderr.strip().splitlines()
    assert result.returncode == 2 and len(lines) == 1, result.stderr
    assert re.fullmatch(rf"cospherical: error: {re.escape(str(out))}/(mesh\.vtu|report\.json|mesh\.png): "
                        r"cannot write: File too large", lines[0]), lines[0]
    assert not out.exists()  # nothing of the failed run is left


def test_a_forged_manifest_or_a_folder_named_like_staging_loses_no_file_of_the_users(tmp_path, capsys):
    """The manifest is a file anyone may have edited: naming the user's files with their SHA-256 under
    each command never makes ``mesh --out`` or ``render --out`` remove them; nor is a folder of the user's
    removed because its name starts like a staging folder's."""
    import hashlib
    import json

    out = tmp_path / "out"
    out.mkdir()
    files = {"notes.txt": "notes", "thesis.tex": "thesis", "mesh.vtk": "a mesh of mine", "data.json": "{}"}
    for name, text in files.items():
        (out / name).write_text(text)
    for name in (".cospherical-staging.", ".cospherical-staging.mine", ".cospherical-staging.a1b2c3d4"):
        (out / name).mkdir()
        (out / name / "kept.txt").write_text(name)
    forged = {name: hashlib.sha256(text.encode()).hexdigest() for name, text in files.items()}
    for argv in (MESH, ["render", "--summary", str(SUMMARY)]):
        (out / MANIFEST).write_text(json.dumps({"mesh": forged, "render": forged}))
        assert main([*argv, "--out", str(out)]) == 0
        capsys.readouterr()
        assert {name: (out / name).read_text() for name in files} == files
        for name in (".cospherical-staging.", ".cospherical-staging.mine", ".cospherical-staging.a1b2c3d4"):
            assert (out / name / "kept.txt").read_text() == name


# --- render: pdflatex in a private folder, the user's files kept ----------------------------------------------

@pytest.mark.oracle_pdflatex
def test_render_pdf_never_writes_through_links_and_keeps_the_users_files(tmp_path, capsys):
    target = victim(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    for name in ("document.pdf", "document.log"):
        (out / name).symlink_to(target)
        refused(capsys, "render", "--summary", SUMMARY, "--out", out, "--pdf", needle="symbolic link")
        (out / name).unlink()
    (out / "document.aux").symlink_to(target)  # pdflatex's own file: it works elsewhere, and never sees this
    (out / "frequencies-my-notes.tex").write_text("notes")
    (out / "comparison-draft.tex").write_text("draft")
    assert main(["render", "--summary", str(SUMMARY), "--out", str(out), "--pdf"]) == 0
    capsys.readouterr()
    assert target.read_text() == "the user's own file\n" and os.readlink(out / "document.aux") == str(target)
    assert (out / "document.pdf").read_bytes().startswith(b"%PDF") and (out / "document.log").is_file()
    assert b"/CreationDate (D:19700101" in (out / "document.pdf").read_bytes()  # no time stamp: the same bytes
    assert not [p for p in out.iterdir() if p.name.startswith(".cospherical-staging.")]
    # without --pdf, the PDF and log of the earlier render go (the manifest says they are ours), nothing else
    assert main(["render", "--summary", str(ROOT / "results" / "bisection-1x2x4.json"), "--out", str(out)]) == 0
    capsys.readouterr()
    names = set(listing(out))
    assert not names & {"document.pdf", "document.log", "frequencies-bisection-1x1x1-optimal.tex"}
    assert {"frequencies-my-notes.tex", "comparison-draft.tex", "document.aux", "document.tex",
            "frequencies-bisection-1x2x4-optimal.tex"} <= names
    assert (out / "frequencies-my-notes.tex").read_text() == "notes"
    assert target.read_text() == "the user's own file\n"
    # a PDF the manifest does not name (the user's, or an older one changed since) stays, and the run says so
    (out / "document.pdf").write_bytes(b"%PDF the user's")
    assert main(["render", "--summary", str(SUMMARY), "--out", str(out)]) == 0
    assert "document.pdf was kept" in capsys.readouterr().err
    assert (out / "document.pdf").read_bytes() == b"%PDF the user's"


@pytest.mark.parametrize("value", ["NaN", "Infinity", "-Infinity"])
def test_render_refuses_a_summary_with_a_number_that_is_not_finite(tmp_path, capsys, value):
    # (the schema's bounds already refuse a share of +-Infinity; NaN passes every bound)
    text = re.sub(r'"share": [0-9.e-]+', f'"share": {value}', SUMMARY.read_text(), count=1)
    assert value in text
    (tmp_path / "summary.json").write_text(text)
    refused(capsys, "render", "--summary", tmp_path / "summary.json", "--out", tmp_path / "out",
            needle="not a finite number" if value == "NaN" else "share")
    assert not (tmp_path / "out").exists()


# --- processes: closed stdout, Ctrl-C on a Dask cluster -----------------------------------------------------------

def test_a_command_with_stdout_closed_gives_one_line(tmp_path):
    command = f"exec {sys.executable} -m cospherical tessellate --box 1 1 1 --code 800000000000 >&-"
    result = subprocess.run(["sh", "-c", command], capture_output=True, text=True, timeout=120)
    assert result.returncode == 2 and result.stderr.strip() == "cospherical: error: standard output is closed"


def _descendants(pid: int) -> list[int]:
    found, frontier = [], [pid]
    while frontier:
        parent = frontier.pop()
        for entry in Path("/proc").iterdir():
            try:
                if entry.name.isdigit() and int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1]) == parent:
                    found.append(int(entry.name))
                    frontier.append(int(entry.name))
            except (OSError, IndexError, ValueError):
                pass
    return found


def test_ctrl_c_on_a_dask_study_is_one_line_and_leaves_nothing(tmp_path):
    # SIGINT to the whole process group, as a terminal's Ctrl-C; TMPDIR here, so that any scratch
    # space Dask would leave (dask-scratch-space/*.lock) is seen
    env = {**os.environ, "TMPDIR": str(tmp_path)}
    process = subprocess.Popen([sys.executable, "-m", "cospherical", "study", "intersection", "--resolution", "8",
                                "--dask-workers", "2", "--format", "json"], stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE, env=env, start_new_session=True)
    deadline = time.monotonic() + 90
    workers: list[int] = []
    while time.monotonic() < deadline and process.poll() is None:
        workers = _descendants(process.pid)
        if len(workers) >= 2 and any((tmp_path / d).exists() for d in os.listdir(tmp_path)):
            break
        time.sleep(0.2)
    time.sleep(2.0)  # the workers at work
    assert process.poll() is None, "the study ended before it was interrupted"
    workers = _descendants(process.pid) or workers
    start = time.monotonic()
    os.killpg(process.pid, signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert time.monotonic() - start < 15
    assert process.returncode == 130 and stderr.decode().strip() == "cospherical: interrupted", stderr.decode()
    deadline = time.monotonic() + 10  # the fork server and resource tracker end when they see us gone
    while time.monotonic() < deadline and [pid for pid in workers if Path(f"/proc/{pid}").exists()]:
        time.sleep(0.2)
    assert not [pid for pid in workers if Path(f"/proc/{pid}").exists()], "a worker outlived the command"
    assert not list(tmp_path.iterdir()), "Dask left files behind"


# --- tools around the package -----------------------------------------------------------------------------------

def test_bench_startup_refuses_a_before_folder_that_does_not_exist(tmp_path):
    result = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "bench_startup.py"), "--runs", "1",
                             "--before", str(tmp_path / "absent")], capture_output=True, text=True, timeout=60)
    assert result.returncode == 2 and len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert "absent" in result.stderr and not result.stdout


def test_setup_waits_for_the_dpkg_lock_instead_of_failing():
    # every apt-get the script runs goes through the one command line that carries the lock timeout
    script = (ROOT / "scripts" / "setup.sh").read_text()
    calls = [line for line in script.splitlines() if "apt-get" in line and not line.lstrip().startswith("#")]
    assert calls and all("DPkg::Lock::Timeout=" in line or '"${apt[@]}"' in line for line in calls), calls
    assert re.search(r"apt=\(apt-get -o DPkg::Lock::Timeout=\d+\)", script)


def test_running_out_of_memory_is_one_line_and_exit_2(tmp_path):
    # a tree under the leaf bound (half the machine) but over this process's address space: 768 MB, which
    # a small mesh fits in (run first, in the same process: the limit is met by the tree, not the imports)
    # and the level-10 tree outgrows after about 2 CPU-s (at 1 GB, 6 to 10)
    script = ("import resource, sys; resource.setrlimit(resource.RLIMIT_AS, (768 << 20, 768 << 20)); "
              "from cospherical.cli import main; "
              "assert main(['mesh', '--domain', '1', '1', '1', '--levels', '3', '--refine', 'plane:1,1,1,1', '--no-uniform']) == 0; "
              "sys.exit(main(sys.argv[1:]))")
    result = subprocess.run([sys.executable, "-c", script, "mesh", "--domain", "1", "1", "1", "--levels", "10",
                             "--refine", "plane:1,1,1,1", "--no-uniform"], capture_output=True, text=True,
                            timeout=600, cwd=tmp_path)
    assert result.returncode == 2, result.stderr[-2000:]
    assert result.stderr.count("\n") == 1 and "out of memory" in result.stderr, result.stderr
