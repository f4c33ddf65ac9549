"""LaTeX tables (jinja2 templates in ``templates/``), element pictures, and PDF compilation.

Templates use ``\\BLOCK{...}`` for statements and ``\\VAR{...}`` for values, so
that LaTeX's own braces need no escaping; every name goes through the ``tex``
filter.  Pictures are generated from each element type's example geometry:
one fixed oblique view, visible edges solid, hidden edges dashed.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
from pathlib import Path
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import jinja2

from ..catalogue import Catalogue, CatalogueType
from ..core.element_types import face_summary
from ..choices import CRITERIA
from ..errors import InputError
from ..files.data import data_path
from ..files.outputs import OutputFolder, atomic_open
from ..formats.patterns import pattern_name
from ..paper import comparison_notes, paper_comparison, paper_notes, paper_studies, paper_study_key
from ..version import __version__

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["element_png", "render_tables", "tex", "tikz_picture"]

_TEX = {
    "\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_",
    "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}",
}


def tex(value: object) -> str:
    """Escape text for LaTeX.

    >>> tex("Generic #5 (50% of a_b & c)")
    'Generic \\\\#5 (50\\\\% of a\\\\_b \\\\& c)'
    """
    return "".join(_TEX.get(ch, ch) for ch in str(value))


def environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(data_path("templates"))),
        block_start_string=r"\BLOCK{", block_end_string="}",
        variable_start_string=r"\VAR{", variable_end_string="}",
        comment_start_string=r"\#{", comment_end_string="}",
        trim_blocks=True, lstrip_blocks=True, keep_trailing_newline=True,
        autoescape=False, undefined=jinja2.StrictUndefined,
    )
    env.filters["tex"] = tex
    return env


# The view: seen from the front, a little from the right and from above.
_TOWARD_VIEWER = (0.35, -1.0, 0.55)


def _normalise(v: Sequence[float]) -> tuple[float, ...]:
    n = math.sqrt(sum(x * x for x in v))
    return tuple(x / n for x in v)


def _drawn_normal(p: tuple[float, ...], q: tuple[float, ...], r: tuple[float, ...]) -> tuple[float, float, float]:
    """(q - p) x (r - p) in floats, as :func:`~cospherical.core.geometry.plane_normal` writes it out: a
    picture's coordinates are the catalogue's float example, not exact values."""
    (x0, y0, z0), (x1, y1, z1), (x2, y2, z2) = p, q, r
    ux, uy, uz, vx, vy, vz = x1 - x0, y1 - y0, z1 - z0, x2 - x0, y2 - y0, z2 - z0
    return (uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx)


def _projection(entry: CatalogueType,
                size: float) -> tuple[list[tuple[float, float]], list[tuple[int, ...]], set[tuple[int, ...]]]:
    """Screen coordinates of the example's vertices and each edge's visibility."""
    d = _normalise(_TOWARD_VIEWER)
    origin = (0.0, 0.0, 0.0)  # a cross product a x b is the drawn normal of (0, a, b); floats, as the picture is
    right = _normalise(_drawn_normal(origin, (0.0, 0.0, 1.0), d))
    up = _drawn_normal(origin, d, right)
    points = entry.example.coordinates
    screen = [(sum(a * b for a, b in zip(p, right)), sum(a * b for a, b in zip(p, up))) for p in points]
    xs, ys = [s[0] for s in screen], [s[1] for s in screen]
    scale = size / max(max(xs) - min(xs), max(ys) - min(ys))
    cx, cy = (max(xs) + min(xs)) / 2, (max(ys) + min(ys)) / 2
    screen = [((x - cx) * scale, (y - cy) * scale) for x, y in screen]
    visible_edges: set[tuple[int, ...]] = set()
    edges: set[tuple[int, ...]] = set()
    for face in entry.reference_faces:
        nodes = face.nodes
        p0, p1, p2 = (points[i] for i in nodes[:3])
        normal = _drawn_normal(p0, p1, p2)
        front = sum(a * b for a, b in zip(normal, d)) > 0
        for i, v in enumerate(nodes):
            edge = tuple(sorted((v, nodes[(i + 1) % len(nodes)])))
            edges.add(edge)
            if front:
                visible_edges.add(edge)
    return screen, sorted(edges), visible_edges


def tikz_picture(entry: CatalogueType, size: float = 1.6) -> str:
    """A TikZ drawing of a catalogue entry's example (size in cm)."""
    screen, edges, visible = _projection(entry, size)
    lines = [r"\begin{tikzpicture}[line join=round]"]
    for hidden in (True, False):  # hidden edges first, so that visible ones are drawn on top
        for a, b in edges:
            if ((a, b) in visible) == hidden:
                continue
            style = "[densely dashed, gray]" if hidden else "[thick]"
            (x1, y1), (x2, y2) = screen[a], screen[b]
            lines.append(rf"\draw{style} ({x1:.3f},{y1:.3f}) -- ({x2:.3f},{y2:.3f});")
    for x, y in screen:
        lines.append(rf"\fill ({x:.3f},{y:.3f}) circle (0.6pt);")
    lines.append(r"\end{tikzpicture}")
    return "\n".join(lines)


