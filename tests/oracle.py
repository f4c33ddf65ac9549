"""Independent checks the tests share: Qhull's merged regions and networkx isomorphism."""

from __future__ import annotations

import shutil
import subprocess

import networkx as nx

QDELAUNAY = shutil.which("qdelaunay")


def qhull_regions(points: dict[int, tuple[float, float, float]]) -> set[frozenset[int]]:
    """Delaunay regions of ``qdelaunay Qz Fv`` (merged, non-simplicial), as node-id sets.

    Fails, never skips, when qhull-bin is not installed: the oracle is part of the suite.
    """
    assert QDELAUNAY, "qdelaunay not found: install Debian's qhull-bin (scripts/setup.sh does)"
    ids = sorted(points)
    text = f"3\n{len(ids)}\n" + "\n".join(" ".join(repr(x) for x in points[i]) for i in ids) + "\n"
    result = subprocess.run([QDELAUNAY, "Qz", "Fv"], input=text, capture_output=True, text=True, check=True)
    lines = result.stdout.split("\n")
    count = int(lines[0])
    regions = set()
    for line in lines[1 : 1 + count]:
        numbers = [int(x) for x in line.split()]
        assert numbers[0] == len(numbers) - 1
        regions.add(frozenset(ids[i] for i in numbers[1:]))
    return regions


def incidence_graph(faces, kinds) -> nx.Graph:
    """Vertex-face incidence graph, faces labelled by kind: it determines the labelled face lattice."""
    graph = nx.Graph()
    for index, (face, kind) in enumerate(zip(faces, kinds)):
        graph.add_node(("face", index), kind=kind)
        for v in face:
            graph.add_node(("vertex", v), kind="vertex")
            graph.add_edge(("face", index), ("vertex", v))
    return graph


def isomorphic(a, b) -> bool:
    """Whether two polyhedra (faces, kinds) have isomorphic labelled face graphs, by networkx."""
    return nx.is_isomorphic(
        incidence_graph(*a), incidence_graph(*b), node_match=lambda x, y: x["kind"] == y["kind"]
    )
