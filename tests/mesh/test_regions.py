"""Devices: regions, contacts, interfaces; the mesh checked by an oracle that reads the files back with meshio.

The oracle knows only the device file (read here with PyYAML and Fractions, not with the
tool's reader) and what meshio reads: the tetrahedra of every element (the solvers'
conforming split, written as a tetrahedral VTU with the element's region) and, read
by VTK, the contact polygons of ``contacts.vtu``.  It checks, exactly (integers on the grid):
every tetrahedron's centroid lies in a box of its region; each region's tetrahedra
fill its volume; every triangle is shared by two tetrahedra of one region or of two
touching regions, or lies on the domain's boundary (the domain on one side only);
each contact's polygons lie in its rectangle and cover its area.
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import meshio
import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings, strategies as st

from cospherical import build_mesh
from cospherical.formats.vtu import write_grid
from cospherical.mesh.tetrahedra import split_tetrahedra
from cospherical.mesh.report import NegativeCoefficients

ROOT = Path(__file__).parents[2]
EXAMPLES = sorted((ROOT / "examples" / "devices").glob("*.yaml"))

pytestmark = [pytest.mark.oracle_meshio, pytest.mark.oracle_vtk]


def _device_boxes(data: dict) -> tuple[list, list, list[Fraction], list[Fraction]]:
    """The regions' boxes and the contacts as Fractions, and the bounding box (low corner, lengths)."""
    def exact(v):
        return Fraction(str(v))

    regions = [[tuple(exact(x) for x in box) for box in r["boxes"]] for r in data["regions"]]
    contacts = [(next(i for i, r in enumerate(data["regions"]) if r["name"] == c["region"]),
                 tuple(exact(x) for x in c["box"])) for c in data.get("contacts", [])]
    boxes = [b for r in regions for b in r]
    low = [min(b[a] for b in boxes) for a in range(3)]
    length = [max(b[a + 3] for b in boxes) - low[a] for a in range(3)]
    return regions, contacts, low, length


