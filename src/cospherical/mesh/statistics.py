"""What really occurs in a mesh: element types and configurations weighted by how often they occur.

The paper's study weighs every bisection configuration the same ("but this is for
sure not true ... a complete study should consider also this case").  Here each
type and configuration is counted over the leaves of a real octree, beside the
uniform-weight bisection study of the same box (octree point policy, the paper's
system), and the share of elements the paper's seven final elements cover.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import asdict, dataclass, replace
from typing import Any, Mapping, NamedTuple

import numpy as np

from ..caches import cached
from ..catalogue import Catalogue
from ..core.configuration import Box, Configuration
from ..files.data import data_path
from .assembly import PAPER_FINAL, Mesh, MeshType, type_info
from .report_sections import ConfigurationFrequency, TypeFrequency, UniformSummary, read_only
from .tree import Octree

__all__ = ["ConfigurationOccurrence", "Frequencies", "UniformStudy", "in_bisection_family", "level_counts",
           "mesh_statistics", "occurrences", "shipped_uniform", "statistics", "uniform_figures", "uniform_study"]

_BISECTION_CONFIGURATIONS = 4096


@dataclass(frozen=True)
class UniformStudy:
    """The uniform-weight bisection study of a box: its elements per type and what each type is.

    Attributes
    ----------
    counts : Mapping of str to int
        Elements per type id, by decreasing count (read-only; keyed by the types the study meets).
    types : Mapping of str to MeshType
        Per type id its name, paper class, VTK cell, vertices and faces (the catalogue's when it
        names the type, :func:`uniform_study`; the type's own, :func:`uniform_figures`; read-only).
    elements : int
        The study's elements, all types together.
    """

    counts: Mapping[str, int]
    types: Mapping[str, MeshType]
    elements: int

    def to_dict(self) -> dict[str, Any]:
        """The study as ``data/uniform-studies.json`` holds it (beside its box)."""
        return {"counts": dict(self.counts), "types": {key: asdict(info) for key, info in self.types.items()},
                "elements": self.elements}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> UniformStudy:
        """A study of ``data/uniform-studies.json`` (its ``box`` is not the study's)."""
        return cls(read_only(data["counts"]), read_only({key: MeshType(**info) for key, info in data["types"].items()}),
                   data["elements"])


@dataclass(frozen=True)
class ConfigurationOccurrence:
    """A leaf configuration met in a mesh (or in a piece of it), and its leaves there.

    Attributes
    ----------
    code : str
        The configuration's whole point-set code.
    leaves : int
        Its leaves (replaced ones too); adds up over a partitioned mesh's pieces.
    in_bisection_family : bool
        Whether the paper's bisection study has its point set (:func:`in_bisection_family`).
    elements_per_leaf : int
        Its elements.
    fvm_adequate : bool
        Whether every circumcenter of its elements lies in the closed leaf.
    tessellated_on_the_fly : bool
        Whether the table lacked it.
    """

    code: str
    leaves: int
    in_bisection_family: bool
    elements_per_leaf: int
    fvm_adequate: bool
    tessellated_on_the_fly: bool


class Frequencies(NamedTuple):
    """What :func:`statistics` found: the report's frequency figures, in its order.

    ``paper_final_share``: the share of elements that are one of the paper's seven final
    elements; ``leaves_in_bisection_family``: leaves whose configuration the bisection study
    has; ``type_frequencies`` (by decreasing count), ``configuration_frequencies`` (by
    decreasing leaves); ``uniform``: the uniform study's figures (``None`` without it).
    """

    paper_final_share: float
    leaves_in_bisection_family: int
    type_frequencies: tuple[TypeFrequency, ...]
    configuration_frequencies: tuple[ConfigurationFrequency, ...]
    uniform: UniformSummary | None


def uniform_study(box: Box, catalogue: Catalogue, computed: bool = False) -> UniformStudy:
    """Element counts per type of the uniform-weight bisection study of ``box`` (octree policy, optimal),
    the types named by ``catalogue``.

    The study is a pure function of the box's proportions (every type id, count and
    VTK cell is unchanged when the box is scaled).  It costs 0.2 s for a cube and
    0.5-0.8 s for the other shapes of the shipped pattern tables, more than a
    small mesh: those shapes' figures ship precomputed in ``data/uniform-studies.json``
    (:func:`shipped_uniform`, written by ``scripts/uniform_studies.py`` from
    :func:`uniform_figures`; the tests compute them again and compare), and any
    other box is computed here.  ``computed=True`` computes it whatever the box
    (``mesh --check all``).
    """
    figures = None if computed else shipped_uniform(box)
    if figures is None:
        figures = uniform_figures(box)
    info = {type_id: type_info(type_id, None, catalogue) if type_id in catalogue else own
            for type_id, own in figures.types.items()}
    return replace(figures, types=read_only(info))


def uniform_figures(box: Box) -> UniformStudy:
    """The uniform bisection study of ``box`` as data no catalogue names: ``counts`` and ``types`` (each type's
    own name, paper class, VTK cell, vertices and faces) per type id, ``elements``."""
    from ..catalogue import Catalogue
    from ..studies.engine import bisection_codes, run_study

    study = run_study("bisection", box, bisection_codes(), "octree", criteria=("optimal",))
    nobody = Catalogue.empty(1)
    return UniformStudy(read_only({tc.type.id: tc.count for tc in study.type_counts("optimal")}),
                        read_only({tc.type.id: type_info(tc.type.id, tc.type, nobody)
                                   for tc in study.type_counts("optimal")}),
                        study.total("optimal"))


def shipped_uniform(box: Box) -> UniformStudy | None:
    """The shipped :func:`uniform_figures` of a box shaped like ``box`` (the same proportions), else ``None``."""
    ours = box.squared
    for figures in _shipped_uniform_studies():
        theirs = Box.parse(figures["box"]).squared
        if all(theirs[a] * ours[0] == ours[a] * theirs[0] for a in range(3)):
            return UniformStudy.from_dict(figures)
    return None


@cached(maxsize=1)
def _shipped_uniform_studies() -> list[dict[str, Any]]:
    """``data/uniform-studies.json``'s studies (package data, as trusted as the code that reads it)."""
    import json

    studies: list[dict[str, Any]] = json.loads(data_path("uniform-studies.json").read_text(encoding="utf-8"))["studies"]
    return studies


def _share(part: int, whole: int) -> float:
    return round(part / whole, 6) if whole else 0.0


def in_bisection_family(configuration: Configuration) -> bool:
    """Whether a leaf's point set is one the paper's bisection study has (octree policy of its edge code).

    >>> in_bisection_family(Configuration.from_code("888888888888+f"))
    False
    >>> in_bisection_family(Configuration.from_code("800000000000+f"))
    True
    """
    code = configuration.point_set_code
    if code is None:  # a configuration without a point-set code is not one of the family's
        return False
    digits = code.split("+")[0]
    return Configuration.from_code(digits, configuration.box).point_set_code == configuration.point_set_code


def mesh_statistics(mesh: Mesh, uniform: UniformStudy | None = None) -> Frequencies:
    """Per element type and per configuration, how often it occurs in the mesh, beside the uniform study.

    Returns :class:`Frequencies`: ``type_frequencies`` (by decreasing count), ``configuration_frequencies``
    (by decreasing leaf count), ``paper_final_share`` (elements whose paper class is
    one of the paper's seven final elements) and, with ``uniform``, its figures.
    """
    type_counts, configurations = occurrences(mesh)
    return statistics(type_counts, configurations, len(mesh.tree), mesh.types, mesh.catalogue, uniform)


def occurrences(mesh: Mesh) -> tuple[Counter[str], dict[str, ConfigurationOccurrence]]:
    """Elements per type id, and per configuration code its leaves (replaced ones too) and what it is.

    Both add up over the pieces of a partitioned mesh (leaves summed per code).
    """
    type_counts: Counter[str] = Counter()
    for rows, type_id in mesh.block_types():
        if len(rows):
            type_counts[type_id] += len(rows)
    configurations: dict[str, ConfigurationOccurrence] = {}
    for _, tessellation, leaves in mesh.groups(all_leaves=True):
        configurations[tessellation.code] = ConfigurationOccurrence(
            tessellation.code, int(len(leaves)), in_bisection_family(tessellation.configuration),
            len(tessellation.elements), tessellation.fvm_adequate, tessellation.on_the_fly)
    return type_counts, configurations


def statistics(type_counts: Counter[str], configurations: Mapping[str, ConfigurationOccurrence], total_leaves: int,
               types: Mapping[str, MeshType], catalogue: Catalogue,
               uniform: UniformStudy | None = None) -> Frequencies:
    """:func:`mesh_statistics` from the :func:`occurrences` of a mesh (or of all its pieces, added up);
    ``catalogue`` names the types met nowhere else."""
    frequencies = tuple(sorted((ConfigurationFrequency(
        c.code, c.leaves, _share(c.leaves, total_leaves),
        _share(1, _BISECTION_CONFIGURATIONS) if c.in_bisection_family else None,
        c.elements_per_leaf, c.fvm_adequate, c.tessellated_on_the_fly) for c in configurations.values()),
        key=lambda c: (-c.leaves, c.code)))
    total = sum(type_counts.values())
    uniform_counts = uniform.counts if uniform is not None else {}
    uniform_total = uniform.elements if uniform is not None else 0
    info = dict(uniform.types) if uniform is not None else {}
    info.update(types)
    rows = []
    for type_id in sorted(set(type_counts) | set(uniform_counts), key=lambda t: (-type_counts[t], t)):
        entry = info.get(type_id) or type_info(type_id, None, catalogue)
        rows.append(TypeFrequency(
            type_id, entry.name, entry.paper_class, entry.vtk, int(type_counts[type_id]),
            _share(type_counts[type_id], total),
            int(uniform_counts.get(type_id, 0)) if uniform is not None else None,
            _share(uniform_counts.get(type_id, 0), uniform_total) if uniform is not None else None))
    final = sum(r.count for r in rows if r.paper_class in PAPER_FINAL)
    summary = None
    if uniform is not None:
        uniform_final = sum(r.uniform_count or 0 for r in rows if r.paper_class in PAPER_FINAL)
        summary = UniformSummary("bisection", "octree", _BISECTION_CONFIGURATIONS, int(uniform_total),
                                 _share(uniform_final, uniform_total))
    return Frequencies(_share(final, total),
                       int(sum(c.leaves for c in frequencies if c.uniform_share is not None)),
                       tuple(rows), frequencies, summary)


def level_counts(tree: Octree) -> Mapping[str, int]:
    """Leaves per level of an octree (levels that occur, as text: the report's keys), read-only."""
    counts = np.bincount(tree.levels.astype(np.int64))
    return read_only({str(level): int(n) for level, n in enumerate(counts.tolist()) if n})
