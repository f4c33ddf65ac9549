"""The output folder: files move in only when the run succeeds, only our own unchanged files are removed, a
hostile manifest removes nothing outside, a failing writer is named by the user's file."""

from __future__ import annotations

import errno
import hashlib
import json
import os
import re
import shutil
from pathlib import Path

import pytest

from cospherical.errors import InputError
from cospherical.api.mesh import mesh_writes as MESH_WRITES
from cospherical.files.outputs import MANIFEST, OutputFolder
from cospherical.mesh.partition import MAX_PARTITIONS
from cospherical.outputs.latex import _RENDERED


def victim(tmp_path: Path) -> Path:
    path = tmp_path / "victim.txt"
    path.write_text("the user's own file\n")
    return path


def listing(folder: Path) -> dict[str, bytes | str]:
    return {p.name: (os.readlink(p) if p.is_symlink() else p.read_bytes()) for p in sorted(folder.iterdir())}


def test_output_folder_moves_files_in_only_when_the_run_succeeds(tmp_path):
    out = tmp_path / "new" / "out"
    with pytest.raises(RuntimeError):
        with OutputFolder(out, "test") as folder:
            folder.path("a.txt").write_text("A")
            raise RuntimeError("the run fails")
    assert not out.exists()  # made by the run that failed, and removed again
    out.mkdir(parents=True)
    (out / "a.txt").write_text("old")
    with pytest.raises(KeyboardInterrupt):
        with OutputFolder(out, "test") as folder:
            folder.path("a.txt").write_text("new")
            raise KeyboardInterrupt
    assert listing(out) == {"a.txt": b"old"}
    with OutputFolder(out, "test") as folder:
        folder.path("a.txt").write_text("new")
        assert (out / "a.txt").read_text() == "old"  # nothing in place before the end
    assert (out / "a.txt").read_text() == "new" and sorted(listing(out)) == [MANIFEST, "a.txt"]


def test_an_output_folder_whose_name_a_file_takes_says_so_and_leaves_the_file(tmp_path):
    taken = tmp_path / "out"
    taken.write_text("the user's")
    with pytest.raises(InputError, match="the output is a folder, and this name is taken by something else"):
        with OutputFolder(taken, "test"):
            pass
    assert taken.read_text() == "the user's"


TEX = re.compile(r"[a-z]+\.tex").fullmatch
RENDER_WRITES = _RENDERED.fullmatch


def test_only_unchanged_files_of_the_same_command_are_removed(tmp_path):
    out = tmp_path / "out"
    with OutputFolder(out, "render", writes=TEX) as folder:
        for name in ("kept.tex", "stale.tex", "edited.tex"):
            folder.path(name).write_text(name)
    with OutputFolder(out, "mesh", writes=MESH_WRITES) as folder:
        folder.path("mesh.vtu").write_text("mesh")
    (out / "edited.tex").write_text("the user changed it")
    (out / "frequencies-my-notes.tex").write_text("notes")
    with OutputFolder(out, "render", writes=TEX) as folder:
        folder.path("kept.tex").write_text("kept.tex")
    # stale.tex: ours, unchanged -> removed; edited.tex, the notes: the user's; mesh.vtu: another command's
    assert sorted(listing(out)) == [MANIFEST, "edited.tex", "frequencies-my-notes.tex", "kept.tex", "mesh.vtu"]


