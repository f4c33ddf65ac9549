"""results/mesh/ holds what the code writes: the smallest committed mesh report made again, byte for byte.

The reports of results/mesh/ are made by the `mesh` commands of docs/concepts/meshing.md (CONTRIBUTING.md);
the results page of the site shows them.  Making all four again costs ~5 CPU-s, so the test makes the
cheapest one (the level-7 point tree, ~0.6 CPU-s with its dual and TetGen's count) from the very command
the page shows, and checks that every committed report has a command there.
"""

import shlex
from pathlib import Path

from cospherical.cli import main

ROOT = Path(__file__).resolve().parents[1]
SMALLEST = "point-1x1x1-L7"


def _commands() -> dict[str, list[str]]:
    """The `cospherical mesh` lines of docs/concepts/meshing.md's first block, by the folder their report is in."""
    text = (ROOT / "docs" / "concepts" / "meshing.md").read_text()
    block = text.split("```sh\n", 1)[1].split("```", 1)[0]
    commands = {}
    for line in block.splitlines():
        if not line.startswith("cospherical mesh "):
            continue
        words = shlex.split(line)[1:]
        option = {words[i]: words[i + 1:i + 4] for i in range(len(words)) if words[i].startswith("--")}
        shape = option["--refine"][0].split(":")[0]
        name = f"{shape}-{'x'.join(option['--domain'])}-L{option['--levels'][0]}"
        if option.get("--delaunay", [""])[0] == "leaf":
            name += "-leaf"
        commands[name] = words
    return commands


def test_every_committed_mesh_report_has_its_command_in_the_docs():
    committed = sorted(path.parent.name for path in (ROOT / "results" / "mesh").glob("*/report.json"))
    assert committed and sorted(_commands()) == committed


def test_the_smallest_mesh_report_is_what_the_code_writes(tmp_path, capsys, monkeypatch):
    words = _commands()[SMALLEST]
    words[words.index("--out") + 1] = str(tmp_path / "out")
    monkeypatch.chdir(ROOT)  # the command names patterns/ relative to the checkout
    assert main(words) == 0, capsys.readouterr().err
    committed = ROOT / "results" / "mesh" / SMALLEST / "report.json"
    assert (tmp_path / "out" / "report.json").read_bytes() == committed.read_bytes(), (
        f"{committed.relative_to(ROOT)} is not what the code writes: run the command of docs/concepts/meshing.md "
        "with --out DIR and copy DIR's report.json and mesh.png over (CONTRIBUTING.md)")
