"""Every closed set of names the package takes, in one place: criteria, point policies, modes, engines, backends.

Each is a ``Literal`` type, for annotations (a type checker then refuses a
misspelt name before it runs), and the tuple of its values, in the order options,
help texts and error messages list them.  The modules that use a set import it
from here; a new name is added here once.

Examples
--------
>>> CRITERIA
('optimal', 'internal_faces', 'internal_edges_and_faces')
>>> SPLIT_CRITERIA == CRITERIA[1:]
True
"""

from __future__ import annotations

from typing import Literal, get_args

__all__ = ["BALANCES", "Balance", "CRITERIA", "Criterion", "DELAUNAY_BACKENDS", "DelaunayBackend",
           "DelaunayMode", "ENGINES", "Engine", "FACE_POINT_SOURCES", "FacePointSource", "INSERTION_ORDERS",
           "InsertionOrder", "KEY_BACKENDS", "KeyBackend", "MODES", "ORBIT_BACKENDS", "OrbitBackend", "POINT_POLICIES",
           "PointPolicy",
           "SPLIT_CRITERIA", "SplitCriterion"]

# How an element may be split (the paper, section 4.2): kept whole (the Delaunay cells), split by
# internal faces only, or by internal edges and faces.
Criterion = Literal["optimal", "internal_faces", "internal_edges_and_faces"]
CRITERIA: tuple[Criterion, ...] = get_args(Criterion)
SplitCriterion = Literal["internal_faces", "internal_edges_and_faces"]
SPLIT_CRITERIA: tuple[SplitCriterion, ...] = get_args(SplitCriterion)

# Where a configuration's face and body points come from: the paper's octree rule, none at all,
# or given explicitly (a real octree leaf, a code's point suffix).
PointPolicy = Literal["octree", "none"]
POINT_POLICIES: tuple[PointPolicy, ...] = get_args(PointPolicy)
FacePointSource = Literal["octree", "none", "explicit"]
FACE_POINT_SOURCES: tuple[FacePointSource, ...] = get_args(FacePointSource)

# The mesh a user asks for: the exact Delaunay subdivision of the vertices, or the leaf mesh as assembled.
DelaunayMode = Literal["global", "leaf"]
MODES: tuple[DelaunayMode, ...] = get_args(DelaunayMode)
# How the global Delaunay step tetrahedralises a cluster: Qhull proposes and integers check, or the exact engine.
Engine = Literal["qhull", "exact"]
ENGINES: tuple[Engine, ...] = get_args(Engine)
# An octree's 2:1 balance: across faces, edges and corners, or across faces and edges (both 1-irregular).
Balance = Literal["vertex", "edge"]
BALANCES: tuple[Balance, ...] = get_args(Balance)

# The Delaunay walk of one configuration: Python integers, or the compiled int64 kernel.
DelaunayBackend = Literal["python", "compiled"]
DELAUNAY_BACKENDS: tuple[DelaunayBackend, ...] = get_args(DelaunayBackend)
# Orbit keys of many cube codes at once: numpy, or the compiled kernel.
KeyBackend = Literal["numpy", "compiled"]
KEY_BACKENDS: tuple[KeyBackend, ...] = get_args(KeyBackend)
# Orbit representatives of any element's codes: once per orbit in Python, or the cube's fast paths.
OrbitBackend = Literal["python", "numpy", "compiled"]
ORBIT_BACKENDS: tuple[OrbitBackend, ...] = get_args(OrbitBackend)

# The intersection study's midpoint insertion orders.
InsertionOrder = Literal["edge", "rank", "reverse"]
INSERTION_ORDERS: tuple[InsertionOrder, ...] = get_args(InsertionOrder)
