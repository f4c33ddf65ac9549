"""A device: named regions of axis-aligned boxes (a material each), named contacts, and its octree.

A device is a domain made of boxes, each box in one region; regions touch along
interfaces, and contacts are rectangles on the boundary of their region (the outer
boundary or an interface).  The octree covers the bounding box (its root is the
bounding box, as ``--domain``'s root is the domain), is refined until every region
boundary and every contact edge lies on leaf faces, is balanced like any tree (so
across interfaces too), and keeps only the leaves inside a region: each leaf lies in
exactly one region, so each element does.

Everything is decided with integers.  A coordinate is an exact rational; it is
resolved by the tree when its position in the bounding box is a dyadic fraction
``p / 2**k`` (the faces of level ``k`` lie there), so the deepest ``k`` over every box and
contact coordinate is the *resolving level* ``R``, and the region boundaries are
integers on the grid of ``2**R`` steps per side.  The distinct box coordinates per
axis cut the bounding box into a small rectilinear grid (the *blocks*), each block in
one region or outside every one: overlaps, contacts on a boundary, connectedness and
which cells a boundary cuts are all read from that grid.

A one-box domain (``--domain a b c``) is a mesh of one region named ``domain``.

Examples
--------
>>> from fractions import Fraction as F
>>> device = Device("L", (Region("si", "Si", ((F(0), F(0), F(0), F(2), F(1), F(1)),
...                                            (F(0), F(1), F(0), F(1), F(2), F(1)))),), (), (), 1)
>>> layout = device_layout(device)
>>> layout.resolving_level, layout.region_volumes
(1, (Fraction(3, 1),))
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np

from ..choices import Balance
from ..core.configuration import Box
from ..errors import InputError, shown
from .octree import MAX_LEVEL, Octree, Shape, build_octree, parse_shape

__all__ = ["AXES", "Contact", "Coordinates", "Device", "DeviceLayout", "MAX_BOXES", "MAX_CONTACTS", "MAX_REFINE", "MAX_REGIONS", "NAME",
           "Region", "Regions", "checked_device", "device_layout", "device_octree"]

AXES = "xyz"
# Bounds of what a device file may describe: the block grid has at most (2 * boxes + 2 * contacts + 2)
# planes per axis (about 4 million blocks at these bounds), held as small integer arrays.
MAX_REGIONS = 64
MAX_BOXES = 64
MAX_CONTACTS = 64
MAX_REFINE = 64
_COORDINATE_NAMES = ("x0", "y0", "z0", "x1", "y1", "z1")
# A name (device, region, material, contact): the device file's rule (schemas/device.schema.json, $defs.name).
# Names are data, written into VTU, Gmsh and DEVSIM as they are: no path separator, quote, space or control.
NAME = re.compile(r"[A-Za-z0-9_.+-]{1,64}")

Coordinates = tuple[Fraction, Fraction, Fraction, Fraction, Fraction, Fraction]


@dataclass(frozen=True)
class Region:
    """A region: its ``name``, its ``material`` (both data, never paths) and its ``boxes`` (x0 y0 z0 x1 y1 z1)."""

    name: str
    material: str
    boxes: tuple[Coordinates, ...]


@dataclass(frozen=True)
class Contact:
    """A contact: its ``name``, the ``region`` (name) whose boundary holds it, a ``box`` flat along one axis."""

    name: str
    region: str
    box: Coordinates

    @property
    def axis(self) -> int:
        """The axis the rectangle is flat along (its normal)."""
        return next(a for a in range(3) if self.box[a] == self.box[a + 3])


@dataclass(frozen=True)
class Device:
    """A device as a device file describes it: regions, contacts, refinement shapes, levels and balance.

    ``refine``: shapes in device coordinates (:class:`~cospherical.mesh.octree.Shape`);
    ``levels``: how deep the shapes refine (the region boundaries may need deeper
    leaves: the tree goes down to the resolving level whatever ``levels`` says).
    ``source``: the file's name when read from one (:func:`~cospherical.formats.device_file.read_device`),
    which the errors found past its parsing name too.
    """

    name: str
    regions: tuple[Region, ...]
    contacts: tuple[Contact, ...]
    refine: tuple[Shape, ...]
    levels: int
    balance: Balance = "vertex"
    source: str | None = field(default=None, compare=False)

    @property
    def bounds(self) -> tuple[tuple[Fraction, Fraction], ...]:
        """Per axis the bounding box's (low, high)."""
        boxes = [b for r in self.regions for b in r.boxes]
        return tuple((min(b[a] for b in boxes), max(b[a + 3] for b in boxes)) for a in range(3))

    @property
    def origin(self) -> tuple[Fraction, Fraction, Fraction]:
        (x, _), (y, _), (z, _) = self.bounds
        return (x, y, z)

    @property
    def has_faces(self) -> bool:
        """Whether the device has named faces (``contacts.vtu``): a contact, or two regions, which touch along an
        interface (the domain is one piece through faces)."""
        return bool(self.contacts) or len(self.regions) > 1

    @property
    def box(self) -> Box:
        """The bounding box's lengths (the octree's root)."""
        return Box.parse([str(high - low) for low, high in self.bounds])


