"""Package data found in one way: in the package, else (catalogue, templates) in the checkout's top level."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

from cospherical.files.data import data_path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE_DATA = ROOT / "src" / "cospherical" / "data"


def test_packaged_files_are_found_in_the_package():
    for schema in sorted((PACKAGE_DATA / "schemas").glob("*.schema.json")):
        path = data_path(f"schemas/{schema.name}")
        assert path == schema and json.loads(path.read_text())["type"] == "object"
    assert data_path("paper.yaml") == PACKAGE_DATA / "paper.yaml"


def test_what_the_wheel_copies_is_found_at_its_top_level_home_in_a_checkout():
    # The wheel's force-include table is the other half of the lookup: every file it copies into
    # cospherical/data/ is found here in a checkout, where the package holds no copy.
    copied = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["hatch"]["build"]["targets"]["wheel"]["force-include"]
    assert copied
    for source, target in copied.items():
        name = target.removeprefix("cospherical/data/")
        assert not (PACKAGE_DATA / name).exists()
        assert data_path(name) == ROOT / source and data_path(name).exists()
    assert data_path("templates").is_dir() and any(data_path("templates").glob("*.tex.j2"))


def test_an_unknown_name_is_a_path_in_the_package_that_does_not_exist():
    path = data_path("schemas/no-such.schema.json")
    assert path.parent == PACKAGE_DATA / "schemas" and not path.exists()