def _oracle(data: dict, folder: Path) -> None:
    regions, contacts, low, length = _device_boxes(data)
    mesh = meshio.read(folder / "tets.vtu")
    grid = int(np.asarray(mesh.field_data["grid_intervals"]).reshape(-1)[0])
    points = np.asarray(mesh.point_data["grid_coordinates"], dtype=np.int64)
    tets = mesh.cells_dict["tetra"].astype(np.int64)
    region = np.asarray(mesh.cell_data_dict["region"]["tetra"], dtype=np.int64)

    def on_grid(box):  # a box in grid units, exact (the device's coordinates are dyadic in its bounding box)
        values = [(box[i] - low[i % 3]) / length[i % 3] * grid for i in range(6)]
        assert all(v.denominator == 1 for v in values)
        return [int(v) for v in values]

    gridded = [[on_grid(b) for b in boxes] for boxes in regions]
    # every centroid in a box of its region (4 x centroid against 4 x the box)
    quad = points[tets].sum(axis=1)
    inside = np.zeros(len(tets), dtype=bool)
    for r, boxes in enumerate(gridded):
        for b in boxes:
            lo, hi = 4 * np.array(b[:3]), 4 * np.array(b[3:])
            inside |= (region == r) & np.all((quad >= lo) & (quad <= hi), axis=1)
    assert inside.all()
    # region volumes: six times a tetrahedron's volume is an integer determinant on the grid
    p = points[tets]
    six = np.abs(np.linalg.det((p[:, 1:] - p[:, :1]).astype(np.float64)).round()).astype(np.int64)
    assert (six > 0).all()
    for r, boxes in enumerate(regions):
        want = sum(((b[3] - b[0]) * (b[4] - b[1]) * (b[5] - b[2]) for b in boxes), Fraction(0))
        got = Fraction(int(six[region == r].sum()), 6 * grid ** 3) * length[0] * length[1] * length[2]
        assert got == want, (r, got, want)

    def in_domain(point3, normal_axis, sign):
        """Whether the domain holds the points just beyond ``point3 / 3`` along ``sign`` x the axis (exact)."""
        held = np.zeros(len(point3), dtype=bool)
        for boxes in gridded:
            for b in boxes:
                lo, hi = 3 * np.array(b[:3]), 3 * np.array(b[3:])
                ok = np.all((point3 >= lo) & (point3 <= hi), axis=1)
                ok &= np.where(sign > 0, point3[np.arange(len(point3)), normal_axis] < hi[normal_axis],
                               point3[np.arange(len(point3)), normal_axis] > lo[normal_axis])
                held |= ok
        return held

    touching = set()
    for r, a_boxes in enumerate(gridded):
        for s, b_boxes in enumerate(gridded):
            for a in a_boxes:
                for b in b_boxes:
                    for k in range(3):
                        others = [j for j in range(3) if j != k]
                        if (a[k + 3] == b[k] or b[k + 3] == a[k]) and all(
                                min(a[j + 3], b[j + 3]) > max(a[j], b[j]) for j in others):
                            touching.add((r, s))
    # faces: each triangle twice (same or touching regions), or once on the boundary
    triangles = np.sort(np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 2, 3]], tets[:, [0, 1, 3]],
                                        tets[:, [0, 1, 2]]]), axis=1)
    owner = np.tile(region, 4)
    order = np.lexsort(triangles.T[::-1])
    triangles, owner = triangles[order], owner[order]
    new = np.r_[True, np.any(triangles[1:] != triangles[:-1], axis=1)]
    starts = np.flatnonzero(new)
    counts = np.diff(np.r_[starts, len(triangles)])
    assert counts.max() <= 2
    pairs = starts[counts == 2]
    for r, s in set(zip(owner[pairs].tolist(), owner[pairs + 1].tolist())):
        assert r == s or (r, s) in touching
    single = triangles[starts[counts == 1]]
    tp = points[single]
    flat = np.array([[np.all(tp[i, :, k] == tp[i, 0, k]) for k in range(3)] for i in range(len(tp))])
    assert flat.any(axis=1).all()  # every boundary triangle is flat in an axis plane
    axis = np.argmax(flat, axis=1)
    centroid3 = tp.sum(axis=1)
    assert (in_domain(centroid3, axis, 1) != in_domain(centroid3, axis, -1)).all()
    # contacts: polygons in the rectangle, covering its area
    ids, polygons, which = _faces_by_vtk(folder / "contacts.vtu")
    for c, (r, box) in enumerate(contacts):
        g = on_grid(box)
        k = next(a for a in range(3) if g[a] == g[a + 3])
        u, v = [a for a in range(3) if a != k]
        twice = 0
        for polygon, tag in zip(polygons, which.tolist()):
            if tag != c:
                continue
            q = points[ids[np.asarray(polygon)]]
            assert np.all(q[:, k] == g[k])
            assert np.all((q[:, u] >= g[u]) & (q[:, u] <= g[u + 3]) & (q[:, v] >= g[v]) & (q[:, v] <= g[v + 3]))
            twice += abs(int((q[:, u] * np.roll(q[:, v], -1) - np.roll(q[:, u], -1) * q[:, v]).sum()))
        assert twice == 2 * (g[u + 3] - g[u]) * (g[v + 3] - g[v]), c


