"""The intersection study's statistics: every configuration counted through its orbit's size, by hand."""

from __future__ import annotations

import numpy as np

from cospherical.studies.intersection.statistics import ElementEntry, statistics
from cospherical.studies.summary import TypeInfo

TETRA = ("tet",)
SPLITS = ("internal_faces", "internal_edges_and_faces")
# Three distinct elements: the tetrahedron (entry 0), a pyramid that splits into two tetrahedra, a cube into six.
ENTRIES = [ElementEntry("tet", {c: (TETRA,) for c in SPLITS}),
           ElementEntry("pyr", {c: (("pyr",), ("tet", "tet")) for c in SPLITS}),
           ElementEntry("cube", {c: (("cube",), ("tet",) * 6) for c in SPLITS})]
TYPES = {"tet": TypeInfo("Tetrahedron", "Tetrahedron", 4, 6, 4), "pyr": TypeInfo("Pyramid", None, 5, 8, 5),
         "cube": TypeInfo("Cube", "Cuboid", 8, 12, 6)}
# Two orbit representatives: the first stands for 3 configurations (2 tetrahedra and a pyramid, FVM-adequate in the
# closed box only), the second for 1 (a cube and a pyramid).
SIZES = np.array([3, 1])
CELLS = {"tets": np.array([2, 0]), "polys": np.array([1, 2]), "closed": np.array([True, False]),
         "open": np.array([False, False])}
ELEMENT_OF = np.array([1, 2, 1])  # each other cell's entry, configuration by configuration


def test_counts_by_hand():
    data = statistics(SIZES, CELLS, ELEMENT_OF, ENTRIES, TYPES)
    assert (data["fvm_adequate"], data["fvm_adequate_open"]) == (3, 0)
    optimal = data["criteria"]["optimal"]
    # tetrahedra 3 x 2; pyramids 3 x 1 + 1 x 1; one cube. Configurations holding each: 3, 3 + 1, 1.
    assert {t: (row["count"], row["configurations"]) for t, row in optimal["types"].items()} == \
           {"tet": (6, 3), "pyr": (4, 4), "cube": (1, 1)}
    assert optimal["total"] == 11 and "splits" not in optimal and "kept" not in optimal
    for criterion in SPLITS:
        # the smallest kept set that tiles everything is the tetrahedron alone: 6 + 4 x 2 + 6 of them
        split = data["criteria"][criterion]
        assert split["kept"] == ["tet"]
        assert {t: (row["count"], row["configurations"]) for t, row in split["types"].items()} == {"tet": (20, 4)}
        assert split["splits"] == {"cube": [{"pieces": ["tet"] * 6, "configurations": 1}],
                                   "pyr": [{"pieces": ["tet", "tet"], "configurations": 4}]}


def test_an_element_that_cannot_split_is_kept_and_weights_follow_the_orbits():
    entries = [ENTRIES[0], ENTRIES[1], ElementEntry("cube", {c: (("cube",),) for c in SPLITS})]
    data = statistics(SIZES * 10, CELLS, ELEMENT_OF, entries, TYPES)
    split = data["criteria"]["internal_faces"]
    assert split["kept"] == ["cube", "tet"]  # the cube must stay; the pyramid still splits
    assert {t: row["count"] for t, row in split["types"].items()} == {"tet": 60 + 40 * 2, "cube": 10}
    assert data["fvm_adequate"] == 30


def test_an_entry_read_from_json():
    entry = ElementEntry.from_json({"type": "pyr", "options": {"internal_faces": [["pyr"], ["tet", "tet"]]}})
    assert entry == ElementEntry("pyr", {"internal_faces": (("pyr",), ("tet", "tet"))})
