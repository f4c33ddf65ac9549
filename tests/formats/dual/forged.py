"""dual.npz files rewritten and re-signed: what only the reader's bounds and the verification refuse."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def _resigned(good: Path, target: Path, manifest_edit=None, members: dict | None = None) -> None:
    """A dual.npz whose manifest or members were rewritten and whose checksums were renewed to match:
    only the reader's own bounds can refuse it."""
    import hashlib
    import io
    import json
    import zipfile

    with zipfile.ZipFile(good) as source:
        blobs = {info.filename[:-4]: source.read(info) for info in source.infolist()}
    manifest = json.loads(np.lib.format.read_array(io.BytesIO(blobs.pop("manifest"))).tobytes().decode())
    for name, array in (members or {}).items():
        buffer = io.BytesIO()
        np.lib.format.write_array(buffer, array, allow_pickle=False)
        blobs[name] = buffer.getvalue()
    manifest["sha256"] = {name: hashlib.sha256(blob).hexdigest() for name, blob in blobs.items()}
    if manifest_edit:
        manifest = manifest_edit(manifest) or manifest
    buffer = io.BytesIO()
    text = manifest if isinstance(manifest, str) else json.dumps(manifest)  # an edit may give the text itself
    np.lib.format.write_array(buffer, np.frombuffer(text.encode(), dtype=np.uint8))
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("manifest.npy", buffer.getvalue())
        for name, blob in blobs.items():
            archive.writestr(f"{name}.npy", blob)


def _edited(good: Path, target: Path, edit) -> None:
    """A re-signed copy of ``good`` whose members ``edit(arrays)`` changed in place (numpy arrays by name)."""
    import io
    import zipfile

    with zipfile.ZipFile(good) as source:
        arrays = {info.filename[:-4]: np.lib.format.read_array(io.BytesIO(source.read(info)))
                  for info in source.infolist() if info.filename != "manifest.npy"}
    changed = set(edit(arrays))
    _resigned(good, target, members={name: arrays[name] for name in changed})

# the cube's six Kuhn tetrahedra around its diagonal 0-6 (corners in VTK hexahedron order) and tetrahedra of the
# same volume (1/6 of the cube) around the other diagonals
KUHN = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]
OTHER_DIAGONAL = [[1, 2, 3, 7], [4, 5, 7, 2], [3, 0, 1, 5]]


def _forged_dual(path: Path, replaced: dict[int, list[list[int]]], tetrahedra: bool = False) -> Path:
    """The dual.npz of the uniform 4 x 4 x 4 cube tree (64 hexahedra, or with ``tetrahedra`` their
    conforming split: each cube's six Kuhn tetrahedra) whose ``replaced`` interior cubes (k: the k-th
    interior one) are given instead as these tetrahedra (corners of the cube, VTK order), its dual
    computed from those elements and written as the mesher writes it: every value is its elements'."""
    from cospherical.core.configuration import Box
    from cospherical.formats.dual import write_dual
    from cospherical.mesh.assembly import assemble
    from cospherical.mesh.dual import mesh_dual
    from cospherical.mesh.octree import build_octree, parse_shape
    from cospherical.mesh.tetrahedra import split_tetrahedra

    mesh = assemble(build_octree(Box.parse(["1", "1", "1"]), 2, [parse_shape("point:0.5,0.5,0.5")]))
    conn, sizes = mesh.connectivity()
    inside = [e for e in range(len(mesh)) if ((mesh.tree.positions[mesh.element_leaf[e]] % 3) > 0).all()]
    assert len(mesh) == 64 and len(inside) == 8 and (sizes == 8).all()
    split = split_tetrahedra(mesh)
    rows = []
    for e in range(len(mesh)):
        own = [np.r_[t, [-1] * 4] for t in split.nodes[split.parent == e]] if tetrahedra else [conn[e]]
        if e in inside and inside.index(e) in replaced:
            if tetrahedra:  # the split is the Kuhn one: the forgery differs from it only where it says
                assert {frozenset(t[:4]) for t in own} == {frozenset(conn[e][k]) for k in KUHN}
            own = [np.r_[conn[e][t], [-1] * 4] for t in replaced[inside.index(e)]]
        rows += own
    nodes = np.array(rows, dtype=np.int32)
    write_dual(mesh_dual(mesh, (nodes, (nodes >= 0).sum(axis=1).astype(np.int8))), path)
    return path


def _with_contact_faces(good: Path, target: Path, faces: np.ndarray, which: np.ndarray, regions=None,
                        element_region=None) -> None:
    """The dual at ``good`` with other contact faces (and contact regions), its contact parts computed again
    from them by the library itself: consistent, so only the check of the faces themselves can refuse it."""
    from dataclasses import replace
    from fractions import Fraction

    from cospherical.formats.dual import read_dual, write_dual
    from cospherical.mesh.regions import region_parts

    dual = read_dual(good)
    parts = dual.regions
    regions = regions or parts.contact_regions
    contacts = tuple((name, region, box, next(a for a in range(3) if Fraction(box[a]) == Fraction(box[a + 3])))
                     for name, region, box in zip(parts.contact_names, regions, parts.contact_boxes))
    element_region = parts.element_region if element_region is None else element_region
    again = region_parts(dual.box, dual.grid, dual.grid_vertices, dual, element_region, parts.names,
                         parts.materials, contacts, faces, which, tuple(Fraction(t) for t in dual.box.texts),
                         parts.origin, boxes=parts.boxes)
    write_dual(replace(dual, regions=again), target)