def test_a_hostile_manifest_cannot_remove_anything_outside(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    target = victim(tmp_path)
    digest = hashlib.sha256(target.read_bytes()).hexdigest()
    (out / MANIFEST).write_text(json.dumps({"render": {"../victim.txt": digest, str(target): digest,
                                                        ".hidden": digest}}))
    with OutputFolder(out, "render", writes=TEX) as folder:
        folder.path("a.tex").write_text("A")
    assert target.read_text() == "the user's own file\n"
    (out / MANIFEST).write_text("[" * 100_000)  # damaged: read as empty, never a traceback
    with OutputFolder(out, "render", writes=TEX) as folder:
        folder.path("a.tex").write_text("A")
    assert json.loads((out / MANIFEST).read_text()) == {"render": {"a.tex": hashlib.sha256(b"A").hexdigest()}}


def test_a_writer_failing_on_a_staged_file_names_the_users_file(tmp_path):
    # a library that writes the staged path itself (not through atomic_open) and fails there
    with pytest.raises(InputError) as raised:
        with OutputFolder(tmp_path / "out", "example") as out:
            staged = out.path("table.dat")
            raise OSError(errno.ENOSPC, "No space left on device", str(staged))
    assert str(raised.value) == f"{tmp_path / 'out' / 'table.dat'}: cannot write: No space left on device"


# A manifest anyone may have edited, naming files of the user's in the folder with their true SHA-256:
# (writer, the name the manifest vouches for, the writer's names). None is removed: a name the writer
# never writes, another command's name, a file when the writer says no names at all.
FORGED = [("mesh", "notes.txt", MESH_WRITES), ("mesh", "thesis.tex", MESH_WRITES),
          ("mesh", "document.pdf", MESH_WRITES), ("mesh", "mesh-01.vtu", MESH_WRITES),
          ("mesh", f"mesh-{MAX_PARTITIONS}.vtu", MESH_WRITES), ("mesh", "mesh.vtk", MESH_WRITES),
          ("render", "thesis.tex", RENDER_WRITES), ("render", "mesh.vtu", RENDER_WRITES),
          ("render", "frequencies-my-notes.tex", RENDER_WRITES), ("render", "document.aux", RENDER_WRITES),
          ("render", "Document.pdf", RENDER_WRITES), ("example", "a.txt", None)]


@pytest.mark.parametrize("writer, name, writes", FORGED, ids=[f"{w}-{n}" for w, n, _ in FORGED])
def test_a_forged_manifest_never_removes_a_file_the_command_does_not_write(tmp_path, writer, name, writes):
    out = tmp_path / "out"
    out.mkdir()
    (out / name).write_text("the user's own file\n")
    digest = hashlib.sha256(b"the user's own file\n").hexdigest()
    (out / MANIFEST).write_text(json.dumps({writer: {name: digest}, "mesh": {name: digest},
                                            "render": {name: digest}}))
    with OutputFolder(out, writer, writes=writes) as folder:
        folder.path("report.json").write_text("{}")
    assert (out / name).read_text() == "the user's own file\n"


def test_the_names_a_command_writes_are_its_only_stale_files_removed(tmp_path):
    # the other half: an earlier run's file under a name the command writes, unchanged, still goes
    out = tmp_path / "out"
    for writer, names, writes in (("mesh", ["dual.npz", "mesh-0.vtu", f"mesh-{MAX_PARTITIONS - 1}.vtu"],
                                   MESH_WRITES),
                                  ("render", ["document.pdf", "document.log",
                                              "comparison-bisection-1x2x4-internal_edges_and_faces.tex"],
                                   RENDER_WRITES)):
        with OutputFolder(out, writer, writes=writes) as folder:
            for name in names:
                folder.path(name).write_text(name)
        with OutputFolder(out, writer, writes=writes) as folder:
            folder.path("report.json" if writer == "mesh" else "document.tex").write_text("")
        assert not any((out / name).exists() for name in names), writer


def _killed_run(out: Path) -> Path:
    """The staging folder of a run killed mid-way (SIGKILL: no clean-up, the lock gone with the process)."""
    folder = OutputFolder(out, "mesh")
    folder.__enter__()
    folder.path("mesh.vtu").write_text("half")
    folder._lock.release(failed=False)
    return folder.staging


def test_a_folder_of_the_users_named_like_a_staging_folder_is_never_removed(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    users = {}
    for name in (".cospherical-staging.", ".cospherical-staging.abcd1234", ".cospherical-staging.my notes"):
        (out / name).mkdir()
        (out / name / "data.txt").write_text(name)
        users[name] = name
    # a real staging folder's mark copied into another folder (cp -r, an archive): not that folder's own
    stale = _killed_run(tmp_path / "elsewhere")
    shutil.copytree(stale, out / ".cospherical-staging.copied")
    (out / ".cospherical-staging.copied" / "data.txt").write_text("copied")
    users[".cospherical-staging.copied"] = "copied"
    (out / ".cospherical-staging.forged").mkdir()
    (out / ".cospherical-staging.forged" / ".cospherical-staging").write_text("0 0\n")
    (out / ".cospherical-staging.forged" / "data.txt").write_text("forged")
    users[".cospherical-staging.forged"] = "forged"
    (out / ".cospherical-staging.link").symlink_to(tmp_path / "elsewhere")  # a link to a marked folder
    killed = _killed_run(out)  # a killed run's own folder, beside them: the only one that goes
    with OutputFolder(out, "mesh", writes=MESH_WRITES) as folder:
        folder.path("mesh.vtu").write_text("mesh")
    assert not killed.exists()
    for name, text in users.items():
        assert (out / name / "data.txt").read_text() == text, name
    assert (out / ".cospherical-staging.link").is_symlink() and stale.is_dir()


def test_only_a_killed_runs_own_temporary_files_are_removed(tmp_path):
    # a temporary file proves itself by its name: its own device and inode; a name alone proves nothing
    from cospherical.files.outputs import _new_temporary, atomic_write

    target = tmp_path / "report.json"

    def killed_run() -> Path:
        fd, tmp = _new_temporary(target)
        tmp.write_text("half")
        os.close(fd)  # the process died: its lock is gone, its file stays
        return tmp

    stale = killed_run()
    assert re.fullmatch(r"\.report\.json\.[0-9a-f]+-[0-9a-f]+\.tmp", stale.name)
    users = {}
    for name in (".report.json.abcd1234.tmp", ".report.json.k3j_x9a2.tmp", ".report.json.0-0.tmp"):
        users[name] = name  # named like a temporary file (by hand, or as an earlier version named them)
    folder = os.stat(tmp_path)
    users[f".report.json.{folder.st_dev:x}-{folder.st_ino:x}.tmp"] = "another file's identity"
    for name, text in users.items():
        (tmp_path / name).write_text(text)
    restored = killed_run()  # a killed run's file copied back from a backup: another inode
    shutil.copy(restored, tmp_path / "backup")
    os.replace(tmp_path / "backup", restored)
    users[restored.name] = "half"
    linked = killed_run()  # a link named after the file it points to is not that file
    moved = tmp_path / "target-of-link"
    os.replace(linked, moved)
    linked.symlink_to(moved)
    fd, live = _new_temporary(target)  # a concurrent run, still writing
    try:
        atomic_write(target, "{}")
        assert not stale.exists()
        assert live.exists()
        for name, text in users.items():
            assert (tmp_path / name).read_text() == text, name
        assert linked.is_symlink() and moved.read_text() == "half"
    finally:
        os.close(fd)
    assert target.read_text() == "{}"