def _faces_by_vtk(path: Path):
    """contacts.vtu read by VTK: the points' global ids, each polygon's point indices, its contact."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    grid = reader.GetOutput()
    ids = vtk_to_numpy(grid.GetPointData().GetArray("global_id")).astype(np.int64)
    which = vtk_to_numpy(grid.GetCellData().GetArray("contact")).astype(np.int64)
    polygons = []
    for i in range(grid.GetNumberOfCells()):
        cell = grid.GetCell(i)
        polygons.append([cell.GetPointId(k) for k in range(cell.GetNumberOfPoints())])
    return ids, polygons, which


def _mesh_and_check(path: Path, folder: Path, dual: bool = False, uniform: bool = False):
    m = build_mesh(device=path, uniform=uniform, dual=dual)
    m.write(folder)
    tets = split_tetrahedra(m.assembled)
    write_grid(folder / "tets.vtu", m.assembled.vertices.astype(np.float64), np.full(len(tets), 10, np.uint8),
               tets.nodes.reshape(-1), 4 * np.arange(1, len(tets) + 1),
               point_data={"grid_coordinates": m.assembled.vertices.astype(np.int64)},
               cell_data={"region": tets.region.astype(np.int32)},
               field_data={"grid_intervals": np.array([m.assembled.grid], dtype=np.int64)})
    _oracle(yaml.safe_load(path.read_text()), folder)
    return m


def _surfaces(data: dict) -> tuple[list[Fraction], dict]:
    """From the device file alone (Fractions): per axis the domain's boundary area normal to it, as a fraction
    of the bounding box's side; per pair of regions (a < b) the area where their boxes touch."""
    regions, _, low, length = _device_boxes(data)
    planes = [sorted({b[a] for boxes in regions for b in boxes} | {b[a + 3] for boxes in regions for b in boxes})
              for a in range(3)]

    def owner(cell):  # the region of a cell of the planes' grid (its center in a box), or -1
        center = [(planes[a][cell[a]] + planes[a][cell[a] + 1]) / 2 for a in range(3)]
        return next((r for r, boxes in enumerate(regions) for b in boxes
                     if all(b[a] < center[a] < b[a + 3] for a in range(3))), -1)

    shape = [len(p) - 1 for p in planes]
    owners = {(i, j, k): owner((i, j, k)) for i in range(shape[0]) for j in range(shape[1]) for k in range(shape[2])}
    sides, touching = [Fraction(0)] * 3, {}
    for axis in range(3):
        b, c = (axis + 1) % 3, (axis + 2) % 3
        for cell in owners:
            for step in (-1, 1):
                beyond = list(cell)
                beyond[axis] += step
                other = owners.get(tuple(beyond), -1)
                area = (planes[b][cell[b] + 1] - planes[b][cell[b]]) * (planes[c][cell[c] + 1] - planes[c][cell[c]])
                here = owners[cell]
                if here >= 0 and other < 0:
                    sides[axis] += area / (length[b] * length[c])
                elif 0 <= here < other:
                    touching[here, other] = touching.get((here, other), Fraction(0)) + area
    return sides, touching


def _on_the_boundary(data: dict, points: np.ndarray, grid: int) -> np.ndarray:
    """Which grid points have the domain on some sides and not on others (from the device file, exactly)."""
    regions, _, low, length = _device_boxes(data)
    boxes = np.array([[int((b[i] - low[i % 3]) / length[i % 3] * grid) for i in range(6)]
                      for r in regions for b in r], dtype=np.int64)
    held = []
    for signs in np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T:  # the eight octants around
        lo, hi, p = boxes[None, :, :3], boxes[None, :, 3:], points[:, None, :]
        inside = np.where(signs > 0, (lo <= p) & (p < hi), (lo < p) & (p <= hi)).all(axis=2).any(axis=1)
        held.append(inside)
    held = np.array(held)
    return held.any(axis=0) & ~held.all(axis=0)


