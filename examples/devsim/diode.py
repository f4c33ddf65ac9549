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


def gmsh_box(fine: float, coarse: float = 0.25, width: float = 0.1):
    """Gmsh's tetrahedral mesh of the unit cube, size ``fine`` within ``width`` of the junction plane, ``coarse``
    elsewhere: (points, tetrahedra, triangles of the sides x = 0 and x = 1 with their side 0 or 1)."""
    import gmsh

    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)  # one thread: the same mesh every run
        gmsh.model.add("diode")
        gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
        gmsh.model.occ.synchronize()
        field = gmsh.model.mesh.field.add("Box")
        for key, value in (("VIn", fine), ("VOut", coarse), ("XMin", 0.5 - width), ("XMax", 0.5 + width),
                           ("YMin", -1), ("YMax", 2), ("ZMin", -1), ("ZMax", 2), ("Thickness", 0.3)):
            gmsh.model.mesh.field.setNumber(field, key, value)
        gmsh.model.mesh.field.setAsBackgroundMesh(field)
        for option in ("Mesh.MeshSizeExtendFromBoundary", "Mesh.MeshSizeFromPoints", "Mesh.MeshSizeFromCurvature"):
            gmsh.option.setNumber(option, 0)
        gmsh.model.mesh.generate(3)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        index = np.zeros(int(tags.max()) + 1, dtype=np.int64)
        index[tags.astype(np.int64)] = np.arange(len(tags))
        _, _, nodes = gmsh.model.mesh.getElements(3)
        tets = index[np.asarray(nodes[0], dtype=np.int64)].reshape(-1, 4)
        sides = []
        for end, x in enumerate((0.0, 1.0)):
            for _, tag in gmsh.model.getEntitiesInBoundingBox(x - 1e-6, -1, -1, x + 1e-6, 2, 2, dim=2):
                _, _, nodes = gmsh.model.mesh.getElements(2, tag)
                triangles = index[np.asarray(nodes[0], dtype=np.int64)].reshape(-1, 3)
                sides.append((triangles, np.full(len(triangles), end)))
        return (np.asarray(coords).reshape(-1, 3), tets, np.concatenate([t for t, _ in sides]),
                np.concatenate([e for _, e in sides]))
    finally:
        gmsh.finalize()


def simplex_currents(devsim, name: str, points, tets, triangles, side, biases, step: float) -> np.ndarray:
    """The anode current on a tetrahedral mesh of the unit cube with DEVSIM's own geometry (contacts: the
    triangles of the sides x = 0, ``side`` 0, and x = 1, ``side`` 1)."""
    elements = np.concatenate([np.column_stack([np.full(len(triangles), 2), 1 + side, triangles]).reshape(-1),
                               np.column_stack([np.full(len(tets), 3), np.zeros(len(tets), dtype=np.int64),
                                                tets]).reshape(-1)])
    quiet(devsim.create_gmsh_mesh, mesh=name, coordinates=(points * UM).reshape(-1).tolist(),
          physical_names=["domain", "xmin", "xmax"], elements=elements.astype(np.int64).tolist())
    quiet(devsim.add_gmsh_region, gmsh_name="domain", mesh=name, region="domain", material="Silicon")
    for contact in ("xmin", "xmax"):
        quiet(devsim.add_gmsh_contact, gmsh_name=contact, mesh=name, name=contact, region="domain", material="metal")
    quiet(devsim.finalize_mesh, mesh=name)
    quiet(devsim.create_device, mesh=name, device=name)
    quiet(physics, devsim, name, "domain")
    try:
        return sweep(devsim, name, "xmin", biases, step)
    finally:
        devsim.delete_device(device=name)
        devsim.delete_mesh(mesh=name)


def gmsh_currents(devsim, fine: float, biases, step: float = 0.05) -> dict:
    """The anode current on Gmsh's mesh of the cube (DEVSIM's own geometry: a Gmsh mesh has no exact dual)."""
    points, tets, triangles, side = gmsh_box(fine)
    return {"fine": fine, "nodes": len(points),
            "devsim": simplex_currents(devsim, f"diode-gmsh-{fine:g}", points, tets, triangles, side, biases, step)}


