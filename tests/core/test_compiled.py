"""The compiled walk: the same cells as the Python walk, and only on frames that fit in int64."""

from __future__ import annotations

from hypothesis import HealthCheck, given, settings
from sampling import examples
from strategies import configurations


@settings(max_examples=examples(150), deadline=None, suppress_health_check=[HealthCheck.too_slow])  # 100; --full 150
@given(configurations())
def test_compiled_and_python_walks_give_the_same_cells(cfg):
    from cospherical.core.delaunay import delaunay_cells
    from cospherical.core.geometry import Frame

    frame = Frame.build(cfg.nodes(), cfg.box.squared)
    assert delaunay_cells(frame, backend="compiled") == delaunay_cells(frame, backend="python")


def test_the_compiled_walk_takes_only_frames_that_fit_in_int64():
    from cospherical.core.compiled import fits

    cube = [(0, 0, 0), (16, 16, 16)]
    assert fits(cube, (1, 1, 1), 16)
    assert not fits([(0, 0, 0), (1 << 10, 0, 0)], (1, 1, 1), 1 << 10)  # 2**17 * 2**80 overflows
    assert not fits(cube, (1 << 40, 1, 1), 16)
    assert not fits([(i, 0, 0) for i in range(63)], (1, 1, 1), 63)  # a bit mask holds 62 points
