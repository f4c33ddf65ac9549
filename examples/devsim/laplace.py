"""Laplace and Poisson in DEVSIM on graded octree meshes: the exact dual beside DEVSIM's own geometry.

    python examples/devsim/laplace.py                 # levels 4 (1x1x1) and 3 (1x2x4): about 10 s
    python examples/devsim/laplace.py --levels 3 3    # the tests' size

Each mesh (a sphere-refined octree, its exact Delaunay subdivision) is handed to
DEVSIM by :func:`cospherical.adapters.devsim.create_device`, contacts on the sides
``x = 0`` and ``x = a``.  Two problems, each solved twice on the same tetrahedra:
with the exact dual (``ExactNodeVolume``, ``ExactEdgeCouple``, what create_device
installs) and with DEVSIM's own geometry (``NodeVolume``, ``EdgeCouple``):

- **Laplace**, ``u = 0`` at ``x = 0`` and ``u = a`` at ``x = a``, no flux elsewhere:
  the solution is ``u = x``, which the box method reproduces exactly when its
  coefficients are the Voronoi dual's (a linear function has zero discrete
  Laplacian).  Printed: the largest ``|u - x|``.
- **Poisson**, ``-div grad u = 1`` with ``u = 0`` on both contacts: the charge
  the contacts take equals the source integrated over the domain, the sum of
  the node volumes.  Printed: the contacts' total over the domain's volume (1
  when the node volumes fill the domain exactly).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import sys

import numpy as np

from cospherical.adapters.devsim import EXACT_EDGE_COUPLE, EXACT_NODE_VOLUME, create_device, import_devsim
from cospherical.core.configuration import Box
from cospherical.mesh.assembly import assemble
from cospherical.mesh.delaunay import delaunay_mesh
from cospherical.mesh.octree import build_octree, parse_shape

GEOMETRIES = {"exact": (EXACT_NODE_VOLUME, EXACT_EDGE_COUPLE), "devsim": ("NodeVolume", "EdgeCouple")}


def graded_mesh(lengths, levels: int):
    """An octree refined to ``levels`` on a sphere in the box, 2:1 balanced; its exact Delaunay subdivision."""
    box = Box.parse(lengths)
    a, b, c = box.to_float()
    sphere = parse_shape(f"sphere:{a / 2},{b / 2},{c / 2},{0.3 * min(a, b, c)}")
    mesh, _, _ = delaunay_mesh(assemble(build_octree(box, levels, [sphere])), "global")
    return mesh


def set_up(devsim, device: str, region: str, source: bool) -> None:
    """Potential, its flux ``(u0 - u1) / length`` and, for Poisson, a unit source; Dirichlet at xmin and xmax."""
    devsim.node_solution(device=device, region=region, name="Potential")
    devsim.edge_from_node_model(device=device, region=region, node_model="Potential")
    devsim.edge_model(device=device, region=region, name="Flux",
                      equation="(Potential@n0 - Potential@n1) * EdgeInverseLength")
    devsim.edge_model(device=device, region=region, name="Flux:Potential@n0", equation="EdgeInverseLength")
    devsim.edge_model(device=device, region=region, name="Flux:Potential@n1", equation="-EdgeInverseLength")
    extra = {}
    if source:
        devsim.node_model(device=device, region=region, name="Source", equation="-1.0")
        extra = {"node_model": "Source"}
    devsim.equation(device=device, region=region, name="PotentialEquation", variable_name="Potential",
                    edge_model="Flux", variable_update="default", **extra)
    for contact in ("xmin", "xmax"):
        devsim.contact_node_model(device=device, contact=contact, name=f"{contact}_bc",
                                  equation=f"Potential - {contact}_bias")
        devsim.contact_node_model(device=device, contact=contact, name=f"{contact}_bc:Potential", equation="1")
        devsim.contact_equation(device=device, contact=contact, name="PotentialEquation",
                                node_model=f"{contact}_bc", edge_charge_model="Flux",
                                node_charge_model="Source" if source else "")


def solve(devsim, handed, geometry: str, bias: float, source: bool):
    """Solve on the device with the chosen geometry: (potential, x, the contacts' total charge)."""
    device, region = handed.name, handed.regions[0]
    volume, couple = GEOMETRIES[geometry]
    devsim.set_parameter(device=device, region=region, name="node_volume_model", value=volume)
    devsim.set_parameter(device=device, region=region, name="edge_couple_model", value=couple)
    devsim.set_parameter(device=device, name="xmin_bias", value=0.0)
    devsim.set_parameter(device=device, name="xmax_bias", value=0.0 if source else bias)
    devsim.set_node_values(device=device, region=region, name="Potential", init_from="node_index")  # far from x
    with contextlib.redirect_stdout(io.StringIO()):  # DEVSIM reports every iteration
        devsim.solve(type="dc", absolute_error=1e-13, relative_error=1e-14, maximum_iterations=5)
    u = np.array(devsim.get_node_model_values(device=device, region=region, name="Potential"))
    x = np.array(devsim.get_node_model_values(device=device, region=region, name="x"))
    charge = sum(devsim.get_contact_charge(device=device, contact=c, equation="PotentialEquation")
                 for c in ("xmin", "xmax"))
    return u, x, charge


def run_case(lengths, levels: int, name: str) -> dict:
    """Laplace and Poisson on one graded mesh, each with both geometries."""
    devsim = import_devsim()
    mesh = graded_mesh(lengths, levels)
    volume = float(np.prod(mesh.box.to_float()))
    a = mesh.box.to_float()[0]
    result = {"box": " x ".join(lengths), "levels": levels}
    for problem, source in (("laplace", False), ("poisson", True)):
        handed = create_device(mesh, device=f"{name}-{problem}", contacts=("xmin", "xmax"))
        result["nodes"] = len(handed.node_ids[handed.regions[0]])
        set_up(devsim, handed.name, handed.regions[0], source)
        for geometry in GEOMETRIES:
            u, x, charge = solve(devsim, handed, geometry, a, source)
            if source:
                result[f"poisson_{geometry}"] = abs(charge) / volume
            else:
                result[f"laplace_{geometry}"] = float(np.abs(u - x).max())
        devsim.delete_device(device=handed.name)
        devsim.delete_mesh(mesh=handed.name)
    return result


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", nargs=2, type=int, default=(4, 3), metavar=("CUBE", "BOX124"),
                        help="octree levels of the 1x1x1 and the 1x2x4 mesh")
    args = parser.parse_args(argv)
    rows = [run_case(["1", "1", "1"], args.levels[0], "cube"), run_case(["1", "2", "4"], args.levels[1], "box124")]
    print(f"{'box':10} {'levels':>6} {'nodes':>6}  {'max|u-x| exact':>15} {'max|u-x| DEVSIM':>16}  "
          f"{'charge/V exact':>15} {'charge/V DEVSIM':>16}")
    for r in rows:
        print(f"{r['box']:10} {r['levels']:>6} {r['nodes']:>6}  {r['laplace_exact']:>15.2e} "
              f"{r['laplace_devsim']:>16.2e}  {r['poisson_exact']:>15.12f} {r['poisson_devsim']:>16.12f}")
    return 0 if all(r["laplace_exact"] < 1e-12 and abs(r["poisson_exact"] - 1) < 1e-12 for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
