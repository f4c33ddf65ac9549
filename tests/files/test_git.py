"""A file's text at a git revision, bounded and decoded like a file on disk."""

from __future__ import annotations

import re
import subprocess

import pytest

from cospherical.errors import FormatError
from cospherical.files import yamlio
from cospherical.files.git import git_text


@pytest.fixture()
def repo(tmp_path):
    """Two commits of notes.yaml (v1, then v2), one of a Latin-1 file; the work tree holds v3."""
    def git(*args):
        subprocess.run(["git", "-c", "user.email=t@example.org", "-c", "user.name=t", *args], cwd=tmp_path,
                       check=True, capture_output=True)

    git("init", "-q")
    (tmp_path / "notes.yaml").write_text("version: 1\n")
    (tmp_path / "latin1.yaml").write_bytes("name: caf\xe9\n".encode("latin-1"))
    git("add", ".")
    git("commit", "-qm", "one")
    (tmp_path / "notes.yaml").write_text("version: 2\nname: été\n")
    git("commit", "-qam", "two")
    (tmp_path / "notes.yaml").write_text("version: 3\n")
    return tmp_path


def test_the_text_at_each_revision_not_the_work_tree(repo, monkeypatch):
    assert git_text("HEAD", repo / "notes.yaml") == "version: 2\nname: été\n"
    assert git_text("HEAD~1", repo / "notes.yaml") == "version: 1\n"
    monkeypatch.chdir(repo.parent)  # a relative path is the caller's, whatever git's own folder
    assert git_text("HEAD~1", f"{repo.name}/notes.yaml") == "version: 1\n"


@pytest.mark.parametrize("rev, name, needle", [
    ("nosuchrev", "notes.yaml", "notes.yaml at nosuchrev"),
    ("HEAD", "latin1.yaml", "not UTF-8 text (byte 9)"),
    ("HEAD", "untracked.yaml", "untracked.yaml at HEAD"),
])
def test_what_cannot_be_read_is_one_line(repo, rev, name, needle):
    (repo / "untracked.yaml").write_text("x: 1\n")
    with pytest.raises(FormatError, match=re.escape(needle)) as error:
        git_text(rev, repo / name)
    assert "\n" not in str(error.value)


def test_a_blob_over_the_bound_is_refused_before_it_is_read(repo, monkeypatch):
    size = len("version: 2\nname: été\n".encode())
    monkeypatch.setattr(yamlio, "MAX_INPUT_BYTES", size - 1)
    with pytest.raises(FormatError, match=rf"too large \({size} bytes; at most {size - 1}\)"):
        git_text("HEAD", repo / "notes.yaml")
    monkeypatch.setattr(yamlio, "MAX_INPUT_BYTES", size)
    assert git_text("HEAD", repo / "notes.yaml").startswith("version: 2")


def test_outside_a_repository_is_one_line(tmp_path):
    (tmp_path / "alone.yaml").write_text("x: 1\n")
    with pytest.raises(FormatError, match="alone.yaml at HEAD"):
        git_text("HEAD", tmp_path / "alone.yaml")
