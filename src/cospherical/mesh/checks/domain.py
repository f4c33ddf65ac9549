"""Where the domain is: its boundary (for the conformity check's faces met once) and its closed inside
(for the circumcenters outside it), the box of the grid or a device's union of boxes, decided exactly."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...core.geometry import in_closed_box

if TYPE_CHECKING:  # a device's module is imported where a device's boundary is asked for
    from ..device import DeviceLayout

__all__ = ["in_closed_domain", "on_domain_boundary"]


def on_domain_boundary(points: np.ndarray, grid: int, layout: DeviceLayout | None = None) -> np.ndarray:
    """Per face (``points``: faces x corners x 3 grid points), whether it lies in the domain's boundary.

    The one place that says where the domain's boundary is, for the mesh's conformity check and
    for check's proof that a dual's elements are a mesh.  The domain is the box of ``grid``
    intervals per side, where a face lies in the boundary when all its corners share a
    coordinate 0 or ``grid``; or a device's union of boxes (``layout``, non-convex, with holes:
    :func:`~cospherical.mesh.device.domain_boundary`).
    """
    if layout is not None:
        from ..device import domain_boundary

        return domain_boundary(layout, points, grid)
    on_boundary = np.zeros(len(points), dtype=bool)
    for axis in range(3):
        for side in (0, grid):
            on_boundary |= np.all(points[:, :, axis] == side, axis=1)
    return on_boundary


def in_closed_domain(numerators: np.ndarray, denominators: np.ndarray, grid: int,
                     layout: DeviceLayout | None = None) -> np.ndarray:
    """Per rational point (``numerators`` (n x 3) over positive ``denominators``, broadcast per row or per
    axis; grid units), whether it lies in the closed domain: the box of ``grid`` intervals per side, or a
    device's union of boxes (``layout``: in the closed block of a region, decided in integers; a point on
    a block plane lies in either block beside it)."""
    inside = in_closed_box(numerators, denominators, 0, grid)
    if layout is None or not len(numerators):
        return inside
    den = np.broadcast_to(denominators, numerators.shape)
    factor = grid // layout.steps  # grid steps per step of the resolving level
    ranges = []
    for axis in range(3):
        planes = (layout.planes[axis] * factor).astype(numerators.dtype)
        scaled = planes[None, :] * den[:, axis, None]
        point = numerators[:, axis, None]
        blocks = len(planes) - 2
        low = np.clip((scaled < point).sum(axis=1) - 1, 0, blocks)  # the blocks whose closed span holds it
        high = np.clip((scaled <= point).sum(axis=1) - 1, 0, blocks)
        ranges.append((low.astype(np.int64), high.astype(np.int64)))
    held = np.zeros(len(numerators), dtype=bool)
    for i in ranges[0]:
        for j in ranges[1]:
            for k in ranges[2]:
                held |= layout.owner[i, j, k] >= 0
    return inside & held
