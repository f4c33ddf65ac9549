"""The dual.npz files the tests of ``cospherical.formats.dual`` read, forge and check."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="package")
def dual_run(tmp_path_factory):
    from cospherical.cli import main

    out = tmp_path_factory.mktemp("dual")
    argv = ["mesh", "--domain", "1", "2", "4", "--refine", "point:1/5,3/10,2/5", "--levels", "3", "--dual",
            "--no-uniform", "--format", "json", "--delaunay", "leaf"]
    assert main([*argv, "--out", str(out / "a")]) == 0
    assert main([*argv, "--out", str(out / "b")]) == 0
    return out


@pytest.fixture(scope="package")
def device_dual(tmp_path_factory):
    """A small device's dual.npz (version 4): two regions, a contact on each, both on the side x = 0 (the
    elements at x = 1 have no contact face)."""
    from fractions import Fraction as F

    from cospherical.api.mesh import build_mesh
    from cospherical.mesh.device import Contact, Device, Region

    def box(*values):
        return tuple(F(v) for v in values)

    device = Device("two", (Region("si", "Si", (box(0, 0, 0, 1, 1, "1/2"),)),
                            Region("ox", "SiO2", (box(0, 0, "1/2", 1, 1, 1),))),
                    (Contact("bulk", "si", box(0, 0, 0, 0, 1, "1/2")), Contact("gate", "ox", box(0, 0, "1/2", 0, 1, 1))),
                    (), 1)
    path = tmp_path_factory.mktemp("device") / "dual.npz"
    from cospherical.formats.dual import write_dual

    write_dual(build_mesh(device=device, uniform=False, dual=True).dual, path)
    return path