def delaunay_currents(devsim, level: int, biases, step: float = 0.05) -> dict:
    """The anode current on a tetrahedral Delaunay mesh (TetGen, else Qhull) of the level's octree vertices,
    with DEVSIM's own geometry: the vertices of this tool's mesh without its co-spherical elements."""
    from cospherical.core.geometry import six_volumes
    from cospherical.mesh.dual import external_tetrahedra

    mesh = junction_mesh(level)
    grid_points = np.asarray(mesh.vertices, dtype=np.int64)
    tets, tool, _ = external_tetrahedra(grid_points)
    flip = six_volumes(grid_points[tets]) < 0
    tets[flip] = tets[flip][:, [0, 2, 1, 3]]
    faces = np.sort(tets[:, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]].reshape(-1, 3), axis=1)
    unique, counts = np.unique(faces, axis=0, return_counts=True)
    outer = unique[counts == 1]
    x = grid_points[outer][:, :, 0]
    side = np.where((x == 0).all(axis=1), 0, np.where((x == mesh.grid).all(axis=1), 1, -1))
    points = grid_points / mesh.grid
    current = simplex_currents(devsim, f"diode-{tool}-L{level}", points, tets, outer[side >= 0], side[side >= 0],
                               biases, step)
    return {"level": level, "tool": tool, "nodes": len(points), "devsim": current}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", nargs="*", type=int, default=[3, 4], help="octree levels of the meshes")
    parser.add_argument("--biases", nargs="+", type=float, default=[round(0.05 * k, 2) for k in range(1, 15)],
                        help="forward biases (V), increasing")
    parser.add_argument("--step", type=float, default=0.05, help="largest bias step of the ramp (V)")
    parser.add_argument("--gmsh", nargs="*", type=float, default=[], metavar="SIZE",
                        help="also Gmsh meshes of the cube, of these element sizes (um) near the junction (0.25 "
                        "elsewhere), solved with DEVSIM's own geometry")
    parser.add_argument("--delaunay", nargs="*", type=int, default=[], metavar="LEVEL",
                        help="also TetGen's (else Qhull's) Delaunay tetrahedra of these levels' vertices, solved "
                        "with DEVSIM's own geometry")
    parser.add_argument("--plot", metavar="FILE", help="write the curves and errors as a PNG")
    args = parser.parse_args(argv)
    devsim = import_devsim()
    extended_precision(devsim)
    biases = np.array(args.biases)
    area = UM * UM
    exact_current = reference(devsim, biases, step=args.step) * area
    rows = [octree_currents(devsim, level, biases, args.step) for level in args.levels]
    meshed = [gmsh_currents(devsim, size, biases, args.step) for size in args.gmsh]
    tetrahedral = [delaunay_currents(devsim, level, biases, args.step) for level in args.delaunay]
    print(f"anode current at {biases[-1]:g} V: 1D reference {exact_current[-1]:.6e} A")
    print(f"{'mesh':>14} {'nodes':>6} {'exact dual':>11} {'DEVSIM geometry':>16}")
    for r in rows:
        errors = [(r[g][-1] - exact_current[-1]) / exact_current[-1] for g in GEOMETRIES]
        print(f"{'octree L' + str(r['level']):>14} {r['nodes']:>6} {errors[0]:>+10.2%} {errors[1]:>+15.2%}")
    for r in meshed:
        error = (r["devsim"][-1] - exact_current[-1]) / exact_current[-1]
        print(f"{'Gmsh ' + format(r['fine'], 'g'):>14} {r['nodes']:>6} {'-':>11} {error:>+15.2%}")
    for r in tetrahedral:
        error = (r["devsim"][-1] - exact_current[-1]) / exact_current[-1]
        print(f"{r['tool'] + ' L' + str(r['level']):>14} {r['nodes']:>6} {'-':>11} {error:>+15.2%}")
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
        for r in meshed:
            label = f"Gmsh {r['fine']:g} um ({r['nodes']} nodes), DEVSIM geometry"
            curves.semilogy(biases, r["devsim"], ":s", ms=3, label=label)
            errors.plot(biases, 100 * (r["devsim"] - exact_current) / exact_current, ":s", ms=3, label=label)
        curves.set(xlabel="anode bias (V)", ylabel="anode current (A)", title="3D pn diode, 1 um cube")
        errors.set(xlabel="anode bias (V)", ylabel="relative error (%)", title="against the 1D reference")
        errors.axhline(0, color="k", lw=0.5)
        curves.legend(fontsize=7)
        figure.tight_layout()
        figure.savefig(args.plot, dpi=110, metadata={"Software": None})
    return 0


if __name__ == "__main__":
    sys.exit(main())
