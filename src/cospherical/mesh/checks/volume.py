"""The volume check: the elements' volumes sum to the domain's, exactly, none flat."""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from ..assembly import Mesh

__all__ = ["VolumeCheck", "check_volume"]


@dataclass(frozen=True)
class VolumeCheck:
    """What :func:`check_volume` found: the elements' volumes summed, exactly.

    Attributes
    ----------
    volume : Fraction
        The elements' volumes summed, as a fraction of the root box's volume.
    flat_elements : int
        Elements of volume <= 0.
    volume_ok : bool
        ``volume`` is the domain's (the root box's, or a device's share of it) and no element is flat.
    """

    volume: Fraction
    flat_elements: int
    volume_ok: bool

    def figures(self) -> dict[str, bool | str | int]:
        """The report's ``volume_ok``, ``volume`` (exact text) and ``flat_elements``, in its order."""
        return {"volume_ok": self.volume_ok, "volume": str(self.volume), "flat_elements": self.flat_elements}


def check_volume(mesh: Mesh) -> VolumeCheck:
    """Volumes sum to the domain's, exactly (integers and rationals), every element of positive volume.

    Examples
    --------
    >>> from cospherical.core.configuration import Box
    >>> from cospherical.mesh.octree import build_octree, parse_shape
    >>> from cospherical.mesh.assembly import assemble
    >>> check_volume(assemble(build_octree(Box.parse([1, 2, 4]), 0, [])))
    VolumeCheck(volume=Fraction(1, 1), flat_elements=0, volume_ok=True)
    """
    depth = mesh.tree.depth
    total = Fraction(0)
    flat = 0
    for _, tessellation, leaves in mesh.groups():
        per_level = np.bincount(mesh.tree.levels[leaves].astype(np.int64), minlength=depth + 1)
        weight = sum(int(count) * 8 ** (depth - level) for level, count in enumerate(per_level.tolist()))
        total += sum((e.unit_volume for e in tessellation.elements), Fraction(0)) * weight
        flat += sum(e.unit_volume <= 0 for e in tessellation.elements) * len(leaves)
    share = total / 8 ** depth
    if mesh.cells is not None:
        per_shape = np.bincount(mesh.cells.shape, minlength=len(mesh.cells.shapes)).tolist()
        share += sum((shape.grid_volume * n for shape, n in zip(mesh.cells.shapes, per_shape)), Fraction(0)) \
            / mesh.grid ** 3
        flat += sum(n for shape, n in zip(mesh.cells.shapes, per_shape) if shape.grid_volume <= 0)
    return VolumeCheck(share, int(flat), share == mesh.domain_share and flat == 0)
