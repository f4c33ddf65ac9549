"""LaTeX tables compiled by a real pdflatex, byte-identical across runs, with escaped names and drawn pictures."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest
from commands import cospherical
from matplotlib.image import imread

from cospherical.catalogue import catalogue_path, load_catalogue
from cospherical.outputs.latex import tikz_picture
from tests.core.test_shapes import SHAPES

ROOT = Path(__file__).resolve().parents[2]
SUMMARIES = [ROOT / "results" / f"bisection-{box}.json" for box in ("1x1x1", "1x2x4", "1x1.4142x1.4142")]


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
    generic = next(t for t in catalogue if t.name.startswith("Generic #"))
    picture = tikz_picture(generic)
    assert picture.count(r"\draw[thick]") + picture.count(r"\draw[densely dashed, gray]") == generic.edges
    assert r"\draw[densely dashed, gray]" in picture or generic.vertices == 4
    elements = (ROOT / "results" / "latex" / "elements.tex").read_text()
    assert r"Generic \#" in elements and "Generic #" not in elements.replace(r"Generic \#", "")


@pytest.mark.oracle_pdflatex
def test_committed_shape_latex_compiles(tmp_path):
    import shutil

    for path in (ROOT / "results" / "latex-shapes").iterdir():
        shutil.copy(path, tmp_path)
    result = subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "document.tex"], cwd=tmp_path,
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stdout[-2000:]
    text = subprocess.run(["pdftotext", str(tmp_path / "document.pdf"), "-"], capture_output=True, text=True).stdout
    assert all(f"1 x 1 x 1 ({name})" in text for name in SHAPES)
