"""What a benchmark script leaves behind: ``results/benchmarks/<script>.json``.

Every figure of time or size in the documentation comes from one of these files, which
the script that measured it wrote, never from a hand-typed table: the benchmarks page
(``docs/results/benchmarks.md``) is rendered from them when the site is built
(``scripts/docs_hooks.py``). A file holds the command as it was run (its size arguments
included, so a quick run at a small size says so), the date, the commit, the machine
(cores, memory, CPU model), the load average before and after, the process's CPU and wall
seconds and peak memory, the script's headline figures as rows ``[what, figure]``, and
everything it printed.

Use::

    with recorded(__file__) as record:
        ...                      # print as before
        record.add("what", "figure")
        record.table(["column", ...], [[cell, ...], ...])   # a whole table, when the figures are one

The file is written when the block ends without an exception (a failed run leaves the
previous file as it was), to a temporary file in the same folder and renamed.
"""

from __future__ import annotations

import contextlib
import datetime
import io
import json
import os
import platform
import resource
import shlex
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FOLDER = ROOT / "results" / "benchmarks"


def machine() -> dict:
    """The machine the figures were measured on: cores, memory, CPU model, system."""
    model = ""
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    memory = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    return {"cores": os.cpu_count(), "memory_gib": round(memory / 2**30, 1),
            "cpu": model or platform.processor() or platform.machine(),
            "system": f"{platform.system()} {platform.release()}", "python": platform.python_version()}


def _process_seconds() -> float | None:
    """Wall seconds since this process started (Linux /proc), so a record covers the whole run, set-up included."""
    try:
        start_ticks = int(Path("/proc/self/stat").read_text().rsplit(")", 1)[1].split()[19])
        uptime = float(Path("/proc/uptime").read_text().split()[0])
    except (OSError, ValueError, IndexError):
        return None
    return uptime - start_ticks / os.sysconf("SC_CLK_TCK")


def _commit() -> str | None:
    """The checkout's commit, ``+changes`` when the measured code (``src/``, ``benchmarks/``, ``examples/``)
    differs from it; other files, such as the records themselves, do not count (a local commit may be rebased later)."""
    result = subprocess.run(["git", "rev-parse", "--short=12", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    changed = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "--", "src", "benchmarks",
                              "examples"], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    return (result.stdout.strip() + ("+changes" if changed else "")) or None


class _Tee(io.TextIOBase):
    """Writes to the terminal and keeps a copy."""

    def __init__(self, stream):
        self.stream, self.kept = stream, io.StringIO()

    def write(self, text):
        self.kept.write(text)
        return self.stream.write(text)

    def flush(self):
        self.stream.flush()


class Record:
    def __init__(self, script: str):
        self.script = Path(script).name
        self.command = " ".join(["python", f"benchmarks/{self.script}", *map(shlex.quote, sys.argv[1:])])
        self.rows: list[list[str]] = []
        self.tables: list[dict] = []
        self.date = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()
        self.load_before = [round(x, 2) for x in os.getloadavg()]
        self.start = time.perf_counter() - (_process_seconds() or 0.0)

    def add(self, what: str, figure: str) -> None:
        """One headline figure, as the page's table shows it."""
        self.rows.append([what, figure])

    def table(self, columns: list[str], rows: list[list]) -> None:
        """A table of figures (cells as the page shows them), rendered whole."""
        self.tables.append({"columns": list(columns), "rows": [[str(cell) for cell in row] for row in rows]})

    def data(self, output: str) -> dict:
        own = resource.getrusage(resource.RUSAGE_SELF)
        children = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime
        return {"script": self.script, "command": self.command, "date": self.date, "commit": _commit(),
                "machine": machine(), "load_average": {"before": self.load_before,
                                                       "after": [round(x, 2) for x in os.getloadavg()]},
                "wall_seconds": round(time.perf_counter() - self.start, 2), "cpu_seconds": round(cpu, 2),  # whole process
                "peak_memory_gib": round(max(own.ru_maxrss, children.ru_maxrss) / 2**20, 3),
                "rows": self.rows, "tables": self.tables, "output": output.splitlines()}


@contextlib.contextmanager
def recorded(script: str, folder: Path = FOLDER, name: str | None = None):
    """Run the block with its output kept; then write ``folder/<name or the script's stem>.json``."""
    record = Record(script)
    tee = _Tee(sys.stdout)
    with contextlib.redirect_stdout(tee):
        yield record
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name or Path(script).stem}.json"
    temporary = path.with_name(f".{path.name}.tmp")
    temporary.write_text(json.dumps(record.data(tee.kept.getvalue()), indent=1) + "\n")
    os.replace(temporary, path)
    print(f"recorded in {path.relative_to(ROOT) if path.is_relative_to(ROOT) else path}")