@pytest.mark.parametrize("example", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_devices_pass_the_oracle(example, tmp_path, capsys):
    from cospherical.cli import main

    # as the docs' command makes it (mesh --device FILE --dual --no-uniform), so its report can be held against
    # the one the devices page shows
    m = _mesh_and_check(example, tmp_path, dual=True)
    committed = ROOT / "results" / "devices" / example.stem / "report.json"
    assert (tmp_path / "report.json").read_bytes() == committed.read_bytes(), (
        f"{committed.relative_to(ROOT)} is not what the code writes: make it again with "
        f"cospherical mesh --device examples/devices/{example.name} --dual --no-uniform --out DIR, copy DIR's "
        "report.json and mesh.png over (CONTRIBUTING.md)")
    if example.stem in ("fin", "l-shape"):  # non-convex: check proves the elements a mesh of the union of boxes
        assert main(["check", str(tmp_path / "dual.npz")]) == 0, capsys.readouterr().err
        # the dual's boundary is the union's (notches, the fin's walls), its interfaces where regions touch
        data = yaml.safe_load(example.read_text())
        sides, touching = _surfaces(data)
        dual = m.dual
        assert list(dual.boundary_area_sums()) == sides
        assert np.array_equal(dual.boundary, _on_the_boundary(data, dual.grid_vertices, dual.grid))
        interfaces = dual.regions.interfaces
        assert [tuple(p) for p in interfaces.regions.tolist()] == sorted(touching)
        assert interfaces.areas() == [touching[tuple(p)] for p in interfaces.regions.tolist()]
        negative = [r.negative_coefficients for r in m.report.device.regions]
        assert dual.negative_coefficients() == NegativeCoefficients(sum(n.interior for n in negative),
                                                                    sum(n.boundary for n in negative))
    report = m.report
    assert report.volume_ok and report.nonconforming_faces == 0
    device = report.device
    assert all(r.volume_ok for r in device.regions) and all(c.area_ok for c in device.contacts)
    # mesh.vtu read by VTK: each cell's region, the names in field data
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(tmp_path / "mesh.vtu"))
    reader.Update()
    grid = reader.GetOutput()
    element = vtk_to_numpy(grid.GetCellData().GetArray("element"))
    region = vtk_to_numpy(grid.GetCellData().GetArray("region"))
    assert np.array_equal(region, m.assembled.element_region[element])
    names = bytes(vtk_to_numpy(grid.GetFieldData().GetArray("region_names"))).decode().split("\n")
    assert names == [r["name"] for r in yaml.safe_load(example.read_text())["regions"]]


@st.composite
def unions(draw):
    """A connected union of unit cubes of a 4 x 4 x 2 grid, in one or two regions, with a contact on a side."""
    cubes = {(0, 0, 0)}
    for _ in range(draw(st.integers(1, 6))):
        x, y, z = draw(st.sampled_from(sorted(cubes)))
        axis, step = draw(st.integers(0, 2)), draw(st.sampled_from((-1, 1)))
        cube = [x, y, z]
        cube[axis] += step
        if 0 <= cube[0] < 4 and 0 <= cube[1] < 4 and 0 <= cube[2] < 2:
            cubes.add(tuple(cube))
    for axis, size in enumerate((4, 4, 2)):  # a bounding box of 1, 2 or 4 cubes: dyadic, as a device needs
        values = [c[axis] for c in cubes]
        if max(values) - min(values) == 2:
            far = max(cubes, key=lambda c: c[axis])
            step = 1 if far[axis] + 1 < size else -1
            near = far if step > 0 else min(cubes, key=lambda c: c[axis])
            cubes.add(tuple(near[a] + (step if a == axis else 0) for a in range(3)))
    cubes = sorted(cubes)
    split = draw(st.integers(1, len(cubes)))
    names = ["a", "b"]
    regions = [{"name": names[k], "material": "Si", "boxes": [[x, y, z, x + 1, y + 1, z + 1] for x, y, z in part]}
               for k, part in enumerate((cubes[:split], cubes[split:])) if part]
    x, y, z = cubes[0]
    # leaves that are not cubes (z stretched) and a refinement point: the leaf mesh is not Delaunay, so each
    # region's cells are re-tessellated, across the faces between its cubes and around its notches
    stretch = draw(st.sampled_from((1, 3)))
    for region in regions:
        region["boxes"] = [[a, b, c * stretch, d, e, f * stretch] for a, b, c, d, e, f in region["boxes"]]
    low = [min(c[a] for c in cubes) for a in range(3)]
    high = [max(c[a] for c in cubes) + 1 for a in range(3)]
    point = [low[a] + (high[a] - low[a]) * draw(st.integers(0, 8)) / 8 for a in range(3)]  # in the bounding box
    return {"device": "union", "regions": regions,
            "contacts": [{"name": "c", "region": "a", "box": [x, y, z * stretch, x + 1, y + 1, z * stretch]}],
            "refine": [{"point": [point[0], point[1], point[2] * stretch]}], "levels": 2}


