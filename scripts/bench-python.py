#!/usr/bin/env python3
"""cablemap.solve_batch per solve beside `cablemap bench`'s, on the same
routings and tensions (issue 27: within 1.2x of the command's figure).

Run with the test script's virtual environment (where scripts/test.sh
installs the package):

    target/python-venv/bin/python scripts/bench-python.py [--bin target/release/cablemap] [--routings 400] [--repeats 3]

`cablemap bench` steps each of its sampled thesis-grid routings through 21
tensions (1.0 to 2.0 N) on one thread and reports the median over routings
of the time per solve. This script hands the same routings (the library's
sample, `cablemap._native.bench_routings`) and tensions to
`cablemap.solve_batch(..., threads=1)` and reports, for gravity on and off:

- batch: the whole batch's time per solve (the Python call, the conversion
  to numpy included), by wall clock and by the process's CPU time (on a
  shared machine the wall time counts the time the process waited for a
  core, which the command's median over routings leaves out), and
- per routing: the median over routings of one-routing batches' time per
  solve (as the command's statistic, with the call's overhead per 21 solves),

each the best of `--repeats` runs, alternated with the command's runs
(best of the same number), and their ratios to the command's median.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

# numpy's OpenBLAS threads spin after a call and take CPU time from the
# solves on a small machine; the batch calls no BLAS routine.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import cablemap  # noqa: E402
from cablemap import _native  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
TENSIONS_N = np.linspace(1.0, 2.0, 21)


def command_medians(binary, routings):
    """`cablemap bench --no-reference --json`'s median µs per solve, by case."""
    out = subprocess.run([binary, "bench", "--no-reference", "--json", "--routings", str(routings)], capture_output=True, text=True, check=True)
    # The JSON array is printed first; the spatial table may follow it.
    rows, _ = json.JSONDecoder().raw_decode(out.stdout.lstrip())
    return {r["label"]: r["median_us_per_solve"] for r in rows}


def batch_us(routings, gravity):
    """µs per solve of one single-threaded batch of every routing: wall
    time, and the process's CPU time (what the solves cost when the machine
    is shared: time the process waited for a core is not counted)."""
    start, cpu = time.perf_counter(), time.process_time()
    out = cablemap.solve_batch(routings, TENSIONS_N, threads=1, gravity=gravity)
    elapsed, cpu = time.perf_counter() - start, time.process_time() - cpu
    assert out["status"].shape == (len(routings), len(TENSIONS_N))
    return elapsed * 1e6 / out["status"].size, cpu * 1e6 / out["status"].size


def per_routing_us(routings, gravity):
    """Median over routings of a one-routing batch's µs per solve."""
    times = []
    for y in routings:
        start = time.perf_counter()
        cablemap.solve_batch(y.reshape(1, 5), TENSIONS_N, threads=1, gravity=gravity)
        times.append((time.perf_counter() - start) * 1e6 / len(TENSIONS_N))
    return statistics.median(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bin", default=os.environ.get("CABLEMAP_BIN", str(REPO / "target" / "release" / "cablemap")))
    parser.add_argument("--routings", type=int, default=400)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    radius_mm = cablemap.Actuator.thesis().rod["radius_mm"]
    routings = np.array(_native.bench_routings(args.routings, radius_mm), dtype=np.float64)
    cases = [("gravity on", True), ("gravity off", False)]
    best = {}
    for _ in range(args.repeats):
        for label, value in command_medians(args.bin, args.routings).items():
            best.setdefault(("command", label), []).append(value)
        for label, gravity in cases:
            wall, cpu = batch_us(routings, gravity)
            best.setdefault(("batch", label), []).append(wall)
            best.setdefault(("batch cpu", label), []).append(cpu)
            best.setdefault(("per routing", label), []).append(per_routing_us(routings, gravity))
    print(f"single thread, {args.routings} thesis-grid routings x {len(TENSIONS_N)} tensions (1.0..2.0 N), best of {args.repeats} runs each")
    print(f"{'case':<12} {'bench µs':>9} {'batch µs':>9} {'ratio':>6} {'batch cpu µs':>13} {'ratio':>6} {'per-routing µs':>15} {'ratio':>6}")
    worst = {"wall": 0.0, "cpu": 0.0}
    for label, _ in cases:
        command = min(best[("command", label)])
        batch, cpu = min(best[("batch", label)]), min(best[("batch cpu", label)])
        single = min(best[("per routing", label)])
        worst["wall"] = max(worst["wall"], batch / command)
        worst["cpu"] = max(worst["cpu"], cpu / command)
        print(
            f"{label:<12} {command:>9.2f} {batch:>9.2f} {batch / command:>6.2f} {cpu:>13.2f} {cpu / command:>6.2f} "
            f"{single:>15.2f} {single / command:>6.2f}"
        )
    print(f"solve_batch / cablemap bench at worst: {worst['wall']:.2f}x by wall time, {worst['cpu']:.2f}x by CPU time (goal ≤ 1.2x)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
