"""Issue 23, item 5: spherical dyads in closed form, against Newton, per pose.

    python benchmarks/bench_spherical.py [--quick] [--rounds 5] [-o benchmarks/bench_spherical.json]

The spherical four-bar (problems/mechanisms/spherical_four_bar.yaml: one spherical dyad placed
by the crank) over a whole crank turn, and the spherical five-bar (spherical_five_bar.yaml: one
spherical dyad placed by the two cranks, the tip's coordinates after it) about its home pose.
Everything is CPU time (``time.process_time``), compiled C on 1 thread, the kernels interleaved
(best of ``--rounds``), with the 1-minute load average (``os.getloadavg()``) beside each part;
the comparisons are ratios within this run.

Measurements
  statuses              the batch FK's statuses (the four-bar: every pose by the closed form)
  newton_from_home_*    the FK before the closed form (Newton on Φ from the file's home pose, the
                        batch's default guess): the share of the poses it solves
  kernel_fk             the FK kernel now: the closed form first, every check of a solved pose
                        (residual, IK round trip, conditioning, limits, passive joints), Newton
                        where it does not settle
  kernel_closed_only    the closed-form kernel alone, with every check
  kernel_newton_alone   the Newton FK alone on the same poses, from a guess 0.01 rad from each
                        (so that it converges: the baseline of the ratio)
  kernel_newton_from_home  the same Newton FK from the home pose (the batch's guess before the
                        closed form; on the four-bar it fails on part of the turn, see above)
  kernel_cones_alone    the cone intersection alone (the pose coordinates, no check)
  batch                 the whole batch call (cn.batch_forward_kinematics, compiled, 1 thread)
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import casadi as ca
import numpy as np

import cpm_nlp as cn
from cpm_nlp.core.batch import evaluate
from cpm_nlp.core.compiled import (
    NativeLoop,
    _source,
    batch_loop_source,
    build_library,
    compiled_function,
    compiler_available,
    generate_source,
)
from cpm_nlp.core.kernels import _newton_fk_kernel, closed_fk_kernel, fk_kernel, shared_values

NEWTON = cn.SolverConfig("newton")


def load() -> float:
    return round(os.getloadavg()[0], 2)


def cpu_per_item(fn, n_items: int) -> float:
    """CPU µs per item of one call of ``fn``."""
    t0 = time.process_time()
    fn()
    return (time.process_time() - t0) / n_items * 1e6


def bench_four_bar(n: int, rounds: int) -> dict:
    q = (np.arange(n) * 2 * np.pi / n + 1e-3)[:, None]  # crank angles over one turn
    return bench("spherical_four_bar", q, "crank angles over one turn", rounds)


def bench_five_bar(n: int, rounds: int) -> dict:
    model = cn.build_model("spherical_five_bar")
    q = model.q_home + np.random.default_rng(0).uniform(-0.4, 0.4, (n, 2))
    return bench("spherical_five_bar", q, "both cranks uniform +-0.4 rad about home, seed 0", rounds)


def bench(name: str, q: np.ndarray, what: str, rounds: int) -> dict:
    model = cn.build_model(name)
    c = model.closure
    n = len(q)
    out: dict = {"poses": n, "poses_are": what, "load_start": load()}
    backend = "compiled" if compiler_available() else "map"
    res = cn.batch_forward_kinematics(model, q, backend=backend, threads=1)
    out["statuses"] = res.counts()
    out["backend"] = backend
    newton = _newton_fk_kernel(c, NEWTON, f"{name}_fk_nw")
    home = dict(zip(newton.outputs, evaluate(newton.function, [q, model.x_home, *shared_values(newton, model, 1e-10)])))
    out["newton_from_home_solved_share"] = float(np.mean(home["status"].ravel() == 0))
    if backend != "compiled":
        return out
    guess = res.x + np.random.default_rng(0).uniform(-0.01, 0.01, res.x.shape)
    kernels = {"fk": fk_kernel(c, NEWTON), "closed_only": closed_fk_kernel(c, NEWTON), "newton_alone": newton}
    calls = {}
    for tag, kern in kernels.items():
        fn = NativeLoop(build_library(_source(c, kern), kern.name), kern.name, compiled_function(c, kern))
        x0s = {tag: guess} if tag == "newton_alone" else {tag: np.tile(model.x_home, (n, 1))}
        if tag == "newton_alone":  # also from home, the batch's guess before the closed form
            x0s["newton_from_home"] = np.tile(model.x_home, (n, 1))
        for key, x0 in x0s.items():
            args = [q, x0, *shared_values(kern, model, NEWTON.tolerance)]
            calls[key] = lambda fn=fn, args=args: evaluate(fn, args, 1)
    # the cones' intersection alone (this model's numbers built in, no check)
    q_sym = ca.SX.sym("q", c.nq)
    bare = ca.Function(
        f"{name}_cones", [q_sym], list(c.fk_closed(q_sym, model.x_home, model.p))[:2], ["q"], ["x", "disc"]
    )
    source = generate_source(bare, bare.name()) + batch_loop_source(bare, bare.name())
    bare_loop = NativeLoop(build_library(source, bare.name()), bare.name(), bare)
    calls["cones_alone"] = lambda: evaluate(bare_loop, [q], 1)
    best = dict.fromkeys(calls, float("inf"))
    for _ in range(rounds):  # interleaved: every kernel sees the same load
        for tag, call in calls.items():
            best[tag] = min(best[tag], cpu_per_item(call, n))
    for tag, value in best.items():
        out[f"kernel_{tag}_us_per_pose"] = value
    out["closed_speedup_vs_newton"] = best["newton_alone"] / best["fk"]
    one_thread = lambda: cn.batch_forward_kinematics(model, q, backend="compiled", threads=1)  # noqa: E731
    out["batch_us_per_pose"] = min(cpu_per_item(one_thread, n) for _ in range(rounds))
    out["load_end"] = load()
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="small sizes (a smoke run, not a measurement)")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("-o", "--output", default=str(Path(__file__).with_suffix(".json")))
    args = parser.parse_args(argv)
    results: dict = {
        "machine": {
            "cpus": os.cpu_count(),
            "platform": platform.platform(),
            "python": platform.python_version(),
            "casadi": ca.__version__,
            "quick": args.quick,
        },
        "four_bar": bench_four_bar(360 if args.quick else 36_000, args.rounds),
        "five_bar": bench_five_bar(360 if args.quick else 20_000, args.rounds),
    }
    for part, values in results.items():
        print(f"[{part}]")
        for k, v in values.items():
            print(f"  {k}: {v:.4g}" if isinstance(v, float) else f"  {k}: {v}")
    Path(args.output).write_text(json.dumps(results, indent=2) + "\n")
    print(f"\nwritten: {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
