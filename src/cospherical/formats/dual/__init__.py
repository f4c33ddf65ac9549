"""``dual.npz``: the finite-volume dual of a mesh, for a solver (reading and writing only).

A zip of ``.npy`` arrays (``numpy.load`` opens it; no pickles), each deflated at
zlib's fastest level (a fifth of the default level's time for about a quarter more
bytes) in blocks on every core when the dual is large (:mod:`~cospherical.formats.deflated`), written deterministically (fixed member order and time stamps: the same mesh
gives the same bytes) and atomically.  Members, ``n`` vertices, ``m`` edges, ``e`` elements:

===========================  ==========  ==================================================
``manifest``                 uint8       JSON text: ``format`` (``cospherical-dual``),
                                         ``version`` (3; 5 for a device, below), ``domain`` (the box, exact
                                         texts), ``grid``, the exact denominators and
                                         factors (decimal texts), ``sha256`` of every
                                         other member
``grid_vertices``            int64 n x3  exact vertices: integers of the grid of ``grid``
                                         intervals per domain side
``vertices``                 f8 n x 3    real coordinates (``grid_vertices / grid * box``)
``edges``                    int64 m x2  vertex pairs ``i < j``, sorted
``length``, ``area``,        f8 m        edge length, signed dual-face area,
``coefficient``                          ``area / length`` (the box method's coupling)
``coefficient_exact``        int64 m     ``coefficient = coefficient_exact * sqrt(
                                         volume_factor_squared) / coefficient_denominator``
                                         (decimal text, ``U``, when int64 is too narrow)
``control_volume``           f8 n        each vertex's control volume
``volume_exact``             int64 n     ``control_volume = volume_exact * sqrt(
                                         volume_factor_squared) / volume_denominator``
``boundary``                 bool n      the vertex is on the domain's boundary
``boundary_area``            f8 n        the boundary's area in its control volume
``boundary_area_exact``      int64 n x3  per axis k, the part in the boundary faces normal
                                         to k (a box's two sides): ``boundary_area = sum over k of
                                         boundary_area_exact[:, k] * sqrt(
                                         boundary_factors_squared[k]) /
                                         boundary_area_denominator``, the factors
                                         ``(b^2 c^2, a^2 c^2, a^2 b^2)`` for a box
                                         ``a x b x c`` (decimal text, ``U``, when int64
                                         is too narrow); on a box each column sums to
                                         twice the denominator
``element_circumcenter``     f8 e x 3    the real circumcenter of each element (mesh order)
``element_nodes``            int e x w   each element's global vertex ids (mesh order),
                                         padded with -1; ``4 <= w <= 64``
``element_sizes``            int e       each element's number of vertices
===========================  ==========  ==================================================

A device's dual (``mesh --device ... --dual``) is version 5: the members above, whose
boundary is the domain's (the union of its boxes: every face met by one element, also
in a notch or a hole inside the bounding box), plus its parts per region, its contacts
and its interfaces (manifest: ``region_names``, ``region_materials``,
``contact_names``, ``contact_regions`` (region indices), ``contact_boxes`` (exact
texts, device units), ``region_boxes`` (per region its boxes: the domain),
``origin`` (the bounding box's low corner, where the grid starts),
``interface_regions`` (per interface its two regions ``[a, b]``, ``a < b``; named
``"a|b"``) and the four part denominators)::

    element_region                   int e     each element's region
    volume_part_vertex, _region      int p     one row per (vertex, region), sorted
    volume_part_exact, volume_part   iU/f8 p   over volume_part_denominator, times
                                               sqrt(volume_factor_squared): its part
                                               of the vertex's control volume
    coupling_part_edge, _region      int q     one row per (edge, region), sorted
    coupling_part_exact, coupling_part         over coupling_part_denominator, times
                                               sqrt(volume_factor_squared): its part
                                               of the edge's coefficient
    contact_face_nodes               int f x w each contact face (polygon, -1 padded)
    contact_face_contact             int f     its contact
    contact_part_vertex, _contact    int r     one row per (vertex, contact), sorted
    contact_part_exact, contact_part iU/f8 r   over contact_part_denominator (device
                                               units): its part of the contact's area
    interface_face_nodes             int g x w each interface face (polygon, -1 padded,
                                               counter-clockwise seen from region a)
    interface_face_interface         int g     its interface
    interface_part_vertex, _interface int s    one row per (vertex, interface), sorted
    interface_part_exact,            iU/f8 s   over interface_part_denominator (device
    interface_part                             units): its part of the interface's area

The parts of a vertex or an edge sum to its total exactly, a region's volume parts
to its volume, a contact's area parts to its rectangle's area, an interface's to the
area where its two regions touch.  A one-box mesh (one region) writes version 3, byte
for byte as before.  Version 4 (a device's dual before version 5) lacks the interface
members and counts the boundary in the bounding box's sides only; all three are read,
and :func:`verify_dual` computes a version 4 or 5 file's parts again from its
elements, their regions and its contact faces (version 5: its boundary and interfaces
from the faces its elements meet once and those between two regions), and proves the
elements a mesh of the union of boxes.

The reader refuses, with one line, a file that is not such a zip, lacks or adds a
member, has an array of the wrong kind or shape, fails a checksum (a truncated or
tampered file), has edges that name no vertex, or elements that are not lists of
distinct vertices.  Versions 1 (no exact boundary areas) and 2 (no elements) are
refused with their version named.

A checksum is no proof: whoever changes a member can renew it.  So
:func:`verify_dual` (``cospherical check``) computes the dual again from the
vertices and elements the file holds and compares every edge, coefficient, control
volume and boundary area with the file's, exactly, and every float with the one the
exact value gives.  A change that keeps the sums (one coefficient ``+k``, another
``-k``) is refused with the first edge it changed.  The cost is that of computing
the dual from its elements (their shapes found by sorting, each shape measured once):
0.5 CPU-s in all, reading and the proof below included, for the 50,912 elements of the
21,512-leaf example of the results page, 4.6 CPU-s for the 799,984 of the README's level-8 tree.
Sums cannot see elements that
overlap and leave a hole of the same volume, so the elements are also proved a mesh
of the domain: every face shared by exactly two elements in opposite orientations, or
by one in the domain's boundary (the mesher's own conformity rule, its memory bounded
before the faces are made).  Elements whose distinct shapes
would need more exact hull work than their number justifies (a small file of many
different 64-vertex shapes would take hours) are refused before any hull is computed.
The circumcentres
(``element_circumcenter``, floats for display) are not compared.
"""


from __future__ import annotations

from typing import TYPE_CHECKING

from ...lazy import on_first_use
from .members import DUAL_FORMAT_VERSION
from .writer import write_dual

if TYPE_CHECKING:  # for the type checker; at run time they are imported on first use (__getattr__)
    from .reader import read_dual as read_dual
    from .verify import domain_sums as domain_sums, dual_layout as dual_layout, verify_dual as verify_dual

__all__ = ["DUAL_FORMAT_VERSION", "domain_sums", "dual_layout", "read_dual", "verify_dual", "write_dual"]

# the reader and the verification, by the module that defines them: writing a dual (`mesh --dual`) needs neither,
# nor the zip reader and the device model they import (6 ms of every such run)
__getattr__ = on_first_use(globals(), {"read_dual": f"{__name__}.reader", "domain_sums": f"{__name__}.verify",
                                       "dual_layout": f"{__name__}.verify", "verify_dual": f"{__name__}.verify"})


def __dir__() -> list[str]:
    return sorted(__all__)