@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=unions())
def test_random_unions_of_boxes_pass_the_oracle(data, tmp_path_factory):
    folder = tmp_path_factory.mktemp("union")
    path = folder / "device.yaml"
    path.write_text(yaml.safe_dump(data))
    m = _mesh_and_check(path, folder / "out")
    _spheres_hold_what_the_mesh_says(m, data, strict=all(_convex(r["boxes"]) for r in data["regions"]))


@pytest.mark.parametrize("side", ["substrate", "oxide"])
def test_a_contact_on_an_interface_is_found_on_its_regions_side(side, tmp_path, capsys):
    # a contact buried at the interface z = 3/4 (its region on one side, the other region on the other): its
    # faces are interface faces, met twice, not faces of the domain's boundary (it had none, and check refused
    # the dual: area 0 is not the rectangle's)
    from cospherical.cli import main

    data = {"device": "buried", "regions": [
        {"name": "substrate", "material": "Si", "boxes": [[0, 0, 0, 1, 1, 0.75]]},
        {"name": "oxide", "material": "SiO2", "boxes": [[0, 0, 0.75, 1, 1, 1]]}],
        "contacts": [{"name": "buried", "region": side, "box": [0.25, 0.25, 0.75, 0.75, 0.75, 0.75]}], "levels": 2}
    path = tmp_path / "device.yaml"
    path.write_text(yaml.safe_dump(data))
    m = _mesh_and_check(path, tmp_path / "out", dual=True)
    contact = m.report.device.contacts[0]
    assert contact.faces > 0 and contact.area_ok and contact.area_parts_sum == "1/4"
    faces = m._result.faces
    region = [r["name"] for r in data["regions"]].index(side)
    assert (m.assembled.element_region[faces.contact_element] == region).all()
    assert main(["check", str(tmp_path / "out" / "dual.npz")]) == 0, capsys.readouterr().err


def _convex(boxes: list[list[int]]) -> bool:
    """Whether unit cubes (stretched alike) fill their bounding box: a convex region."""
    low = [min(b[a] for b in boxes) for a in range(3)]
    high = [max(b[a + 3] for b in boxes) for a in range(3)]
    volume = sum((b[3] - b[0]) * (b[4] - b[1]) * (b[5] - b[2]) for b in boxes)
    return volume == (high[0] - low[0]) * (high[1] - low[1]) * (high[2] - low[2])


@pytest.fixture(scope="module")
def mos_dual(tmp_path_factory):
    folder = tmp_path_factory.mktemp("mos")
    m = build_mesh(device=EXAMPLES[[p.stem for p in EXAMPLES].index("mos-capacitor")], uniform=False, dual=True)
    m.write(folder)
    return m, folder / "dual.npz"


def test_the_dual_splits_exactly_per_region(mos_dual):
    m, _ = mos_dual
    dual, parts = m.dual, m.dual.regions
    # every vertex's and edge's parts sum to its total exactly
    for index, values, den, total, total_den, count in (
            (parts.volume_vertex, parts.volume_exact, parts.volume_denominator, dual.volume_exact,
             dual.volume_denominator, len(dual.vertices)),
            (parts.coupling_edge, parts.coupling_exact, parts.coupling_denominator, dual.coefficient_exact,
             dual.coefficient_denominator, len(dual.edges))):
        summed = np.zeros(count, dtype=object)
        np.add.at(summed, index, values.astype(object))
        assert all(Fraction(int(a), den) == Fraction(int(b), total_den) for a, b in zip(summed, total))
    # a region's parts sum to its volume (the factor a*b*c is 1 here), a contact's to its rectangle's area
    assert parts.region_volumes() == [Fraction(3, 4), Fraction(1, 4)]
    assert parts.contact_areas() == [Fraction(1), Fraction(1, 4)]
    # an interface vertex has a part in each region
    both = np.bincount(parts.volume_vertex, minlength=len(dual.vertices)) == 2
    assert both.sum() == m.report.device.interfaces[0].nodes


