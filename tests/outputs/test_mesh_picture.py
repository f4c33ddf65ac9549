"""``mesh.png``: the picture's sections are VTK's cut of the same grid, drawn in their types' colours."""

from __future__ import annotations

import numpy as np
import pytest
import vtk
from vtk.util.numpy_support import vtk_to_numpy

from cospherical.formats.mesh import write_vtu
from tests.formats.test_mesh import mixed_mesh, read_vtk


@pytest.mark.oracle_vtk
def test_the_picture_cuts_what_vtk_cuts(tmp_path):
    """The picture's sections are VTK's cut of the same grid by the same plane (vtkCutter), element for element."""
    from cospherical.outputs.mesh_picture import cut_polygons

    mesh = mixed_mesh()
    write_vtu(mesh, tmp_path / "mesh.vtu")
    at = 0.3
    polygons, types = cut_polygons(mesh, at)
    plane = vtk.vtkPlane()
    plane.SetOrigin(0, 0, (round(at * mesh.grid) + 1 / 3) / mesh.grid)
    plane.SetNormal(0, 0, 1)
    cutter = vtk.vtkCutter()
    cutter.SetCutFunction(plane)
    cutter.SetInputData(read_vtk(tmp_path / "mesh.vtu"))
    sizes = vtk.vtkCellSizeFilter()
    sizes.SetInputConnection(cutter.GetOutputPort())
    sizes.Update()
    cut = sizes.GetOutput()
    element = vtk_to_numpy(cut.GetCellData().GetArray("element"))
    area = np.bincount(element, vtk_to_numpy(cut.GetCellData().GetArray("Area")), minlength=len(mesh))
    theirs = np.sort(area[area > 0])

    def shoelace(p):
        x, y = p[:, 0], p[:, 1]
        return 0.5 * (x * np.roll(y, -1) - np.roll(x, -1) * y).sum()

    ours = np.array([shoelace(p) for p in polygons])
    assert (ours > 0).all()  # convex, counter-clockwise
    assert len(ours) == len(theirs) == len(types)
    assert np.allclose(np.sort(ours), theirs, rtol=1e-9, atol=1e-15)
    assert abs(ours.sum() - 1) < 1e-12
    # the picture shows these sections: deep inside each (2 pixels from every side), its type's colour
    from PIL import Image

    from cospherical.outputs.mesh_picture import TAB20, cut_png, frame

    cut_png(mesh, tmp_path / "mesh.png", at=at)
    pixels = np.asarray(Image.open(tmp_path / "mesh.png").convert("RGB"))
    _, _, x0, y0, scale = frame(1.0, 1.0)
    commonest = sorted(set(types), key=lambda t: (-types.count(t), t))
    checked = 0
    for polygon, t in zip(polygons, types):
        corners = np.c_[x0 + polygon[:, 0] * scale, y0 + (1 - polygon[:, 1]) * scale]  # pixel space
        center = corners.mean(axis=0)
        edges = np.roll(corners, -1, axis=0) - corners
        to_center = center - corners
        # distance of the centre from each edge's line: |2-D cross product| / edge length
        away = np.abs(edges[:, 0] * to_center[:, 1] - edges[:, 1] * to_center[:, 0]) / np.hypot(*edges.T)
        if away.min() > 2:
            assert tuple(pixels[int(center[1]), int(center[0])]) == TAB20[commonest.index(t) % 20]
            checked += 1
    assert checked > len(polygons) / 2


@pytest.mark.oracle_vtk
def test_png_bytes_are_the_pixels_for_pillow_and_libpng(tmp_path):
    """png_bytes' file decodes to the very pixels in Pillow's decoder and in VTK's (libpng), CRCs checked."""
    from PIL import Image

    from cospherical.outputs.mesh_picture import _ROWS, png_bytes

    rng = np.random.default_rng(5)
    pixels = np.repeat(rng.integers(0, 256, (7, 11, 3), dtype=np.uint8), 20, axis=0)  # rows equal to the one above,
    assert len(pixels) > 2 * _ROWS  # in bands of rows filtered and deflated in turn
    pixels[::4] = rng.integers(0, 256, pixels[::4].shape, dtype=np.uint8)  # and rows that differ, wrapping mod 256
    path = tmp_path / "picture.png"
    path.write_bytes(png_bytes(pixels))
    assert png_bytes(pixels) == path.read_bytes()  # deterministic
    with Image.open(path) as image:
        image.verify()
    with Image.open(path) as image:
        assert image.mode == "RGB" and np.array_equal(np.asarray(image), pixels)
    reader = vtk.vtkPNGReader()
    reader.SetFileName(str(path))
    reader.Update()
    decoded = vtk_to_numpy(reader.GetOutput().GetPointData().GetScalars())
    assert np.array_equal(decoded.reshape(pixels.shape)[::-1], pixels)  # VTK's rows run bottom-up
    with pytest.raises(ValueError, match="RGB picture of uint8"):
        png_bytes(pixels[:, :, :2])


def test_the_pixels_read_are_pillows_tobytes():
    """_pixels (Pillow's raw encoder run as tobytes runs it, in several buffers here) gives tobytes' very pixels."""
    from PIL import Image, ImageDraw

    from cospherical.outputs.mesh_picture import _pixels

    image = Image.new("RGB", (301, 250), (255, 255, 255))  # 225,750 bytes: four buffers of 64 KiB
    ImageDraw.Draw(image).polygon([(3, 5), (290, 40), (120, 240)], fill=(31, 119, 180), outline=(0, 0, 0))
    pixels = _pixels(image)
    assert pixels.shape == (250, 301, 3) and pixels.dtype == np.uint8
    assert pixels.tobytes() == image.tobytes() and np.array_equal(pixels, np.asarray(image))
