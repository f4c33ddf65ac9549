"""A 3D pn diode in DEVSIM: the current on this tool's mesh with the exact dual, against a converged 1D reference.

    python examples/devsim/diode.py                        # levels 3 and 4: the docs' table and figure
    python examples/devsim/diode.py --levels 2 --biases 0.1 --step 0.1  # a few seconds

The device: a 1 um silicon cube, p-type below ``x = 0.5 um`` (2e16 cm^-3) and n-type above
(1e16 cm^-3), with erf flanks (``NA = 2e16 erfc((x - 0.5 um) / 0.1 um) / 2``,
``ND = 1e16 erfc((0.5 um - x) / 0.1 um) / 2``), ohmic contacts on the sides ``x = 0`` (anode) and ``x = 1 um``
(cathode); drift-diffusion with Scharfetter-Gummel fluxes and Shockley-Read-Hall
recombination (DEVSIM's ``simple_physics``), forward bias 0 to 0.7 V.  The doping
varies along ``x`` only, so the exact current is the 1D one times the area: the
reference is DEVSIM's 1D diode on a fine mesh (refined until the current at
0.7 V stops changing in its 5th digit).

Meshes: octrees of the cube refined on the junction plane to the level L, 2:1
balanced, their exact Delaunay subdivision, handed to DEVSIM by
:func:`cospherical.adapters.devsim.create_device`.  Each is solved twice on the
same tetrahedra: with the exact dual (``exact``) and with DEVSIM's own geometry
(``devsim``, its ``NodeVolume`` and ``EdgeCouple``).  Printed: nodes and the
relative error of the anode current at the highest bias for both; with ``--plot
FILE`` the curves and the relative error against the bias.
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

UM = 1e-4  # DEVSIM's physics is in centimetres
JUNCTION, FLANK, ACCEPTORS, DONORS = 0.5 * UM, 0.1 * UM, 2e16, 1e16
GEOMETRIES = {"exact": (EXACT_NODE_VOLUME, EXACT_EDGE_COUPLE), "devsim": ("NodeVolume", "EdgeCouple")}


def quiet(call, *args, **kwargs):
    """Call a DEVSIM function without its report of every Newton iteration on stdout."""
    with contextlib.redirect_stdout(io.StringIO()):
        return call(*args, **kwargs)


def extended_precision(devsim) -> None:
    """Newton in DEVSIM's 128-bit floats: in double precision the minority carriers (1e4 cm^-3 beside 1e16)
    stall the relative error above any useful tolerance, with either geometry."""
    for name in ("extended_solver", "extended_model", "extended_equation"):
        devsim.set_parameter(name=name, value=True)


def physics(devsim, device: str, region: str) -> None:
    """Silicon at 300 K, the erf doping, Poisson then drift-diffusion with SRH, contacts ohmic."""
    from devsim.python_packages.model_create import CreateSolution
    from devsim.python_packages.simple_physics import (
        CreateSiliconDriftDiffusion, CreateSiliconDriftDiffusionAtContact, CreateSiliconPotentialOnly,
        CreateSiliconPotentialOnlyContact, GetContactBiasName, SetSiliconParameters)

    SetSiliconParameters(device, region, 300)
    devsim.node_model(device=device, region=region, name="Acceptors",
                      equation=f"{ACCEPTORS:g} * 0.5 * erfc((x - {JUNCTION:g}) / {FLANK:g})")
    devsim.node_model(device=device, region=region, name="Donors",
                      equation=f"{DONORS:g} * 0.5 * erfc(({JUNCTION:g} - x) / {FLANK:g})")
    devsim.node_model(device=device, region=region, name="NetDoping", equation="Donors - Acceptors")
    CreateSolution(device, region, "Potential")
    CreateSiliconPotentialOnly(device, region)
    for contact in devsim.get_contact_list(device=device):
        devsim.set_parameter(device=device, name=GetContactBiasName(contact), value=0.0)
        CreateSiliconPotentialOnlyContact(device, region, contact)
    quiet(devsim.solve, type="dc", absolute_error=1.0, relative_error=1e-7, maximum_iterations=40)
    CreateSolution(device, region, "Electrons")
    CreateSolution(device, region, "Holes")
    devsim.set_node_values(device=device, region=region, name="Electrons", init_from="IntrinsicElectrons")
    devsim.set_node_values(device=device, region=region, name="Holes", init_from="IntrinsicHoles")
    CreateSiliconDriftDiffusion(device, region)
    for contact in devsim.get_contact_list(device=device):
        CreateSiliconDriftDiffusionAtContact(device, region, contact)


def sweep(devsim, device: str, anode: str, biases, step: float = 0.05) -> np.ndarray:
    """The anode's total current (electrons and holes) at each bias, ramped from 0 V in steps of at most ``step``."""
    from devsim.python_packages.simple_physics import GetContactBiasName

    currents, at = [], 0.0
    devsim.set_parameter(device=device, name=GetContactBiasName(anode), value=0.0)
    quiet(devsim.solve, type="dc", absolute_error=1e10, relative_error=1e-10, maximum_iterations=40)
    for bias in biases:
        steps = max(1, int(np.ceil(abs(bias - at) / step - 1e-9)))
        for v in np.linspace(at, bias, steps + 1)[1:]:
            devsim.set_parameter(device=device, name=GetContactBiasName(anode), value=float(v))
            quiet(devsim.solve, type="dc", absolute_error=1e10, relative_error=1e-10, maximum_iterations=40)
        at = bias
        currents.append(sum(devsim.get_contact_current(device=device, contact=anode, equation=equation)
                            for equation in ("ElectronContinuityEquation", "HoleContinuityEquation")))
    return np.array(currents)


