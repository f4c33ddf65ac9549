"""Hypothesis strategies for configurations and refinement shapes."""

from __future__ import annotations

import math  # noqa: F401 (shapes() evaluates sqrt lengths with it)
from fractions import Fraction

from hypothesis import strategies as st

from cospherical import Box, Configuration, Length

LENGTHS = st.one_of(
    st.sampled_from(["1", "2", "4", "1.4142", "sqrt(2)", "sqrt(3)", "3/2", "0.75"]),
    st.fractions(min_value=Fraction(1, 4), max_value=4, max_denominator=12).map(str),
)
PARAMETERS = st.fractions(min_value=0, max_value=1, max_denominator=16).filter(lambda t: 0 < t < 1)


@st.composite
def configurations(draw, dyadic: bool = False) -> Configuration:
    box = Box.parse([draw(LENGTHS) for _ in range(3)])
    if dyadic:
        values = st.sampled_from([Fraction(n, 16) for n in range(1, 16)])
    else:
        values = PARAMETERS
    steiner = {k: draw(values) for k in range(12) if draw(st.booleans())}
    # Make equal parameters on parallel edges likely, so face and body points occur.
    if draw(st.booleans()):
        for axis_edges in ((0, 2, 4, 6), (1, 3, 5, 7), (8, 9, 10, 11)):
            t = draw(values)
            for k in axis_edges:
                if k in steiner:
                    steiner[k] = t
    policy = draw(st.sampled_from(["octree", "none", "explicit"]))
    if policy != "explicit":
        return Configuration.from_steiner(box, steiner, policy)
    # Face points as data, as at an octree leaf: any subset of the faces that may carry one.
    admissible = sorted(Configuration.from_steiner(box, steiner).admissible_faces)
    faces = draw(st.sets(st.sampled_from(admissible))) if admissible else set()
    return Configuration.from_steiner(box, steiner, faces=faces, body=len(faces) == 6 and draw(st.booleans()))


def random_configuration(rng) -> Configuration:
    """A random configuration from a ``random.Random``: random box, random rational t."""
    def length() -> Length:
        if rng.random() < 0.2:
            return Length.parse(f"sqrt({rng.randint(1, 12)}/{rng.randint(1, 5)})")
        return Length.parse(Fraction(rng.randint(1, 40), rng.randint(1, 10)))

    box = Box(length(), length(), length())
    steiner = {}
    for k in range(12):
        if rng.random() < 0.6:
            den = rng.randint(2, 20)
            steiner[k] = Fraction(rng.randint(1, den - 1), den)
    if rng.random() < 0.5:  # equal parameters on parallel edges: face and body points
        for axis_edges in ((0, 2, 4, 6), (1, 3, 5, 7), (8, 9, 10, 11)):
            den = rng.randint(2, 9)
            t = Fraction(rng.randint(1, den - 1), den)
            for k in axis_edges:
                if k in steiner or rng.random() < 0.5:
                    steiner[k] = t
    return Configuration.from_steiner(box, steiner, rng.choice(["octree", "none"]))


# Refinement shapes of the mesher (``--refine KIND:NUMBERS``) on boxes with rational and sqrt lengths
NUMBERS = st.sampled_from(["0", "1", "1/3", "0.5", "-0.25", "2", "0.1234567891", "1e-10", "7/16", "sqrt(2)"])
BOXES = st.sampled_from([("1", "1", "1"), ("1", "2", "4"), ("3/2", "1", "0.75"), ("sqrt(2)", "1", "1")])


@st.composite
def shapes(draw):
    kind = draw(st.sampled_from(["point", "box", "plane", "sphere"]))
    count = {"point": 3, "box": 6, "plane": 4, "sphere": 4}[kind]
    values = [draw(NUMBERS) for _ in range(count)]
    if kind == "box":
        for a in range(3):
            lo, hi = sorted(values[a::3][:2], key=lambda v: float(eval(v.replace("sqrt", "math.sqrt"))))
            values[a], values[a + 3] = lo, hi
    return f"{kind}:{','.join(values)}"
