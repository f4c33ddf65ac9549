"""A picture of a meshed octree: a cut through the mesh, each element's section coloured by its type."""

from __future__ import annotations

import math
import struct
import zlib
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..files.yamlio import atomic_open
from ..mesh.assembly import Mesh

if TYPE_CHECKING:
    from PIL import Image, ImageFont

__all__ = ["TAB20", "cut_png", "cut_polygons", "frame", "png_bytes"]

# matplotlib's tab20 palette (its colours for the commonest types first, as the pictures always had)
TAB20 = ((31, 119, 180), (174, 199, 232), (255, 127, 14), (255, 187, 120), (44, 160, 44), (152, 223, 138),
         (214, 39, 40), (255, 152, 150), (148, 103, 189), (197, 176, 213), (140, 86, 75), (196, 156, 148),
         (227, 119, 194), (247, 182, 210), (127, 127, 127), (199, 199, 199), (188, 189, 34), (219, 219, 141),
         (23, 190, 207), (158, 218, 229))
WHITE, BLACK, GREY = (255, 255, 255), (0, 0, 0), (204, 204, 204)
_ROWS = 64  # rows of a picture filtered and deflated at a time (png_bytes)
_OVER = 3  # over-sampling of the polygons: their outlines a third of a pixel wide, as thin as matplotlib's


# the picture's axes (horizontal, vertical) for a cut across each axis: x-y for z, x-z for y, y-z for x
_PLANES = {0: (1, 2), 1: (0, 2), 2: (0, 1)}


def cut_polygons(mesh: Mesh, at: float = 0.5, axis: int = 2) -> tuple[list[np.ndarray], list[str]]:
    """The sections of the elements by the plane z = ``at`` (fraction of the domain height), in real x, y.

    ``axis``: the cut's normal (2: z, the default; 1: a cut y = ``at`` drawn in x, z; 0: in y, z).

    The plane is moved by a third of the finest grid step off ``at`` so that no face
    lies in it (a section is then always a proper convex polygon, its corners where
    the element's edges cross the plane).  Computed per block of alike elements (a configuration's
    element on all its leaves, a cell shape): those whose edges cross alike share one array.
    Returns the polygons and each one's element type id.
    """
    polygons, types, _ = _sections(mesh, at, axis)
    return polygons, types


