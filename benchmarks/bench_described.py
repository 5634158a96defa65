"""Batch FK throughput of the 3-PRS written once, as the mechanism file prs3.yaml (the built-in
``prs3``), against the hand-written closures it replaced, kept as the test reference
tests/reference/prs3_closures.py (issue 21: generated FK and batch within 1.1x of the hand-written
module; issue 11 asked 1.5x).

    python benchmarks/bench_described.py [--n 20000] [--repeat 5] [--json benchmarks/bench_described.json]

Both models (the reference built from its declaration directly, not registered) have the
same parameters (problems/prs3_forward_kinematics.yaml); the same N
random actuator vectors (s within +-2 mm) are solved by ``cn.batch_forward_kinematics``
(Newton; ``--backend map`` or ``compiled``) for each, interleaved, warm (solvers built before the clock
starts); the median of the repeats is taken.  The machine's load (os.getloadavg()) is
recorded beside the figures.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import cpm_nlp as cn  # noqa: E402
from tests.reference import prs3_closures  # noqa: E402 - the hand-written closures, a test reference

PARAMS = {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"}
#: issue 21: generated FK and batch within 1.1x of the hand-written module
TARGET = 1.1


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=20000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--backend", default="map", choices=("map", "compiled"))
    args = ap.parse_args()
    newton = cn.SolverConfig("newton")
    models = {
        "hand-written reference": prs3_closures.reference_model(PARAMS),
        "file prs3": cn.build_model("prs3", PARAMS),
    }
    qs = np.random.default_rng(0).uniform(-2e-3, 2e-3, (args.n, 3))
    for m in models.values():  # warm: solvers and kernels built
        cn.batch_forward_kinematics(m, qs[:100], newton, backend=args.backend)
    times: dict[str, list[float]] = {k: [] for k in models}
    load_before = os.getloadavg()
    for _ in range(args.repeat):
        for name, m in models.items():
            t0 = time.perf_counter()
            res = cn.batch_forward_kinematics(m, qs, newton, backend=args.backend)
            times[name].append(time.perf_counter() - t0)
            assert int(np.sum(res.ok)) == args.n, name
    load_after = os.getloadavg()
    med = {k: statistics.median(v) for k, v in times.items()}
    ratio = med["file prs3"] / med["hand-written reference"]
    out = {
        "n": args.n,
        "backend": args.backend,
        "repeat": args.repeat,
        "median_seconds": med,
        "poses_per_second": {k: args.n / v for k, v in med.items()},
        "ratio_file_over_hand": ratio,
        "target": f"<= {TARGET}",
        "met": ratio <= TARGET,
        "loadavg_before": load_before,
        "loadavg_after": load_after,
        "machine": platform.platform(),
        "cpus": os.cpu_count(),
    }
    for k, v in med.items():
        print(f"{k:24s} {v * 1e3:9.1f} ms for {args.n} poses  ({args.n / v:,.0f} poses/s)")
    print(f"ratio file / hand: {ratio:.3f} (target <= {TARGET}); load {load_before} -> {load_after}")
    if args.json:
        runs = json.loads(args.json.read_text()) if args.json.exists() else {}
        runs[args.backend] = out
        args.json.write_text(json.dumps(runs, indent=2) + "\n")


if __name__ == "__main__":
    main()
