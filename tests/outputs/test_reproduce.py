"""``cospherical reproduce``: the committed catalogue, pattern tables and results, regenerated."""

from __future__ import annotations

import filecmp
import os
from pathlib import Path

from cospherical.files.outputs import _new_temporary

ROOT = Path(__file__).resolve().parents[2]


def test_reproduce_regenerates_committed_files_byte_for_byte(tmp_path, monkeypatch, capsys):
    # From nothing, in one run, whatever state the catalogue is in: here the catalogue the
    # package would read is corrupt, and the root holds stale, half-written and corrupt outputs.
    import cospherical.catalogue.names as names
    from cospherical.cli import main

    corrupt = tmp_path / "corrupt-catalogue.yaml"
    corrupt.write_text("types: [unclosed\n")
    monkeypatch.setattr(names, "catalogue_path", lambda: corrupt)
    names.shipped_catalogue.cache_clear()
    root = tmp_path / "root"
    (root / "catalogue").mkdir(parents=True)
    (root / "catalogue" / "catalogue.yaml").write_text("types: [unclosed\n")
    (root / "results").mkdir()
    (root / "results" / "summary.md").write_text("stale")
    fd, stale = _new_temporary(root / "results" / "summary.md")
    stale.write_text("left by a killed run")
    os.close(fd)
    try:
        assert main(["reproduce", "--root", str(root)]) == 0, capsys.readouterr().err
    finally:
        names.shipped_catalogue.cache_clear()
    tmp_path = root
    for folder in ("catalogue", "patterns", "results"):
        # results/sweep/, results/intersection/, results/mesh/, results/devices/ and results/benchmarks/ come from other
        # commands and the benchmark scripts (CONTRIBUTING.md), not from reproduce
        committed = sorted(p.relative_to(ROOT) for p in (ROOT / folder).rglob("*") if p.is_file()
                           and not {"sweep", "intersection", "mesh", "devices", "benchmarks"} & set(p.relative_to(ROOT).parts))
        assert committed == sorted(p.relative_to(tmp_path) for p in (tmp_path / folder).rglob("*") if p.is_file())
        for name in committed:
            if name.suffix == ".png":  # pictures depend on the matplotlib build; check they are pictures
                assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
                continue
            assert filecmp.cmp(ROOT / name, tmp_path / name, shallow=False), str(name)
