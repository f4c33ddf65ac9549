"""Independent checks the tests share: Qhull's merged regions (a configuration, a whole mesh), networkx isomorphism."""

from __future__ import annotations

import functools
import math
import shutil
import subprocess

import networkx as nx
import numpy as np

QDELAUNAY = shutil.which("qdelaunay")


def qhull_regions(points: dict[int, tuple[float, float, float]]) -> set[frozenset[int]]:
    """Delaunay regions of ``qdelaunay Qz Fv`` (merged, non-simplicial), as node-id sets.

    Fails, never skips, when qhull-bin is not installed: the oracle is part of the suite.
    """
    assert QDELAUNAY, "qdelaunay not found: install Debian's qhull-bin (scripts/setup.sh does)"
    ids = sorted(points)
    text = f"3\n{len(ids)}\n" + "\n".join(" ".join(repr(x) for x in points[i]) for i in ids) + "\n"
    return {frozenset(ids[i] for i in region) for region in _qdelaunay(text)}


@functools.lru_cache(maxsize=4096)
def _qdelaunay(text: str) -> tuple[tuple[int, ...], ...]:
    # Qhull's regions of one input, as point indices; the same input text is run once per test process
    # (a bisection configuration without face points is the same point set under both face-point policies)
    result = subprocess.run([QDELAUNAY, "Qz", "Fv"], input=text, capture_output=True, text=True, check=True)
    lines = result.stdout.split("\n")
    count = int(lines[0])
    regions = []
    for line in lines[1 : 1 + count]:
        numbers = [int(x) for x in line.split()]
        assert numbers[0] == len(numbers) - 1
        regions.append(tuple(numbers[1:]))
    return tuple(regions)


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


def _isometry(corners, image_corners, squared):
    """The affine map of the box taking its corners to ``image_corners``, checked to be an isometry.

    Nodes are in the box's unit coordinates, corner k at its VTK position: the map is
    ``origin + x*X + y*Y + z*Z`` with X, Y, Z the images of the three edges at corner 0.
    It must send all eight corners where the node map says, and keep the Gram matrix of
    those three edges in the box's metric (a linear map keeping the inner products of a
    basis is orthogonal).
    """
    origin = image_corners[0]
    columns = [tuple(b - a for a, b in zip(origin, image_corners[k])) for k in (1, 3, 4)]

    def apply(p):
        return tuple(origin[i] + sum(p[j] * columns[j][i] for j in range(3) if columns[j][i]) for i in range(3))

    edges = [tuple(b - a for a, b in zip(corners[0], corners[k])) for k in (1, 3, 4)]
    assert tuple(corners[0]) == (0, 0, 0) and edges == [(1, 0, 0), (0, 1, 0), (0, 0, 1)], "not unit coordinates"
    for a in range(3):
        for b in range(3):
            assert sum(w * x * y for w, x, y in zip(squared, edges[a], edges[b])) == \
                sum(w * x * y for w, x, y in zip(squared, columns[a], columns[b])), "not an isometry"
    assert all(apply(corners[k]) == image_corners[k] for k in range(8)), "corners not mapped affinely"
    return apply