def element_png(entry: CatalogueType, path: Path, size_px: int = 160) -> None:
    """A PNG picture of a catalogue entry's example (matplotlib, deterministic metadata)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    screen, edges, visible = _projection(entry, 1.0)
    fig = plt.figure(figsize=(size_px / 100, size_px / 100), dpi=100)
    ax = fig.add_axes((0.05, 0.05, 0.9, 0.9))
    for a, b in edges:
        (x1, y1), (x2, y2) = screen[a], screen[b]
        if (a, b) in visible:
            ax.plot([x1, x2], [y1, y2], color="black", linewidth=1.4, solid_capstyle="round")
        else:
            ax.plot([x1, x2], [y1, y2], color="gray", linewidth=0.8, linestyle=(0, (3, 2)))
    ax.plot([x for x, _ in screen], [y for _, y in screen], "o", color="black", markersize=2.5)
    ax.set_xlim(-0.55, 0.55)
    ax.set_ylim(-0.55, 0.55)
    ax.set_aspect("equal")
    ax.axis("off")
    save_png(fig, path)


def save_png(fig: Figure, path: Path, dpi: int = 100) -> None:
    """Save a matplotlib figure atomically (temporary file, then rename), without a version stamp."""
    import matplotlib.pyplot as plt

    try:
        with atomic_open(path, binary=True) as handle:
            fig.savefig(handle, format="png", metadata={"Software": None}, dpi=dpi)
    finally:
        plt.close(fig)


def _type_rows(summaries: list[dict[str, Any]], catalogue: Catalogue) -> list[dict[str, Any]]:
    seen: dict[str, dict[str, Any]] = {}
    for summary in summaries:
        for data in summary["criteria"].values():
            for type_id, t in data["types"].items():
                seen.setdefault(type_id, t)
    rows = []
    for type_id in sorted(seen, key=lambda i: (seen[i]["vertices"], seen[i]["faces"], i)):
        t = seen[type_id]
        entry = catalogue.get(type_id)
        rows.append({**t, "face_summary": face_summary(dict(entry.face_kinds)) if entry else "--",
                     "picture": tikz_picture(entry) if entry else None})
    return rows


def _stem(summary: dict[str, Any]) -> str:
    if summary["study"] == "intersection":
        return f"intersection-r{summary['resolution']}-{summary['insertion_order']}"
    return pattern_name(summary["study"], summary["box"], summary["face_points"], summary.get("element", "cuboid"))


def _readable(name: str) -> str:
    """A criterion or paper-study key as words for a caption: ``internal_faces`` -> ``internal faces``,
    ``bisection_A`` -> ``case A``, ``intersection_cube`` -> ``intersection study``."""
    if name.startswith("bisection_"):
        return "case " + name.split("_", 1)[1].replace("_", " ")
    if name.startswith("intersection_"):
        return "intersection study"
    return name.replace("_", " ")


def render_tables(summaries: list[dict[str, Any]], catalogue: Catalogue, out: Path, title: str, pdf: bool = False) -> list[Path]:
    """Write every table of the studies' summaries, and ``document.tex`` including them all
    (and, with ``pdf``, ``document.pdf`` compiled from it, with its log).

    The folder is written as one :class:`~cospherical.files.outputs.OutputFolder`:
    all files appear together when everything, the PDF included, has succeeded,
    and a table, PDF or log of an earlier render that this one does not write
    again is removed only if the folder's manifest says an earlier render wrote
    it, unchanged since.
    """
    known = ("document.tex", "document.pdf", "document.log") if pdf else ("document.tex",)
    with OutputFolder(out, "render", known, writes=_RENDERED.fullmatch) as folder:  # a link at a known name is refused before the work
        names = _write_tables(summaries, catalogue, folder, title)
        if pdf:
            names += _compile_pdf(folder, out)
    return [out / name for name in names]


def _write_tables(summaries: list[dict[str, Any]], catalogue: Catalogue, folder: OutputFolder, title: str) -> list[str]:
    env = environment()
    written: list[str] = []

    def write(name: str, template: str, **context: object) -> str:
        if not _OUR_NAME.fullmatch(name):  # names come from validated summaries; never a path
            raise InputError(f"{name!r}: not a file name of a rendered table")
        folder.path(name).write_text(env.get_template(template).render(**context), encoding="utf-8", newline="\n")
        written.append(name)
        return name

    sections = [{"title": "Element types",
                 "files": [write("elements.tex", "elements.tex.j2", types=_type_rows(summaries, catalogue),
                                 caption="Element types met, with a picture of an example")]}]
    fvm_rows = []
    for summary in summaries:
        stem = _stem(summary)
        key, _ = paper_study_key(summary)
        box = " x ".join(summary["box"]) + (f" ({summary['element']})" if "element" in summary else "")
        files = []
        for criterion, data in summary["criteria"].items():
            rows = [{"name": t["name"], "paper_class": t["paper_class"], "count": t["count"], "share": t["share"],
                     "configurations": t["configurations"]} for t in data["types"].values()]
            files.append(write(f"frequencies-{stem}-{criterion}.tex", "frequencies.tex.j2", rows=rows,
                               total=data["total"], types_count=data["types_count"],
                               caption=f"Element frequencies, box {box}, {summary['face_points']} points, "
                                       f"{_readable(criterion)}"))
            if key and criterion in paper_studies()[key]:
                table = paper_comparison(summary, key, criterion)
                crows = [{"label": r["class"], "paper": "--" if r["paper"] is None else f"{r['paper']:,}",
                          "ours": "--" if r["ours"] is None else f"{r['ours']:,}",
                          "differs": r["paper"] != r["ours"]} for r in table["rows"]]
                total = {"paper": f"{table['total']['paper']:,}", "ours": f"{table['total']['ours']:,}",
                         "differs": table["total"]["paper"] != table["total"]["ours"]}
                notes = [paper_notes()[n] for n in comparison_notes(summary, key, [criterion])]
                files.append(write(f"comparison-{stem}-{criterion}.tex", "comparison.tex.j2", rows=crows,
                                   total=total, notes=notes,
                                   caption=f"Beside the paper ({_readable(key)}), box {box}, "
                                           f"{summary['face_points']} points, {_readable(criterion)}"))
        fvm_rows.append({"box": box, "face_points": summary["face_points"],
                         "configurations": summary["configurations"], "closed": summary["fvm_adequate"],
                         "open": summary["fvm_adequate_open"],
                         "paper": paper_comparison(summary, key)["fvm_adequate"]["paper"] if key else None})
        sections.append({"title": f"{summary['study'].capitalize()} study, box {box}, {summary['face_points']} points",
                         "files": files})
    sections.insert(1, {"title": "Finite-volume circumcenter test",
                        "files": [write("fvm.tex", "fvm.tex.j2", rows=fvm_rows,
                                        caption="Configurations whose element circumcenters all lie in the box "
                                        "(in the base element for a prism, pyramid or tetrahedron)")]})
    write("document.tex", "document.tex.j2", title=title, version=__version__, sections=sections)
    return written


# The names of the files render_tables writes: a table's, checked as it is written, and every name of a
# render (the only files of an earlier render it may remove).
_OUR_NAME = re.compile(r"[0-9a-z][0-9a-z._-]*\.tex")
_RENDERED = re.compile(r"(?:elements|fvm|document)\.tex|document\.(?:pdf|log)"
                       rf"|(?:frequencies|comparison)-[0-9a-z][0-9a-z._-]*-(?:{'|'.join(CRITERIA)})\.tex")


# pdfTeX stamps the time of the run into the PDF (dates and the file id) unless told a fixed one.
_REPRODUCIBLE_TEX = {"SOURCE_DATE_EPOCH": "0", "FORCE_SOURCE_DATE": "1"}


def _compile_pdf(folder: OutputFolder, out: Path, document: str = "document.tex") -> list[str]:
    """Compile the staged ``document.tex`` with pdflatex (twice, for the long tables) in the private
    staging folder, where nothing it writes can follow a link in ``out``; the PDF and its log are
    then outputs like the tables."""
    pdflatex = shutil.which("pdflatex")
    if pdflatex is None:
        raise InputError("pdflatex not found: install a TeX engine (Debian: texlive-latex-base, "
                         "texlive-latex-recommended, texlive-pictures)")
    stem = Path(document).stem
    for _ in range(2):
        result = subprocess.run([pdflatex, "-interaction=nonstopmode", "-halt-on-error", "-no-shell-escape",
                                 document], cwd=folder.staging, capture_output=True, text=True,
                                stdin=subprocess.DEVNULL, errors="replace", env={**os.environ, **_REPRODUCIBLE_TEX})
        if result.returncode != 0:
            error = next((line for line in result.stdout.splitlines() if line.startswith("!")), "pdflatex failed")
            raise InputError(f"{out / document}: {error}")
    names = [f"{stem}.pdf", f"{stem}.log"]
    for name in names:
        folder.path(name)
    return names
