"""Benchmark: all assembly modes of a 6-UPS Stewart-Gough platform (issue 11).

    python benchmarks/bench_modes.py [--starts 3000] [--repeats 3] [--json benchmarks/bench_modes.json]

Target: ``assembly_modes: all`` with a few thousand starts in under 10 s on the
2-core machine.  Measured: the wall time of
:func:`cpm_nlp.analysis.assembly.assembly_modes` (batch Newton from every
start, merge, checks, the ordinary FK), best of ``--repeats`` runs after one
warm-up (the first run builds the kernels), and -- as the baseline of the same
run -- the same starts solved one by one with ``cn.forward_kinematics`` and
Newton (a plain loop, the rate measured on ``--baseline`` starts and scaled to
all of them).  The load average (os.getloadavg) is recorded beside each figure.
The Stewart platform is the hand-written LoopClosure of tests/gallery_closures.py.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import cpm_nlp as cn  # noqa: E402
from cpm_nlp.analysis.assembly import assembly_modes, search_region  # noqa: E402
from tests import gallery_closures as gc  # noqa: E402

TARGET_SECONDS = 10.0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--starts", type=int, default=3000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--baseline", type=int, default=300, help="starts of the one-by-one baseline")
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    model = gc.stewart_model()
    lengths = model.closure.ik(np.array([0.01, -0.005, 0.24, 0.06, -0.04, 0.1]), model.p)[1]
    lengths = np.asarray(lengths).ravel()
    assembly_modes(model, lengths, starts=64)  # warm-up: kernels built
    times, loads = [], []
    found = None
    for _ in range(args.repeats):
        loads.append(os.getloadavg()[0])
        t0 = time.perf_counter()
        found = assembly_modes(model, lengths, starts=args.starts)
        times.append(time.perf_counter() - t0)
    best = min(times)
    region = search_region(model)
    lo, hi = region.lower, region.upper
    rng = np.random.default_rng(0)
    starts = lo + (hi - lo) * rng.random((args.baseline, lo.size))
    newton = cn.SolverConfig("newton")
    load_base = os.getloadavg()[0]
    t0 = time.perf_counter()
    for x0 in starts:
        cn.forward_kinematics(model, lengths, newton, x0)
    per_start = (time.perf_counter() - t0) / args.baseline
    baseline = per_start * args.starts
    result = {
        "case": "stewart_all_modes",
        "starts": args.starts,
        "modes": found.count,
        "converged": found.converged,
        "seconds": best,
        "seconds_runs": times,
        "load_avg_1min": loads,
        "target_seconds": TARGET_SECONDS,
        "met": best < TARGET_SECONDS,
        "baseline_loop_seconds": baseline,
        "baseline_load_avg_1min": load_base,
        "speed_up_vs_loop": baseline / best,
        "threads": os.cpu_count(),
    }
    print(
        f"all assembly modes, 6-UPS, {args.starts} starts: {best:.3f} s (target < {TARGET_SECONDS:g} s: "
        f"{'met' if result['met'] else 'MISSED'}), {found.count} modes; one-by-one Newton loop: {baseline:.3f} s "
        f"(x{result['speed_up_vs_loop']:.1f}); load {loads}"
    )
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=2) + "\n")
        print(f"written: {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