@dataclass(frozen=True)
class DeviceLayout:
    """A device checked and cut into blocks on the integer grid of its resolving level.

    ``resolving_level``: the level ``R`` whose faces hold every box and contact
    coordinate; ``planes[a]``: the distinct coordinates along axis ``a`` in steps of
    ``2**-R`` of the bounding box (``0`` .. ``2**R``); ``owner[i, j, k]``: the region of
    block ``(i, j, k)`` (-1: outside every region); ``contacts``: per contact
    ``(axis, value, low, high)`` in grid steps (``low``/``high`` its two other axes'
    ranges); ``region_volumes``: each region's exact volume in device units.
    """

    device: Device
    resolving_level: int
    planes: tuple[np.ndarray, np.ndarray, np.ndarray]
    owner: np.ndarray
    contacts: tuple[tuple[int, int, tuple[int, int], tuple[int, int]], ...]
    region_volumes: tuple[Fraction, ...]

    @property
    def steps(self) -> int:
        return 1 << self.resolving_level

    def cuts(self, level: int, cells: np.ndarray) -> np.ndarray:
        """Which cells (n x 3 at ``level``) a region boundary cuts, or whose face a boundary or a contact's edge crosses.

        A cell is cut when blocks of different owners (regions, or outside every region:
        each leaf lies in one region) meet inside it: across some
        plane strictly inside the cell, in the cell's open span of the other two axes
        (counted with a prefix sum per plane).  It is also split when the blocks just
        beyond one of its faces, over the face's open rectangle, are not all of one
        owner: a leaf beside a boundary that turns there would get a face point
        without its edge points (the neighbour's kept children do not cover its
        face).  A contact's rectangle must be a union of leaf faces: a cell with a
        face in the contact's plane that meets the rectangle without lying in it is
        split.
        """
        if level >= self.resolving_level:
            return np.zeros(len(cells), dtype=bool)
        size = self.steps >> level
        low = cells.astype(np.int64) * size
        high = low + size
        cut = np.zeros(len(cells), dtype=bool)
        for axis in range(3):
            b, c = (axis + 1) % 3, (axis + 2) % 3
            owner = np.moveaxis(self.owner, axis, 0)  # (blocks along axis, b, c)
            if b > c:
                owner = owner.transpose(0, 2, 1)
            # open spans of the cells along b and c, as block ranges
            first_b = np.searchsorted(self.planes[b], low[:, b], "right") - 1
            end_b = np.searchsorted(self.planes[b], high[:, b], "left")
            first_c = np.searchsorted(self.planes[c], low[:, c], "right") - 1
            end_c = np.searchsorted(self.planes[c], high[:, c], "left")
            # planes strictly inside the open spans: indices into the changes between blocks
            inner_b = (np.searchsorted(self.planes[b], low[:, b], "right") - 1, end_b - 1)
            inner_c = (np.searchsorted(self.planes[c], low[:, c], "right") - 1, end_c - 1)
            changes = owner[1:] != owner[:-1]  # across plane planes[axis][i + 1]
            for i in np.flatnonzero(changes.any(axis=(1, 2))).tolist():
                value = self.planes[axis][i + 1]
                rows = np.flatnonzero((low[:, axis] < value) & (value < high[:, axis]))
                cut[rows[_any(changes[i], first_b[rows], end_b[rows], first_c[rows], end_c[rows])]] = True
            for i, value in enumerate(self.planes[axis].tolist()):
                for layer, rows in ((i - 1, np.flatnonzero(low[:, axis] == value)),
                                    (i, np.flatnonzero(high[:, axis] == value))):
                    if not len(rows) or not 0 <= layer < owner.shape[0]:
                        continue
                    blocks = owner[layer]
                    along_b = blocks[1:] != blocks[:-1]  # across planes[b][j + 1]
                    along_c = blocks[:, 1:] != blocks[:, :-1]  # across planes[c][k + 1]
                    hit = _any(along_b, inner_b[0][rows], inner_b[1][rows], first_c[rows], end_c[rows])
                    hit |= _any(along_c, first_b[rows], end_b[rows], inner_c[0][rows], inner_c[1][rows])
                    cut[rows[hit]] = True
        for axis, value, (p0, p1), (q0, q1) in self.contacts:
            b, c = (axis + 1) % 3, (axis + 2) % 3
            touching = (low[:, axis] == value) | (high[:, axis] == value)
            meets = (low[:, b] < p1) & (high[:, b] > p0) & (low[:, c] < q1) & (high[:, c] > q0)
            inside = (low[:, b] >= p0) & (high[:, b] <= p1) & (low[:, c] >= q0) & (high[:, c] <= q1)
            cut |= touching & meets & ~inside
        return cut

    def convex(self, region: int) -> bool:
        """Whether a region is convex: a union of boxes is convex exactly when it fills its bounding box."""
        blocks = np.argwhere(self.owner == region)
        low, high = blocks.min(axis=0), blocks.max(axis=0) + 1
        return bool(np.all(self.owner[low[0]:high[0], low[1]:high[1], low[2]:high[2]] == region))

    def blocks_of(self, low: np.ndarray) -> tuple[np.ndarray, ...]:
        """The block holding each grid point ``low`` (n x 3, in steps of the resolving level), as index arrays."""
        return tuple(np.minimum(np.searchsorted(self.planes[a], low[:, a], "right") - 1, len(self.planes[a]) - 2)
                     for a in range(3))


