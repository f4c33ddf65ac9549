"""Progress bars on stderr (tqdm), silent when stderr is not a terminal."""

from __future__ import annotations

from contextlib import contextmanager

from tqdm import tqdm


@contextmanager
def progress_bar(total: int, label: str):
    """Yield ``advance(n)``; the bar shows configurations done out of ``total``."""
    with tqdm(total=total, desc=label, unit="cfg", disable=None, leave=False) as bar:
        yield bar.update


@contextmanager
def stage_bars(stages: dict[str, tuple[int | None, str, str]]):
    """Yield ``advance(stage, n)``; one bar per stage (total or None, label, unit), opened when it starts."""
    bars: dict[str, tqdm] = {}

    def advance(stage: str, n: int) -> None:
        if stage not in bars:
            total, label, unit = stages[stage]
            bars[stage] = tqdm(total=total, desc=label, unit=unit, disable=None, leave=False)
        bars[stage].update(n)

    try:
        yield advance
    finally:
        for bar in bars.values():
            bar.close()
