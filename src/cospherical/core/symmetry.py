"""The symmetry group of a base element acting on node ids, configurations and tessellations.

A symmetry is an isometry of the element in its box: a permutation of its
corners, with the affine map of unit coordinates that makes it.  For the cuboid
these are the box's: axes permuted (only axes of equal length may be swapped)
and any of them reflected, 48 elements for a cube, 16 when exactly two lengths
agree, 8 otherwise.  A study tessellates one representative per orbit and maps
the result to every other member.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from functools import cached_property
from itertools import combinations, permutations, product
from operator import itemgetter
from typing import TYPE_CHECKING, Callable, Sequence, cast

if TYPE_CHECKING:
    import numpy as np
# numpy is imported by the functions that compute in bulk: tessellating one
# configuration maps polyhedra with these symmetries and needs no numpy (its
# import is a third of a command's start-up).

from ..caches import cached
from ..choices import KEY_BACKENDS, ORBIT_BACKENDS, KeyBackend, OrbitBackend
from ..errors import InputError
from .codes import REVERSED_DIGIT, code_digits, key_code, parse_point_suffix, point_suffix
from .configuration import Box, Configuration
from .geometry import Rational, cross, determinant, sub, tetra_six_volume
from .polyhedron import Polyhedron
from .box import CORNERS, EDGES, FACES, Point
from .shapes import Shape, standard_shape

__all__ = ["Symmetry", "axis_maps", "box_symmetries", "code_digits", "key_code", "map_polyhedron", "orbit_keys",
           "orbit_point_keys", "orbit_representatives", "shape_symmetries"]


# (coefficient, shift) of a coordinate that a box symmetry keeps (x) or reflects (1 - x)
_AXIS_MAPS: tuple[tuple[Rational, Rational], ...] = ((1, 0), (-1, 1))


@dataclass(frozen=True)
class Symmetry:
    """An isometry of a base element: a permutation of its corners, acting on nodes, codes and points.

    ``corner_map[i]`` is the image of corner i; ``linear`` and ``shift`` the affine map of
    unit coordinates (rational: it maps rational corners to rational corners).  It has
    ``proper`` (keeps orientation), ``point(p)``, ``node_map`` (node id -> image),
    ``edge_map`` (per edge: the image edge and whether t becomes 1 - t), ``face_map``,
    ``code(code)``, ``configuration(cfg)``, ``polyhedron(poly)`` and ``inverse()``.

    Examples
    --------
    >>> swap = shape_symmetries(standard_shape("prism"))[1]  # x <-> y: corners 1 and 2, 4 and 5
    >>> swap.corner_map, swap.proper, swap.code("800000000")
    ((0, 2, 1, 3, 5, 4), False, '008000000')
    >>> flip = box_symmetries(Box.parse(["1", "1", "1"]))[1]  # z -> 1 - z
    >>> flip.code("800000000000+f4"), flip.node_map[26]
    ('000080000000+f5', 26)
    """

    shape: Shape = field(repr=False, compare=False)
    corner_map: tuple[int, ...]
    linear: tuple[tuple[Rational, ...], ...] = field(repr=False)
    shift: tuple[Rational, ...] = field(repr=False)

    @cached_property
    def proper(self) -> bool:
        """Whether it keeps orientation (a rotation rather than a reflection)."""
        m = self.linear
        return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])) > 0

    @cached_property
    def _axes(self) -> tuple[tuple[int, bool], ...] | None:
        # The box's symmetries take each coordinate to one coordinate, or to 1 minus it: the
        # cheap form of point() that a study's mapping of every member runs on.
        axes = []
        for row, b in zip(self.linear, self.shift):
            nonzero = [(a, x) for a, x in enumerate(row) if x != 0]
            if len(nonzero) != 1 or (nonzero[0][1], b) not in _AXIS_MAPS:
                return None
            axes.append((nonzero[0][0], nonzero[0][1] < 0))
        return tuple(axes)

    def point(self, p: Sequence[Rational]) -> Point:
        """The image of a point (unit coordinates)."""
        if self._axes is not None:
            image = [1 - p[a] if flip else p[a] for a, flip in self._axes]
        else:
            image = [sum(a * x for a, x in zip(row, p)) + b for row, b in zip(self.linear, self.shift)]
        return (image[0], image[1], image[2])

    @cached_property
    def edge_map(self) -> tuple[tuple[int, bool], ...]:
        """For edge k: (image edge, whether t becomes 1 - t)."""
        shape, image = self.shape, self.corner_map
        result = []
        for k, (i, j) in enumerate(shape.edges):
            target = shape.edge_index(image[i], image[j])
            result.append((target, image[shape.edge_start(k)] != shape.edge_start(target)))
        return tuple(result)

    @cached_property
    def face_map(self) -> tuple[int, ...]:
        """The image of every face."""
        index = {frozenset(face): f for f, face in enumerate(self.shape.faces)}
        return tuple(index[frozenset(self.corner_map[i] for i in face)] for face in self.shape.faces)

    @cached_property
    def node_map(self) -> tuple[int, ...]:
        """The image of every node id: corners, edge points, face points, the body point."""
        shape = self.shape
        nodes = list(self.corner_map)
        nodes += [len(shape.corners) + target for target, _ in self.edge_map]
        nodes += [shape.face_nodes[self.face_map[f]] for f in shape.quad_faces]
        if shape.body_node is not None:
            nodes.append(shape.body_node)
        return tuple(nodes)

    def configuration(self, cfg: Configuration) -> Configuration:
        """The image of a configuration; explicit face and body points go with it."""
        params: list[Fraction | None] = [None] * len(cfg.steiner)
        for k, t in enumerate(cfg.steiner):
            if t is not None:
                image, reverse = self.edge_map[k]
                params[image] = 1 - t if reverse else t
        if cfg.face_points != "explicit":
            return Configuration(cfg.shape, tuple(params), cfg.face_points)
        faces = frozenset(self.face_map[f] for f in cfg.point_faces)  # the explicit faces
        return Configuration(cfg.shape, tuple(params), "explicit", faces, cfg.body)

    def code(self, code: str) -> str:
        """The image of a configuration code (digit n becomes 16 - n on a reversed edge; the
        faces of a point suffix map with their nodes)."""
        edges, plus, suffix = code.partition("+")
        digits = ["0"] * len(edges)
        for (image, reverse), digit in zip(self.edge_map, edges):
            digits[image] = REVERSED_DIGIT[digit.lower()] if reverse else digit
        if not plus:
            return "".join(digits)
        faces, body = parse_point_suffix(code, suffix)
        return "".join(digits) + "+" + point_suffix({self.face_map[f] for f in faces}, body)

    def polyhedron(self, poly: Polyhedron) -> Polyhedron:
        """The image of a polyhedron, faces normalised as the Delaunay stage writes them."""
        return map_polyhedron(poly, self.node_map, self.proper, self.point)

    def inverse(self) -> "Symmetry":
        return self._inverse

    @cached_property
    def _inverse(self) -> "Symmetry":
        n = len(self.corner_map)
        return next(s for s in shape_symmetries(self.shape)
                    if all(s.corner_map[self.corner_map[i]] == i for i in range(n)))


def map_polyhedron(poly: Polyhedron, nodes: Sequence[int], proper: bool,
                   point: Callable[[Sequence[Rational]], Point]) -> Polyhedron:
    """The image of a polyhedron under an isometry given by its node map (``nodes[v]``), whether
    it keeps orientation, and its action on unit coordinates; faces normalised as the Delaunay
    stage writes them (shared by the box's symmetries and those of other shapes)."""
    faces = []
    for face in poly.faces:
        image = [nodes[v] for v in face]
        if not proper:  # a reflection turns counter-clockwise into clockwise
            image.reverse()
        start = image.index(min(image))
        faces.append(tuple(image[start:] + image[:start]))
    order = sorted(range(len(faces)), key=lambda i: faces[i])
    return Polyhedron(
        nodes=tuple(sorted(nodes[v] for v in poly.nodes)),
        faces=tuple(faces[i] for i in order),
        face_kinds=tuple(poly.face_kinds[i] for i in order),
        unit_volume=poly.unit_volume,
        center=point(poly.center),
    )


def orbit_keys(digits: np.ndarray, symmetries: Sequence[Symmetry],
               backend: KeyBackend = "numpy") -> tuple[np.ndarray, np.ndarray]:
    """For rows of 12 hex digits: the orbit representative's code as a base-16 number (the
    smallest image) and the index of the first symmetry taking the row to it
    (``backend`` as in :func:`orbit_point_keys`)."""
    keys, _, sym_index = orbit_point_keys(digits, None, symmetries, backend)
    return keys, sym_index


def orbit_point_keys(
    digits: np.ndarray, masks: np.ndarray | None, symmetries: Sequence[Symmetry], backend: KeyBackend = "numpy"
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`orbit_keys` for whole point sets: rows of 12 hex digits with a point mask each
    (bit f: face f carries a point, bit 6: the body point; ``None``: no face points).  The smallest image compares the
    edge digits first, then the mask; returns its code as a base-16 number, its mask, and
    the first symmetry reaching it.  A zero mask gives exactly the keys of the 12 digits.

    ``backend``: ``"numpy"`` (the default) or ``"compiled"`` (the numba kernel of
    :mod:`cospherical.core.compiled`), the same keys either way.  Loading the
    kernel costs ~1.5 s; numpy does 4096 rows x 48 symmetries in ~25 ms but is
    ~15x slower per row (measured: 10 s against 0.7 s for a million rows), so
    break-even is near 100,000 rows: bulk work (the intersection study) asks
    for the kernel."""
    import numpy as np

    if backend not in KEY_BACKENDS:
        raise InputError(f"backend {backend!r}: one of {', '.join(KEY_BACKENDS)}")
    digits = np.ascontiguousarray(digits).reshape(-1, 12)  # any integer type: millions of rows stay small
    masks = np.zeros(len(digits), dtype=np.int64) if masks is None else np.ascontiguousarray(masks, dtype=np.int64)
    targets = np.array([[target for target, _ in sym.edge_map] for sym in symmetries], dtype=np.int64).reshape(-1, 12)
    reverse = np.array([[rev for _, rev in sym.edge_map] for sym in symmetries], dtype=np.bool_).reshape(-1, 12)
    faces = np.array([sym.face_map for sym in symmetries], dtype=np.int64).reshape(-1, 6)
    if backend == "compiled":
        from .compiled import orbit_keys as kernel

        keys: tuple[np.ndarray, np.ndarray, np.ndarray] = kernel(digits, targets, reverse, masks, faces)
        return keys
    return _orbit_keys_numpy(digits, targets, reverse, masks, faces)


def _orbit_keys_numpy(digits: np.ndarray, targets: np.ndarray, reverse: np.ndarray, masks: np.ndarray,
                      faces: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    # compiled.orbit_keys, vectorised over the rows: the same smallest image
    # (code as base 16, then mask) and the first symmetry reaching it.
    import numpy as np

    digits = digits.astype(np.int64)
    best = np.full(len(digits), -1, dtype=np.int64)
    best_mask = np.zeros(len(digits), dtype=np.int64)
    best_sym = np.zeros(len(digits), dtype=np.int64)
    for s in range(len(targets)):
        image = np.where(reverse[s] & (digits != 0), 16 - digits, digits)
        key = (image << (4 * (11 - targets[s]))).sum(axis=1)
        mask = masks & 64
        for f in range(6):
            mask |= ((masks >> f) & 1) << faces[s, f]
        better = (best < 0) | (key < best) | ((key == best) & (mask < best_mask))
        best = np.where(better, key, best)
        best_mask = np.where(better, mask, best_mask)
        best_sym = np.where(better, s, best_sym)
    return best, best_mask, best_sym


def orbit_representatives(codes: Sequence[str], symmetries: Sequence[Symmetry],
                          backend: OrbitBackend = "python") -> tuple[list[str], list[int]]:
    """For each code, its orbit's representative (the smallest image: edge digits as a base-16
    number, then the face and body points) and the index of the first symmetry taking the code to it.

    The one orbit function of every base element; a code with a point suffix
    (``+f...``) has a representative with one.  ``backend``: ``"python"`` (the
    default: once per orbit, about 50 us a code in the worst case, no numpy, whose
    import costs a tenth of a second: a bisection study's 4096 codes take 15 ms),
    or, for the cuboid, the cube's fast paths ``"numpy"`` (about 6 us a code after
    its import) and ``"compiled"`` (:func:`orbit_point_keys`, for hundreds of
    thousands of codes); other elements' codes take the Python path whatever the
    backend.  ``"python"`` needs the symmetries to form a group, as an element's
    isometries always do; on any other set of the cuboid's it computes with numpy.

    Examples
    --------
    >>> shape = standard_shape("tetrahedron")
    >>> orbit_representatives(["800000", "008000", "080000"], shape_symmetries(shape))[0]
    ['000800', '000800', '000008']
    >>> orbit_representatives(["800000000000", "000000000008"], box_symmetries(Box.parse(["1", "1", "1"])))[0]
    ['000000000008', '000000000008']
    """
    if backend not in ORBIT_BACKENDS:
        raise InputError(f"backend {backend!r}: one of {', '.join(ORBIT_BACKENDS)}")
    if not symmetries:
        raise ValueError("orbit representatives: no symmetries (the identity at least)")
    shape = symmetries[0].shape
    cube_path = len(shape.edges) == 12 and len(shape.faces) == 6
    body_bit = 1 << len(shape.faces)
    suffixed = ["+" in code for code in codes]
    masks = [_point_mask(code, body_bit) if s else 0 for code, s in zip(codes, suffixed)]
    group = _group(tuple(symmetries)) if backend == "python" or not cube_path else None
    if group is not None:
        keys, image_masks, sym_index = _orbit_keys_python(codes, masks, group)
    elif not cube_path:
        raise ValueError("orbit representatives: these symmetries are no group of the element")
    else:
        import numpy as np

        keys, image_masks, sym_index = (a.tolist() for a in orbit_point_keys(
            code_digits(codes), np.array(masks, dtype=np.int64), symmetries,
            "numpy" if backend == "python" else backend))
    width = len(shape.edges)
    reps = ["%0*x" % (width, k) + ("+" + _mask_suffix(m, body_bit) if s else "")
            for k, m, s in zip(keys, image_masks, suffixed)]
    return reps, sym_index


def _point_mask(code: str, body_bit: int = 1 << 6) -> int:
    # The face and body points of a code as a mask: bit f for face f, body_bit (1 << the number
    # of faces, the cuboid's by default) for the body point, which no symmetry moves
    faces, body = parse_point_suffix(code, code.partition("+")[2])
    return sum(1 << f for f in faces) | (body_bit if body else 0)


def _mask_suffix(mask: int, body_bit: int) -> str:
    return point_suffix((f for f in range(body_bit.bit_length() - 1) if mask >> f & 1), bool(mask & body_bit))


@dataclass(frozen=True)
class _Group:
    """What :func:`_orbit_keys_python` needs of a group of symmetries."""

    images: tuple[Callable[[str], tuple[str, ...]], ...]  # per symmetry: picks the image's hex digits from a code's digits and their reversals
    faces: tuple[tuple[int, ...], ...]  # per symmetry: the image of every face
    compose: tuple[tuple[int, ...], ...]  # compose[u][v]: the index of u after v
    inverse: tuple[int, ...]
    edges: int  # the number of edges, hence of digits in a code
    body_bit: int  # the body point's bit in a mask: 1 << the number of faces


@cached(maxsize=16)
def _group(symmetries: tuple[Symmetry, ...]) -> _Group | None:
    """The tables of :class:`_Group`; ``None`` unless the symmetries form a group
    (an element's isometries always do)."""
    index = {sym.corner_map: i for i, sym in enumerate(symmetries)}
    compose = []
    for u in symmetries:
        row = []
        for v in symmetries:
            image = index.get(tuple(u.corner_map[c] for c in v.corner_map))
            if image is None:
                return None
            row.append(image)
        compose.append(tuple(row))
    inverse: list[int | None] = []
    for sym in symmetries:
        back = [0] * len(sym.corner_map)
        for i, c in enumerate(sym.corner_map):
            back[c] = i
        inverse.append(index.get(tuple(back)))
    if None in inverse:
        return None
    images = []
    for sym in symmetries:
        n = len(sym.edge_map)
        source = [0] * n  # digit j of the image: digit k of the code, or its reversal (at n + k)
        for k, (target, reverse) in enumerate(sym.edge_map):
            source[target] = n * reverse + k
        images.append(itemgetter(*source) if n > 1 else (lambda digits, k=source[0]: (digits[k],)))
    shape = symmetries[0].shape
    return _Group(tuple(images), tuple(sym.face_map for sym in symmetries), tuple(compose), tuple(cast("list[int]", inverse)),
                  len(shape.edges), 1 << len(shape.faces))


_REVERSAL = str.maketrans(REVERSED_DIGIT)


def _orbit_keys_python(codes: Sequence[str], masks: Sequence[int], group: _Group
                       ) -> tuple[list[int], list[int], list[int]]:
    # orbit_point_keys without numpy: the same smallest image (code as base 16, then
    # mask) and first symmetry reaching it, found once per orbit.  The images of an
    # orbit's first code r under every symmetry are its members; a member m = s(r)
    # is taken to the smallest image exactly by the t = u after s^-1 with u(r) smallest.
    edges, body_bit = group.edges, group.body_bit
    answers: dict[tuple[int, int], tuple[int, int, int]] = {}
    keys: list[int] = []
    image_masks: list[int] = []
    sym_index: list[int] = []
    for code, mask in zip(codes, masks):
        row = (int(code[:edges], 16), mask)
        if row not in answers:
            digits = code[:edges].lower()
            digits += digits.translate(_REVERSAL)
            images = []
            for pick, faces in zip(group.images, group.faces):
                image_mask = mask & body_bit
                for f in range(len(faces)):
                    if mask >> f & 1:
                        image_mask |= 1 << faces[f]
                images.append((int("".join(pick(digits)), 16), image_mask))
            best = min(images)
            smallest = [u for u, image in enumerate(images) if image == best]
            for s, image in enumerate(images):
                if image not in answers:
                    inverse = group.inverse[s]
                    answers[image] = (*best, min(group.compose[u][inverse] for u in smallest))
        key, image_mask, first = answers[row]
        keys.append(key)
        image_masks.append(image_mask)
        sym_index.append(first)
    return keys, image_masks, sym_index


def _affine(sources: Sequence[Point], targets: Sequence[Point]
            ) -> tuple[tuple[tuple[Rational, ...], ...], tuple[Rational, ...]]:
    """The affine map of unit coordinates taking four affinely independent points to four others."""
    # Solve M (s_i - s_0) = (t_i - t_0) for i = 1..3 by Cramer's rule, row by row.
    u = [sub(s, sources[0]) for s in sources[1:]]
    v = [sub(t, targets[0]) for t in targets[1:]]
    det = determinant(u[0], u[1], u[2])
    # With U the matrix of columns u[i], the rows of det * U^-1 are these cross products.
    inverse_t = [cross(u[1], u[2]), cross(u[2], u[0]), cross(u[0], u[1])]
    linear = tuple(tuple(Fraction(sum(v[i][row] * inverse_t[i][col] for i in range(3))) / det for col in range(3))
                   for row in range(3))
    shift = tuple(t - sum(a * x for a, x in zip(r, sources[0])) for r, t in zip(linear, targets[0]))
    return linear, shift


_CUBOID_CORNERS = tuple(tuple(Fraction(x) for x in c) for c in CORNERS)


@cached(maxsize=64)  # a study maps every member through its shape's symmetries
def shape_symmetries(shape: Shape) -> tuple[Symmetry, ...]:
    """The isometries of the scaled shape, identity first (see :class:`Symmetry`).

    >>> [len(shape_symmetries(standard_shape(name))) for name in ("cuboid", "prism", "pyramid", "tetrahedron")]
    [48, 4, 8, 6]
    """
    if shape.corners == _CUBOID_CORNERS and shape.edges == EDGES \
            and [set(face) for face in shape.faces] == [set(face) for face in FACES]:
        return _box_isometries(shape)  # the same group, in the box's order (see _box_isometries)
    corners, weights = shape.corners, shape.box.squared

    def distance(i: int, j: int) -> Rational:
        return sum(w * (a - b) ** 2 for w, a, b in zip(weights, corners[i], corners[j]))

    n = len(corners)
    found = []

    def extend(images: list[int]) -> None:
        # Backtracking: a permutation keeping every squared distance is an isometry
        # of the corners, hence of their convex hull.
        i = len(images)
        if i == n:
            found.append(tuple(images))
            return
        for j in range(n):
            if j not in images and all(distance(i, k) == distance(j, images[k]) for k in range(i)):
                extend(images + [j])

    extend([])
    basis = next(b for b in combinations(range(n), 4) if tetra_six_volume(*(corners[i] for i in b)) != 0)
    result = []
    for images in sorted(found, key=lambda p: p != tuple(range(n))):
        linear, shift = _affine([corners[i] for i in basis], [corners[images[i]] for i in basis])
        result.append(Symmetry(shape, images, linear, shift))
    return tuple(result)


def box_symmetries(box: Box) -> tuple[Symmetry, ...]:
    """All symmetries of the box: the isometries of the cuboid in it, identity first."""
    return shape_symmetries(standard_shape("cuboid", box))


def axis_maps(squared: Sequence[Rational]) -> tuple[tuple[tuple[int, ...], tuple[bool, ...]], ...]:
    """A box's symmetries as maps of its axes, from its squared edge lengths: ``(perm, flips)``, the image
    point's coordinate ``i`` being the point's coordinate ``perm[i]``, reflected where ``flips[i]``; the
    permutations of axes of equal length, each with every reflection, identity first (the order that the
    study tables' symmetry indices refer to).

    Examples
    --------
    >>> len(axis_maps((1, 1, 1))), len(axis_maps((1, 2, 2))), axis_maps((1, 2, 4))[1]
    (48, 16, ((0, 1, 2), (False, False, True)))
    """
    return tuple((perm, flips) for perm in permutations(range(3))
                 if all(squared[i] == squared[perm[i]] for i in range(3))
                 for flips in product((False, True), repeat=3))


def _box_isometries(shape: Shape) -> tuple[Symmetry, ...]:
    # The cuboid's isometries built directly as the box's (axis_maps): q[i] = p[perm[i]], reflected
    # (1 - x) where flips[i].
    corner_index: dict[tuple[Rational, ...], int] = {corner: i for i, corner in enumerate(CORNERS)}
    result = []
    for perm, flips in axis_maps(shape.box.squared):
        def point(p: Sequence[Rational]) -> tuple[Rational, ...]:
            return tuple(1 - p[a] if f else p[a] for a, f in zip(perm, flips))
        corner_map = tuple(corner_index[point(c)] for c in CORNERS)
        linear = tuple(tuple(Fraction(-1 if f else 1) if col == a else Fraction(0) for col in range(3))
                       for a, f in zip(perm, flips))
        shift = tuple(Fraction(int(f)) for f in flips)
        result.append(Symmetry(shape, corner_map, linear, shift))
    return tuple(result)
