"""The output folder: files move in only when the run succeeds, only our own unchanged files are removed, a
hostile manifest removes nothing outside, a failing writer is named by the user's file."""

from __future__ import annotations

import errno
import hashlib
import json
import os
from pathlib import Path

import pytest

from cospherical.errors import InputError
from cospherical.files.outputs import MANIFEST, OutputFolder


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


def test_only_unchanged_files_of_the_same_command_are_removed(tmp_path):
    out = tmp_path / "out"
    with OutputFolder(out, "render") as folder:
        for name in ("kept.tex", "stale.tex", "edited.tex"):
            folder.path(name).write_text(name)
    with OutputFolder(out, "mesh") as folder:
        folder.path("mesh.vtu").write_text("mesh")
    (out / "edited.tex").write_text("the user changed it")
    (out / "frequencies-my-notes.tex").write_text("notes")
    with OutputFolder(out, "render") as folder:
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
    with OutputFolder(out, "render") as folder:
        folder.path("a.tex").write_text("A")
    assert target.read_text() == "the user's own file\n"
    (out / MANIFEST).write_text("[" * 100_000)  # damaged: read as empty, never a traceback
    with OutputFolder(out, "render") as folder:
        folder.path("a.tex").write_text("A")
    assert json.loads((out / MANIFEST).read_text()) == {"render": {"a.tex": hashlib.sha256(b"A").hexdigest()}}


def test_a_writer_failing_on_a_staged_file_names_the_users_file(tmp_path):
    # a library that writes the staged path itself (not through atomic_open) and fails there
    with pytest.raises(InputError) as raised:
        with OutputFolder(tmp_path / "out", "example") as out:
            staged = out.path("table.dat")
            raise OSError(errno.ENOSPC, "No space left on device", str(staged))
    assert str(raised.value) == f"{tmp_path / 'out' / 'table.dat'}: cannot write: No space left on device"
