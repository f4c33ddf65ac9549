"""Devices: time and memory of the example devices, and a diode beside the one-box mesh of the same size.

    python benchmarks/bench_devices.py [--levels 7] [--anode] [--pairs 3] [--warmup 1] [--devices GLOB]

Whole processes, each measured by the kernel (``os.wait4``: user + system CPU, peak
resident memory) and by the wall clock, every output written (``--dual --out``):

(1) ``cospherical mesh --device examples/devices/NAME.yaml --dual --out DIR`` for each
    example device, as shipped (``--devices GLOB``: those whose name matches);
(2) the pn diode (one silicon cube refined at its junction plane z = 1/2, two contacts)
    at ``--levels L`` against ``cospherical mesh --domain 1 1 1 --refine plane:0,0,1,0.5
    --levels L --dual --out DIR``, the same tree and the same elements as one box: what a
    device adds (its region arrays, the dual's parts per region, the contact and interface
    faces, contacts.vtu) over a mesh without regions.  The goal: the device at most 1.3
    times the box's CPU.  Level 7 gives 164 k elements; level 8 about 650 k and level 9
    about 2.6 M (minutes and GBs: run them on a quiet machine).  ``--anode`` refines both
    at the anode contact's plane z = 1 too (``plane:0,0,1,1``), half again the leaves:
    about 1 M elements at level 8.  The two run in turn, box then device, ``--pairs N`` times
    (default 3) after ``--warmup`` pairs not counted (default 1: a first run after a change of
    the code also writes Python's and the schemas' caches); the ratios are taken pair by pair and their median is the figure (a shared
    machine's speed drifts between runs, much less within a pair).

Writes results/benchmarks/bench_devices.json (benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from record import recorded  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "devices"


def run_usage(command: list[str]) -> tuple[float, float, float]:
    """Wall seconds, CPU seconds (user + system) and peak GB of one whole process (``os.wait4``)."""
    start = time.perf_counter()
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        process = subprocess.Popen(command, stdout=out, stderr=err, text=True)
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.perf_counter() - start
        if os.waitstatus_to_exitcode(status):
            err.seek(0)
            sys.exit(f"{' '.join(command)}: {err.read().strip()[-500:]}")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024**2


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, default=7, help="the diode's level for the comparison (default 7)")
    parser.add_argument("--anode", action="store_true", help="refine the diode at its anode's plane z = 1 too")
    parser.add_argument("--pairs", type=int, default=3, help="box/device runs in turn (default 3)")
    parser.add_argument("--warmup", type=int, default=1, help="runs not counted first (default 1)")
    parser.add_argument("--devices", default="*", metavar="GLOB", help="the example devices (1) meshes (default: all)")
    args = parser.parse_args()
    cospherical = [sys.executable, "-m", "cospherical", "mesh"]
    with recorded(__file__) as record, tempfile.TemporaryDirectory() as scratch:
        rows = []
        for _ in range(args.warmup):  # not counted: the first process after a change of the code writes its caches
            run_usage(cospherical + ["--device", str(EXAMPLES / "pn-diode.yaml"), "--out", str(Path(scratch) / "warm")])
        for path in sorted(EXAMPLES.glob(f"{args.devices}.yaml")):
            out = Path(scratch) / path.stem
            wall, cpu, peak = run_usage(cospherical + ["--device", str(path), "--dual", "--out", str(out)])
            report = json.loads((out / "report.json").read_text())
            rows.append([path.stem, f"{report['elements']:,}", f"{cpu:.2f}", f"{wall:.2f}", f"{peak:.2f}"])
            print(f"{path.stem:14s} {report['elements']:>9,} elements  {cpu:6.2f} CPU-s  {wall:6.2f} s  {peak:.2f} GB")
        record.table(["example", "elements", "CPU s", "wall s", "peak GB"], rows)
        diode = Path(scratch) / "diode.yaml"
        text = (EXAMPLES / "pn-diode.yaml").read_text().replace("levels: 5", f"levels: {args.levels}")
        planes = ["plane:0,0,1,0.5"]
        if args.anode:
            text = text.replace("refine:\n", "refine:\n  - plane: [0, 0, 1, 1]\n")
            planes.append("plane:0,0,1,1")
        diode.write_text(text)
        commands = {"one box": ["--domain", "1", "1", "1", *(f"--refine={p}" for p in planes),
                                "--levels", str(args.levels), "--no-uniform"],
                    "diode device": ["--device", str(diode), "--no-uniform"]}
        runs: dict[str, list[tuple[float, float, float]]] = {name: [] for name in commands}
        elements = {}
        for counted in [False] * args.warmup + [True] * args.pairs:
            for name, command in commands.items():
                out = Path(scratch) / name.replace(" ", "-")
                usage = run_usage(cospherical + command + ["--dual", "--out", str(out)])
                if not counted:
                    continue
                runs[name].append(usage)
                elements[name] = json.loads((out / "report.json").read_text())["elements"]
                wall, cpu, peak = runs[name][-1]
                print(f"{name:14s} level {args.levels}: {elements[name]:,} elements  {cpu:6.2f} CPU-s  {wall:6.2f} s  "
                      f"{peak:.2f} GB")
        for name in commands:
            wall, cpu, peak = (statistics.median(run[i] for run in runs[name]) for i in range(3))
            record.add(f"{name}, level {args.levels}{' and the anode plane' if args.anode else ''} "
                       f"({elements[name]:,} elements, --dual --out; median of {args.pairs})",
                       f"{cpu:.2f} CPU-s, {wall:.2f} s wall, {peak:.2f} GB peak")
        pairs = list(zip(runs["diode device"], runs["one box"]))
        ratio = statistics.median(device[1] / box[1] for device, box in pairs)
        memory = statistics.median(device[2] / box[2] for device, box in pairs)
        spread = ", ".join(f"{device[1] / box[1]:.2f}" for device, box in pairs)
        print(f"device / box: {ratio:.2f} x CPU (pairs: {spread}), {memory:.2f} x peak memory "
              "(goal: at most 1.3 x)")
        record.add("diode device / one box, pair by pair (median)",
                   f"{ratio:.2f} x CPU (pairs {spread}), {memory:.2f} x peak memory (goal: <= 1.3 x)")


if __name__ == "__main__":
    main()
