"""Reading ``dual.npz``: truncated, tampered, re-signed with hostile numbers or inflating files refused in one
line, from the headers before the data; rows proved distinct even when every hash collides."""

from __future__ import annotations

import json
import time
import warnings

import numpy as np
import pytest

from .forged import _resigned


def test_a_truncated_or_tampered_dual_npz_is_refused_with_one_line(dual_run, tmp_path, capsys):
    import struct
    import zipfile

    from cospherical.cli import main

    good = (dual_run / "a" / "dual.npz").read_bytes()
    assert main(["check", str(dual_run / "a" / "dual.npz")]) == 0
    (tmp_path / "truncated.npz").write_bytes(good[: len(good) // 2])
    # a member rewritten with a valid zip CRC: only the manifest's checksum can tell
    with zipfile.ZipFile(dual_run / "a" / "dual.npz") as source, \
            zipfile.ZipFile(tmp_path / "tampered.npz", "w") as target:
        for info in source.infolist():
            data = source.read(info)
            if info.filename == "coefficient.npy":
                data = data[:-8] + np.float64(1e9).tobytes()
            target.writestr(info, data)
    flipped = bytearray(good)
    with zipfile.ZipFile(dual_run / "a" / "dual.npz") as source:  # a byte in the middle of a member's deflated data
        info = source.getinfo("edges.npy")
        name_length, extra_length = struct.unpack("<HH", good[info.header_offset + 26:info.header_offset + 30])
        start = info.header_offset + 30 + name_length + extra_length  # after its local header
    flipped[start + info.compress_size // 2] ^= 0xFF
    (tmp_path / "flipped.npz").write_bytes(bytes(flipped))
    (tmp_path / "empty.npz").write_bytes(b"")
    with zipfile.ZipFile(dual_run / "a" / "dual.npz") as source, \
            zipfile.ZipFile(tmp_path / "twice.npz", "w") as target, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # zipfile's "Duplicate name"
        edges = source.read("edges.npy")
        for info in source.infolist():
            target.writestr(info.filename, source.read(info))
        target.writestr("edges.npy", edges)  # a reader takes one of the two: which?
    capsys.readouterr()
    for name in ("truncated", "tampered", "flipped", "empty", "twice"):
        assert main(["check", str(tmp_path / f"{name}.npz")]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"{name}.npz" in err and "Traceback" not in err
    assert "member 'edges.npy' appears twice" in err


@pytest.mark.parametrize("case", ["factor 1e999999999", "factor 1e400", "grid 10**400", "integers --5",
                                  "integers of 5000 digits", "boundary factors not the domain's",
                                  "manifest nested 100,000 deep", "manifest with a repeated key",
                                  "a grid vertex outside the grid", "version 2 (no elements)",
                                  "volume denominator of 1000 digits", "boundary denominator of 1000 digits",
                                  "version 3.0", "version 10**400"])
def test_a_resigned_dual_npz_with_hostile_numbers_is_one_line_at_once(dual_run, tmp_path, capsys, case):
    from cospherical.cli import main

    good = dual_run / "a" / "dual.npz"
    edits = {"factor 1e999999999": lambda m: m.update(volume_factor_squared="1e999999999"),
             "factor 1e400": lambda m: m.update(volume_factor_squared="1" + "0" * 400),
             "grid 10**400": lambda m: m.update(grid=10**400),
             "boundary factors not the domain's": lambda m: m.update(boundary_factors_squared=["1e400", "1", "1"]),
             # the manifest read by the readers' one JSON parser (json.loads recursed: a RecursionError
             # traceback), which also refuses a repeated key instead of keeping the last
             "manifest nested 100,000 deep": lambda m: "[" * 100_000 + "]" * 100_000,
             "manifest with a repeated key": lambda m: json.dumps(m)[:-1] + ', "version": 1}',
             "version 2 (no elements)": lambda m: m.update(version=2),
             "version 3.0": lambda m: m.update(version=3.0),  # a float: not what the writer writes
             "version 10**400": lambda m: m.update(version=10**400),
             # the sums they give are named, cut: not a line of a thousand digits
             "volume denominator of 1000 digits": lambda m: m.update(volume_denominator="9" * 1000),
             "boundary denominator of 1000 digits": lambda m: m.update(boundary_area_denominator="9" * 1000)}
    members = None
    if case.startswith("integers"):
        from cospherical.formats.dual import read_dual

        count = len(read_dual(good).volume_exact)
        members = {"volume_exact": np.array(["--5" if "--5" in case else "9" * 5000] * count)}
    if case == "a grid vertex outside the grid":  # re-signed: the checks' sums never read the vertices
        from cospherical.formats.dual import read_dual

        vertices = read_dual(good).grid_vertices.copy()
        vertices[0] = [-1, 10**15, 0]
        members = {"grid_vertices": vertices}
    _resigned(good, tmp_path / "hostile.npz", edits.get(case), members)
    capsys.readouterr()
    start = time.monotonic()
    assert main(["check", str(tmp_path / "hostile.npz")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and len(err) < 400, err
    assert time.monotonic() - start < 30  # 10**999999999 would take far longer
    assert case != "manifest with a repeated key" or "repeated key 'version'" in err, err
    assert not case.startswith("version 2") or "dual format version 2; this reads 3, 4 and 5 (write it again with " \
        "cospherical mesh --dual)" in err, err
    assert not case.startswith("version 3") or "dual format version 3.0; this reads" in err, err


def test_a_dual_npz_that_inflates_is_refused_from_its_headers(dual_run, tmp_path, capsys, monkeypatch):
    """A member whose header claims 100 MB of zeros (deflated to 100 KB, re-signed) is refused
    from the headers, before its data is read: the shapes disagree. Consistent claims beyond
    half the machine's memory are refused likewise (here the machine is made small)."""
    import hashlib
    import io
    import tracemalloc
    import zipfile

    from cospherical.cli import main
    from cospherical.formats.dual import reader as dual_format

    good = dual_run / "a" / "dual.npz"
    bomb = tmp_path / "bomb.npz"
    count = 25 << 22  # 105 MB
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "|b1", "fortran_order": False, "shape": (count,)})
    digest = hashlib.sha256(header.getvalue())
    zeros = bytes(1 << 22)
    for _ in range(count // len(zeros)):
        digest.update(zeros)
    with zipfile.ZipFile(good) as source, zipfile.ZipFile(bomb, "w", zipfile.ZIP_DEFLATED, compresslevel=1) as out:
        for info in source.infolist():
            if info.filename == "boundary.npy":
                with out.open("boundary.npy", "w", force_zip64=True) as member:
                    member.write(header.getvalue())
                    for _ in range(count // len(zeros)):
                        member.write(zeros)
            elif info.filename == "manifest.npy":
                manifest = json.loads(np.lib.format.read_array(io.BytesIO(source.read(info))).tobytes())
                manifest["sha256"]["boundary"] = digest.hexdigest()  # re-signed: only the reader's bounds refuse it
                text = np.frombuffer(json.dumps(manifest).encode(), dtype=np.uint8)
                buffer = io.BytesIO()
                np.lib.format.write_array(buffer, text)
                out.writestr("manifest.npy", buffer.getvalue())
            else:
                out.writestr(info.filename, source.read(info))
    assert bomb.stat().st_size < 1 << 20
    capsys.readouterr()
    tracemalloc.start()
    try:
        assert main(["check", str(bomb)]) == 2
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"member boundary: bool ({count},), expected b (" in err, err
    assert peak < 20 * 2**20, peak  # it read the 100 MB (twice: the data and its array) before

    monkeypatch.setattr(dual_format, "machine_memory", lambda: 2 * good.stat().st_size)
    assert main(["check", str(good)]) == 2
    assert "more than half this machine's memory" in capsys.readouterr().err


def test_distinct_elements_are_proved_distinct_even_when_every_hash_collides(dual_run, monkeypatch):
    """Elements are proved pairwise different by one hash per element; equal hashes (here: all of them) send
    the proof to sorting the elements themselves, which finds them different, as they are."""
    from cospherical.formats.dual import read_dual
    from cospherical.mesh.dual import shapes

    good = dual_run / "a" / "dual.npz"
    monkeypatch.setattr(shapes, "_ROW_HASH", np.zeros_like(shapes._ROW_HASH))
    assert len(read_dual(good).element_sizes) > 1
