"""Timing: ``rawehelix modes mobile_end`` at N = 8, 32, 128, without and with
structural damping (issue 26; a benchmark, not a test).

    .venv/bin/python benchmarks/modal_lowest.py [--runs 3] [--elements 8 32 128]
        [--rawehelix PATH] [--timeout 300]

Runs the command line (a fresh process each time: import, JIT cache, the
stationary Newton solve, the modal solve, the writers) ``--runs`` times per
case and prints the median wall time of the process, the ``wall_s`` that the
command reports (stationary + modal solve) and its exit code.  The damped case
is ``--set damping.bending_s=1e-3 --set damping.torsion_s=1e-3``, the one of
the issue.  ``--rawehelix`` times another installation (e.g. the main
branch's .venv/bin/rawehelix) for a before/after comparison.
"""

from __future__ import annotations

import argparse
import pathlib
import re
import statistics
import subprocess
import sys
import tempfile
import time

DAMPING = ("--set", "damping.bending_s=1e-3", "--set", "damping.torsion_s=1e-3")
CASES = {"undamped": (), "damped": DAMPING}


def run_once(rawehelix: str, elements: int, extra: tuple, timeout: float) -> tuple:
    """(wall s of the process, reported wall_s or None, exit code)."""
    with tempfile.TemporaryDirectory() as out:
        cmd = [rawehelix, "modes", "mobile_end", "--elements", str(elements), "-o", out, *extra]
        start = time.perf_counter()
        try:
            done = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return time.perf_counter() - start, None, "timeout"
        wall = time.perf_counter() - start
    found = re.search(r"dofs, ([0-9.]+) s\)", done.stdout)
    return wall, float(found.group(1)) if found else None, done.returncode


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--elements", type=int, nargs="+", default=[8, 32, 128])
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    parser.add_argument("--rawehelix", default=str(pathlib.Path(sys.executable).parent
                                                   / "rawehelix"))
    parser.add_argument("--timeout", type=float, default=300.0)
    args = parser.parse_args(argv)
    print(f"{'case':>9} {'N':>4}  {'wall s (median)':>15}  {'reported s':>10}  exit codes")
    for case in args.cases:
        for n in args.elements:
            runs = [run_once(args.rawehelix, n, CASES[case], args.timeout)
                    for _ in range(args.runs)]
            wall = statistics.median(r[0] for r in runs)
            reported = [r[1] for r in runs if r[1] is not None]
            rep = f"{statistics.median(reported):10.2f}" if reported else f"{'-':>10}"
            print(f"{case:>9} {n:>4}  {wall:15.2f}  {rep}  {[r[2] for r in runs]}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
