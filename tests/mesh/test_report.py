"""A mesh's report: every figure recounted from the mesh's own arrays, the JSON shape, the typed view of it."""

from __future__ import annotations

import dataclasses
import json
import pickle
from collections import Counter
from fractions import Fraction

import numpy as np
import pytest

from cospherical.core.configuration import Box
from cospherical.files.yamlio import validate
from cospherical.mesh.assembly import assemble
from cospherical.mesh.octree import build_octree, parse_shape
from cospherical.mesh.report import MeshReport, OutsideType, TreeSummary, checked_mesh_report, mesh_report

DOMAIN = (1, 2, 4)


@pytest.fixture(scope="module")
def mesh():
    """Two levels in a 1 x 2 x 4 box, refined towards a point: 15 leaves."""
    return assemble(build_octree(Box.parse(list(DOMAIN)), 2, [parse_shape("point:0.1,0.1,0.1")]))


@pytest.fixture(scope="module")
def report(mesh):
    stages: list[str] = []
    progress: list[int] = []
    found = checked_mesh_report(mesh, TreeSummary("refine"), None, uniform=False, stage=stages.append,
                                progress=progress.append)
    return found, stages, progress


def _faces(mesh) -> Counter:
    faces: Counter = Counter()
    for _, nodes, cycles, _ in mesh.blocks():
        for row in nodes:
            for cycle in cycles:
                faces[frozenset(int(row[i]) for i in cycle)] += 1
    return faces


def test_the_figures_recounted_from_the_mesh(mesh, report):
    data = report[0].report
    validate(data.to_dict(), "mesh-report", "report")
    blocks = list(mesh.blocks())
    assert data.elements == sum(len(nodes) for _, nodes, _, _ in blocks) == len(mesh)
    assert data.vertices == len(np.unique(mesh.vertices, axis=0))
    assert data.leaves == len(mesh.tree) == sum(data.leaves_per_level.values())
    assert data.leaves_per_level == {str(k): v for k, v in sorted(Counter(mesh.tree.levels.tolist()).items())}
    counts = Counter()
    for _, nodes, _, type_id in blocks:
        counts[type_id] += len(nodes)
    assert {row.id: row.count for row in data.type_frequencies} == counts and data.types == len(counts)
    assert (data.volume, data.volume_ok, data.flat_elements) == ("1", True, 0)


def test_faces_recounted_and_the_boundary_covers_the_box(mesh, report):
    data = report[0].report
    faces = _faces(mesh)
    assert data.nonconforming_faces == 0 and set(faces.values()) <= {1, 2}
    assert data.interior_faces == sum(n == 2 for n in faces.values())
    assert data.boundary_faces == sum(n == 1 for n in faces.values())
    # every boundary face lies on a side of the box, and their areas add up to the box's surface
    points = mesh.points()
    area = 0.0
    for face, n in faces.items():
        if n == 1:
            corners = points[sorted(face)]
            assert any(np.all(corners[:, axis] == 0) or np.allclose(corners[:, axis], DOMAIN[axis])
                       for axis in range(3))
            center = corners.mean(axis=0)  # the face is convex: a fan from its center, in any order of the corners
            normal_axis = next(a for a in range(3) if np.ptp(corners[:, a]) == 0)
            u, v = (a for a in range(3) if a != normal_axis)
            angles = np.arctan2(corners[:, v] - center[v], corners[:, u] - center[u])
            ring = corners[np.argsort(angles)]
            area += 0.5 * abs(np.sum(ring[:, u] * np.roll(ring[:, v], -1) - np.roll(ring[:, u], -1) * ring[:, v]))
    a, b, c = DOMAIN
    assert area == pytest.approx(2 * (a * b + b * c + c * a), rel=1e-12)


def test_each_check_is_announced_and_the_delaunay_check_kept(mesh, report):
    found, stages, progress = report
    assert stages == ["volume", "conformity", "circumcenters", "delaunay", "statistics"]
    assert sum(progress) == len(mesh) and found.delaunay is not None
    assert found.report.delaunay_violations == found.delaunay.figures()["delaunay_violations"]


def test_without_the_delaunay_check_its_figures_are_absent(mesh):
    typed = mesh_report(mesh, TreeSummary("refine"), None, uniform=False, delaunay=False)
    data = typed.to_dict()
    assert typed.delaunay_violations is None and typed.delaunay_ties is None and typed.uniform is None
    assert data["delaunay_violations"] is None and "delaunay_ties" not in data and "uniform" not in data
    assert typed.checks is not None and dict(typed.checks.not_run or {}) == {
        "delaunay": "not asked for (--no-delaunay): delaunay_violations is null"}
    validate(data, "mesh-report", "report")


