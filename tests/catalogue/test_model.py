"""The catalogue as an object: its lookups agree with the document it was read from."""

import dataclasses

import pytest
import yaml

from cospherical.catalogue import Catalogue, catalogue_path, shipped_catalogue


def test_lookups_agree_with_the_file():
    document = yaml.load(catalogue_path().read_text(), Loader=yaml.CSafeLoader)
    catalogue = shipped_catalogue()
    assert isinstance(catalogue, Catalogue) and catalogue.version == document["version"]
    assert [t.id for t in catalogue] == [entry["id"] for entry in document["types"]]
    for entry in document["types"]:
        found = catalogue[entry["id"]]
        assert catalogue.by_code(entry["code"]) is found and catalogue.name_of(entry["code"]) == entry["name"]
        assert (found.vtk, found.paper_class) == (entry.get("vtk"), (entry["aliases"] or [None])[0])
        assert [list(f.nodes) for f in found.reference_faces] == [f["nodes"] for f in entry["reference_faces"]]
        assert {c: [[[p.type, list(p.nodes)] for p in split] for split in splits] for c, splits in found.splits.items()} \
            == {c: [[[p["type"], p["nodes"]] for p in split] for split in splits] for c, splits in entry["splits"].items()}
    for criterion, entry in document["criteria"].items():
        assert catalogue.kept(criterion) == set(entry["kept"])
    assert catalogue.kept("optimal") == frozenset() and "v4f4-000000" not in catalogue
    assert catalogue.get("v4f4-000000") is None and catalogue.name_of("v4:none") is None
    with pytest.raises(KeyError):
        catalogue["v4f4-000000"]
    with pytest.raises(dataclasses.FrozenInstanceError):
        catalogue.version = "0"  # type: ignore[misc]
    copy = catalogue.to_dict()
    copy["types"].clear()  # a copy: the catalogue's own document is untouched
    assert catalogue.to_dict() == document
