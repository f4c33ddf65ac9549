"""Progress bars on stderr (tqdm), silent when stderr is not a terminal."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, NoReturn, cast

if TYPE_CHECKING:
    from tqdm import tqdm

__all__ = ["progress_bar", "stage_bars"]


def _quiet(*args: object) -> None:
    pass


@contextmanager
def progress_bar(total: int, label: str) -> Iterator[Callable[[int], None]]:
    """Yield ``advance(n)``; the bar shows configurations done out of ``total``."""
    if not sys.stderr.isatty():  # tqdm would draw nothing; not importing it saves start-up time
        yield _quiet
        return
    from tqdm import tqdm

    with tqdm(total=total, desc=label, unit="cfg", disable=None, leave=False) as bar:
        # update's result (whether it redrew) is no caller's business: handed on as a callback that returns nothing
        yield cast(Callable[[int], None], bar.update)


@contextmanager
def stage_bars(stages: dict[str, tuple[int | None, str, str]]) -> Iterator[Callable[[str, int], None]]:
    """Yield ``advance(stage, n)``; one bar per stage (total or None, label, unit), opened when it starts."""
    if not sys.stderr.isatty():  # as progress_bar: nothing drawn, tqdm (and the multiprocessing it imports) not imported
        yield _quiet
        return
    bars: dict[str, tqdm[NoReturn]] = {}

    def advance(stage: str, n: int) -> None:
        if stage not in bars:
            from tqdm import tqdm

            total, label, unit = stages[stage]
            bars[stage] = tqdm(total=total, desc=label, unit=unit, disable=None, leave=False)
        bars[stage].update(n)

    try:
        yield advance
    finally:
        for bar in bars.values():
            bar.close()
