"""What occurs in a mesh: types and configurations counted over its leaves, beside the uniform bisection study."""

from __future__ import annotations

import dataclasses
from collections import Counter

import pytest

from cospherical.catalogue import shipped_catalogue
from cospherical.core.configuration import Box, Configuration
from cospherical.mesh.assembly import PAPER_FINAL, assemble
from cospherical.mesh.octree import build_octree, parse_shape
from cospherical.mesh.statistics import (in_bisection_family, level_counts, mesh_statistics, occurrences,
                                         shipped_uniform, statistics, uniform_figures, uniform_study)

CUBE = Box.parse(["1", "1", "1"])


@pytest.fixture(scope="module")
def mesh():
    """Three levels in the cube, refined towards a sphere: leaves of several configurations."""
    return assemble(build_octree(CUBE, 3, [parse_shape("sphere:0.5,0.5,0.5,0.3")]))


@pytest.fixture(scope="module")
def uniform():
    return uniform_study(CUBE, shipped_catalogue(), computed=True)


def test_the_uniform_study_of_the_cube_is_the_papers_table_2(uniform):
    # Box A of the paper: 37,259 elements over the 4096 bisection configurations, 195 cuboids, 18,450 tetrahedra.
    assert uniform.elements == 37259 == sum(uniform.counts.values())
    by_class = Counter()
    for type_id, count in uniform.counts.items():
        by_class[uniform.types[type_id].paper_class] += count
    assert by_class["Cuboid"] == 195 and by_class["Tetrahedron"] == 18450


def test_the_shipped_uniform_studies_are_the_computed_ones(uniform, full):
    # The cube's figures (computed above, 0.2 s); with --full every shipped box's (about 2 s in all).
    shipped = uniform_study(CUBE, shipped_catalogue())
    assert shipped == uniform and list(shipped.counts) == list(uniform.counts)  # the same order too
    for box in (["1", "1", "1"], ["2", "2", "2"], ["3/2", "3", "6"], ["1", "1.4142", "1.4142"], ["7", "7*sqrt(2)", "7*sqrt(2)"]):
        assert shipped_uniform(Box.parse(box)) is not None, box  # a box of a shipped shape, scaled or not
    for box in (["1", "1", "3"], ["2", "1", "1"], ["1", "1.4143", "1.4142"]):
        assert shipped_uniform(Box.parse(box)) is None, box  # computed: other proportions, or the same turned
    if full:
        import importlib.util
        from pathlib import Path

        script = Path(__file__).resolve().parents[2] / "scripts" / "uniform_studies.py"
        spec = importlib.util.spec_from_file_location("uniform_studies", script)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        assert [uniform_figures(Box.parse(list(b))) for b in module.BOXES] == [
            shipped_uniform(Box.parse(list(b))) for b in module.BOXES]


def test_the_shipped_uniform_studies_cover_the_shipped_tables():
    from pathlib import Path

    import yaml

    for path in sorted((Path(__file__).resolve().parents[2] / "patterns").glob("*.yaml")):
        header = yaml.safe_load(path.read_text().split("\nconfigurations:\n")[0])
        if header.get("element", "cuboid") == "cuboid":
            assert shipped_uniform(Box.parse(header["box"])) is not None, path.name


def test_occurrences_add_up_to_the_mesh(mesh):
    types, configurations = occurrences(mesh)
    assert sum(types.values()) == len(mesh)
    assert sum(c.leaves for c in configurations.values()) == len(mesh.tree)
    assert level_counts(mesh.tree) == {str(k): v for k, v in sorted(Counter(mesh.tree.levels.tolist()).items())}
    assert len(configurations) > 2


def test_shares_and_the_papers_final_elements(mesh, uniform):
    data = mesh_statistics(mesh, uniform)
    rows = data.type_frequencies
    assert [r.count for r in rows] == sorted((r.count for r in rows), reverse=True)
    assert sum(r.count for r in rows) == len(mesh)
    assert sum(r.share for r in rows) == pytest.approx(1, abs=1e-5)
    final = sum(r.count for r in rows if r.paper_class in PAPER_FINAL)
    assert data.paper_final_share == round(final / len(mesh), 6)
    assert sum(r.uniform_count for r in rows) == 37259  # every type of the uniform study has its row
    assert data.uniform.elements == 37259 and data.uniform.configurations == 4096
    leaves = data.configuration_frequencies
    assert sum(c.leaves for c in leaves) == len(mesh.tree)
    assert data.leaves_in_bisection_family == sum(c.leaves for c in leaves if c.uniform_share is not None)
    assert mesh_statistics(mesh).uniform is None


def test_pieces_add_up_like_the_whole(mesh):
    # A partitioned mesh's pieces add their occurrences: twice the same mesh counts everything twice.
    types, configurations = occurrences(mesh)
    doubled = {code: dataclasses.replace(c, leaves=2 * c.leaves) for code, c in configurations.items()}
    once = statistics(types, configurations, len(mesh.tree), mesh.types, mesh.catalogue)
    twice = statistics(types + types, doubled, 2 * len(mesh.tree), mesh.types, mesh.catalogue)
    assert [(r.id, r.share) for r in once.type_frequencies] == [(r.id, r.share) for r in twice.type_frequencies]
    assert once.paper_final_share == twice.paper_final_share


@pytest.mark.parametrize("code, member", [
    ("000000000000", True), ("888888888888", True),          # octree face and body points: the bisection study's
    ("888888888888+f", False), ("888800000000+f4", True),   # all faces dropped; a refined face that the octree has
    ("880000000000+f", True), ("888800000000+f", False),     # an unsplit face: no point; four split edges, no point
])
def test_a_leaf_is_in_the_bisection_family_when_its_point_set_is(code, member):
    configuration = Configuration.from_code(code)
    octree = Configuration.from_code(code.split("+")[0])
    assert in_bisection_family(configuration) is member
    assert member == (sorted(configuration.nodes().values()) == sorted(octree.nodes().values()))


def test_a_type_is_named_by_the_catalogue_or_by_itself(mesh):
    types, configurations = occurrences(mesh)
    data = statistics(types, configurations, len(mesh.tree), {}, shipped_catalogue())
    for row in data.type_frequencies:
        entry = shipped_catalogue()[row.id]
        assert (row.name, row.paper_class) == (entry.name, entry.paper_class)
