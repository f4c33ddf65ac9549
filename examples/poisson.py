"""Solve -div grad u = f on the unit cube with the box method on cospherical meshes, beside discretize.

    python examples/poisson.py                       # uniform levels 2-4, graded 4-6 (about a minute)
    python examples/poisson.py --uniform 2 3 4 5 6 --graded 4 5 6 7 --times

The box method (vertex-centred finite volumes) on the exact dual of each mesh:
``K u = M f`` with ``K = dual.laplacian()`` (coefficient = dual-face area / edge
length) and ``M = dual.mass()`` (the control volumes), Dirichlet values from the
exact solution at the boundary vertices.  Beside it, on the same octrees,
discretize's own cell-centred finite volumes (``TreeMesh``, weak Dirichlet data
on the boundary faces), when discretize is installed (the ``compare`` extra).

Two exact solutions: ``sines`` = sin(pi x) sin(pi y) sin(pi z), and ``mixed`` =
x^3 y + e^y sin(2z) (not symmetric).  Trees: ``uniform`` (every leaf at the level
L) and ``graded`` (level L where a leaf meets the sphere of radius 0.3 at the
centre, level L - 2 elsewhere, 2:1 balanced across faces, edges and corners), both
built by discretize when it is installed (its ``diagonal_balance`` is our vertex
balance), else by ``build_octree``.  Errors: max and L2 (``sqrt(sum volume *
error^2)``) over the unknowns; the order compares consecutive levels,
``log2(e(L-1) / e(L))`` (the finest leaf halves).  The mesh's elements come from
the shipped pattern table of the cube's leaves.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np
from scipy.sparse import diags
from scipy.sparse.linalg import cg

from cospherical import load_patterns
from cospherical.core.configuration import Box
from cospherical.formats.mesh import table_lookup
from cospherical.mesh.assembly import assemble
from cospherical.mesh.dual import mesh_dual
from cospherical.mesh.octree import build_octree, parse_shape

PI = math.pi
SOLUTIONS = {
    "sines": (lambda x, y, z: np.sin(PI * x) * np.sin(PI * y) * np.sin(PI * z),
              lambda x, y, z: 3 * PI ** 2 * np.sin(PI * x) * np.sin(PI * y) * np.sin(PI * z)),
    "mixed": (lambda x, y, z: x ** 3 * y + np.exp(y) * np.sin(2 * z),
              lambda x, y, z: -6 * x * y + 3 * np.exp(y) * np.sin(2 * z)),
}
CUBE = Box.parse(["1", "1", "1"])


TABLE = Path(__file__).resolve().parent.parent / "patterns" / "leaves-1x1x1.yaml"


def octree(kind: str, level: int):
    """A uniform or a sphere-graded octree of the unit cube (discretize's when it is installed)."""
    try:
        import discretize
    except ImportError:
        shape = "box:0,0,0,1,1,1" if kind == "uniform" else "sphere:0.5,0.5,0.5,0.3"
        return build_octree(CUBE, level, [parse_shape(shape)])
    from cospherical.mesh.octree import leaves_octree

    n = 2 ** level
    mesh = discretize.TreeMesh([[(1 / n, n)]] * 3, diagonal_balance=True)

    def wanted(cell) -> int:
        if kind == "uniform":
            return level
        offset, half = np.abs(np.asarray(cell.center) - 0.5), np.asarray(cell.h) / 2
        meets = np.linalg.norm(np.maximum(offset - half, 0)) <= 0.3 <= np.linalg.norm(offset + half)
        return level if meets else level - 2  # the sphere's surface at L, the rest at L - 2

    mesh.refine(wanted)
    h = mesh.h_gridded[:, 0]
    levels = np.rint(np.log2(1 / h)).astype(int)
    positions = np.rint((mesh.cell_centers - h[:, None] / 2) / h[:, None]).astype(int)
    return leaves_octree(CUBE, levels, positions)


def solve(matrix, rhs) -> np.ndarray:
    """Conjugate gradients with a Jacobi preconditioner, to 1e-12 relative residual (both matrices are SPD)."""
    solution, info = cg(matrix, rhs, rtol=1e-12, maxiter=20 * matrix.shape[0], M=diags(1 / matrix.diagonal()))
    if info != 0:
        raise RuntimeError(f"conjugate gradients did not converge ({info})")
    return solution


def box_method(tree, exact, source, cache: dict, lookup=None) -> dict:
    """Solve on the tree's cospherical mesh: unknowns, nonzeros, max and L2 errors, seconds."""
    start = time.perf_counter()
    dual = mesh_dual(assemble(tree, lookup, cache=cache))
    k = dual.laplacian()
    x, y, z = dual.vertices.T
    u = exact(x, y, z)
    inner = np.flatnonzero(~dual.boundary)
    outer = np.flatnonzero(dual.boundary)
    kk = k[inner][:, inner].tocsr()
    rhs = dual.control_volume[inner] * source(x[inner], y[inner], z[inner]) - k[inner][:, outer] @ u[outer]
    built = time.perf_counter()
    solution = solve(kk, rhs)
    error = solution - u[inner]
    return {"unknowns": len(inner), "nonzeros": kk.nnz, "max": float(np.abs(error).max()),
            "l2": float(np.sqrt((dual.control_volume[inner] * error ** 2).sum())),
            "build": built - start, "solve": time.perf_counter() - built}


def cell_centered(tree, exact, source) -> dict:
    """discretize's cell-centred finite volumes on the same leaves (weak Dirichlet data on boundary faces)."""
    import discretize
    start = time.perf_counter()
    n = 2 ** tree.depth
    mesh = discretize.TreeMesh([[(1 / n, n)]] * 3, diagonal_balance=True)
    centers = (tree.positions + 0.5) / (1 << tree.levels.astype(np.int64))[:, None]
    mesh.insert_cells(centers, tree.levels.astype(int), finalize=True)
    if mesh.n_cells != len(tree):
        raise RuntimeError(f"discretize made {mesh.n_cells} cells of our {len(tree)} leaves")
    volume = diags(mesh.cell_volumes)
    div = mesh.face_divergence
    face_inverse = mesh.get_face_inner_product(invert_matrix=True)
    boundary = mesh.boundary_face_scalar_integral
    g = exact(*mesh.boundary_faces.T)
    a = (volume @ div @ face_inverse @ div.T @ volume).tocsr()
    c = mesh.cell_centers
    rhs = volume @ source(*c.T) + volume @ div @ face_inverse @ (boundary @ g)
    built = time.perf_counter()
    solution = solve(a, rhs)
    error = solution - exact(*c.T)
    return {"unknowns": mesh.n_cells, "nonzeros": a.nnz, "max": float(np.abs(error).max()),
            "l2": float(np.sqrt((mesh.cell_volumes * error ** 2).sum())),
            "build": built - start, "solve": time.perf_counter() - built}


def order(rows: list[dict], key: str) -> list[str]:
    return ["-"] + [f"{math.log2(a[key] / b[key]):.2f}" for a, b in zip(rows, rows[1:])]


def main(argv=None) -> list[dict]:
    """Print the table; return its rows (each a solution, tree, level and method with its figures)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--uniform", type=int, nargs="*", default=[2, 3, 4], metavar="LEVEL")
    parser.add_argument("--graded", type=int, nargs="*", default=[4, 5, 6], metavar="LEVEL")
    parser.add_argument("--times", action="store_true", help="also print build and solve seconds")
    args = parser.parse_args(argv)
    try:
        import discretize  # noqa: F401
        methods = ("box", "discretize")
    except ImportError:
        methods = ("box",)
        print("(discretize is not installed: pip install 'cospherical[compare]' for its column)")
    cache: dict = {}
    lookup = table_lookup(load_patterns(TABLE), "optimal", CUBE, str(TABLE)) if TABLE.exists() else None
    header = "solution  tree     level  method       unknowns   nonzeros   max error  order    L2 error  order"
    if args.times:
        header += "  build s  solve s"
    print(header)
    table = []
    for name, (exact, source) in SOLUTIONS.items():
        for kind, levels in (("uniform", args.uniform), ("graded", args.graded)):
            trees = [octree(kind, level) for level in levels]
            for method in methods:
                rows = [box_method(t, exact, source, cache, lookup) if method == "box"
                        else cell_centered(t, exact, source) for t in trees]
                for level, row, o_max, o_l2 in zip(levels, rows, order(rows, "max"), order(rows, "l2")):
                    line = (f"{name:9s} {kind:8s} {level:5d}  {method:10s} {row['unknowns']:9,d} {row['nonzeros']:10,d}"
                            f"  {row['max']:9.3e} {o_max:>6s}  {row['l2']:9.3e} {o_l2:>6s}")
                    if args.times:
                        line += f"  {row['build']:7.2f}  {row['solve']:7.2f}"
                    print(line)
                    table.append({"solution": name, "tree": kind, "level": level, "method": method, **row,
                                  "max_order": o_max, "l2_order": o_l2})
    return table


if __name__ == "__main__":
    main()
