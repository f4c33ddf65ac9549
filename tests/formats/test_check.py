"""``cospherical check`` of pattern tables: a bad configuration code is one line naming it."""

from __future__ import annotations

import pytest

from cospherical import Box
from cospherical.catalogue import shipped_catalogue
from cospherical.cli import main
from cospherical.files.yamlio import dump_yaml, load_yaml
from cospherical.formats.patterns import write_patterns
from cospherical.studies.engine import run_study

CUBE = ("1", "1", "1")


@pytest.mark.parametrize(
    "key, needle",
    [
        ("800000000000+f0", "configurations/800000000000+f0: face 0"),  # edges 4, 8, 9 are not split
        ("888800000000+f44", "configurations"),  # not a whole-point-set code: the schema refuses it
        ("888800000000+f4b", "configurations/888800000000+f4b: body point"),
    ],
)
def test_leaf_tables_with_bad_codes_fail_check_in_one_line(tmp_path, capsys, key, needle):
    path = tmp_path / "leaves.yaml"
    write_patterns(run_study("leaves", Box.parse(CUBE), ["888800000000+f4", "000000000000+f"], "explicit"), path,
                   shipped_catalogue()["version"])
    data = load_yaml(path)
    data["configurations"][key] = data["configurations"].pop("888800000000+f4")
    dump_yaml(data, path)
    assert main(["check", str(path)]) == 2
    out, err = capsys.readouterr()
    assert len(err.strip().splitlines()) == 1 and needle in err, err
