"""Pattern tables: per configuration code, the elements a mesh generator puts there.

A table is YAML: a header (schema_version, generator and catalogue versions,
study, box, point policy, scheme, criteria) and, for every configuration code,
``fvm_adequate`` and per criterion the list of elements, each with its type id,
node ids in the type's reference order (see the catalogue) and circumcenter.
Where a criterion gives the same elements as an earlier one, the entry is that
criterion's name (``internal_faces: optimal``) instead of a copy.
A mesh generator looks a configuration up like this::

    table = cospherical.patterns.load("patterns/bisection-1x1x1.yaml")
    for element in table.elements("800000000000"):
        print(element["type"], element["nodes"])
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Mapping

from ..catalogue import split_tessellation
from ..core.configuration import Configuration
from ..core.symmetry import key_code
from ..core.tessellation import Tessellation, tessellate
from ..errors import FormatError
from ..files.yamlio import atomic_open, atomic_write, load_yaml, validate, yaml_float, yaml_text
from ..studies.bisection import Study
from ..studies.intersection import completed, orbits
from ..version import __version__

__all__ = ["PatternTable", "SCHEMA_VERSION", "configuration_lines", "element_lines", "entry_elements", "load", "pattern_chunk", "pattern_name", "patterns_text",
           "table_from_data", "write_pattern_table", "write_patterns"]

SCHEMA_VERSION = 1
SCHEMES = {
    "bisection": "midpoints: every Steiner point at t = 1/2",
    "leaves": "octree leaves: midpoints at t = 1/2, the centre of every face whose neighbour is refined "
    "(any set of faces with four split edges), never a body point; keys are whole-point-set codes",
}


def pattern_name(study: str, box_texts, face_points: str = "octree", element: str = "cuboid") -> str:
    """File stem for a study's outputs, e.g. ``bisection-1x1.4142x1.4142``; another base element
    than the cuboid is named after the study: ``bisection-prism-1x1x1``."""
    box = "x".join(re.sub(r"[^0-9a-z./]+", "", text.replace("/", "_")) for text in box_texts)
    # explicit points are named by the codes inside the table, not by its file name
    return f"{study}-{'' if element == 'cuboid' else element + '-'}{box}" + (
        "" if face_points in ("octree", "explicit") else f"-{face_points}")


def patterns_text(study: Study, catalogue_version: str) -> str:
    """The pattern table of a study as YAML text (deterministic)."""
    header = {
        "schema_version": SCHEMA_VERSION,
        "generator": f"cospherical {__version__}",
        "catalogue_version": catalogue_version,
        "study": study.name,
        **({"element": study.element} if study.element != "cuboid" else {}),
        "box": list(study.box.texts),
        "face_points": study.face_points,
        "scheme": SCHEMES.get(study.name, study.name),
        "criteria": list(study.criteria),
    }
    lines = [yaml_text(header).rstrip("\n"), "configurations:"]
    for code in sorted(study.codes):
        rep, _ = study.representative[code]
        lines.extend(configuration_lines(
            code,
            study.tessellations[rep].fvm_adequate,  # a symmetry keeps circumcenters in the box
            {criterion: study.choices[criterion].tessellations[rep] for criterion in study.criteria},
            lambda tess: study.member_tessellation(code, tess)))
    return "\n".join(lines) + "\n"


def configuration_lines(code: str, fvm_adequate: bool, tessellations: Mapping[str, Tessellation],
                        image: Callable[[Tessellation], Tessellation] = lambda tess: tess) -> list[str]:
    """The YAML lines of one configuration's entry in a pattern table, every table's.

    ``tessellations``: per criterion, in the table's order.  Where a criterion
    gives the same elements as an earlier one (most configurations need no
    split), the entry names that criterion instead of a copy.  ``image`` maps a
    tessellation to the configuration ``code`` (a study keeps one per orbit).
    """
    lines = [f"  '{code}':", f"    fvm_adequate: {'true' if fvm_adequate else 'false'}"]
    written: dict[tuple, str] = {}
    for criterion, tess in tessellations.items():
        key = tuple(e.polyhedron.nodes for e in tess.elements)
        if key in written:
            lines.append(f"    {criterion}: {written[key]}")
            continue
        written[key] = criterion
        lines.extend(element_lines(criterion, image(tess)))
    return lines


def element_lines(criterion: str, tess) -> list[str]:
    """The YAML lines of one configuration's elements under a criterion (inside its entry)."""
    lines = [f"    {criterion}:"]
    for element in tess.elements:
        nodes = ", ".join(map(str, element.nodes))
        center = ", ".join(yaml_float(x) for x in tess.circumcenter(element))
        mirror = ", mirror: true" if element.mirrored else ""
        lines.append(f"    - {{type: {element.type.id}, nodes: [{nodes}], circumcenter: [{center}]{mirror}}}")
    return lines


def write_patterns(study: Study, path: str | Path, catalogue_version: str) -> None:
    atomic_write(path, patterns_text(study, catalogue_version))


