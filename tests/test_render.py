"""LaTeX tables compiled by a real pdflatex, pictures, and VTU export read back by meshio."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import meshio
import numpy as np
import pytest
from matplotlib.image import imread

from cospherical import Configuration, tessellate
from cospherical.catalogue import catalogue_path, load_catalogue
from cospherical.formats.vtu import write_vtu
from cospherical.outputs.latex import tikz_picture

ROOT = Path(__file__).resolve().parents[1]
SUMMARIES = [ROOT / "results" / f"bisection-{box}.json" for box in ("1x1x1", "1x2x4", "1x1.4142x1.4142")]


def cospherical(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "cospherical", *args], capture_output=True, text=True, cwd=cwd)


@pytest.mark.oracle_pdflatex
def test_full_document_compiles_and_page_one_is_not_blank(tmp_path):
    assert shutil.which("pdflatex") and shutil.which("pdftoppm"), "install texlive and poppler-utils (scripts/setup.sh)"
    result = cospherical("render", "--summary", *map(str, SUMMARIES), "--out", str(tmp_path), "--pdf")
    assert result.returncode == 0, result.stderr
    pdf = tmp_path / "document.pdf"
    assert pdf.stat().st_size > 10_000
    subprocess.run(["pdftoppm", "-r", "50", "-f", "1", "-l", "1", "-png", str(pdf), str(tmp_path / "page")], check=True)
    (page,) = tmp_path.glob("page*.png")
    pixels = imread(page)
    ink = (pixels[..., :3].mean(axis=2) < 0.5).mean()
    assert 0.005 < ink < 0.5, f"page 1 looks blank or black: {ink:.4f} of the pixels are dark"
    text = subprocess.run(["pdftotext", str(pdf), "-"], capture_output=True, text=True).stdout
    assert "Generic #10" in text and "37,259" in text and "Element types" in text
    log = (tmp_path / "document.log").read_text(errors="replace")
    assert "Overfull \\hbox" not in log, "a table is wider than the text block"
    captions = [line for tex in tmp_path.glob("*.tex") for line in tex.read_text().splitlines() if "\\caption" in line]
    assert captions and not [c for c in captions if "\\_" in c], "captions show internal ids"


def test_rendered_tex_is_byte_identical_across_runs(tmp_path):
    for run in ("a", "b"):
        assert cospherical("render", "--summary", *map(str, SUMMARIES), "--out", str(tmp_path / run)).returncode == 0
    names = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert names == sorted(p.name for p in (tmp_path / "b").iterdir()) and "document.tex" in names
    for name in names:
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes(), name


def test_names_are_escaped_and_pictures_drawn():
    catalogue = load_catalogue(catalogue_path())
    generic = next(t for t in catalogue["types"] if t["name"].startswith("Generic #"))
    picture = tikz_picture(generic)
    assert picture.count(r"\draw[thick]") + picture.count(r"\draw[densely dashed, gray]") == generic["edges"]
    assert r"\draw[densely dashed, gray]" in picture or generic["vertices"] == 4
    elements = (ROOT / "results" / "latex" / "elements.tex").read_text()
    assert r"Generic \#" in elements and "Generic #" not in elements.replace(r"Generic \#", "")


def test_render_refuses_bad_summaries(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"study": "bisection"}')
    result = cospherical("render", "--summary", str(bad), "--out", str(tmp_path / "out"))
    assert result.returncode == 2 and "not a study summary" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("option", [["--box", "1", "2", "4"], ["--element", "prism"], ["--face-points", "none"]])
def test_render_refuses_a_study_option_beside_a_summary(tmp_path, capsys, option):
    # it would do nothing: the summary says its own box, element and points
    from cospherical.cli import main

    assert main(["render", "--summary", str(SUMMARIES[0]), *option, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"{option[0]} goes with --study" in err and err.count("\n") == 1, err
    assert not (tmp_path / "out").exists()
@pytest.mark.oracle_meshio
def test_vtu_reads_back(tmp_path):
    for code, expect_polyhedra in (("888800000000", False), ("880000000000", True)):
        tess = tessellate(Configuration.from_code(code, ("1", "2", "4") if not expect_polyhedra else ("1", "1", "1")))
        path = tmp_path / f"{code}.vtu"
        write_vtu(tess, path)
        mesh = meshio.read(path)
        assert len(mesh.points) == len(tess.nodes)
        assert sum(len(block.data) for block in mesh.cells) == len(tess.elements)
        assert any(block.type.startswith("polyhedron") for block in mesh.cells) == expect_polyhedra
        hashes = sorted(int(x) for block in mesh.cell_data["type_hash"] for x in np.ravel(block))
        assert hashes == sorted(int(e.type.id.rsplit("-", 1)[1], 16) for e in tess.elements)


@pytest.mark.oracle_meshio
def test_tessellate_cli_writes_vtu(tmp_path):
    path = tmp_path / "out.vtu"
    result = cospherical("tessellate", "--box", "1", "1", "1", "--code", "888888888888", "--vtu", str(path))
    assert result.returncode == 0, result.stderr
    mesh = meshio.read(path)
    assert [block.type for block in mesh.cells] == ["hexahedron"] and len(mesh.cells[0].data) == 8
