"""The catalogue file: one element type per line, read back as written, replaced whole or not at all."""

from __future__ import annotations

import os

import pytest
import yaml

from cospherical.catalogue import Catalogue, load_catalogue, shipped_catalogue
from cospherical.formats.catalogue_file import write_catalogue


@pytest.mark.oracle_pyyaml
def test_written_one_type_per_line_and_read_back_alike(tmp_path):
    catalogue = shipped_catalogue()
    path = tmp_path / "catalogue.yaml"
    write_catalogue(catalogue, path)
    lines = path.read_text().splitlines()
    start = lines.index("types:") + 1
    assert len(lines) - start == len(catalogue) and all(line.startswith("- {") for line in lines[start:])
    assert load_catalogue(path).to_dict() == catalogue.to_dict() == yaml.load(path.read_text(), Loader=yaml.CSafeLoader)
    again = tmp_path / "again.yaml"
    write_catalogue(load_catalogue(path), again)
    assert again.read_bytes() == path.read_bytes()  # a fixed point: reading and writing changes nothing


def test_a_failed_write_leaves_the_old_file(tmp_path):
    path = tmp_path / "catalogue.yaml"
    path.write_text("old\n")
    data = shipped_catalogue().to_dict()
    broken = Catalogue.from_dict({**data, "types": [{**data["types"][0], "aliases": [object()]}]})  # not JSON
    with pytest.raises(TypeError):
        write_catalogue(broken, path)
    assert path.read_text() == "old\n" and os.listdir(tmp_path) == ["catalogue.yaml"]
