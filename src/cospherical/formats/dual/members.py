"""The members of ``dual.npz`` (kinds, shapes, counts per version) and the bounds its reader holds them to."""

from __future__ import annotations

import re

__all__ = ["DUAL_FORMAT_VERSION"]

DUAL_FORMAT_VERSION = 5
# Version 3 is version 5 without the region and interface members: a one-box mesh (one region) still
# writes it, byte for byte as before.  Version 4 (a device's dual before version 5) has the region
# members but no interfaces, and its boundary figures are the bounding box's sides; all three are read
# (a version 4 dual read and written again stays version 4).
_VERSIONS = (3, 4, 5)
_MAX_DUAL_FILE = 16 * 1024**3
# member -> (dtype kind, columns or None, which count: n vertices, m edges, e elements)
_MEMBERS = {
    "grid_vertices": ("i", 3, "n"), "vertices": ("f", 3, "n"), "edges": ("i", 2, "m"), "length": ("f", None, "m"),
    "area": ("f", None, "m"), "coefficient": ("f", None, "m"), "coefficient_exact": ("iU", None, "m"),
    "control_volume": ("f", None, "n"), "volume_exact": ("iU", None, "n"), "boundary": ("b", None, "n"),
    "boundary_area": ("f", None, "n"), "boundary_area_exact": ("iU", 3, "n"), "element_circumcenter": ("f", 3, "e"),
    "element_nodes": ("i", "w", "e"), "element_sizes": ("i", None, "e"),
}
# a device's members (versions 4 and 5): p control-volume parts, q coupling parts, f contact faces, r contact area parts
_REGION_MEMBERS = {
    "element_region": ("i", None, "e"),
    "volume_part_vertex": ("i", None, "p"), "volume_part_region": ("i", None, "p"),
    "volume_part_exact": ("iU", None, "p"), "volume_part": ("f", None, "p"),
    "coupling_part_edge": ("i", None, "q"), "coupling_part_region": ("i", None, "q"),
    "coupling_part_exact": ("iU", None, "q"), "coupling_part": ("f", None, "q"),
    "contact_face_nodes": ("i", "w", "f"), "contact_face_contact": ("i", None, "f"),
    "contact_part_vertex": ("i", None, "r"), "contact_part_contact": ("i", None, "r"),
    "contact_part_exact": ("iU", None, "r"), "contact_part": ("f", None, "r"),
}
# a device's interfaces (version 5): g interface faces, s interface area parts
_INTERFACE_MEMBERS = {
    "interface_face_nodes": ("i", "w", "g"), "interface_face_interface": ("i", None, "g"),
    "interface_part_vertex": ("i", None, "s"), "interface_part_interface": ("i", None, "s"),
    "interface_part_exact": ("iU", None, "s"), "interface_part": ("f", None, "s"),
}
_MAX_NAMES = 64
# the most vertices an element may list: a leaf's 26 points, or a cell of the global mode (co-spherical
# grid points); bounds the exact hull computed per distinct element shape when the dual is verified
_MAX_ELEMENT_NODES = 64
# the manifest's exact numbers as written: plain integers and fractions of bounded length, so that a
# hostile text such as "1e999999999" never reaches Fraction (which would compute 10**999999999)
# the manifest's exact numbers, and the members' written as text: under Python's own bound on decimal text
# (sys.int_max_str_digits, 4300 by default); a 1e-12 x 1 x 3e9 box's coefficients need 1049 digits at level 4
_MAX_TEXT_DIGITS = 4000
_INTEGER = re.compile(r"-?[0-9]{1,%d}" % _MAX_TEXT_DIGITS)
_POSITIVE = re.compile(r"[1-9][0-9]{0,%d}" % (_MAX_TEXT_DIGITS - 1))
_POSITIVE_FRACTION = re.compile(r"[1-9][0-9]{0,%d}(/[1-9][0-9]{0,%d})?" % (_MAX_TEXT_DIGITS - 1, _MAX_TEXT_DIGITS - 1))
_MAX_GRID = 1 << 40
_FRACTION = re.compile(r"-?[0-9]{1,%d}(/[1-9][0-9]{0,%d})?" % (_MAX_TEXT_DIGITS - 1, _MAX_TEXT_DIGITS - 1))
