"""Benchmark: does the default assembly-mode search find every mode (issue 20, item 2)?

    python benchmarks/bench_assembly_modes.py [--seeds 100] [--platforms 40] [--reference 100000]
        [--before] [--json benchmarks/bench_assembly_modes.json]

1. Dietmaier's 6-6 platform with 40 real modes (tests/corpus/dietmaier_6_6.yaml, the
   numbers in tests/dietmaier.py): the default search (``assembly_modes`` with its default
   starts) with ``--seeds`` different seeds; the fraction that found all 40, each mode checked
   in numpy (leg lengths to 1e-9; 40 distinct verified poses are all there are), with its
   Clopper-Pearson 95 % lower bound; the time per search, wall and CPU, and the load average.
2. The same probability from the basins: one search of ``--reference`` starts gives the
   fraction p_i of the starts that reach each mode; a search of N uniform starts finds them
   all with probability prod_i (1 - (1 - p_i)^N) (the starts are independent draws of one
   distribution; the home start aside), given for the default N and others.
3. The round trip on random 6-6 platforms (tests/random_platforms.py): a random pose, its leg
   lengths, the default search must contain that pose.
4. ``--before``: items 1 and 3 with the search as it was (2000 starts, no damped steps), in
   the same run, for the ratio.
5. The certificate that no other real mode exists in the search region
   (:func:`cpm_nlp.analysis.mode_certificate.certify_modes`): its time and sub-boxes on
   Freudenstein's four-bar, the five-bar and the 3-RRR, and on Dietmaier's platform within
   ``--certify-boxes`` sub-boxes (where it does not finish).

Rates and ratios within one run; nothing here is asserted (tests/test_benchmarks.py runs it
small as a smoke test).
"""

from __future__ import annotations

import argparse
import inspect
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from cpm_nlp.analysis import assembly  # noqa: E402
from cpm_nlp.analysis.mode_certificate import certify_modes  # noqa: E402
from tests import dietmaier  # noqa: E402
from tests.analysis.test_mode_certificate import file_model, four_bar  # noqa: E402
from tests.random_platforms import Platform66, contains  # noqa: E402

#: the search before this benchmark's change: 2000 starts, plain Newton from each
BEFORE = {"starts": 2000, "damped_steps": 0}


def lower_bound(k: int, n: int, alpha: float = 0.05) -> float:
    """Clopper-Pearson one-sided lower bound of a binomial proportion (bisection on the tail)."""
    if k == 0:
        return 0.0

    def tail(p: float) -> float:  # P(X >= k | p)
        return sum(math.comb(n, j) * p**j * (1 - p) ** (n - j) for j in range(k, n + 1))

    lo, hi = 0.0, k / n
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if tail(mid) < alpha else (lo, mid)
    return lo


def default_starts() -> int:
    return int(inspect.signature(assembly.assembly_modes).parameters["starts"].default)


def verified(found) -> int:
    """Distinct modes whose six leg lengths match Dietmaier's to 1e-9 (numpy, not the closure)."""
    good = [m.x for m in found.modes if np.max(np.abs(dietmaier.lengths(m.x) - dietmaier.LENGTHS)) < 1e-9]
    frames = [np.r_[dietmaier.rotation(*x[3:]).ravel(), x[:3]] for x in good]
    distinct = []
    for f in frames:
        if all(np.max(np.abs(f - g)) > 1e-6 for g in distinct):
            distinct.append(f)
    return len(distinct)


def timed(fn, *args, **kwargs):
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn(*args, **kwargs)
    return out, time.perf_counter() - t0, time.process_time() - c0


def dietmaier_rate(model, seeds: int, starts: int) -> dict:
    rows = []
    for seed in range(seeds):
        found, wall, cpu = timed(assembly.assembly_modes, model, dietmaier.LENGTHS, starts=starts, seed=seed)
        rows.append(
            {
                "seed": seed,
                "modes": found.count,
                "verified": verified(found),
                "complete_estimate": found.completeness.complete,
                "wall_s": wall,
                "cpu_s": cpu,
                "load_avg_1min": os.getloadavg()[0],
            }
        )
        print(json.dumps(rows[-1]), flush=True)
    k = sum(r["verified"] == dietmaier.MODES for r in rows)
    return {
        "starts": starts,
        "searches": seeds,
        "found_all_40": k,
        "rate": k / seeds,
        "rate_lower_95": lower_bound(k, seeds),
        "modes_found_min": min(r["verified"] for r in rows),
        "complete_estimate_when_all_found": sum(r["complete_estimate"] for r in rows if r["verified"] == 40),
        "complete_estimate_when_some_missed": sum(r["complete_estimate"] for r in rows if r["verified"] < 40),
        "wall_s_median": float(np.median([r["wall_s"] for r in rows])),
        "cpu_s_median": float(np.median([r["cpu_s"] for r in rows])),
        "load_avg_1min_median": float(np.median([r["load_avg_1min"] for r in rows])),
        "rows": rows,
    }