def reference(devsim, biases, spacing: float = 2e-3 * UM, step: float = 0.05) -> np.ndarray:
    """The 1D diode's current density (A/cm^2) on a uniform mesh of the given spacing."""
    name = f"diode-1d-{spacing:g}"
    devsim.create_1d_mesh(mesh=name)
    devsim.add_1d_mesh_line(mesh=name, pos=0.0, ps=spacing, tag="xmin")
    devsim.add_1d_mesh_line(mesh=name, pos=UM, ps=spacing, tag="xmax")
    for tag in ("xmin", "xmax"):
        devsim.add_1d_contact(mesh=name, name=tag, tag=tag, material="metal")
    devsim.add_1d_region(mesh=name, material="Si", region="domain", tag1="xmin", tag2="xmax")
    devsim.finalize_mesh(mesh=name)
    devsim.create_device(mesh=name, device=name)
    quiet(physics, devsim, name, "domain")
    current = sweep(devsim, name, "xmin", biases, step)
    devsim.delete_device(device=name)
    devsim.delete_mesh(mesh=name)
    return current


def junction_mesh(level: int):
    """The unit cube refined on the junction plane x = 1/2 to ``level``, its exact Delaunay subdivision."""
    tree = build_octree(Box.parse(["1", "1", "1"]), level, [parse_shape("plane:1,0,0,0.5")])
    return delaunay_mesh(assemble(tree), "global")[0]


def octree_currents(devsim, level: int, biases, step: float = 0.05) -> dict:
    """The anode current on the level's mesh, with the exact dual and with DEVSIM's geometry; nodes."""
    mesh = junction_mesh(level)
    handed = create_device(mesh, device=f"diode-L{level}", contacts=("xmin", "xmax"), scale=UM)
    region = handed.regions[0]
    quiet(physics, devsim, handed.name, region)
    result = {"level": level, "nodes": len(handed.node_ids[region])}
    for geometry, (volume, couple) in GEOMETRIES.items():
        devsim.set_parameter(device=handed.name, region=region, name="node_volume_model", value=volume)
        devsim.set_parameter(device=handed.name, region=region, name="edge_couple_model", value=couple)
        result[geometry] = sweep(devsim, handed.name, "xmin", biases, step)
    devsim.delete_device(device=handed.name)
    devsim.delete_mesh(mesh=handed.name)
    return result


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", nargs="+", type=int, default=[3, 4], help="octree levels of the meshes")
    parser.add_argument("--biases", nargs="+", type=float, default=[round(0.05 * k, 2) for k in range(1, 15)],
                        help="forward biases (V), increasing")
    parser.add_argument("--step", type=float, default=0.05, help="largest bias step of the ramp (V)")
    parser.add_argument("--plot", metavar="FILE", help="write the curves and errors as a PNG")
    args = parser.parse_args(argv)
    devsim = import_devsim()
    extended_precision(devsim)
    biases = np.array(args.biases)
    area = UM * UM
    exact_current = reference(devsim, biases, step=args.step) * area
    rows = [octree_currents(devsim, level, biases, args.step) for level in args.levels]
    print(f"anode current at {biases[-1]:g} V: 1D reference {exact_current[-1]:.6e} A")
    print(f"{'level':>5} {'nodes':>6} {'exact dual':>11} {'DEVSIM geometry':>16}")
    for r in rows:
        errors = [(r[g][-1] - exact_current[-1]) / exact_current[-1] for g in GEOMETRIES]
        print(f"{r['level']:>5} {r['nodes']:>6} {errors[0]:>+10.2%} {errors[1]:>+15.2%}")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        figure, (curves, errors) = plt.subplots(1, 2, figsize=(11, 4.2))
        curves.semilogy(biases, exact_current, "k-", label="1D reference")
        for r in rows:
            for geometry, style in (("exact", "-o"), ("devsim", "--x")):
                label = f"L{r['level']} ({r['nodes']} nodes), {'exact dual' if geometry == 'exact' else 'DEVSIM geometry'}"
                curves.semilogy(biases, r[geometry], style, ms=3, label=label)
                errors.plot(biases, 100 * (r[geometry] - exact_current) / exact_current, style, ms=3, label=label)
        curves.set(xlabel="anode bias (V)", ylabel="anode current (A)", title="3D pn diode, 1 um cube")
        errors.set(xlabel="anode bias (V)", ylabel="relative error (%)", title="against the 1D reference")
        errors.axhline(0, color="k", lw=0.5)
        curves.legend(fontsize=7)
        figure.tight_layout()
        figure.savefig(args.plot, dpi=110, metadata={"Software": None})
    return 0


if __name__ == "__main__":
    sys.exit(main())
