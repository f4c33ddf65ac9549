"""The JSON/YAML shape of a tessellation, as ``cospherical tessellate`` prints it."""

from __future__ import annotations

from typing import Any

from ..catalogue import type_name
from ..core.tessellation import Tessellation

__all__ = ["tessellation_data"]


def tessellation_data(tess: Tessellation) -> dict[str, Any]:
    """The JSON/YAML shape of ``cospherical tessellate``: nodes in box coordinates, elements with
    the catalogue's names, circumcenters in box coordinates, and the FVM tests.

    Examples
    --------
    >>> from cospherical import Configuration, tessellate
    >>> data = tessellation_data(tessellate(Configuration.from_code("800000000000", ("1", "2", "4"))))
    >>> data["elements"][0]["name"], data["elements"][0]["circumcenter"]
    ('Rectangular Pyramid', [0.25, 1.0, 2.0])
    """
    cfg = tess.configuration
    real = cfg.real_nodes()
    return {
        **({"element": cfg.shape.name} if cfg.shape.name != "cuboid" else {}),  # the cuboid is the default
        "box": list(cfg.box.texts),
        "code": cfg.code,
        "point_set_code": cfg.point_set_code,  # the key of this point set in any pattern table
        "face_points": cfg.face_points,
        "faces": sorted(cfg.point_faces),
        "body_point": cfg.has_body_point,
        "steiner": {str(k): str(t) for k, t in enumerate(cfg.steiner) if t is not None},
        "nodes": {str(i): list(p) for i, p in real.items()},
        "elements": [
            {
                "type": e.type.id,
                "name": type_name(e.type),
                "nodes": list(e.nodes),
                "vertices": e.type.vertices,
                "edges": e.type.edges,
                "faces": e.type.faces,
                "circumcenter": list(tess.circumcenter(e)),
                **({"mirror": True} if e.mirrored else {}),
            }
            for e in tess.elements
        ],
        "fvm_adequate": tess.fvm_adequate,
        "fvm_adequate_open": tess.fvm_adequate_open,
    }
