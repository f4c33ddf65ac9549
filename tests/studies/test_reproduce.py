"""The studies ``reproduce`` runs: the paper's boxes under both policies, the leaf studies, the other base elements."""

from __future__ import annotations

from fractions import Fraction
from itertools import product

from cospherical.core.exact import Length
from cospherical.paper import paper_studies
from cospherical.studies import engine, leaves
from cospherical.studies import reproduce as studies
from cospherical.studies.reproduce import LEAF_BOXES, PAPER_BOXES, paper_studies_total, run_paper_studies

# The cuboid's faces by their edges (design notes: VTK hexahedron edges (0,1) (1,2) (2,3) (3,0) (4,5) (5,6) (6,7)
# (7,4) (0,4) (1,5) (2,6) (3,7)): bottom, top, and the four sides.
FACE_EDGES = ((0, 1, 2, 3), (4, 5, 6, 7), (0, 4, 8, 9), (1, 5, 9, 10), (2, 6, 10, 11), (3, 7, 11, 8))


def test_the_total_counts_every_configuration_of_every_study():
    # A leaf configuration: an edge mask, and any set of the faces whose four edges are all split.
    leaf = sum(2 ** sum(all(mask[k] for k in face) for face in FACE_EDGES) for mask in product((0, 1), repeat=12))
    assert leaf == 6210
    assert paper_studies_total() == 4 * 2 * 2**12 + 2 * leaf + 2**9 + 2**8 + 2**6  # prism, pyramid, tetrahedron edges


def test_the_boxes_are_the_papers():
    def value(text) -> tuple[float, ...]:
        return tuple(round(float(Length.parse(str(x))), 4) for x in text)

    boxes = {value(box) for box in PAPER_BOXES}
    for key, study in paper_studies().items():
        if key.startswith("bisection"):
            assert value(study["box"]) in boxes, key
    assert ("1", "1.4142", "1.4142") in PAPER_BOXES and ("1", "sqrt(2)", "sqrt(2)") in PAPER_BOXES  # C as computed, and exact
    assert Length.parse("1.4142").squared == Fraction(7071, 5000) ** 2
    assert set(LEAF_BOXES) <= set(PAPER_BOXES)


def test_every_study_runs_and_reports_its_progress(monkeypatch):
    # On 4 configurations per study (the first codes of each family): the studies come out in order, each of its
    # box, policy and element, and the progress adds up to the total announced.
    for module in (engine, studies):
        monkeypatch.setattr(module, "bisection_codes", lambda element="cuboid", real=engine.bisection_codes:
                            real(element)[:4])
    for module in (leaves, studies):
        monkeypatch.setattr(module, "leaf_codes", lambda real=leaves.leaf_codes: real()[:4])
    done = []
    run = run_paper_studies(progress=done.append)
    assert sum(done) == paper_studies_total() == 8 * 4 + 2 * 4 + 3 * 4
    assert [(s.box.texts, s.face_points) for s in run.bisection] == [(box, policy) for box in PAPER_BOXES
                                                                     for policy in ("octree", "none")]
    assert [(s.name, s.box.texts) for s in run.leaves] == [("leaves", box) for box in LEAF_BOXES]
    assert [s.element for s in run.shapes] == ["prism", "pyramid", "tetrahedron"]
    assert all(s.configurations == 4 for s in run.bisection + run.leaves + run.shapes)