def qhull_regions_by_orbit(configurations, symmetries) -> list[set[frozenset[int]]]:
    """Qhull's regions of every configuration of one box, running Qhull once per orbit.

    The Delaunay subdivision of a point set is unique, so an isometry taking one point set
    onto another takes its regions onto the other's: Qhull's answer for an orbit's
    representative, carried across by the node map of a box symmetry, is Qhull's answer for
    every member.  That the node map is such an isometry is checked here exactly rather
    than taken from the library: it must pair the two point sets one to one, and every
    node must land where the affine map fixed by the corners puts it, that map keeping
    the box's metric (see :func:`_isometry`).
    """
    from cospherical import Configuration
    from cospherical.core.symmetry import orbit_representatives

    configurations = list(configurations)
    reps, sym_index = orbit_representatives([cfg.code for cfg in configurations], symmetries)
    answers: dict[str, tuple[dict, set]] = {}
    maps: dict[int, object] = {}
    found = []
    mapped: set = set()  # (symmetry, point, image) triples already checked: the same map, the same answer
    for cfg, rep, index in zip(configurations, reps, sym_index):
        if rep not in answers:
            image = Configuration.from_code(rep, cfg.box, cfg.face_points)
            answers[rep] = (image.nodes(), qhull_regions(image.real_nodes()))
        image_nodes, regions = answers[rep]
        node_map, nodes = symmetries[index].node_map, cfg.nodes()
        if index not in maps:
            maps[index] = _isometry([nodes[k] for k in range(8)], [image_nodes[node_map[k]] for k in range(8)],
                                    cfg.box.squared)
        assert sorted(node_map[n] for n in nodes) == sorted(image_nodes), (cfg.code, rep)
        for n, p in nodes.items():
            if (index, p, image_nodes[node_map[n]]) not in mapped:
                assert maps[index](p) == image_nodes[node_map[n]], (cfg.code, rep)
                mapped.add((index, p, image_nodes[node_map[n]]))
        back = {node_map[n]: n for n in nodes}
        found.append({frozenset(back[n] for n in region) for region in regions})
    return found


def _det3(a, b, c):
    return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]))


def _det4(rows):
    total = 0
    for j in range(4):
        minor = [[r[k] for k in range(4) if k != j] for r in rows[1:]]
        total += (-1) ** j * rows[0][j] * _det3(*minor)
    return total


def oracle_cells(mesh) -> set[frozenset[int]]:
    """Qhull's tetrahedra of every vertex, merged across faces when the fifth point is exactly on the sphere."""
    from scipy.spatial import Delaunay

    den = math.lcm(*(w.denominator for w in mesh.box.squared))
    w = [int(x * den) for x in mesh.box.squared]
    coords = [tuple(int(x) for x in v) for v in mesh.vertices]
    tri = Delaunay(mesh.vertices * (np.array(mesh.box.to_float()) / mesh.grid), qhull_options="Qbb Qc Qz Q12 Qt")
    assert len(tri.coplanar) == 0
    simplices = tri.simplices.tolist()

    def on_sphere(tet, v) -> bool:
        o = coords[tet[0]]
        rows = []
        for u in (*tet[1:], v):
            d = [coords[u][a] - o[a] for a in range(3)]
            rows.append([*d, sum(w[a] * d[a] ** 2 for a in range(3))])
        return _det4(rows) == 0

    def flat(tet) -> bool:
        o = coords[tet[0]]
        return _det3(*([coords[u][a] - o[a] for a in range(3)] for u in tet[1:])) == 0

    parent = list(range(len(simplices)))

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    is_flat = [flat(t) for t in simplices]
    for t, tet in enumerate(simplices):
        for i, u in enumerate(tri.neighbors[t].tolist()):
            if u < 0 or is_flat[t] or is_flat[u]:
                continue
            if on_sphere(tet, simplices[u][list(tri.neighbors[u]).index(t)]):
                parent[find(t)] = find(u)
    # through flat tetrahedra (four co-circular points): join their solid neighbours that share a sphere
    flat_parent = {t: t for t, f in enumerate(is_flat) if f}

    def flat_find(x):
        while flat_parent[x] != x:
            x = flat_parent[x]
        return x

    for t in flat_parent:
        for u in tri.neighbors[t].tolist():
            if u in flat_parent:
                flat_parent[flat_find(t)] = flat_find(u)
    around: dict[int, set[int]] = {}
    for t in flat_parent:
        around.setdefault(flat_find(t), set()).update(u for u in tri.neighbors[t].tolist()
                                                      if u >= 0 and not is_flat[u])
    for solid in around.values():
        solid = sorted(solid)
        for i, a in enumerate(solid):
            for b in solid[i + 1:]:
                if all(on_sphere(simplices[a], v) for v in simplices[b]):
                    parent[find(a)] = find(b)
    cells: dict[int, set[int]] = {}
    for t, tet in enumerate(simplices):
        if not is_flat[t]:
            cells.setdefault(find(t), set()).update(tet)
    return {frozenset(c) for c in cells.values()}