def test_check_proves_the_region_parts_and_refuses_altered_ones(mos_dual, tmp_path, capsys):
    import sys
    sys.path.insert(0, str(Path(__file__).parents[1] / "formats"))
    from dual.forged import _resigned

    from cospherical.cli import main

    m, path = mos_dual
    assert main(["check", str(path)]) == 0
    capsys.readouterr()
    parts = m.dual.regions
    scale = {"volume_part": parts.volume_factor / parts.volume_denominator,
             "coupling_part": parts.volume_factor / parts.coupling_denominator,
             "contact_part": 1 / parts.contact_denominator, "interface_part": 1 / parts.interfaces.denominator}
    with np.load(path) as archive:
        members = {name: archive[name + "_exact"] for name in scale}
    for name, values in members.items():
        altered = values.copy()
        altered[0] += 1  # a part moved between two rows keeps every sum; its floats follow (only recomputing finds it)
        altered[1] -= 1
        target = tmp_path / f"{name}.npz"
        _resigned(path, target, members={name + "_exact": altered, name: altered.astype(np.float64) * scale[name]})
        assert main(["check", str(target)]) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and name.rsplit("_", 1)[0] in err, err
    # an interface face turned over (its normal into the substrate), or given to no interface: the faces are
    # compared with its elements' as oriented sets
    with np.load(path) as archive:
        faces, which = archive["interface_face_nodes"], archive["interface_face_interface"]
    turned = faces.copy()
    size = int((turned[0] >= 0).sum())
    turned[0, :size] = turned[0, :size][::-1]
    fewer = {"interface_face_nodes": faces[1:], "interface_face_interface": which[1:]}
    for name, members in (("turned", {"interface_face_nodes": turned}), ("fewer", fewer)):
        _resigned(path, tmp_path / f"{name}.npz", members=members)
        assert main(["check", str(tmp_path / f"{name}.npz")]) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and "member interface_face_nodes: not the faces between" in err, err


_STACK = """device: stack
regions:
  - {name: a, material: Si, boxes: [[0, 0, 0, 1, 2, 2]]}
  - {name: b, material: Ox, boxes: [[0, 0, 2, 1, 2, 3], [0, 0, 3, 1, 2, 4]]}
refine: [{point: [0.1, 0.1, 1.9]}]
levels: 4
"""


# One region of four boxes, not convex, in a 3 x 1 x 4 bounding box (leaves that are not cubes): near its notch a
# cell of the Delaunay subdivision of the region's vertices leaves the region, so one cluster keeps its leaf elements.
_NOTCH = """device: notch
regions:
  - name: a
    material: Si
    boxes: [[0, 0, 0, 1.5, 0.5, 2], [0, 0, 2, 1.5, 0.5, 4], [1.5, 0, 0, 3, 0.5, 2], [1.5, 0.5, 0, 3, 1, 2]]
refine: [{point: [0.739, 0.081, 1.123]}]
levels: 4
"""