@dataclass(frozen=True)
class PatternTable:
    """A loaded, validated pattern table."""

    header: dict
    configurations: dict[str, dict]

    def elements(self, code: str, criterion: str = "optimal") -> list[dict]:
        """The elements of one configuration: dicts with ``type``, ``nodes``, ``circumcenter``."""
        if code not in self.configurations:
            raise KeyError(f"configuration {code!r} is not in this table")
        if criterion not in self.header["criteria"]:
            raise KeyError(f"criterion {criterion!r} is not in this table: {', '.join(self.header['criteria'])}")
        return entry_elements(self.configurations[code], criterion)


def entry_elements(entry: dict, criterion: str) -> list[dict] | None:
    """The elements of a configuration's entry under a criterion, following a reference to the
    criterion with the same elements (``internal_faces: optimal``); ``None`` where there are none.

    >>> entry_elements({"optimal": [{"type": "v4f4-8f0284"}], "internal_faces": "optimal"}, "internal_faces")
    [{'type': 'v4f4-8f0284'}]
    """
    elements = entry.get(criterion)
    for _ in range(len(entry)):  # a chain of references is never longer than the entry; a cycle ends here
        if not isinstance(elements, str):
            return elements
        elements = entry.get(elements)
    return None


def load(path: str | Path) -> PatternTable:
    """Read a pattern table and validate it (JSON Schema, criterion references).

    Parameters
    ----------
    path : str or Path
        A pattern table, such as ``patterns/bisection-1x1x1.yaml``.

    Returns
    -------
    PatternTable
        ``header`` and, through :meth:`PatternTable.elements`, each configuration's
        elements per criterion.

    Raises
    ------
    FormatError
        The file cannot be read or does not have the format; the message names the place.

    See the README ("Pattern tables for a mesh generator") for an example, run by the tests.
    """
    return table_from_data(load_yaml(path), str(path))


def table_from_data(data, name: str) -> PatternTable:
    """A :class:`PatternTable` from parsed YAML, validated (schema, criteria references)."""
    validate(data, "patterns", name)
    criteria = data["criteria"]
    for code, entry in data["configurations"].items():
        for i, criterion in enumerate(criteria):
            if criterion not in entry:
                raise FormatError(f"{name}: configuration {code}: no {criterion!r} elements")
            same = entry[criterion]
            if isinstance(same, str) and same not in criteria[:i]:
                raise FormatError(f"{name}: configuration {code}: {criterion} refers to {same!r}, "
                                  "which is not an earlier criterion of the table")
    header = {k: v for k, v in data.items() if k != "configurations"}
    return PatternTable(header, data["configurations"])


# ---------------------------------------------------------------------------
# The intersection study's pattern table: one entry per orbit representative
# (large: written on request, in chunks on the workers).

SYMMETRY_CONVENTION = (
    "One entry per orbit of the cube's 48 symmetries. The representative is the configuration "
    "whose code, read as a base-16 number, is the smallest of its images; a symmetry sends the "
    "point at t on an edge to the image edge at t or, where the edge is reversed, at 1 - t. "
    "To use an entry for another configuration: cospherical.symmetry.orbit_keys(digits, "
    "box_symmetries(cube)) gives its representative and the index of a symmetry taking it there; "
    "map the representative's nodes back with that symmetry's inverse (Symmetry.node_map).")


def pattern_chunk(codes: list[int], kept: dict[str, list[str]]) -> str:
    """Pattern-table entries (YAML text) of some representatives, every criterion of ``kept``."""
    lines = []
    for code in codes:
        text = key_code(code)
        tess = tessellate(Configuration.from_code(text))
        tessellations = {"optimal": tess}
        for criterion, types in kept.items():
            tessellations[criterion] = split_tessellation(tess, frozenset(types), criterion)[0]
        lines.extend(configuration_lines(text, tess.fvm_adequate, tessellations))
    return "\n".join(lines) + "\n" if lines else ""


def write_pattern_table(summary: dict, path, catalogue_version: str, jobs: int = 1, progress=None,
                        chunk: int = 2000, scheduler: str | None = None, dask_workers: int | None = None) -> None:
    """Write the pattern table of the study's orbit representatives (``summary`` gives the kept sets)."""
    resolution, order = summary["resolution"], summary["insertion_order"]
    reps, _, _ = orbits(resolution, order)
    kept = {c: data["kept"] for c, data in summary["criteria"].items() if c != "optimal"}
    header = {
        "schema_version": SCHEMA_VERSION, "generator": f"cospherical {__version__}",
        "catalogue_version": catalogue_version, "study": "intersection", "box": ["1", "1", "1"],
        "face_points": "octree",
        "scheme": f"midpoint scheme at multiples of 1/{resolution}, insertion order {order} (paper, section 5)",
        "symmetry": SYMMETRY_CONVENTION, "criteria": ["optimal", *kept],
    }
    with atomic_open(path) as handle:
        handle.write(yaml_text(header) + "configurations:\n")
        tasks = {i: (reps[i:i + chunk].tolist(), kept) for i in range(0, len(reps), chunk)}
        waiting, next_start = {}, 0
        for start, text in completed(pattern_chunk, tasks, jobs, scheduler, dask_workers):
            waiting[start] = text
            while next_start in waiting:  # in code order, whatever order the chunks finish in
                handle.write(waiting.pop(next_start))
                if progress:
                    progress(len(tasks[next_start][0]))
                next_start += chunk