def _sections(mesh: Mesh, at: float, axis: int) -> tuple[list[np.ndarray], list[str], list[int]]:
    """:func:`cut_polygons`, and each polygon's element.

    Blocks of elements with the same face list (a configuration's element on all its leaves, a cell
    shape: their edges are the same columns) are cut together, and the polygons put back in the
    blocks' order (then by which edges cross the plane, then element order within a block).
    """
    grid = mesh.grid
    across = (*_PLANES[axis], axis)
    z0 = round(at * grid) + 1 / 3
    scale = np.array(mesh.box.to_float())[list(across)] / grid
    # a leaf's elements lie in its box: only the leaves the plane crosses can hold a section (a cell of
    # the global Delaunay subdivision may reach beyond its first leaf: cells are always looked at)
    low = mesh.tree.positions[:, axis].astype(np.int64) * mesh.leaf_size()
    near = (low < z0) & (low + mesh.leaf_size() > z0)
    vertices = mesh.vertices[:, list(across)]  # the picture's two axes, then the cut's
    # per face list: the blocks' crossing elements, (block, element, vertex ids) stacked
    alike: dict[Any, tuple[list[int], list[np.ndarray], list[np.ndarray]]] = {}
    types: list[str] = []  # per block
    for element_rows, nodes, faces, type_id in mesh.blocks(near):
        if type_id is None:  # a mesh's blocks all have types: only an element list's have none
            raise ValueError("mesh_picture: an element without a type")
        z = vertices[nodes, 2]  # (elements, nodes)
        crossing = np.flatnonzero((z.min(axis=1) < z0) & (z.max(axis=1) > z0))
        types.append(type_id)
        if len(crossing):
            blocks, rows, ids = alike.setdefault(faces, ([], [], []))
            blocks.append(len(types) - 1)
            rows.append(element_rows[crossing])
            ids.append(nodes[crossing])
    polygons: list[np.ndarray] = []
    keys: list[tuple[int, int, int]] = []  # per polygon: its block, its edges' mask, its place in the block
    elements: list[int] = []
    for faces, (blocks, rows, ids) in alike.items():
        # an element's edges (pairs of positions in its node list)
        edges = sorted({tuple(sorted((c[i], c[(i + 1) % len(c)]))) for c in faces for i in range(len(c))})
        ends = np.array(edges, dtype=np.intp).reshape(-1, 2)
        nodes = np.concatenate(ids)
        block = np.repeat(blocks, [len(r) for r in rows])
        place = np.concatenate([np.arange(len(r)) for r in rows])
        element = np.concatenate(rows)
        pa, pb = vertices[nodes[:, ends[:, 0]]].astype(float), vertices[nodes[:, ends[:, 1]]].astype(float)
        za, zb = pa[..., 2] - z0, pb[..., 2] - z0  # (elements, edges)
        cut = za * zb < 0
        masks = (cut.astype(np.int64) << np.arange(len(ends))).sum(axis=1)
        for mask in sorted(set(masks.tolist())):
            chosen = np.flatnonzero(masks == mask)
            which = np.flatnonzero(cut[chosen[0]])
            ra, rb = pa[chosen][:, which], pb[chosen][:, which]  # (rows, corners, 3)
            t = (za[chosen][:, which] / (za[chosen][:, which] - zb[chosen][:, which]))[..., None]
            xy = (ra + t * (rb - ra))[..., :2]
            center = xy.mean(axis=1, keepdims=True)
            angle = np.arctan2(xy[..., 1] - center[..., 1], xy[..., 0] - center[..., 0])
            xy = np.take_along_axis(xy, np.argsort(angle, axis=1)[..., None], axis=1) * scale[:2]
            polygons.extend(xy)
            keys.extend(zip(block[chosen].tolist(), [mask] * len(chosen), place[chosen].tolist()))
            elements.extend(element[chosen].tolist())
    order = sorted(range(len(polygons)), key=keys.__getitem__)
    return [polygons[i] for i in order], [types[keys[i][0]] for i in order], [elements[i] for i in order]