@dataclass(frozen=True)
class Regions:
    """Which region each leaf of a mesh's tree lies in, and the regions' names and materials.

    ``leaf_region`` (int32, one per leaf of the tree, in its order) indexes ``names``
    and ``materials``; ``layout`` is the device's (``None`` for a one-box domain, one
    region named ``domain``).  An element lies in its leaf's region: a cell of the
    global Delaunay mode never leaves its region (:mod:`cospherical.mesh.regions`).
    """

    names: tuple[str, ...]
    materials: tuple[str, ...]
    leaf_region: np.ndarray
    layout: DeviceLayout | None = None


def _any(marks: np.ndarray, r0: np.ndarray, r1: np.ndarray, c0: np.ndarray, c1: np.ndarray) -> np.ndarray:
    """Per query, whether ``marks[r0:r1, c0:c1]`` holds a True (a 2D prefix sum; empty ranges hold none)."""
    table = np.zeros((marks.shape[0] + 1, marks.shape[1] + 1), dtype=np.int64)
    table[1:, 1:] = np.cumsum(np.cumsum(marks, axis=0), axis=1)
    r0, r1 = np.clip(r0, 0, marks.shape[0]), np.clip(r1, 0, marks.shape[0])
    c0, c1 = np.clip(c0, 0, marks.shape[1]), np.clip(c1, 0, marks.shape[1])
    r1, c1 = np.maximum(r1, r0), np.maximum(c1, c0)
    held: np.ndarray = table[r1, c1] - table[r0, c1] - table[r1, c0] + table[r0, c0] > 0
    return held


def _dyadic_level(value: Fraction, low: Fraction, length: Fraction) -> int | None:
    """The level whose faces hold ``value`` in ``[low, low + length]``, or ``None`` when none does."""
    t = (value - low) / length
    den = t.denominator
    if den & (den - 1):
        return None
    return den.bit_length() - 1


