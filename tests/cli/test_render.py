"""``cospherical render`` refuses what is not a study summary, and study options beside one."""

from __future__ import annotations

import pytest
from commands import in_process

from tests.outputs.test_latex import SUMMARIES


def test_render_refuses_bad_summaries(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text('{"study": "bisection"}')
    result = in_process(capsys, "render", "--summary", bad, "--out", tmp_path / "out")
    assert result.returncode == 2 and "not a study summary" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("option", [["--box", "1", "2", "4"], ["--element", "prism"], ["--face-points", "none"]])
def test_render_refuses_a_study_option_beside_a_summary(tmp_path, capsys, option):
    # it would do nothing: the summary says its own box, element and points
    from cospherical.cli import main

    assert main(["render", "--summary", str(SUMMARIES[0]), *option, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"{option[0]} goes with --study" in err and err.count("\n") == 1, err
    assert not (tmp_path / "out").exists()
