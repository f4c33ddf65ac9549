"""The report's typed sections: each reads back the JSON it writes, keys in the file's order, and cannot be changed."""

from __future__ import annotations

import dataclasses
import json
import pickle

import pytest

from cospherical.mesh import report_sections as sections
from cospherical.mesh.report_sections import (ChecksSummary, DelaunaySpheres, LeafMeshSummary, NegativeCoefficients,
                                              RegionSummary, TreeSummary, plain)

# One JSON object per section, its keys in the order report.json writes them
EXAMPLES = {
    "TreeSummary": {"source": "device", "device": "diode", "levels": 4, "refine": ["point:0,0,0"],
                    "balance": "vertex", "resolving_level": 2, "depth": 4},
    "LeafMeshSummary": {"elements": 9, "delaunay_violations": 1, "delaunay_ties": 0, "elements_replaced": 2},
    "OutsideType": {"id": "t1", "name": "my type", "count": 3, "example": [["0", "1/2", "1"], ["1", "0", "0"]]},
    "TypeFrequency": {"id": "t1", "name": "Cuboid", "paper_class": None, "vtk": "hexahedron", "count": 3,
                      "share": 0.5, "uniform_count": None, "uniform_share": None},
    "ConfigurationFrequency": {"code": "800000000000+f", "leaves": 2, "share": 0.25, "uniform_share": 0.000244,
                               "elements_per_leaf": 3, "fvm_adequate": True, "tessellated_on_the_fly": False},
    "UniformSummary": {"study": "bisection", "face_points": "octree", "configurations": 4096, "elements": 37259,
                       "paper_final_share": 0.9},
    "NegativeCoefficients": {"interior": 0, "boundary": 2},
    "MixedCounts": {"elements": 1, "edges": 5, "faces": 4, "nonzeros": 14},
    "TetrahedralCounts": {"tool": "tetgen", "elements": 2, "edges": 6, "faces": 7, "nonzeros": 16, "flat": 0},
    "DualSummary": {"edges": 5, "volume_sum": "1", "coefficient_min": -0.5, "coefficient_max": None,
                    "boundary_vertices": 4, "mixed": {"elements": 1, "edges": 5, "faces": 4, "nonzeros": 14},
                    "tetrahedral": None},
    "RegionSummary": {"name": "r", "material": "Si", "elements": 1, "nodes": 4, "volume": "1", "volume_ok": True,
                      "negative_coefficients": {"interior": 0, "boundary": 1}, "control_volume_sum": "1"},
    "ContactSummary": {"name": "c", "region": "r", "faces": 1, "nodes": 3, "area": "1/2", "area_ok": True,
                       "area_parts_sum": "1/2"},
    "InterfaceSummary": {"name": "r|s", "faces": 1, "nodes": 3},
    "DeviceSummary": {"name": "d", "resolving_level": 1, "depth": 2, "origin": ["0", "0", "1/3"],
                      "regions": [{"name": "r", "material": "Si", "elements": 1, "nodes": 4, "volume": "1",
                                   "volume_ok": False}], "contacts": [], "interfaces": []},
    "DelaunaySpheres": {"bounded_by_the_tree": 4},
    "ChecksSummary": {"run": ["volume", "conformity"], "not_run": {"delaunay": "not asked for"}},
}


def test_every_section_has_an_example():
    assert set(EXAMPLES) == {name for name in sections.__all__ if name[0].isupper()} - {"ReadOnlyMapping"}


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_a_section_reads_back_what_it_writes_keys_in_order(name):
    kind = getattr(sections, name)
    data = EXAMPLES[name]
    typed = kind.from_dict(json.loads(json.dumps(data)))
    assert json.dumps(typed.to_dict()) == json.dumps(data)  # the same keys, in the same order, the same values
    assert kind.from_dict(typed.to_dict()) == typed
    assert pickle.loads(pickle.dumps(typed)) == typed  # reports and pieces' figures travel between processes
    with pytest.raises(TypeError):
        kind.from_dict({**data, "unknown": 1})
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(typed, dataclasses.fields(typed)[0].name, None)


def test_fields_that_are_not_computed_are_absent_not_null():
    assert TreeSummary("leaves", depth=3).to_dict() == {"source": "leaves", "depth": 3}
    assert list(RegionSummary("r", "Si", 1, 4, "1", True).to_dict())[-1] == "volume_ok"
    assert LeafMeshSummary(1, 0, 0, 0, fallback="leaf elements").to_dict()["fallback"] == "leaf elements"
    assert "fallback" not in LeafMeshSummary(1, 0, 0, 0).to_dict()
    assert ChecksSummary(("volume",), DelaunaySpheres(2)).to_dict() == {
        "run": ["volume"], "delaunay_spheres": {"bounded_by_the_tree": 2}}


def test_what_a_section_holds_cannot_be_changed_through_it_or_its_dict():
    checks = ChecksSummary.from_dict(EXAMPLES["ChecksSummary"])
    with pytest.raises(TypeError):
        checks.not_run["volume"] = "no"  # read-only: keyed by open-ended names
    data = checks.to_dict()
    data["not_run"]["volume"] = "no"
    data["run"].append("delaunay")
    assert checks.run == ("volume", "conformity") and "volume" not in checks.not_run
    assert plain((NegativeCoefficients(1, 2), {"a": (1, 2)})) == [{"interior": 1, "boundary": 2}, {"a": [1, 2]}]


def test_a_check_not_run_moves_from_run_to_not_run_with_its_reason_first():
    checks = ChecksSummary.from_dict(EXAMPLES["ChecksSummary"])
    moved = checks.not_running("conformity", "proven")
    assert moved.run == ("volume",) and list(moved.not_run.items())[0] == ("conformity", "proven")
    assert dict(moved.not_run) == {"conformity": "proven", **checks.not_run}
    assert checks.not_running("delaunay", "not run anyway") is checks  # not in run: unchanged
    assert ChecksSummary.from_dict(moved.to_dict()) == moved


def test_leaf_mesh_figures_of_pieces_add_up():
    total = LeafMeshSummary(3, 1, 0, 2) + LeafMeshSummary(4, 0, 1, 0)
    assert total == LeafMeshSummary(7, 1, 1, 2)