@pytest.mark.parametrize("source", ["stack", "fin", "notch"])
def test_within_each_region_every_element_is_an_empty_sphere_of_the_region_vertices(source, tmp_path):
    """What the devices page promises, decided here with Fractions: each element's nodes lie on one sphere; an
    element the mesh does not name as violating holds no vertex of its region's closed boxes strictly inside (nor,
    where no cluster kept its leaf elements, on it but its own nodes); one it names holds one.  The 1 x 2 x 4 stack
    has leaves that are not cubes (its leaf mesh is not Delaunay: cells are re-tessellated per region, across the
    face between region b's two boxes); the notch keeps the leaf elements of a cluster."""
    path = tmp_path / "device.yaml"
    path.write_text({"stack": _STACK, "notch": _NOTCH}.get(source) or (EXAMPLES[0].parent / "fin.yaml").read_text())
    m = build_mesh(device=path, uniform=False, dual=source == "notch")
    report = m.report
    assert report.volume_ok and report.nonconforming_faces == 0
    violating = set(m.violating.tolist())
    if source == "stack":
        assert report.regions_retessellated >= 1 and not violating
    if source == "notch":
        assert violating and report.regions_retessellated >= 1
    crossing = _spheres_hold_what_the_mesh_says(m, yaml.safe_load(path.read_text()), strict=source != "notch",
                                                face=(2, 3 * m.assembled.grid // 4))  # b's two boxes meet at z = 3
    if source == "stack":
        assert crossing  # cells cross the face between region b's two boxes
    if source == "notch":
        _negatives_per_region_are_the_duals(m)


def _spheres_hold_what_the_mesh_says(m, data: dict, strict: bool, face: tuple[int, int] = (0, -1)) -> int:
    """Each element's nodes on one sphere (Fractions); it holds a vertex of its region's closed boxes strictly
    inside exactly when the mesh names it violating; with ``strict``, no such vertex on it but its own nodes either.
    Returns how many elements have nodes strictly on both sides of the plane ``face`` (axis, grid coordinate)."""
    violating = set(m.violating.tolist())
    assert len(violating) == m.report.delaunay_violations
    regions, _, low, length = _device_boxes(data)
    mesh = m.assembled
    grid = mesh.grid
    # integer coordinates proportional to the real ones (the box's lengths are rational)
    scale = [Fraction(x) / grid for x in length]
    common = 1
    for s in scale:
        common = common * s.denominator // np.gcd(common, s.denominator)
    factor = [int(s * common) for s in scale]
    points = [[int(g) * f for g, f in zip(row, factor)] for row in mesh.vertices.tolist()]
    members = []
    for boxes in regions:
        on = np.zeros(len(mesh.vertices), dtype=bool)
        for b in boxes:
            g = [int((b[i] - low[i % 3]) / length[i % 3] * grid) for i in range(6)]
            on |= np.all((mesh.vertices >= g[:3]) & (mesh.vertices <= g[3:]), axis=1)
        members.append(np.flatnonzero(on))
    real = np.array(points, dtype=np.float64)
    conn, sizes = mesh.connectivity()
    element_region = mesh.element_region
    crossing = 0
    for e, nodes in enumerate(conn.tolist()):
        nodes = [v for v in nodes if v >= 0]
        region = int(element_region[e])
        p = [points[v] for v in nodes]
        center = _circumcenter(p)
        radius = sum((x - c) ** 2 for x, c in zip(p[0], center))
        assert all(sum((x - c) ** 2 for x, c in zip(q, center)) == radius for q in p)
        own = set(nodes)
        # floats only narrow the vertices down (a wide margin); each one near the sphere is decided exactly
        near = members[region][((real[members[region]] - [float(c) for c in center]) ** 2).sum(axis=1)
                               <= float(radius) * (1 + 1e-6) + 1e-9]
        sides = [sum((x - c) ** 2 for x, c in zip(points[v], center)) - radius for v in near.tolist() if v not in own]
        assert (e in violating) == any(side < 0 for side in sides)
        if strict:
            assert all(side > 0 for side in sides)
        crossing += {np.sign(mesh.vertices[v][face[0]] - face[1]) for v in nodes} >= {-1, 1}
    return crossing


def _negatives_per_region_are_the_duals(m) -> None:
    """A one-region device: the report's interior negative coefficients are the dual's negative coefficients on
    edges of no face met once (the domain's boundary), counted here from the element faces."""
    mesh, dual = m.assembled, m.dual
    single: dict[tuple[int, ...], int] = {}
    for _, nodes, faces, _ in mesh.blocks():
        for cycle in faces:
            for row in nodes[:, list(cycle)].tolist():
                key = tuple(sorted(row))
                single[key] = single.get(key, 0) + 1
    boundary = set()
    for key, count in single.items():
        if count == 1:
            boundary |= {(a, b) for a in key for b in key if a < b}
    negative = [tuple(edge) for edge, c in zip(dual.edges.tolist(), dual.coefficient_exact.tolist()) if c < 0]
    interior = sum(1 for a, b in negative if (min(a, b), max(a, b)) not in boundary)
    assert m.report.device.regions[0].negative_coefficients.interior == interior


def _circumcenter(p: list[list[int]]) -> list[Fraction]:
    """The center of the sphere through the first four affinely independent points (Cramer's rule, exact)."""
    import itertools

    for i, j, k in itertools.combinations(range(1, len(p)), 3):
        rows = [[2 * (q[a] - p[0][a]) for a in range(3)] for q in (p[i], p[j], p[k])]
        rhs = [sum(x * x for x in q) - sum(x * x for x in p[0]) for q in (p[i], p[j], p[k])]
        det = _det(rows)
        if det:
            return [Fraction(_det([[rhs[r] if c == a else rows[r][c] for c in range(3)] for r in range(3)]), det)
                    for a in range(3)]
    raise AssertionError("a flat element")


def _det(m: list[list[int]]) -> int:
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


_HOLE = """device: cavity
regions:
  - name: shell
    material: Si
    boxes: [[0, 0, 0, 4, 4, 1], [0, 0, 3, 4, 4, 4], [0, 0, 1, 1, 4, 3], [3, 0, 1, 4, 4, 3], [1, 0, 1, 3, 1, 3],
            [1, 3, 1, 3, 4, 3]]
  - {name: core, material: Ox, boxes: [[1, 1, 1, 2, 3, 3]]}
contacts: [{name: inner, region: shell, box: [3, 1, 1, 3, 3, 3]}]
levels: 1
"""


def test_a_domain_with_a_box_shaped_hole_passes_the_oracle(tmp_path):
    """A shell around a cavity half filled by another region: the hole's leaves are dropped, and a contact lies on
    the cavity's wall (a boundary inside the bounding box)."""
    path = tmp_path / "cavity.yaml"
    path.write_text(_HOLE)
    m = _mesh_and_check(path, tmp_path / "out")
    assert m.report.volume == "15/16" and m.report.volume_ok  # 64 - 4 (the empty half of the cavity) of 4 x 4 x 4


@pytest.mark.parametrize("regions", [1, 2])
def test_contacts_vtu_is_written_when_the_device_has_named_faces_and_meshio_reads_it(regions, tmp_path):
    """A device of one region and no contact has no named face: no contacts.vtu (meshio cannot read a VTU of no
    cells), and the folder's manifest does not list it; with two regions and no contact, its interface faces are
    there and meshio reads them, none a contact."""
    text = "device: plain\nregions:\n  - {name: a, material: Si, boxes: [[0, 0, 0, 1, 1, 0.5]]}\n"
    if regions == 2:
        text += "  - {name: b, material: Ox, boxes: [[0, 0, 0.5, 1, 1, 1]]}\n"
    path = tmp_path / "device.yaml"
    path.write_text(text + "levels: 1\n")
    build_mesh(device=path, uniform=False).write(tmp_path / "out")
    written = tmp_path / "out" / "contacts.vtu"
    manifest = (tmp_path / "out" / ".cospherical-manifest.json").read_text()
    assert written.exists() == (regions == 2) and ("contacts.vtu" in manifest) == (regions == 2)
    if regions == 2:
        read = meshio.read(written)
        assert (read.cell_data_dict["contact"]["polygon"] == -1).all()
        assert (read.cell_data_dict["interface"]["polygon"] == 0).all() and len(read.cells_dict["polygon"]) == 4
