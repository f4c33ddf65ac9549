"""``cospherical tessellate``: its JSON and YAML, deterministic; its help's numbering; face points given on the
command line; other elements and shape files; the VTU it writes.

Most run the command's code in the test's process (commands.in_process: a process adds 0.4 CPU-s of start-up each);
the JSON contract and the determinism across processes run real ``python -m cospherical`` processes."""

from __future__ import annotations

import json

import meshio
import pytest
import yaml
from commands import cospherical, in_process

from cospherical.cli import main


def test_tessellate_with_faces_on_the_command_line(capsys):
    by_flag = in_process(capsys, "tessellate", "--box", "1", "1", "1", "--code", "888888888888", "--faces", "0", "4")
    assert by_flag.returncode == 0, by_flag.stderr
    data = json.loads(by_flag.stdout)
    assert data["code"] == "888888888888+f04" and data["face_points"] == "explicit"
    assert data["faces"] == [0, 4] and data["body_point"] is False and data["point_set_code"] == data["code"]
    assert set(data["nodes"]) == {str(i) for i in range(20)} | {"20", "24"}
    by_code = in_process(capsys, "tessellate", "--box", "1", "1", "1", "--code", "888888888888+f04")
    assert by_code.stdout == by_flag.stdout
    by_steiner = in_process(capsys, "tessellate", "--box", "1", "1", "1", "--steiner", *(f"{k}:1/2" for k in range(12)),
                            "--faces", "0", "4")
    assert json.loads(by_steiner.stdout)["elements"] == data["elements"]


def test_no_faces_given_explicitly_is_policy_none(capsys):
    args = ("tessellate", "--box", "1", "2", "4", "--code", "888888888888")
    explicit = json.loads(in_process(capsys, *args, "--faces").stdout)
    none = json.loads(in_process(capsys, *args, "--face-points", "none").stdout)
    assert explicit["code"] == "888888888888+f" and none["code"] == "888888888888"
    assert explicit["point_set_code"] == none["point_set_code"] == "888888888888+f"
    assert explicit["elements"] == none["elements"] and explicit["nodes"] == none["nodes"]


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--code", "800000000000", "--faces", "0"], "face 0"),
        (["--steiner", "0:1/4", "4:1/2", "8:1/2", "9:1/2", "--faces", "0"], "different parameters"),
        (["--code", "888888888888", "--faces", "0", "0"], "twice"),
        (["--code", "888888888888", "--faces", "6"], "face"),
        (["--code", "888888888888", "--faces", "x"], "face"),
        (["--code", "888888888888+f4x"], "suffix"),
        (["--code", "888888888888+f44"], "twice"),
        (["--code", "888888888888+f"], None),
        (["--code", "888888888888+f0", "--faces", "4"], "suffix"),
        (["--code", "888888888888", "--faces", "0", "--face-points", "none"], "not allowed"),
        (["--code", "888888888888", "--body"], "body point"),
    ],
)
def test_bad_face_points_on_the_command_line_exit_2_in_one_line(args, needle, capsys):
    # in-process (cli/test_cli.py runs the same error path as a subprocess): a dozen interpreter starts saved
    status = main(["tessellate", "--box", "1", "1", "1", *args])
    out, err = capsys.readouterr()
    if needle is None:  # the empty suffix is a valid code
        assert status == 0, err
        return
    assert status == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0] and "Traceback" not in err, err


@pytest.mark.oracle_meshio
def test_tessellate_cli_writes_vtu(tmp_path, capsys):
    path = tmp_path / "out.vtu"
    result = in_process(capsys, "tessellate", "--box", "1", "1", "1", "--code", "888888888888", "--vtu", str(path))
    assert result.returncode == 0, result.stderr
    mesh = meshio.read(path)
    assert [block.type for block in mesh.cells] == ["hexahedron"] and len(mesh.cells[0].data) == 8


def test_tessellate_json_contract():
    result = cospherical("tessellate", "--box", "1", "1", "1", "--code", "800000000000")
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["box"] == ["1", "1", "1"] and data["code"] == "800000000000"
    assert data["nodes"]["8"] == [0.5, 0.0, 0.0]
    assert set(data["nodes"]) == {str(i) for i in range(9)}
    assert len(data["elements"]) == 4
    for element in data["elements"]:
        assert {"type", "name", "nodes", "vertices", "edges", "faces", "circumcenter"} <= set(element)
        assert element["name"] == "Rectangular Pyramid" and len(element["nodes"]) == 5
        assert (element["vertices"], element["edges"], element["faces"]) == (5, 8, 5)
    assert data["fvm_adequate"] is True


@pytest.mark.oracle_pyyaml
def test_tessellate_steiner_and_yaml_agree_with_code(capsys):
    box = ("tessellate", "--box", "1", "sqrt(2)", "1.4142")
    by_code = json.loads(in_process(capsys, *box, "--code", "800080000008").stdout)
    result = in_process(capsys, *box, "--steiner", "0:1/2", "4:0.5", "11:8/16", "--format", "yaml")
    assert result.returncode == 0, result.stderr
    assert yaml.safe_load(result.stdout) == by_code


def test_output_is_deterministic():
    args = ("tessellate", "--box", "1", "2", "4", "--code", "88808a000c01", "--face-points", "none")
    assert cospherical(*args).stdout == cospherical(*args).stdout


def test_tessellate_help_shows_the_numbering(capsys):
    with pytest.raises(SystemExit):
        main(["tessellate", "--help"])
    out = capsys.readouterr().out
    assert "0 (0,0,0)" in out and "(0,1) (1,2)" in out and "20-25" in out


def test_cli_element_and_shape_file(tmp_path, capsys):
    import json

    result = in_process(capsys, "tessellate", "--element", "pyramid", "--box", "1", "1", "1", "--code", "88880000")
    data = json.loads(result.stdout)
    assert data["element"] == "pyramid" and data["faces"] == [0] and "13" in data["nodes"]
    assert [e["name"] for e in data["elements"]] == ["Rectangular Pyramid"] * 4
    bad = tmp_path / "bowtie.yaml"
    bad.write_text("corners: [[0,0,0],[1,0,0],[1,1,0],[0,1,0],['1/2','1/2',1]]\n"
                   "edges: [[0,1],[1,2],[2,3],[3,0],[0,4],[1,4],[2,4],[3,4]]\n"
                   "faces: [[0,1,3,2],[0,1,4],[1,2,4],[2,3,4],[3,0,4]]\n")
    for args in (["--shape", str(bad)], ["--element", "prism", "--code", "88888888"],
                 ["--element", "tetrahedron", "--steiner", "6:1/2"], ["--element", "prism", "--faces", "0"]):
        result = in_process(capsys, "tessellate", "--box", "1", "1", "1", *args)
        assert result.returncode == 2 and result.stdout == "" and len(result.stderr.strip().splitlines()) == 1, args
