"""Sweep figures: the pgfplots tables hold exactly the data given, the PNGs are pictures of it without a stamp."""

from __future__ import annotations

import re

import numpy as np
import pytest

from cospherical.outputs.figures import heatmap_png, heatmap_tex, steps_png, steps_tex

BOXES = [{"box": ["1", "1", "1"], "fvm_adequate": 4096}, {"box": ["1", "1", "sqrt(2)"], "fvm_adequate": 4096},
         {"box": ["1", "3/2", "3/2"], "fvm_adequate": 0}, {"box": ["1", "3/2", "2"], "fvm_adequate": 1234}]
# Along 1,r,r: adequate up to sqrt 2 included, then fewer; a point step at the threshold itself.
PROFILE = {"ray": "1,r,r", "steps": [
    {"r_from": "1", "r_to": "sqrt(2)", "fvm_adequate": 4096},
    {"r_from": "sqrt(2)", "r_to": "sqrt(2)", "fvm_adequate": 4096},
    {"r_from": "sqrt(2)", "r_to": "3/2", "fvm_adequate": 3900},
]}


def test_the_heatmap_table_is_every_box_once(tmp_path):
    heatmap_tex(BOXES, tmp_path / "heatmap.tex")
    text = (tmp_path / "heatmap.tex").read_text()
    table = re.search(r"b c fvm\n(.*?)\n};", text, re.S).group(1).splitlines()
    rows = [tuple(float(x) for x in line.split()) for line in table]
    assert rows == [(1, 1, 4096), (1, pytest.approx(2 ** 0.5, abs=1e-5), 4096), (1.5, 1.5, 0), (1.5, 2, 1234)]
    assert "mark size=30.0pt" in text  # two values of b: marks as wide as half the plot each


def test_the_steps_are_lines_on_intervals_and_dots_at_thresholds(tmp_path):
    steps_tex(PROFILE, tmp_path / "steps.tex")
    text = (tmp_path / "steps.tex").read_text()
    line = re.search(r"\\addplot\[const plot.*?coordinates \{\n(.*?)\n\};", text, re.S).group(1)
    points = [tuple(float(x) for x in p.split(",")) for p in re.findall(r"\(([^)]*)\)", line)]
    root2 = pytest.approx(2 ** 0.5, abs=1e-5)
    assert points == [(1, 4096), (root2, 4096), (root2, 3900), (1.5, 3900)]
    marks = re.findall(r"only marks.*coordinates \{\(([^)]*)\)\}", text)
    assert [tuple(float(x) for x in m.split(",")) for m in marks] == [(root2, 4096)]
    assert "boxes (1,r,r)" in text


def test_pictures_of_the_data_without_a_stamp(tmp_path):
    import matplotlib.image

    heatmap_png(BOXES, tmp_path / "heatmap.png")
    steps_png(PROFILE, tmp_path / "steps.png")
    for name in ("heatmap.png", "steps.png"):
        picture = matplotlib.image.imread(tmp_path / name)
        assert picture.ndim == 3 and len(np.unique(picture.reshape(-1, picture.shape[2]), axis=0)) > 8
    assert b"Software" not in (tmp_path / "heatmap.png").read_bytes()  # no version stamp: reruns are byte-identical
