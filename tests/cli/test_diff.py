"""``cospherical diff``: exit status as diff(1), the report in every format, OLD read from git with --rev."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest
import yaml

from cospherical.cli import main
from cospherical.formats.check import document_data, read_document_file
from cospherical.formats.diff import diff_documents

ROOT = Path(__file__).resolve().parents[2]
CATALOGUE = ROOT / "catalogue" / "catalogue.yaml"
TABLE = ROOT / "patterns" / "bisection-tetrahedron-1x1x1.yaml"  # the smallest shipped table: 64 lines


@pytest.fixture(scope="module")
def edited(tmp_path_factory) -> dict[str, Path]:
    """The shipped catalogue with the tetrahedron renamed, the tetrahedron's table with a configuration dropped."""
    root = tmp_path_factory.mktemp("edited")
    text = CATALOGUE.read_text()
    assert text.count('"name": "Tetrahedron"') == 1
    (root / "catalogue.yaml").write_text(text.replace('"name": "Tetrahedron"', '"name": "Renamed Tetrahedron"'))
    lines = TABLE.read_text().splitlines(keepends=True)
    dropped = next(i for i, line in enumerate(lines) if line.startswith("  '000008'"))
    (root / "patterns.yaml").write_text("".join(lines[:dropped] + lines[dropped + 1:]))
    return {"catalogue": root / "catalogue.yaml", "patterns": root / "patterns.yaml"}


def run(capsys, *argv) -> tuple[int, str, str]:
    status = main(["diff", *map(str, argv)])
    out, err = capsys.readouterr()
    return status, out, err


def test_no_difference_exits_0_silently(capsys):
    for path in (CATALOGUE, TABLE):
        assert run(capsys, path, path) == (0, "", "")


@pytest.mark.oracle_pyyaml
@pytest.mark.parametrize("kind", ["catalogue", "patterns"])
def test_differences_exit_1_and_every_format_holds_the_same_report(capsys, edited, kind):
    old, new = {"catalogue": CATALOGUE, "patterns": TABLE}[kind], edited[kind]
    expected = diff_documents(document_data(read_document_file(old)[1]), document_data(read_document_file(new)[1]),
                              str(old), str(new))
    status, text, _ = run(capsys, old, new)
    assert status == 1 and text.splitlines()[:2] == [f"--- {old}", f"+++ {new}"]
    assert ("~ renamed" in text and "'Renamed Tetrahedron'" in text) if kind == "catalogue" else \
        "- configuration 000008" in text
    for fmt, read in (("json", json.loads), ("yaml", yaml.safe_load)):
        status, out, _ = run(capsys, old, new, "--format", fmt)
        assert status == 1 and read(out) == {"old": str(old), "new": str(new), **expected}


@pytest.mark.parametrize("argv, needle", [
    (["{catalogue}", "{patterns}"], "cannot compare a catalogue"),
    (["{catalogue}", "{junk}"], "junk.yaml"),
    (["{catalogue}"], "give OLD NEW"),
    (["--rev", "HEAD", "{catalogue}", "{catalogue}"], "with --rev give one FILE"),
])
def test_trouble_exits_2_with_one_line(capsys, tmp_path, argv, needle):
    (tmp_path / "junk.yaml").write_text("a: [1, 2\n")
    names = {"catalogue": CATALOGUE, "patterns": TABLE, "junk": tmp_path / "junk.yaml"}
    status, out, err = run(capsys, *(a.format(**names) for a in argv))
    assert status == 2 and out == "" and len(err.strip().splitlines()) == 1 and needle in err


def test_rev_reads_the_old_version_from_git(capsys, edited, tmp_path, monkeypatch):
    def git(*args):
        subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@example.invalid", *args], cwd=tmp_path,
                       check=True, capture_output=True)

    git("init", "-q")
    target = tmp_path / "catalogue.yaml"
    target.write_bytes(CATALOGUE.read_bytes())
    git("add", ".")
    git("commit", "-qm", "v1")
    monkeypatch.chdir(tmp_path)
    assert run(capsys, "--rev", "HEAD", "catalogue.yaml")[0] == 0
    target.write_bytes(edited["catalogue"].read_bytes())
    status, out, _ = run(capsys, "--rev", "HEAD", "catalogue.yaml")
    assert status == 1 and "Renamed Tetrahedron" in out and out.splitlines()[0] == "--- catalogue.yaml@HEAD"
    status, _, err = run(capsys, "--rev", "nosuchrev", "catalogue.yaml")
    assert status == 2 and len(err.strip().splitlines()) == 1 and "catalogue.yaml at nosuchrev" in err
