"""The MOS capacitor in DEVSIM: Poisson in silicon and oxide, each region with its part of the exact dual.

    python examples/devsim/moscap.py                 # the device file's level 5: 6,235 nodes, a few seconds
    python examples/devsim/moscap.py --levels 3      # the tests' size

The device is ``examples/devices/mos-capacitor.yaml``: a substrate (silicon, the
lower 3/4 of a unit cube) under an oxide, the bulk contact below, the gate a square
on top.  Poisson's equation ``-div(eps grad u) = rho`` with ``eps`` 11.7 in silicon
and 3.9 in the oxide, a uniform charge ``rho = -1`` in the silicon (a depleted
p-type substrate) and none in the oxide, ``u`` continuous across the interface
(DEVSIM's ``continuous`` interface equation: the fluxes of both regions' parts of
an interface node add up), ``u = 1`` on the gate and ``0`` on the bulk.

Gauss's law: the charges the two contacts take add up to the charge in the
silicon, ``rho`` times its volume.  The box method keeps that balance whatever
the mesh, so the sum is ``rho`` times the silicon's node volumes: exact with the
exact dual's parts per region (they sum to the substrate's volume, 3/4), and off by
DEVSIM's own geometry's excess.  Printed: both sums over ``rho * 3/4``.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import sys
from dataclasses import replace
from pathlib import Path

from cospherical import build_mesh
from cospherical.adapters.devsim import EXACT_EDGE_COUPLE, EXACT_NODE_VOLUME, create_device, import_devsim
from cospherical.formats.device_file import read_device

DEVICE = Path(__file__).resolve().parents[1] / "devices" / "mos-capacitor.yaml"
PERMITTIVITY = {"substrate": 11.7, "oxide": 3.9}
CHARGE = -1.0
GEOMETRIES = {"exact": (EXACT_NODE_VOLUME, EXACT_EDGE_COUPLE), "devsim": ("NodeVolume", "EdgeCouple")}


def set_up(devsim, device: str) -> None:
    """Poisson in both regions, continuity at the interface, Dirichlet at the contacts."""
    for region, eps in PERMITTIVITY.items():
        devsim.node_solution(device=device, region=region, name="Potential")
        devsim.edge_from_node_model(device=device, region=region, node_model="Potential")
        devsim.edge_model(device=device, region=region, name="DField",
                          equation=f"{eps} * (Potential@n0 - Potential@n1) * EdgeInverseLength")
        devsim.edge_model(device=device, region=region, name="DField:Potential@n0", equation=f"{eps} * EdgeInverseLength")
        devsim.edge_model(device=device, region=region, name="DField:Potential@n1",
                          equation=f"-{eps} * EdgeInverseLength")
        devsim.node_model(device=device, region=region, name="Source",
                          equation=f"{-CHARGE if region == 'substrate' else 0.0}")
        devsim.equation(device=device, region=region, name="PotentialEquation", variable_name="Potential",
                        edge_model="DField", node_model="Source", variable_update="default")
    for interface in devsim.get_interface_list(device=device):
        devsim.interface_model(device=device, interface=interface, name="continuous",
                               equation="Potential@r0 - Potential@r1")
        devsim.interface_model(device=device, interface=interface, name="continuous:Potential@r0", equation="1")
        devsim.interface_model(device=device, interface=interface, name="continuous:Potential@r1", equation="-1")
        devsim.interface_equation(device=device, interface=interface, name="PotentialEquation",
                                  interface_model="continuous", type="continuous")
    for contact, bias in (("gate", 1.0), ("bulk", 0.0)):
        devsim.contact_node_model(device=device, contact=contact, name=f"{contact}_bc", equation=f"Potential - {bias}")
        devsim.contact_node_model(device=device, contact=contact, name=f"{contact}_bc:Potential", equation="1")
        devsim.contact_equation(device=device, contact=contact, name="PotentialEquation", node_model=f"{contact}_bc",
                                edge_charge_model="DField", node_charge_model="Source")


def balance(devsim, device: str, geometry: str) -> float:
    """The contacts' total charge over the silicon's charge, solved with the chosen geometry in both regions."""
    volume, couple = GEOMETRIES[geometry]
    for region in PERMITTIVITY:
        devsim.set_parameter(device=device, region=region, name="node_volume_model", value=volume)
        devsim.set_parameter(device=device, region=region, name="edge_couple_model", value=couple)
    with contextlib.redirect_stdout(io.StringIO()):
        devsim.solve(type="dc", absolute_error=1e-12, relative_error=1e-12, maximum_iterations=5)
    total = sum(devsim.get_contact_charge(device=device, contact=c, equation="PotentialEquation")
                for c in ("gate", "bulk"))
    return abs(total) / abs(CHARGE * 0.75)


def run(levels: int | None = None, name: str = "moscap") -> dict:
    devsim = import_devsim()
    device = read_device(DEVICE)
    mesh = build_mesh(device=device if levels is None else replace(device, levels=levels), uniform=False)
    handed = create_device(mesh, device=name)
    try:
        set_up(devsim, name)
        return {"nodes": len(mesh.vertices), **{g: balance(devsim, name, g) for g in GEOMETRIES}}
    finally:
        devsim.delete_device(device=name)
        devsim.delete_mesh(mesh=name)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, help="refine to this level instead of the device file's")
    result = run(parser.parse_args(argv).levels)
    print(f"nodes {result['nodes']:,}; contact charge / silicon charge: exact dual {result['exact']:.15f}, "
          f"DEVSIM geometry {result['devsim']:.6f}")
    return 0 if abs(result["exact"] - 1) < 1e-12 else 1


if __name__ == "__main__":
    sys.exit(main())