def checked_device(device: Device) -> Device:
    """``device`` as the device file would give it, or one :class:`InputError`: names by :data:`NAME`, six
    exact coordinates per box (integers, fractions or their texts: through
    :func:`~cospherical.core.exact.parse_rational`, never a float), refinement shapes as
    :class:`~cospherical.mesh.octree.Shape` (or their texts), counts bounded first.  A ``Device`` built in
    Python skips the file's schema; this holds it to the same rules."""
    from ..core.exact import parse_rational

    if not isinstance(device, Device):
        raise InputError(f"device {shown(device)}: a Device, or a device file's path")

    def sequence(value: object, what: str, most: int) -> tuple[Any, ...]:
        if not isinstance(value, (tuple, list)) or len(value) > most:
            raise InputError(f"device {shown(device.name)}: its {what}: a list of at most {most}, not {shown(value)}")
        return tuple(value)

    def name(value: object, what: str) -> str:
        if not isinstance(value, str) or not NAME.fullmatch(value):
            raise InputError(f"{what} name {shown(value)}: 1 to 64 of A-Z a-z 0-9 _ . + -")
        return value

    def coordinates(value: object, what: str) -> Coordinates:
        if not isinstance(value, (tuple, list)) or len(value) != 6:
            raise InputError(f"{what}: six coordinates x0 y0 z0 x1 y1 z1, not {shown(value)}")
        x0, y0, z0, x1, y1, z1 = (Fraction(parse_rational(x, what)) for x in value)
        return (x0, y0, z0, x1, y1, z1)

    name(device.name, "device")
    regions = []
    for region in sequence(device.regions, "regions", MAX_REGIONS):
        if not isinstance(region, Region):
            raise InputError(f"device {shown(device.name)}: {shown(region)} is not a Region")
        label = f"region {shown(name(region.name, 'region'))}"
        boxes = sequence(region.boxes, f"{label}'s boxes", MAX_BOXES)
        regions.append(Region(region.name, name(region.material, "material"),
                              tuple(coordinates(box, f"{label} box {k}") for k, box in enumerate(boxes))))
    contacts = []
    for contact in sequence(device.contacts, "contacts", MAX_CONTACTS):
        if not isinstance(contact, Contact):
            raise InputError(f"device {shown(device.name)}: {shown(contact)} is not a Contact")
        label = f"contact {shown(name(contact.name, 'contact'))}"
        contacts.append(Contact(contact.name, name(contact.region, "region"), coordinates(contact.box, label)))
    refine = tuple(shape if isinstance(shape, Shape) else parse_shape(shape)
                   for shape in sequence(device.refine, "refine", MAX_REFINE))
    return Device(device.name, tuple(regions), tuple(contacts), refine, device.levels, device.balance)