def cut_png(mesh: Mesh, path: Path, title: str = "", at: float = 0.5, legend: int = 10, axis: int = 2,
            by_region: bool = False) -> None:
    """Write the cut through the mesh at z = ``at`` as PNG, elements coloured by type (legend: the commonest).

    ``axis``: the cut's normal (see :func:`cut_polygons`); ``by_region``: colour the
    sections by the element's region (a device's; the legend names them) instead.

    Drawn with Pillow from the section polygons (a few thousand): the polygons
    three times over-sampled and averaged down, outlined in black, in axes with
    ticks, a title and a legend.  matplotlib would take a second to import and
    draw the same; Pillow's own font makes the bytes the same on every machine.
    """
    from PIL import Image, ImageDraw, ImageFont

    polygons, types, elements = _sections(mesh, at, axis)
    if by_region:
        regions, names = mesh.element_region, mesh.regions
        assert regions is not None and names is not None, "by region: a device's mesh"
        types = [names.names[r] for r in regions[np.array(elements, dtype=np.int64)].tolist()]
    counts: dict[str, int] = {}
    for t in types:
        counts[t] = counts.get(t, 0) + 1
    order = sorted(counts, key=lambda t: (-counts[t], t))
    colour = {t: TAB20[i % len(TAB20)] for i, t in enumerate(order)}
    lengths = mesh.box.to_float()
    a, b = (lengths[k] for k in _PLANES[axis])
    width, height, x0, y0, scale = frame(a, b)
    w, h = max(1, round(scale * a)), max(1, round(scale * b))  # a 1e-12 x 1 section is one pixel wide, not empty
    image = Image.new("RGB", (width, height), WHITE)
    over = Image.new("RGB", (w * _OVER, h * _OVER), WHITE)
    pen = ImageDraw.Draw(over)
    s = scale * _OVER
    if polygons:  # every corner in pixels at once (the same two float operations per corner), then drawn in order
        corners = np.concatenate(polygons)
        pixels = np.column_stack([corners[:, 0] * s, (b - corners[:, 1]) * s]).ravel().tolist()
        at = 0
        for polygon, t in zip(polygons, types):
            end = at + 2 * len(polygon)
            pen.polygon(pixels[at:end], fill=colour[t], outline=BLACK)
            at = end
    image.paste(over.reduce(_OVER), (x0, y0))
    draw = ImageDraw.Draw(image)
    draw.rectangle((x0 - 1, y0 - 1, x0 + w, y0 + h), outline=BLACK)
    ticks, label = ImageFont.load_default(18), ImageFont.load_default(18)
    for value, text in _ticks(a):
        x = x0 + value * scale
        draw.line((x, y0 + h, x, y0 + h + 6), fill=BLACK)
        draw.text((x, y0 + h + 9), text, font=ticks, fill=BLACK, anchor="mt")
    for value, text in _ticks(b):
        y = y0 + h - value * scale
        draw.line((x0 - 7, y, x0 - 1, y), fill=BLACK)
        draw.text((x0 - 10, y), text, font=ticks, fill=BLACK, anchor="rm")
    draw.text((x0 + w / 2, y0 + h + 34), "xyz"[_PLANES[axis][0]], font=label, fill=BLACK, anchor="mt")
    draw.text((x0 - 10 - ticks.getlength(_ticks(b)[-1][1]) - 14, y0 + h / 2), "xyz"[_PLANES[axis][1]], font=label,
              fill=BLACK,
              anchor="rm")
    small = ImageFont.load_default(14)
    lines = _wrap(title or f"cut at z = {at:g} of the domain height", small, width - 40)
    for i, line in enumerate(lines):
        draw.text((x0 + w / 2, y0 - 8 - 18 * (len(lines) - 1 - i)), line, font=small, fill=BLACK, anchor="md")
    shown = order[:legend]
    if shown:
        font = ImageFont.load_default(13)
        heading = "region (sections)" if by_region else "element type (sections)"
        rows = [heading] + [f"{t if by_region else mesh.type_name(t)} ({counts[t]})" for t in shown]
        box_width = 12 + 28 + 8 + max(int(font.getlength(r)) for r in rows) + 12
        lx, ly = x0 + w + 12, y0
        draw.rectangle((lx, ly, lx + box_width, ly + 10 + 20 * len(rows)), fill=WHITE, outline=GREY)
        draw.text((lx + box_width / 2, ly + 6), rows[0], font=font, fill=BLACK, anchor="mt")
        for i, (t, row) in enumerate(zip(shown, rows[1:]), 1):
            y = ly + 8 + 20 * i
            draw.rectangle((lx + 12, y + 2, lx + 40, y + 12), fill=colour[t], outline=BLACK)
            draw.text((lx + 48, y + 7), row, font=font, fill=BLACK, anchor="lm")
    with atomic_open(path, binary=True) as handle:
        handle.write(png_bytes(_pixels(image)))


def _pixels(image: Image.Image) -> np.ndarray:
    """An RGB picture's pixels (height x width x 3, ``uint8``): its bytes from Pillow's raw encoder, as ``tobytes()``.

    ``Image.tobytes()`` (and ``numpy.asarray(image)``, through it) runs the same encoder the same way, but
    first imports Pillow's file-format base module (and ``logging`` with it, ~6 ms of a run) for the size
    of a buffer; nothing else in a mesh run needs that module.
    """
    from PIL import Image

    width, height = image.size
    encoder = Image.core.raw_encoder("RGB", "RGB")
    encoder.setimage(image.im, (0, 0, width, height))
    pixels = np.empty(3 * width * height, dtype=np.uint8)  # filled buffer by buffer: one copy of the picture
    at, status = 0, 0
    while not status:
        _, status, chunk = encoder.encode(max(1 << 16, 4 * width))
        pixels[at:at + len(chunk)] = np.frombuffer(chunk, dtype=np.uint8)
        at += len(chunk)
    if status < 0 or at != len(pixels):
        raise OSError(f"mesh.png: Pillow's raw encoder failed ({status}, {at} of {len(pixels)} bytes)")
    return pixels.reshape(height, width, 3)


