"""The JSON/YAML shape of a tessellation: what it says of each element holds for the nodes it lists."""

from __future__ import annotations

import json
import random

import numpy as np
import pytest

from cospherical import Configuration, tessellate
from cospherical.formats.tessellation import tessellation_data


@pytest.mark.parametrize("box", [("1", "2", "4"), ("1", "1", "1"), ("1", "sqrt(2)", "1.4142")])
def test_circumcenters_nodes_and_verdicts_agree_with_the_coordinates(box):
    rng = random.Random(str(box))
    lengths = np.array([float(Configuration.from_code("0" * 12, box=box).box.lengths[k]) for k in range(3)])
    verdicts = set()
    for mask in rng.sample(range(4096), 12):
        code = "".join("8" if mask >> k & 1 else "0" for k in range(12))
        data = json.loads(json.dumps(tessellation_data(tessellate(Configuration.from_code(code, box=box)))))
        nodes = {int(i): np.array(p) for i, p in data["nodes"].items()}
        assert data["code"] == code and data["box"] == list(box)
        assert {n for e in data["elements"] for n in e["nodes"]} == set(nodes)  # every node is some element's
        closed = opened = True
        for element in data["elements"]:
            center = np.array(element["circumcenter"])
            radii = [np.linalg.norm(nodes[n] - center) for n in element["nodes"]]
            assert np.ptp(radii) < 1e-9 * max(radii), (code, element["name"])  # one sphere through all its nodes
            assert len(element["nodes"]) == element["vertices"] and element["name"]
            closed &= bool(np.all(center >= -1e-12) and np.all(center <= lengths + 1e-12))
            opened &= bool(np.all(center > 1e-12) and np.all(center < lengths - 1e-12))
        assert (data["fvm_adequate"], data["fvm_adequate_open"]) == (closed, opened), code
        verdicts.add((closed, opened))
    if box == ("1", "2", "4"):  # most of its configurations are not FVM-adequate: both verdicts are met
        assert {True, False} <= {closed for closed, _ in verdicts}, verdicts
