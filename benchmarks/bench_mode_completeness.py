"""Benchmark: how complete the default assembly-mode search is on general 6-6
Stewart-Gough platforms (issue 20).

    python benchmarks/bench_mode_completeness.py [--platforms 40] [--starts 12000]
        [--reference 20000] [--reference-platforms 10] [--json benchmarks/bench_mode_completeness.json]

Round trip: for each of ``--platforms`` random platforms (tests/random_platforms.py,
seeds 0, 1, ...), a random pose (seeded), its leg lengths (numpy IK), then
:func:`cpm_nlp.analysis.assembly.assembly_modes` with ``--starts`` starts (the
default of ``assembly_modes: all``): the search must contain that pose (rotation
matrix and position within 1e-6).  The rate of containment estimates, for a mode
drawn as the pose is, the probability that the default search finds it; its
Clopper-Pearson 95 % lower bound is given beside it.  Recall: on the first
``--reference-platforms`` platforms a search with ``--reference`` starts (another
seed) is the reference set of modes; the fraction of its modes the default search
found is reported (every mode, not only the drawn one).  Also: the number of real
modes per platform, the completeness estimate's verdict, the time per search
(wall, load average beside it).
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

from cpm_nlp.analysis.assembly import DEFAULT_STARTS, assembly_modes  # noqa: E402
from tests.random_platforms import Platform66, contains  # noqa: E402


def _lower_bound(k: int, n: int, alpha: float = 0.05) -> float:
    """Clopper-Pearson one-sided lower bound of a binomial proportion (bisection on the tail)."""
    from math import comb

    if k == 0:
        return 0.0

    def tail(p: float) -> float:  # P(X >= k | p)
        return sum(comb(n, j) * p**j * (1 - p) ** (n - j) for j in range(k, n + 1))

    lo, hi = 0.0, k / n
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if tail(mid) < alpha else (lo, mid)
    return lo


def _same(platform: Platform66, a, b) -> bool:
    Ra, pa = platform.pose_matrix(a.x)
    Rb, pb = platform.pose_matrix(b.x)
    return bool(np.max(np.abs(Ra - Rb)) < 1e-6 and np.max(np.abs(pa - pb)) < 1e-6)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--platforms", type=int, default=40)
    ap.add_argument("--starts", type=int, default=DEFAULT_STARTS)
    ap.add_argument("--reference", type=int, default=20000)
    ap.add_argument("--reference-platforms", type=int, default=10)
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args()
    rows, found_ref, total_ref = [], 0, 0
    for seed in range(args.platforms):
        platform = Platform66(seed)
        model = platform.model()
        pose = platform.random_pose(np.random.default_rng(1000 + seed))
        lengths = platform.lengths(pose)
        t0 = time.perf_counter()
        found = assembly_modes(model, lengths, starts=args.starts, seed=seed)
        seconds = time.perf_counter() - t0
        row = {
            "seed": seed,
            "modes": found.count,
            "contains_pose": contains(found, platform, pose),
            "complete_estimate": found.completeness.complete,
            "unseen_chao1": found.completeness.unseen,
            "smallest_basin": found.completeness.smallest_basin,
            "seconds": seconds,
            "load_avg_1min": os.getloadavg()[0],
        }
        if seed < args.reference_platforms:
            ref = assembly_modes(model, lengths, starts=args.reference, seed=10_000 + seed)
            hit = sum(any(_same(platform, r, m) for m in found.modes) for r in ref.modes)
            row.update(reference_modes=ref.count, reference_found=hit)
            found_ref += hit
            total_ref += ref.count
        rows.append(row)
        print(json.dumps(row), flush=True)
    k = sum(r["contains_pose"] for r in rows)
    n = len(rows)
    out = {
        "case": "random 6-6 platforms, round trip",
        "platforms": n,
        "starts": args.starts,
        "contains_pose": k,
        "rate": k / n,
        "rate_lower_95": _lower_bound(k, n),
        "reference_starts": args.reference,
        "reference_modes": total_ref,
        "reference_modes_found": found_ref,
        "modes_per_platform": [r["modes"] for r in rows],
        "seconds_median": float(np.median([r["seconds"] for r in rows])),
        "seconds_max": float(np.max([r["seconds"] for r in rows])),
        "rows": rows,
    }
    print(json.dumps({k: v for k, v in out.items() if k != "rows"}, indent=2))
    if args.json:
        args.json.write_text(json.dumps(out, indent=2) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