def basin_estimate(model, reference: int, starts: list[int]) -> dict:
    found, wall, cpu = timed(assembly.assembly_modes, model, dietmaier.LENGTHS, starts=reference, seed=10**6)
    basins = np.array(sorted(m.basin for m in found.modes)) / reference
    return {
        "reference_starts": reference,
        "modes": found.count,
        "verified": verified(found),
        "smallest_basins": basins[:5].tolist(),
        "p_all": {str(n): float(np.prod(1 - (1 - basins) ** n)) for n in starts},
        "wall_s": wall,
        "cpu_s": cpu,
    }


def round_trip(platforms: int, starts: int) -> dict:
    rows = []
    for seed in range(platforms):
        platform = Platform66(seed)
        model = platform.model()
        pose = platform.random_pose(np.random.default_rng(1000 + seed))
        found, wall, cpu = timed(assembly.assembly_modes, model, platform.lengths(pose), starts=starts, seed=seed)
        rows.append(
            {"seed": seed, "modes": found.count, "contains_pose": contains(found, platform, pose), "wall_s": wall}
        )
        rows[-1].update(cpu_s=cpu, load_avg_1min=os.getloadavg()[0])
        print(json.dumps(rows[-1]), flush=True)
    k = sum(r["contains_pose"] for r in rows)
    return {
        "starts": starts,
        "platforms": platforms,
        "contains_pose": k,
        "rate": k / max(platforms, 1),
        "rate_lower_95": lower_bound(k, platforms) if platforms else None,
        "modes_per_platform": [r["modes"] for r in rows],
        "wall_s_median": float(np.median([r["wall_s"] for r in rows])) if rows else None,
        "cpu_s_median": float(np.median([r["cpu_s"] for r in rows])) if rows else None,
        "rows": rows,
    }


def certificates(boxes: int, starts: int) -> list[dict]:
    cases = [
        ("Freudenstein four-bar, crank 70 deg", four_bar(), np.array([math.radians(70)]), None),
        ("five-bar (problems/mechanisms/five_bar.yaml), home + 0.1 rad", file_model("five_bar"), 0.1, None),
        ("3-RRR (problems/mechanisms/rrr3.yaml), home", file_model("rrr3"), 0.0, None),
        ("Dietmaier 6-6 platform", dietmaier.model(), dietmaier.LENGTHS, boxes),
    ]
    rows = []
    for name, model, q, budget in cases:
        q = model.q_home + q if np.ndim(q) == 0 else q
        found = assembly.assembly_modes(model, q, starts=starts)
        kwargs = {} if budget is None else {"max_boxes": budget}
        cert, wall, cpu = timed(certify_modes, model, found, **kwargs)
        rows.append({"case": name, "modes": found.count, **cert.as_dict(), "wall_s": wall, "cpu_s": cpu})
        rows[-1]["load_avg_1min"] = os.getloadavg()[0]
        print(json.dumps(rows[-1]), flush=True)
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=100, help="searches of Dietmaier's platform, one seed each")
    ap.add_argument("--platforms", type=int, default=40, help="random 6-6 platforms of the round trip")
    ap.add_argument("--reference", type=int, default=100_000, help="starts of the basin estimate (0: none)")
    ap.add_argument("--starts", type=int, default=None, help="starts per search (default: the search's default)")
    ap.add_argument("--before", action="store_true", help="also the search as it was (2000 starts, plain Newton)")
    ap.add_argument("--certify-boxes", type=int, default=200_000, help="sub-box budget of the 6-6 certificate")
    ap.add_argument("--json", type=Path, default=Path(__file__).with_suffix(".json"))
    args = ap.parse_args(argv)
    starts = args.starts or default_starts()
    model = dietmaier.model()
    out = {
        "case": "assembly-mode search: Dietmaier's 40 modes, random 6-6 round trip",
        "defaults": {"starts": starts, "damped_steps": assembly.DAMPED_STEPS, "step_limit": assembly.STEP_LIMIT},
        "cpu_count": os.cpu_count(),
        "load_avg_start": os.getloadavg(),
    }
    out["certificate"] = certificates(args.certify_boxes, starts)
    out["dietmaier"] = dietmaier_rate(model, args.seeds, starts)
    if args.reference:
        grid = sorted({2000, 4000, 8000, 10000, 12000, 16000, 20000, starts})
        out["dietmaier_basins"] = basin_estimate(model, args.reference, grid)
    out["random_66"] = round_trip(args.platforms, starts)
    if args.before:
        steps = assembly.DAMPED_STEPS
        assembly.DAMPED_STEPS = BEFORE["damped_steps"]
        try:
            out["before"] = {
                **BEFORE,
                "dietmaier": dietmaier_rate(model, args.seeds, BEFORE["starts"]),
                "random_66": round_trip(args.platforms, BEFORE["starts"]),
            }
        finally:
            assembly.DAMPED_STEPS = steps
    out["load_avg_end"] = os.getloadavg()
    summary = {k: v for k, v in out.items() if k not in ("dietmaier", "random_66", "before", "certificate")}
    for part in ("dietmaier", "random_66"):
        summary[part] = {k: v for k, v in out[part].items() if k != "rows"}
    if "before" in out:
        summary["before"] = {
            part: {k: v for k, v in out["before"][part].items() if k != "rows"} for part in ("dietmaier", "random_66")
        }
    print(json.dumps(summary, indent=2))
    args.json.write_text(json.dumps(out, indent=2) + "\n", encoding="utf-8")
    print(f"written: {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
