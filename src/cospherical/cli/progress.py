"""Progress bars on stderr (tqdm), silent when stderr is not a terminal."""

from __future__ import annotations

from contextlib import contextmanager

from tqdm import tqdm


@contextmanager
def progress_bar(total: int, label: str):
    """Yield ``advance(n)``; the bar shows configurations done out of ``total``."""
    with tqdm(total=total, desc=label, unit="cfg", disable=None, leave=False) as bar:
        yield bar.update
