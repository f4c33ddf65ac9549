"""Writing ``dual.npz``: deterministic, read back alike by meshio, each member what numpy.save writes,
exact values wider than int64 written whole."""

from __future__ import annotations


import numpy as np
import pytest



@pytest.mark.oracle_meshio
def test_mesh_dual_writes_a_deterministic_dual_npz_and_vtu_data(dual_run):
    import json
    import zipfile

    import meshio

    from cospherical.formats.dual import read_dual

    a, b = dual_run / "a", dual_run / "b"
    assert (a / "dual.npz").read_bytes() == (b / "dual.npz").read_bytes()
    with zipfile.ZipFile(a / "dual.npz") as archive:  # no clock, no umask in the file; every member deflated
        assert {(i.date_time, i.external_attr >> 16, i.compress_type) for i in archive.infolist()} == {
            ((1980, 1, 1, 0, 0, 0), 0o644, zipfile.ZIP_DEFLATED)}
    report = json.loads((a / "report.json").read_text())
    dual = read_dual(a / "dual.npz")
    assert dual.volume_sum() == 1 and len(dual.edges) == report["dual"]["edges"]
    # a 1 x 2 x 4 leaf mesh is not Delaunay: the report says so, the file keeps every edge
    assert report["negative_coefficients"] == dual.negative_coefficients().to_dict()
    assert report["negative_coefficients"]["interior"] > 0
    assert report["dual"]["mixed"]["nonzeros"] == dual.laplacian().nnz
    vtu = meshio.read(a / "mesh.vtu")
    assert np.array_equal(vtu.point_data["control_volume"], dual.control_volume)
    assert np.array_equal(vtu.point_data["boundary_area"], dual.boundary_area)
    assert dual.boundary_area_sums() == (2, 2, 2)  # read back: the exact areas and their factors
    ok = np.concatenate(vtu.cell_data["delaunay_ok"])
    assert (ok == 0).sum() == report["delaunay_violations"] > 0
    assert np.concatenate(vtu.cell_data["circumcenter"]).shape == (report["elements"], 3)


def test_each_member_is_what_numpy_save_writes():
    """The writer makes each .npy itself (its header, then the array's own bytes): its bytes are numpy.save's, for
    every kind of member (ints, floats, bools, bytes, decimal text, empty, a non-contiguous view)."""
    import io

    from cospherical.formats.dual.writer import _npy

    for array in (np.arange(10), np.zeros((5, 3)), np.array([], dtype=np.int64), np.zeros((0, 3)),
                  np.array(["12", "-3"], dtype="U200"), np.array([], dtype="U200"), np.frombuffer(b"{}", np.uint8),
                  np.ones((4, 3), dtype=bool), np.arange(6, dtype=np.int32).reshape(3, 2)[:, :1]):
        saved = io.BytesIO()
        np.save(saved, array, allow_pickle=False)
        header, data = _npy(array)
        assert header + bytes(data) == saved.getvalue()


def test_exact_values_wider_than_the_text_column_are_written_whole(tmp_path, capsys):
    """Lengths of 37-digit fractions make coefficients of about 220 digits: they were cut to 200 characters
    without a word, and check refused the mesher's own file.  Written whole, the file reads back as the dual
    it was made from and check recomputes every value."""
    from cospherical.cli import main
    from cospherical.formats.dual import read_dual

    lengths = ["1234567890123456789012345678901234567/9876543210987654321098765432109876543",
               "9876543210987654321098765432109876541/1234567890123456789012345678901234569",
               "1357913579135791357913579135791357913/2468024680246802468024680246802468029"]
    out = tmp_path / "wide"
    assert main(["mesh", "--domain", *lengths, "--levels", "1", "--refine", "point:0.1,0.1,0.1", "--dual",
                 "--no-uniform", "--out", str(out)]) == 0
    dual = read_dual(out / "dual.npz")
    assert dual.coefficient_exact.dtype == object and max(len(str(v)) for v in dual.coefficient_exact) > 200
    capsys.readouterr()
    assert main(["check", str(out / "dual.npz")]) == 0, capsys.readouterr().err


def test_writing_loads_neither_the_reader_nor_the_verification():
    """The package gives the writer at once and the reader and the verification when first asked for: a run that
    writes dual.npz imports neither (nor the zip reader they need), and every name still imports."""
    import subprocess
    import sys

    script = ("import sys\nimport cospherical.formats.dual as d\n"
              "before = {m for m in ('cospherical.formats.dual.reader', 'cospherical.formats.dual.verify', 'zipfile') "
              "if m in sys.modules}\n"
              "from cospherical.formats.dual import read_dual, verify_dual, domain_sums, dual_layout, write_dual\n"
              "assert read_dual.__module__.endswith('.reader') and verify_dual.__module__.endswith('.verify')\n"
              "assert d.dual_layout is dual_layout and 'read_dual' in dir(d)\n"
              "try:\n    d.no_such_name\nexcept AttributeError:\n    print(sorted(before))\n")
    assert subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          check=True).stdout.split() == ["[]"]


def test_a_small_dual_is_written_without_threads_and_a_large_one_with_them_the_same_bytes(tmp_path, monkeypatch):
    """Below formats.deflated.SERIAL_BYTES the mesher writes dual.npz after the other files in its own thread (no
    pool, no concurrent.futures); above it beside them, deflated in threads: every file the same bytes."""
    from concurrent.futures import ThreadPoolExecutor

    from cospherical.api.mesh import build_mesh
    from cospherical.cli import main
    from cospherical.formats import deflated
    from cospherical.formats.dual.writer import threaded, write_dual

    argv = ["mesh", "--domain", "1", "1", "1", "--refine", "point:0.3,0.3,0.3", "--levels", "2", "--dual",
            "--format", "json"]
    dual = build_mesh(domain=(1, 1, 1), levels=2, refine=["point:0.3,0.3,0.3"], dual=True).dual
    assert not threaded(dual)
    assert main([*argv, "--out", str(tmp_path / "inline")]) == 0
    monkeypatch.setattr(deflated, "SERIAL_BYTES", 0)
    assert threaded(dual)
    assert main([*argv, "--out", str(tmp_path / "threads")]) == 0
    with ThreadPoolExecutor(3) as pool:
        write_dual(dual, tmp_path / "pool.npz", pool)
    for name in ("dual.npz", "mesh.vtu", "report.json"):
        assert (tmp_path / "inline" / name).read_bytes() == (tmp_path / "threads" / name).read_bytes()
    assert (tmp_path / "pool.npz").read_bytes() == (tmp_path / "inline" / "dual.npz").read_bytes()