def test_the_typed_report_reads_and_writes_the_same_json(report):
    made = report[0].report
    data = json.loads(json.dumps(made.to_dict()))  # as report.json holds it
    typed = MeshReport.from_dict(data, timings={"tree": 0.5})
    assert typed == made and typed.to_dict() == data and typed.timings == {"tree": 0.5}
    assert list(typed.to_dict()) == list(data)  # the order report.json writes
    assert MeshReport.from_dict(typed.to_dict()) == typed  # timings are not compared
    copy = typed.to_dict()
    copy["type_frequencies"][0]["count"] = -1
    copy["leaves_per_level"]["9"] = 1
    assert typed.type_frequencies[0].count > 0 and "9" not in typed.leaves_per_level  # a copy: changing it changes nothing
    with pytest.raises(TypeError):
        MeshReport.from_dict({**data, "unknown": 1})
    with pytest.raises(TypeError):
        MeshReport.from_dict({**data, "checks": {**data["checks"], "unknown": 1}})  # the sections' keys too
    assert Fraction(typed.volume) == 1


def test_the_typed_report_cannot_be_changed(report):
    typed = report[0].report
    assert isinstance(typed.type_frequencies, tuple) and isinstance(typed.configuration_frequencies, tuple)
    with pytest.raises(dataclasses.FrozenInstanceError):
        typed.type_frequencies[0].count = 0
    with pytest.raises(TypeError):
        typed.leaves_per_level["0"] = 2  # read-only mappings
    with pytest.raises(TypeError):
        typed.timings["tree"] = 1.0
    assert pickle.loads(pickle.dumps(typed)) == typed  # read-only, yet it travels between processes


def test_every_section_reads_back_what_it_writes(report):
    # The sections this small mesh lacks (a device, the dual, the leaf mesh, a type outside the catalogue)
    # are read and written by the API's and the devices' tests; here one of each is read back from JSON.
    data = json.loads(json.dumps(report[0].report.to_dict()))
    outside = OutsideType("t1", "my type", 3, (("0", "1/2", "1"), ("1", "0", "0")))
    sections = dict(types_outside_catalogue=[outside.to_dict()],
                leaf_mesh={"elements": 9, "delaunay_violations": 1, "delaunay_ties": 0, "elements_replaced": 2,
                           "fallback": "leaf elements"},
                negative_coefficients={"interior": 0, "boundary": 2},
                dual={"edges": 5, "volume_sum": "1", "coefficient_min": None, "coefficient_max": 0.5,
                      "boundary_vertices": 4, "mixed": {"elements": 1, "edges": 5, "faces": 4, "nonzeros": 14},
                      "tetrahedral": {"tool": "qhull", "elements": 2, "edges": 6, "faces": 7, "nonzeros": 16,
                                      "flat": 1}},
                device={"name": "d", "resolving_level": 1, "depth": 2, "origin": ["0", "0", "1/3"],
                        "regions": [{"name": "r", "material": "Si", "elements": 1, "nodes": 4, "volume": "1",
                                     "volume_ok": True, "negative_coefficients": {"interior": 0, "boundary": 1},
                                     "control_volume_sum": "1"},
                                    {"name": "s", "material": "Ox", "elements": 1, "nodes": 4, "volume": "1",
                                     "volume_ok": False}],
                        "contacts": [{"name": "c", "region": "r", "faces": 1, "nodes": 3, "area": "1/2",
                                      "area_ok": True}], "interfaces": [{"name": "r|s", "faces": 1, "nodes": 3}]})
    data.update(sections)
    typed = MeshReport.from_dict(data)
    assert typed.to_dict() == data and MeshReport.from_dict(typed.to_dict()) == typed
    for key, section in sections.items():  # each section's keys in the order written above (the file's)
        assert json.dumps(typed.to_dict()[key]) == json.dumps(section), key
    assert typed.types_outside_catalogue == (outside,) and typed.leaf_mesh.fallback == "leaf elements"
    assert typed.dual.tetrahedral.flat == 1 and typed.device.regions[1].negative_coefficients is None
    assert typed.device.contacts[0].area_parts_sum is None and typed.device.origin == ("0", "0", "1/3")