def device_layout(device: Device) -> DeviceLayout:
    """Check a device's geometry exactly and cut it into blocks (see the module).

    Refused, each with one line naming what: a box of no volume, a coordinate that no
    dyadic refinement of the bounding box resolves, or one needing more than
    :data:`~cospherical.mesh.octree.MAX_LEVEL` levels, two boxes that overlap, a
    contact naming an unknown region or not flat along exactly one axis or not on the
    boundary of its region, two regions or contacts of one name, and a domain in more
    than one piece (boxes must touch the rest along a face: a disconnected domain is
    refused, each piece is its own device).
    """
    device = checked_device(device)
    regions = device.regions
    if not regions:
        raise InputError(f"device {shown(device.name)}: no regions")
    if len(regions) > MAX_REGIONS:
        raise InputError(f"device {shown(device.name)}: {len(regions)} regions, at most {MAX_REGIONS}")
    boxes = [(r, k, box) for r, region in enumerate(regions) for k, box in enumerate(region.boxes)]
    if len(boxes) > MAX_BOXES:
        raise InputError(f"device {shown(device.name)}: {len(boxes)} boxes, at most {MAX_BOXES}")
    if len(device.contacts) > MAX_CONTACTS:
        raise InputError(f"device {shown(device.name)}: {len(device.contacts)} contacts, at most {MAX_CONTACTS}")
    for kind, names in (("region", [r.name for r in regions]), ("contact", [c.name for c in device.contacts])):
        seen: set[str] = set()
        for name in names:
            if name in seen:
                raise InputError(f"device {shown(device.name)}: two {kind}s named {shown(name)}")
            seen.add(name)
    # one name space: Gmsh's physical names, meshio's field data and DEVSIM take a name for one thing
    taken = {r.name for r in regions} & {c.name for c in device.contacts}
    if taken:
        raise InputError(f"device {shown(device.name)}: a region and a contact both named {shown(min(taken))}")

    def where(r: int, k: int) -> str:
        return f"region {shown(regions[r].name)} box {k}"

    for r, k, box in boxes:
        for a in range(3):
            if box[a] >= box[a + 3]:
                raise InputError(f"{where(r, k)}: {_COORDINATE_NAMES[a + 3]} = {box[a + 3]} must be above "
                                 f"{_COORDINATE_NAMES[a]} = {box[a]} (a box has volume)")
    bounds = device.bounds
    lengths = [high - low for low, high in bounds]
    resolving = 0
    named = {region.name: r for r, region in enumerate(regions)}
    checked = [(where(r, k), box) for r, k, box in boxes]
    for c, contact in enumerate(device.contacts):
        if contact.region not in named:
            raise InputError(f"contact {shown(contact.name)}: region {shown(contact.region)} is not a region of the "
                             "device")
        flat = [a for a in range(3) if contact.box[a] == contact.box[a + 3]]
        if len(flat) != 1 or any(contact.box[a] > contact.box[a + 3] for a in range(3)):
            raise InputError(f"contact {shown(contact.name)}: its box must be a rectangle, flat along exactly one "
                             "axis (x0 = x1, y0 = y1 or z0 = z1) and low <= high along the others")
        for a in range(3):
            low, high = bounds[a]
            if not low <= contact.box[a] <= contact.box[a + 3] <= high:
                raise InputError(f"contact {shown(contact.name)}: outside the device's bounding box along "
                                 f"{AXES[a]}")
        checked.append((f"contact {shown(contact.name)}", contact.box))
    for what, box in checked:
        for i, value in enumerate(box):
            a = i % 3
            level = _dyadic_level(value, bounds[a][0], lengths[a])
            if level is None:
                raise InputError(f"{what}: {_COORDINATE_NAMES[i]} = {value} is not resolved by any dyadic "
                                 f"refinement of the bounding box {AXES[a]} = {bounds[a][0]} .. {bounds[a][1]} "
                                 f"(its position there, {(value - bounds[a][0]) / lengths[a]}, is no p / 2**k)")
            if level > MAX_LEVEL:
                raise InputError(f"{what}: {_COORDINATE_NAMES[i]} = {value} needs {level} levels to be resolved, "
                                 f"above {MAX_LEVEL}")
            resolving = max(resolving, level)
    steps = 1 << resolving

    def grid(box: Coordinates) -> list[int]:
        return [int((box[i] - bounds[i % 3][0]) / lengths[i % 3] * steps) for i in range(6)]

    gridded = [grid(box) for _, box in checked]
    planes = tuple(np.unique(np.array([0, steps] + [g[a] for g in gridded] + [g[a + 3] for g in gridded],
                                      dtype=np.int64)) for a in range(3))
    owner = np.full(tuple(len(p) - 1 for p in planes), -1, dtype=np.int16)
    owner_box = np.full(owner.shape, -1, dtype=np.int16)
    for index, ((r, k, _), g) in enumerate(zip(boxes, gridded)):
        span = tuple(slice(int(np.searchsorted(planes[a], g[a])), int(np.searchsorted(planes[a], g[a + 3])))
                     for a in range(3))
        claimed = owner_box[span]
        if (claimed >= 0).any():
            r0, k0, _ = boxes[int(claimed[claimed >= 0][0])]
            raise InputError(f"{where(r, k)} overlaps {where(r0, k0)}")
        owner[span] = r
        owner_box[span] = index
    _check_connected(owner_box, boxes, where)
    contacts: list[tuple[int, int, tuple[int, int], tuple[int, int]]] = []
    for contact, g in zip(device.contacts, gridded[len(boxes):]):
        axis = contact.axis
        b, c = (axis + 1) % 3, (axis + 2) % 3
        at = g[axis]
        i = int(np.searchsorted(planes[axis], at))
        span_b = slice(int(np.searchsorted(planes[b], g[b])), int(np.searchsorted(planes[b], g[b + 3])))
        span_c = slice(int(np.searchsorted(planes[c], g[c])), int(np.searchsorted(planes[c], g[c + 3])))
        moved = np.moveaxis(owner, axis, 0)
        if b > c:
            moved = moved.transpose(0, 2, 1)
        region = named[contact.region]
        below = moved[i - 1, span_b, span_c] if i > 0 else np.full((span_b.stop - span_b.start,
                                                                      span_c.stop - span_c.start), -1)
        above = moved[i, span_b, span_c] if i < moved.shape[0] else np.full(below.shape, -1)
        # on the boundary of its region: the region on exactly one side, everywhere on the rectangle
        if not below.size or not np.all((below == region) != (above == region)):
            raise InputError(f"contact {shown(contact.name)}: not on the boundary of region {shown(contact.region)} "
                             f"(the rectangle {AXES[axis]} = {contact.box[axis]} must have the region on one side "
                             "only, everywhere)")
        for earlier, (axis0, at0, (p0, p1), (q0, q1)) in zip(device.contacts, contacts):
            if axis0 == axis and at0 == at and max(p0, g[b]) < min(p1, g[b + 3]) and \
                    max(q0, g[c]) < min(q1, g[c + 3]):
                raise InputError(f"contact {shown(contact.name)} overlaps contact {shown(earlier.name)}: a face is "
                                 "in one contact")
        contacts.append((axis, at, (g[b], g[b + 3]), (g[c], g[c + 3])))
    volume_unit = Fraction(math.prod(lengths)) / steps ** 3
    sizes = [np.diff(p) for p in planes]
    block_volume = sizes[0][:, None, None] * sizes[1][None, :, None] * sizes[2][None, None, :]
    volumes = tuple(int(block_volume[owner == r].sum()) * volume_unit for r in range(len(regions)))
    return DeviceLayout(device, resolving, (planes[0], planes[1], planes[2]), owner, tuple(contacts), volumes)