def png_bytes(pixels: np.ndarray) -> bytes:
    """The PNG file of an RGB picture (``pixels``: height x width x 3, ``uint8``), as a preview is: fast, lossless.

    Every row filtered by PNG's "Up" filter (its bytes minus the row above's, modulo 256:
    a picture of flat colours becomes mostly zeros) and deflated at zlib level 1, as
    ``mesh.vtu``'s data is.  Pillow's encoder (each row's filter chosen among five, zlib
    level 6) made files 8-25 % smaller in four to five times the time (0.028 s against
    0.006 s for a 1300 x 845 picture) and imported its PNG plugin to do it.  The same
    pixels give the same bytes.
    """
    height, width, channels = pixels.shape
    if channels != 3 or pixels.dtype != np.uint8:
        raise ValueError(f"png_bytes: an RGB picture of uint8, not {channels} channels of {pixels.dtype}")
    flat = pixels.reshape(height, 3 * width)
    deflate, data = zlib.compressobj(1), []
    for start in range(0, height, _ROWS):  # a band of rows at a time: the filtered copy is a band, not the picture
        band = flat[start:start + _ROWS]
        rows = np.empty((len(band), 1 + 3 * width), dtype=np.uint8)
        rows[:, 0] = 2  # "Up"; above the first row are zeros, so its bytes are its own
        np.subtract(band[0], flat[start - 1] if start else 0, out=rows[0, 1:])
        np.subtract(band[1:], band[:-1], out=rows[1:, 1:])  # uint8: wraps modulo 256, as the filter is defined
        data.append(deflate.compress(rows.data))
    data.append(deflate.flush())

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)  # 8 bits per sample, RGB, deflate, no interlace
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", b"".join(data))
            + chunk(b"IEND", b""))


def frame(a: float, b: float) -> tuple[int, int, int, int, float]:
    """The picture of an ``a`` x ``b`` section: its width and height, the pixel of the section's corner (0, b), pixels per unit.

    The axes have the left two thirds (the legend the rest); the section is drawn to
    scale in them, centred.
    """
    width, height = 1300, round(845 * min(2.0, max(0.6, b / a)))
    left, right, top, bottom = 0.07 * width, 0.66 * width, 0.08 * height, 0.92 * height
    scale = min((right - left) / a, (bottom - top) / b)
    return width, height, round((left + right - scale * a) / 2), round((top + bottom - scale * b) / 2), scale


def _ticks(length: float) -> list[tuple[float, str]]:
    """Round tick values from 0 to ``length``: steps of 1, 2 or 5 times a power of ten, 4 to 10 of them."""
    power = 10.0 ** math.floor(math.log10(length))
    step = next(m * power for m in (0.1, 0.2, 0.5, 1, 2, 5, 10) if length / (m * power) <= 8)
    decimals = max(0, -math.floor(math.log10(step) + 1e-9))
    return [(i * step, f"{i * step:.{decimals}f}") for i in range(int(length / step + 1e-9) + 1)]


def _wrap(text: str, font: ImageFont.FreeTypeFont | ImageFont.ImageFont, width: float) -> list[str]:
    """``text`` broken at spaces into lines no wider than ``width`` pixels (a longer word stays whole)."""
    lines: list[str] = []
    for word in text.split(" "):
        if lines and font.getlength(lines[-1] + " " + word) <= width:
            lines[-1] += " " + word
        else:
            lines.append(word)
    return lines
