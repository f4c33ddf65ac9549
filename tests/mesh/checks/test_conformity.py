"""The conformity check: a mesh's own faces, and faces of bare element lists (a dual's), paired alike."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

from cospherical.core.configuration import Box
from cospherical.errors import InputError
from cospherical.mesh.assembly import assemble
from cospherical.mesh.checks import check_conformity, element_faces, pair_faces
from cospherical.mesh.octree import build_octree, parse_shape

from ..test_dual import octrees

BRICK = Box.parse(["1", "2", "4"])


def _shapes(vertices: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Each element's class of translates, node for node (what check computes from a dual's elements)."""
    coords = np.where((conn >= 0)[..., None], vertices[np.maximum(conn, 0)], 0)
    relative = np.where((conn >= 0)[..., None], coords - coords[:, :1], -1).reshape(len(conn), -1)
    return np.unique(relative, axis=0, return_inverse=True)[1].reshape(-1)


def test_faces_of_elements_given_by_their_vertices_pair_as_the_meshs_own():
    """The faces check computes from bare element lists (a dual's) pair exactly as the mesh's own faces do:
    same interior pairs and boundary faces; and faces that would take more memory than allowed are
    refused before any is made."""
    mesh = assemble(build_octree(BRICK, 3, [parse_shape("sphere:0.5,1,2,0.6")]))
    conn, sizes = mesh.connectivity()
    shape = _shapes(mesh.vertices, conn)
    faces = element_faces(mesh.vertices, conn, sizes, shape, BRICK.squared)
    needed = sum(rows.nbytes for parts in faces.values() for rows in parts)
    found = pair_faces(faces, mesh.vertices, mesh.grid)
    own = check_conformity(mesh)
    assert found == own and own.nonconforming_faces == 0 and own.interior_faces > 0
    # one element's nodes moved to another's: the faces no longer pair
    conn[3] = conn[200]
    broken = pair_faces(element_faces(mesh.vertices, conn, sizes, _shapes(mesh.vertices, conn), BRICK.squared),
                        mesh.vertices, mesh.grid)
    assert broken.nonconforming_faces > 0
    with pytest.raises(InputError, match="faces need"):
        element_faces(mesh.vertices, conn, sizes, shape, BRICK.squared, most_bytes=needed)


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(octrees())
def test_bare_element_lists_pair_as_the_mesh_on_any_octree(mesh):
    conn, sizes = mesh.connectivity()
    faces = element_faces(mesh.vertices, conn, sizes, _shapes(mesh.vertices, conn), mesh.box.squared)
    assert pair_faces(faces, mesh.vertices, mesh.grid) == check_conformity(mesh)


def test_faces_given_as_columns_of_a_table_pair_as_the_same_faces_given_as_rows():
    # A mesh hands its faces as columns of a leaf table (its rows rank alike: ranked together, from the
    # first row); any other table's rows are ranked one by one. Either way the pairs, the faces met once
    # and the examples are those of the same faces given as plain rows of ids.
    rng = np.random.default_rng(5)
    grid = 64
    vertices = rng.integers(1, grid, (400, 3))  # off the box's boundary: a face met once is nonconforming
    ranked_alike = np.sort(rng.permuted(np.tile(np.arange(400), (50, 1)), axis=1)[:, :4], axis=1)
    shuffled = rng.permuted(ranked_alike, axis=1)
    assert (np.diff(ranked_alike, axis=1) > 0).all() and not (np.diff(shuffled, axis=1) > 0).all()
    cycles = [(0, 1, 2), (2, 1, 0), (0, 1, 3), (1, 2, 3), (3, 2, 1)]
    for table in (ranked_alike, shuffled, ranked_alike[:1]):
        as_columns = {3: [(table, cycle) for cycle in cycles]}
        as_rows = {3: [table[:, list(cycle)] for cycle in cycles]}
        found = pair_faces(as_columns, vertices, grid, examples=50)
        assert found == pair_faces(as_rows, vertices, grid, examples=50)
        assert found.interior_faces == 2 * len(table) and found.nonconforming_faces == 1 * len(table)