def _check_connected(owner_box: np.ndarray, boxes: list[tuple[int, int, Coordinates]],
                     where: Callable[[int, int], str]) -> None:
    """Refuse a domain whose blocks are not one piece through shared faces (naming a box of another piece).

    Two blocks inside share a face only where their boxes touch along a face (the same
    box, or two whose faces meet over a rectangle of positive area: boxes do not
    overlap), so the pieces are those of the boxes' graph: at most 64 boxes, joined here
    exactly, with no graph library (a one-box device needs none of it).
    """
    piece = list(range(len(boxes)))

    def root(i: int) -> int:
        while piece[i] != i:
            i = piece[i]
        return i

    for i, (_, _, a) in enumerate(boxes):
        for j in range(i):
            b = boxes[j][2]
            if any((a[k + 3] == b[k] or b[k + 3] == a[k])
                   and all(min(a[m + 3], b[m + 3]) > max(a[m], b[m]) for m in range(3) if m != k)
                   for k in range(3)):
                piece[root(i)] = root(j)
    label = np.array([root(i) for i in range(len(boxes))], dtype=np.int64)
    inside = (owner_box >= 0).reshape(-1)
    of_block = label[np.maximum(owner_box.reshape(-1), 0)]
    first = of_block[inside][0]  # the piece of the first block inside, in block order
    strays = np.flatnonzero(inside & (of_block != first))
    if len(strays):
        r, k, _ = boxes[int(owner_box.reshape(-1)[strays[0]])]
        raise InputError(f"{where(r, k)} does not touch the rest of the device along a face: a device is one "
                         "connected piece (mesh each piece as its own device)")


