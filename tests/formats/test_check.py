"""``cospherical check``, the deep check of catalogues and pattern tables: good files pass, each kind of damage
is one line naming it."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest
from commands import cospherical, in_process, one_clean_line

from cospherical import Box
from cospherical.catalogue import catalogue_path, load_catalogue, shipped_catalogue
from cospherical.cli import main
from cospherical.errors import FormatError
from cospherical.files.flowyaml import mapping_line
from cospherical.files.yamlio import dump_yaml, load_yaml
from cospherical.formats.patterns import write_patterns
from cospherical.studies.engine import run_study

CUBE = ("1", "1", "1")
ROOT = Path(__file__).resolve().parents[2]


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
                   shipped_catalogue().version)
    data = load_yaml(path)
    data["configurations"][key] = data["configurations"].pop("888800000000+f4")
    dump_yaml(data, path)
    assert main(["check", str(path)]) == 2
    out, err = capsys.readouterr()
    assert len(err.strip().splitlines()) == 1 and needle in err, err


@pytest.fixture(scope="module")
def small_table(tmp_path_factory):
    """A pattern table of a few configurations of the 1x2x4 box, as data to break."""
    path = tmp_path_factory.mktemp("small") / "small.yaml"
    codes = ["000000000000", "800000000000", "880000000000", "888888888888"]
    study = run_study("bisection", Box.parse(("1", "2", "4")), codes)
    write_patterns(study, path, load_catalogue(catalogue_path()).version)
    return load_yaml(path)


@pytest.fixture(scope="module")
def catalogue_data():
    """The shipped catalogue as data, read once: each case edits a copy."""
    return load_yaml(ROOT / "catalogue" / "catalogue.yaml")


def write(tmp_path, name, data) -> str:
    path = tmp_path / name
    dump_yaml(data, path)
    return str(path)


def test_good_files_pass_the_deep_check(tmp_path, small_table):
    # a real process, as a user runs it; the refusals below run the command's code in the test's process
    result = cospherical("check", str(ROOT / "catalogue" / "catalogue.yaml"), write(tmp_path, "good.yaml", small_table))
    assert result.returncode == 0, result.stderr
    assert "ok, catalogue of" in result.stdout and "ok, pattern table of 4 configurations" in result.stdout


@pytest.mark.parametrize(
    "edit, needle",
    [
        (lambda d: d["configurations"]["800000000000"]["optimal"][0].update(type="v5f5-ffffff"), "unknown element type"),
        (lambda d: d["configurations"]["800000000000"]["optimal"][0].update(nodes=[0, 1, 2, 3, 26]), "node 26 is not a point"),
        (lambda d: d["configurations"]["800000000000"]["optimal"][0].update(nodes=[0, 1, 2, 3, 40]), "800000000000"),
        (lambda d: d["configurations"]["800000000000"]["optimal"].pop(), "do not fill the box"),
        (lambda d: d["configurations"]["880000000000"]["optimal"][0].update(
            nodes=list(reversed(d["configurations"]["880000000000"]["optimal"][0]["nodes"]))), "configurations/880000000000"),
        (lambda d: d["configurations"]["800000000000"]["optimal"].append(  # a copy: a shared object is a YAML alias
            copy.deepcopy(d["configurations"]["800000000000"]["optimal"][0])), "do not fill the box"),
        (lambda d: d["configurations"]["000000000000"].update(internal_faces="internal_edges_and_faces"), "internal_faces"),
        (lambda d: d.update(box=["1", "0", "4"]), "box"),
        (lambda d: d.update(schema_version=2), "schema_version"),
    ],
)
def test_bad_pattern_tables_are_refused(tmp_path, capsys, small_table, edit, needle):
    data = copy.deepcopy(small_table)
    edit(data)
    one_clean_line(in_process(capsys, "check", write(tmp_path, "bad.yaml", data)), needle)


def test_repeated_configuration_codes_are_refused(tmp_path, capsys, small_table):
    text = Path(write(tmp_path, "good.yaml", small_table)).read_text().splitlines()
    start = text.index("configurations:") + 1
    end = next(i for i in range(start + 1, len(text)) if text[i].startswith("  '"))
    duplicated = text[: end] + text[start:end] + text[end:]
    path = tmp_path / "twice.yaml"
    path.write_text("\n".join(duplicated[:200]) + "\n")
    one_clean_line(in_process(capsys, "check", path), "repeated key '000000000000'")


@pytest.mark.parametrize(
    "edit, needle",
    [
        (lambda d: d["types"].append(copy.deepcopy(d["types"][0])), "appears more than once"),
        (lambda d: d["types"][0].update(edges=99), "V/E/F"),
        (lambda d: d["types"][0]["reference_faces"][0].update(nodes=[0, 1, 9]), "reference_faces"),
        (lambda d: d["criteria"]["internal_faces"]["kept"].append("v4f4-000000"), "unknown type"),
        (lambda d: d["types"][0].pop("code"), "code"),
    ],
)
def test_bad_catalogues_are_refused(tmp_path, capsys, catalogue_data, edit, needle):
    data = copy.deepcopy(catalogue_data)
    edit(data)
    one_clean_line(in_process(capsys, "check", write(tmp_path, "bad-catalogue.yaml", data)), needle)


# Tables of the leaf family broken as the attacks broke them, and variants: each is refused by
# check and, with the same line, by the mesher that would use it (tests/formats/test_mesh.py).
LEAVES = ROOT / "patterns" / "leaves-1x1x1.yaml"
HEXAHEDRON, TETRAHEDRON = "v8f6-c3cb81", "v4f4-8f0284"
# the cube's six Kuhn tetrahedra around its diagonal 0-6, each positively oriented (VTK order)
KUHN = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]


def leaf_entries(*codes) -> dict:
    """The entries of ``codes`` in patterns/leaves-1x1x1.yaml, as data."""
    lines = {line.split("'")[1]: line for line in LEAVES.read_text().splitlines() if line.startswith("  '")}
    return {code: json.loads(lines[code].split(": ", 1)[1]) for code in codes}


def leaf_table(path: Path, entries: dict) -> Path:
    """A table of the leaf family of the unit cube (patterns/leaves-1x1x1.yaml's header) holding ``entries``."""
    text = LEAVES.read_text()
    header = text[:text.index("configurations:\n")]
    path.write_text(header + "configurations:\n" + "".join(mapping_line(code, entry) for code, entry in entries.items()))
    return path


def _optimal(elements: list) -> dict:
    return {"fvm_adequate": True, "optimal": elements, "internal_faces": "optimal",
            "internal_edges_and_faces": "optimal"}


def _element(type_id: str, nodes: list) -> dict:
    return {"type": type_id, "nodes": nodes, "circumcenter": [0.5, 0.5, 0.5]}  # every subset of the cube's corners


def _pyramid(entry: dict, nodes: list) -> dict:
    return _optimal([{**entry["optimal"][0], "nodes": nodes}] + entry["optimal"][1:])


# name -> (configuration, its broken entry from the good one, what the line says)
BROKEN = {
    "hexahedron mirrored": ("000000000000+f", lambda e: _optimal([_element(HEXAHEDRON, [0, 3, 2, 1, 4, 7, 6, 5])]),
                            "reference order"),
    "hexahedron mirrored in x": ("000000000000+f",
                                 lambda e: _optimal([_element(HEXAHEDRON, [1, 0, 3, 2, 5, 4, 7, 6])]), "reference order"),
    "hexahedron upside down": ("000000000000+f",
                               lambda e: _optimal([_element(HEXAHEDRON, [4, 5, 6, 7, 0, 1, 2, 3])]), "reference order"),
    "pyramid base clockwise": ("800000000000+f", lambda e: _pyramid(e, [0, 4, 7, 3, 8]), "reference order"),
    "pyramid base clockwise, turned": ("800000000000+f", lambda e: _pyramid(e, [3, 0, 4, 7, 8]), "reference order"),
    "wrong type id": ("000000000000+f", lambda e: _optimal([{**e["optimal"][0], "type": "v8f6-3bec1c"}]),
                      "type v8f6-3bec1c, recomputed v8f6-c3cb81"),
    "pyramid typed quadrilateral": ("800000000000+f",
                                    lambda e: _optimal([{**e["optimal"][0], "type": "v5f5-45a4de"}] + e["optimal"][1:]),
                                    "recomputed v5f5-58e6ed"),
    "500 copies of the cube": ("000000000000+f", lambda e: _optimal(e["optimal"] * 500), "do not fill the box"),
    "a Kuhn tetrahedron replaced by one of the other diagonal": (
        "000000000000+f", lambda e: _optimal([_element(TETRAHEDRON, t) for t in KUHN[:5] + [[1, 2, 3, 7]]]),
        "has no element on its other side"),
    "a Kuhn tetrahedron twice": (
        "000000000000+f", lambda e: _optimal([_element(TETRAHEDRON, t) for t in KUHN[:5] + [KUHN[0]]]),
        "belongs to 2 elements on the same side"),
}


def broken_table(path: Path, code: str, broken) -> Path:
    """A leaf table of the empty cube's and one edge point's entries, the entry of ``code`` passed through ``broken``."""
    entries = leaf_entries("000000000000+f", "800000000000+f")
    entries[code] = broken(entries[code])
    return leaf_table(path, entries)


@pytest.mark.parametrize("case", BROKEN)
def test_a_broken_leaf_table_is_refused_naming_the_configuration(tmp_path, capsys, case):
    code, broken, needle = BROKEN[case]
    path = broken_table(tmp_path / "broken.yaml", code, broken)
    assert main(["check", str(path)]) == 2
    line = capsys.readouterr().err.strip()
    assert len(line.splitlines()) == 1 and needle in line and f"broken.yaml: configurations/{code}" in line, line


def test_the_good_leaf_table_passes(tmp_path, capsys):
    path = leaf_table(tmp_path / "good.yaml", leaf_entries("000000000000+f", "800000000000+f"))
    assert main(["check", str(path)]) == 0, capsys.readouterr().err
    # the Kuhn tetrahedra tile the cube: the face rule refuses overlaps, not splits
    path = leaf_table(tmp_path / "kuhn.yaml", {"000000000000+f": _optimal([_element(TETRAHEDRON, t) for t in KUHN])})
    assert main(["check", str(path)]) == 0, capsys.readouterr().err


def _vtk_valid(points: list, cells: list[tuple[int, list[int]]]) -> list[bool]:
    """VTK's own verdict on each cell (VTK cell type, point ids): valid for its cell validator (planar convex
    faces, consistently oriented, edges and faces not crossing) with a positive signed volume (verdict's,
    through vtkMeshQuality: the validator passes an inverted tetrahedron)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkUnstructuredGrid
    from vtkmodules.vtkFiltersGeneral import vtkCellValidator
    from vtkmodules.vtkFiltersVerdict import vtkMeshQuality

    grid = vtkUnstructuredGrid()
    vtk_points = vtkPoints()
    for point in points:
        vtk_points.InsertNextPoint(*point)
    grid.SetPoints(vtk_points)
    for cell_type, ids in cells:
        grid.InsertNextCell(cell_type, len(ids), ids)
    validator = vtkCellValidator()
    validator.SetInputData(grid)
    validator.Update()
    quality = vtkMeshQuality()
    quality.SetInputData(grid)
    quality.SetTetQualityMeasureToVolume()
    quality.SetPyramidQualityMeasureToVolume()
    quality.SetWedgeQualityMeasureToVolume()
    quality.SetHexQualityMeasureToVolume()
    quality.Update()
    state = vtk_to_numpy(validator.GetOutput().GetCellData().GetArray("ValidityState"))
    volume = vtk_to_numpy(quality.GetOutput().GetCellData().GetArray("Quality"))
    return ((state == 0) & (volume > 0)).tolist()


@pytest.mark.oracle_vtk
def test_the_node_orders_check_accepts_are_those_vtk_finds_valid():
    """Orders of a VTK cell's nodes: the symmetries of its vertex-edge graph (networkx's; a tetrahedron's
    24, a pyramid's 8, a wedge's 12, a hexahedron's 48: combinatorially the same cell, mirror images
    among them) and a seeded sample of the other orders.  check accepts exactly those VTK finds valid:
    the turns of the cell, never a mirror image or a reordered cell."""
    import random
    from itertools import permutations

    import networkx as nx

    from cospherical.core.configuration import Configuration
    from cospherical.formats.check import EntryCheck
    from cospherical.formats.patterns import load

    check = EntryCheck(load(LEAVES).header, shipped_catalogue(), "leaves")
    catalogue = shipped_catalogue()
    vtk_type = {"tetra": 10, "wedge": 13, "hexahedron": 12, "pyramid": 14}
    cases = [("000000000000+f", _optimal([_element(TETRAHEDRON, t) for t in KUHN])),
             ("800000000000+f", leaf_entries("800000000000+f")["800000000000+f"]),
             ("000000000088+f", leaf_entries("000000000088+f")["000000000088+f"]),
             ("000000000000+f", _optimal([_element(HEXAHEDRON, list(range(8)))]))]
    points, cells, accepted, turns = [], [], [], 0
    for code, entry in cases:
        first = entry["optimal"][0]
        graph = nx.Graph((f[k], f[k - 1]) for face in catalogue[first["type"]].reference_faces for f in [face.nodes]
                         for k in range(len(f)))
        symmetries = [tuple(m[i] for i in range(len(graph)))
                      for m in nx.algorithms.isomorphism.GraphMatcher(graph, graph).isomorphisms_iter()]
        assert len(symmetries) == {4: 24, 5: 8, 6: 12, 8: 48}[len(graph)]
        every = list(permutations(range(len(graph))))
        others = random.Random(5).sample(every, min(24, len(every)))
        orders = symmetries + [p for p in others if p not in symmetries]
        turns += len(symmetries) // 2 if len(graph) != 5 else 4  # a pyramid turns about its axis only
        nodes = Configuration.from_code(code, Box.parse(CUBE)).nodes()
        ids = sorted(nodes)
        for order in orders:
            element = [first["nodes"][i] for i in order]
            try:
                check(code, {**entry, "optimal": [{**first, "nodes": element}] + entry["optimal"][1:]})
                accepted.append(True)
            except FormatError as error:
                assert "reference order" in str(error), error  # the same element: only its order is wrong
                accepted.append(False)
            cells.append((vtk_type[catalogue[first["type"]].vtk], [len(points) + ids.index(n) for n in element]))
        points += [tuple(map(float, nodes[n])) for n in ids]
    assert accepted == _vtk_valid(points, cells)
    assert sum(accepted) == turns


def test_an_entry_met_again_is_checked_once_and_a_changed_one_again(tmp_path, capsys):
    # check shares its work across the files of one run (SharedChecks): an entry that passed is
    # skipped where it recurs (same text, points, box, base element and criteria), nowhere else.
    from cospherical.formats.check import EntryCheck, SharedChecks, check_patterns
    from cospherical.formats.patterns import load

    good = leaf_table(tmp_path / "good.yaml", leaf_entries("000000000000+f", "800000000000+f"))
    shared = SharedChecks()
    check_patterns(load(good), shipped_catalogue(), "good", shared=shared)
    table = load(good)
    texts = {code: table.configurations.text(code) for code in table.configurations}
    again = EntryCheck(table.header, shipped_catalogue(), "again", shared=shared)
    assert all(again.passed_before(code, text) for code, text in texts.items())
    other_box = EntryCheck({**table.header, "box": ["1", "2", "4"]}, shipped_catalogue(), "brick", shared=shared)
    assert not any(other_box.passed_before(code, text) for code, text in texts.items())
    assert not again.passed_before("000000000000+f", texts["000000000000+f"].replace("true", "false", 1))
    # the broken table after the good one: its untouched entry is skipped, its broken one still refused
    code, broken, needle = BROKEN["a Kuhn tetrahedron twice"]
    bad = broken_table(tmp_path / "broken.yaml", code, broken)
    assert main(["check", str(good), str(bad)]) == 2
    line = capsys.readouterr().err.strip()
    assert len(line.splitlines()) == 1 and needle in line and f"broken.yaml: configurations/{code}" in line, line