def device_octree(layout: DeviceLayout, max_leaves: int | None = None) -> tuple[Octree, np.ndarray]:
    """The device's octree (inside leaves only) and each leaf's region.

    The tree over the bounding box is refined by the device's shapes down to its
    levels and wherever a region boundary or a contact edge cuts a cell (down to the
    resolving level), balanced, and the leaves outside every region are dropped
    (balance holds among the rest: they are a subset of a balanced tree).
    """
    device = layout.device
    shapes = [_shifted(shape, device.origin) for shape in device.refine]
    tree = build_octree(device.box, device.levels, shapes, device.balance, max_leaves, must_split=layout.cuts,
                        resolve=layout.resolving_level,
                        name=f"device {shown(device.name)} (levels {device.levels}, its boxes resolved at level "
                             f"{layout.resolving_level})")
    region = leaf_owner(layout, tree.levels, tree.positions)
    keep = region >= 0
    if keep.all():  # the boxes fill their bounding box: every leaf stays, no copy of the tree
        return tree, region.astype(np.int32)
    return (Octree(tree.box, tree.levels[keep], tree.positions[keep], tree.vertex_balanced),
            region[keep].astype(np.int32))


def leaf_owner(layout: DeviceLayout, levels: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """The region of each leaf: the owner of the block holding its low corner.

    A leaf at or above the resolving level lies in one block's owner (the tree split
    every cell a boundary cuts); a deeper one lies in one block of that level's grid.
    """
    levels = levels.astype(np.int64)
    resolving = layout.resolving_level
    low = np.where((levels <= resolving)[:, None], positions.astype(np.int64) << np.maximum(resolving - levels, 0)[:, None],
                   positions.astype(np.int64) >> np.maximum(levels - resolving, 0)[:, None])
    owner: np.ndarray = layout.owner[layout.blocks_of(low)].astype(np.int64)
    return owner


def _shifted(shape: Shape, origin: tuple[Fraction, Fraction, Fraction]) -> Shape:
    """A refinement shape in device coordinates moved to the bounding box's frame (its low corner at 0)."""
    v = list(shape.values)
    if shape.kind in ("point", "sphere", "box"):
        for i in range(6 if shape.kind == "box" else 3):
            v[i] -= origin[i % 3]
    else:  # plane n . x = d: n . (x' + origin) = d
        v[3] -= sum(v[a] * origin[a] for a in range(3))
    return Shape(shape.kind, tuple(v), shape.text)


def domain_boundary(layout: DeviceLayout, points: np.ndarray, grid: int) -> np.ndarray:
    """Which faces (n x size x 3 vertices, mesh grid units of ``grid`` per side) lie on the domain's boundary.

    A face lies on the boundary when it is flat in a plane of the blocks and, at its
    vertex centroid (an interior point of it), the domain lies on one side only;
    decided in integers (the centroid times the face size against the block planes).
    """
    n, size, _ = points.shape
    factor = grid // layout.steps  # grid steps per step of the resolving level (the tree is at least that deep)
    result = np.zeros(n, dtype=bool)
    sums = points.astype(np.int64).sum(axis=1)
    for axis in range(3):
        flat = np.all(points[:, :, axis] == points[:, :1, axis], axis=1)
        value = points[:, 0, axis].astype(np.int64)
        planes = layout.planes[axis] * factor
        at = np.searchsorted(planes, value)
        flat &= (at < len(planes)) & (planes[np.minimum(at, len(planes) - 1)] == value)
        rows = np.flatnonzero(flat)
        if not len(rows):
            continue
        index = []
        for other in ((axis + 1) % 3, (axis + 2) % 3):
            scaled = layout.planes[other] * factor * size
            index.append(np.minimum(np.searchsorted(scaled, sums[rows, other], "right") - 1, len(scaled) - 2))
        owner = np.moveaxis(layout.owner, axis, 0)
        i = at[rows]
        b, c = (index[0], index[1]) if (axis + 1) % 3 < (axis + 2) % 3 else (index[1], index[0])
        below = np.where(i > 0, owner[np.maximum(i - 1, 0), b, c], -1) if owner.shape[0] else -1
        above = np.where(i < owner.shape[0], owner[np.minimum(i, owner.shape[0] - 1), b, c], -1)
        result[rows] = (below < 0) != (above < 0)
    return result
