"""Issue 23, items 3 and 4: the batch FK at the arithmetic limit, and the embedding FK's call.

    python benchmarks/bench_batch_speed.py [--quick] [-o benchmarks/bench_batch_speed.json]

Everything is CPU time (``time.process_time``: every thread of the process), so a shared
machine slows the figures less than wall time would; each figure has the 1-minute load
average (``os.getloadavg()``) beside it, and the comparisons are ratios taken in this run,
the two sides interleaved (best of ``--rounds`` rounds).

Measurements
  kernel_*            the 3-PRS FK kernel's C alone (its loop over poses, 1 thread): the whole
                      kernel for every pose (the loop before the first pass) with the flags before
                      issue 23 (-O3) and with today's ``compiled.CFLAGS``, and today's library
                      (the first pass: the reduced Newton alone where it settles, its work on the
                      shared numbers and the guess once per call, the limits built in where the
                      model has none); each checked equal to CasADi's virtual machine to the bit
  batch_cpu_*         cn.batch_forward_kinematics(backend="compiled") on 1 and 2 threads: CPU µs
                      per pose, every check of every pose included (target <= 1 µs: 2 M poses/s
                      on 2 cores); poses/s of wall time beside it
  fixed_cost          CPU µs of a one-pose batch call (the cost of a call besides its poses)
  fivebar_*           the share of five-bar poses (uniform +-0.25 rad about home, seed 0) that
                      the 3-step reduced Newton does not settle (what fell back to the full
                      Newton before the adaptive steps) and that the FK's full path answers now
                      (target < 5 %); CPU µs per pose of the reduced-only and full-only kernels
  fivebar closed form the five-bar's FK kernel before the closed-form dyad (the Newton FK: reduced,
                      then full) and now (closed form first, every check, Newton where it does
                      not settle), the closed-form kernel alone (with every check) and the
                      circle-circle intersection alone (no check), CPU µs per pose of the
                      compiled C (1 thread), interleaved; the share the closed form answers; and
                      the whole batch call per pose (target <= 0.1 µs, item 5)
  jansen_*            Jansen's leg (problems/mechanisms/jansen.yaml) over a full turn: its FK kernel
                      now (three closed-form dyads first, every check, Newton where they do not
                      settle) against the Newton FK alone on the same poses from a guess near each
                      (so that Newton converges), CPU µs per pose of the compiled C (1 thread),
                      interleaved; and the whole batch call per pose
  single_fk_function  one call of cn.functions(model).fk on numpy arrays (target <= 10 µs), and
                      on DMs (CasADi's own call, the path every call took before)
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

import casadi as ca
import numpy as np

import cpm_nlp as cn
from cpm_nlp.core.batch import evaluate
from cpm_nlp.core.compiled import (
    CFLAGS,
    NativeLoop,
    batch_loop_source,
    build_library,
    compiled_function,
    compiler_available,
    generate_source,
    native_loop,
)
from cpm_nlp.core.kernels import (
    PATHS,
    Kernel,
    _newton_fk_kernel,
    closed_fk_kernel,
    fk_kernel,
    full_fk_kernel,
    reduced_fk_kernel,
    shared_values,
)

PAPER = {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"}
STROKE = 2.3e-3  # m, the actuator range of prs3-ruiz.md Fig. 6
#: the flags of the compiled path before issue 23 (for the ratio in this run)
CFLAGS_BEFORE = ("-O3", "-fPIC", "-shared")
NEWTON = cn.SolverConfig("newton")


def load() -> float:
    return round(os.getloadavg()[0], 2)


def cpu_per_item(fn, n_items: int, rounds: int) -> float:
    """Best CPU µs per item over ``rounds`` calls of ``fn``."""
    best = float("inf")
    for _ in range(rounds):
        t0 = time.process_time()
        fn()
        best = min(best, (time.process_time() - t0) / n_items * 1e6)
    return best


def median_cpu_call(fn, n: int) -> float:
    """Median CPU µs of one call, over ``n`` blocks of 20 calls."""
    fn()
    times = []
    for _ in range(n):
        t0 = time.process_time()
        for _ in range(20):
            fn()
        times.append((time.process_time() - t0) / 20 * 1e6)
    return statistics.median(times)


def whole_loop(c, kern: Kernel, flags: tuple[str, ...] = CFLAGS) -> NativeLoop:
    """The kernel's library as before the first pass: the whole kernel for every pose."""
    src = generate_source(kern.function, kern.name) + batch_loop_source(kern.function, kern.name)
    return NativeLoop(build_library(src, kern.name, flags), kern.name, compiled_function(c, kern))


def same_bits(a: list[np.ndarray], b: list[np.ndarray]) -> bool:
    return all(np.array_equal(x.view(np.int64), y.view(np.int64)) for x, y in zip(a, b))


def bench_kernel(model: cn.Model, n: int, rounds: int) -> dict:
    c = model.closure
    kern = fk_kernel(c, NEWTON)
    q = np.random.default_rng(0).uniform(-STROKE, STROKE, (n, 3))
    args = [q, model.x_home, *shared_values(kern, model, NEWTON.tolerance)]
    reference = evaluate(kern.function, args, 1)
    loops = {
        "before": whole_loop(c, kern, CFLAGS_BEFORE),
        "whole": whole_loop(c, kern),
        "now": native_loop(c, kern),
    }
    out: dict = {"poses": n, "flags_before": " ".join(CFLAGS_BEFORE), "flags_now": " ".join(CFLAGS)}
    for tag, loop in loops.items():
        got = evaluate(loop, args, 1)
        out[f"kernel_{tag}_same_bits_as_vm"] = same_bits(reference, got)
    times: dict[str, list[float]] = {tag: [] for tag in loops}
    for _ in range(rounds):  # interleaved: both see the same load
        for tag, loop in loops.items():
            times[tag].append(cpu_per_item(lambda loop=loop: evaluate(loop, args, 1), n, 1))
    for tag in loops:
        out[f"kernel_{tag}_us_per_pose"] = min(times[tag])
    out["kernel_ratio_whole_vs_before"] = out["kernel_whole_us_per_pose"] / out["kernel_before_us_per_pose"]
    out["kernel_ratio_now_vs_whole"] = out["kernel_now_us_per_pose"] / out["kernel_whole_us_per_pose"]
    out["kernel_load"] = load()
    return out


def bench_batch(model: cn.Model, n: int, rounds: int) -> dict:
    q = np.random.default_rng(1).uniform(-STROKE, STROKE, (n, 3))
    out: dict = {"poses": n}
    res = cn.batch_forward_kinematics(model, q, backend="compiled")
    out["statuses"] = res.counts()
    out["reduced_share"] = float(np.mean(res.path_codes == 0))
    for threads in (1, 2):
        best_cpu, best_wall = float("inf"), 0.0
        for _ in range(rounds):
            t0, w0 = time.process_time(), time.perf_counter()
            cn.batch_forward_kinematics(model, q, backend="compiled", threads=threads)
            best_cpu = min(best_cpu, (time.process_time() - t0) / n * 1e6)
            best_wall = max(best_wall, n / (time.perf_counter() - w0))
        out[f"batch_cpu_us_per_pose_{threads}_thread"] = best_cpu
        out[f"batch_poses_per_s_{threads}_thread"] = best_wall
        out[f"batch_load_{threads}_thread"] = load()
    one = q[:1]
    out["fixed_cost_us"] = median_cpu_call(
        lambda: cn.batch_forward_kinematics(model, one, backend="compiled", threads=1), 100
    )
    out["fixed_cost_load"] = load()
    return out


def bench_fivebar(n: int, rounds: int) -> dict:
    model = cn.build_model("five_bar")
    c = model.closure
    q = model.q_home + np.random.default_rng(0).uniform(-0.25, 0.25, (n, c.nq))
    out: dict = {"poses": n, "spread_rad": 0.25, "seed": 0}
    reduced = reduced_fk_kernel(c, NEWTON)
    r_out = dict(
        zip(reduced.outputs, evaluate(reduced.function, [q, model.x_home, *shared_values(reduced, model, 1e-10)]))
    )
    out["fallback_share_3_steps"] = float(np.mean(r_out["status"].ravel() != 0))
    backend = "compiled" if compiler_available() else "map"
    res = cn.batch_forward_kinematics(model, q, backend=backend)
    out["fallback_share_now"] = float(np.mean(res.path_codes == 1))
    out["closed_share"] = float(np.mean(res.path_codes == PATHS.index("closed")))
    out["statuses"] = res.counts()
    out["backend"] = backend
    if backend == "compiled":
        full = full_fk_kernel(c, NEWTON)
        kernels = {
            "reduced_3_steps": reduced,
            "full": full,
            "newton_before_closed": _newton_fk_kernel(c, NEWTON, "five_bar_fk_newton_paths"),
            "fk": fk_kernel(c, NEWTON),
            "closed_only": closed_fk_kernel(c, NEWTON),
        }
        calls = {}
        for tag, kern in kernels.items():
            # the Newton FK's own loop as before (its reduced Newton would run as a first pass too)
            fn = whole_loop(c, kern) if tag == "newton_before_closed" else native_loop(c, kern)
            args = [q, model.x_home, *shared_values(kern, model, NEWTON.tolerance)]
            out[f"kernel_{tag}_same_bits_as_vm"] = same_bits(evaluate(kern.function, args, 1), evaluate(fn, args, 1))
            calls[tag] = lambda fn=fn, args=args: evaluate(fn, args, 1)
        whole = whole_loop(c, kernels["fk"])
        args = [q, model.x_home, *shared_values(kernels["fk"], model, NEWTON.tolerance)]
        calls["fk_whole"] = lambda: evaluate(whole, args, 1)
        # the circle-circle intersection alone (this model's numbers built in, no checks): what
        # pylinkage's dyad computes
        q_sym = ca.SX.sym("q", c.nq)
        closed = list(c.fk_closed(q_sym, model.x_home, model.p))[:2]
        bare = ca.Function("five_bar_fk_closed_bare", [q_sym], closed, ["q"], ["x", "disc"])
        source = generate_source(bare, bare.name()) + batch_loop_source(bare, bare.name())
        bare_loop = NativeLoop(build_library(source, bare.name()), bare.name(), bare)
        calls["closed_form_alone"] = lambda: evaluate(bare_loop, [q], 1)
        best = dict.fromkeys(calls, float("inf"))
        for _ in range(rounds):  # interleaved: every kernel sees the same load
            for tag, call in calls.items():
                best[tag] = min(best[tag], cpu_per_item(call, n, 1))
        for tag, value in best.items():
            out[f"kernel_{tag}_us_per_pose"] = value
        out["closed_speedup_vs_newton"] = best["newton_before_closed"] / best["fk"]
        out["fk_ratio_now_vs_whole"] = best["fk"] / best["fk_whole"]
        one_thread = lambda: cn.batch_forward_kinematics(model, q, backend="compiled", threads=1)  # noqa: E731
        one_thread()
        out["fivebar_batch_us_per_pose"] = cpu_per_item(one_thread, n, rounds)
    out["load"] = load()
    return out


def bench_jansen(n: int, rounds: int) -> dict:
    model = cn.build_model("jansen")
    c = model.closure
    q = (np.arange(1, n + 1) * 2 * np.pi / n)[:, None]
    out: dict = {"poses": n, "poses_are": "crank angles over one turn"}
    if not compiler_available():
        return out
    res = cn.batch_forward_kinematics(model, q, backend="compiled", threads=1)
    out["statuses"] = res.counts()
    guess = res.x + np.random.default_rng(0).uniform(-0.01, 0.01, res.x.shape)
    calls = {}
    kernels = {"fk": fk_kernel(c, NEWTON), "newton_alone": _newton_fk_kernel(c, NEWTON, "jansen_fk_nw")}
    for tag, kern in kernels.items():
        fn = native_loop(c, kern)
        x0 = model.x_home if tag == "fk" else guess  # the fk from home, as the batch call (one guess)
        args = [q, x0, *shared_values(kern, model, NEWTON.tolerance)]
        out[f"jansen_kernel_{tag}_same_bits_as_vm"] = same_bits(evaluate(kern.function, args, 1), evaluate(fn, args, 1))
        calls[tag] = lambda fn=fn, args=args: evaluate(fn, args, 1)
    whole = whole_loop(c, kernels["fk"])
    args_whole = [q, model.x_home, *shared_values(kernels["fk"], model, NEWTON.tolerance)]
    calls["fk_whole"] = lambda: evaluate(whole, args_whole, 1)
    best = dict.fromkeys(calls, float("inf"))
    for _ in range(rounds):
        for tag, call in calls.items():
            best[tag] = min(best[tag], cpu_per_item(call, n, 1))
    for tag, value in best.items():
        out[f"jansen_kernel_{tag}_us_per_pose"] = value
    out["jansen_closed_speedup_vs_newton"] = best["newton_alone"] / best["fk"]
    out["jansen_fk_ratio_now_vs_whole"] = best["fk"] / best["fk_whole"]
    one_thread = lambda: cn.batch_forward_kinematics(model, q, backend="compiled", threads=1)  # noqa: E731
    out["jansen_batch_us_per_pose"] = cpu_per_item(one_thread, n, rounds)
    out["load"] = load()
    return out


def bench_single(model: cn.Model, n: int) -> dict:
    q = np.array([1e-3, 0.5e-3, -0.3e-3])
    fns = cn.functions(model)
    qd, xd = ca.DM(q), ca.DM(model.x_home)
    out = {
        "single_fk_function_us": median_cpu_call(lambda: fns.fk(q, model.x_home), n),
        "single_fk_function_named_us": median_cpu_call(lambda: fns.fk(q=q, x0=model.x_home), n),
        "single_fk_function_casadi_dm_us": median_cpu_call(lambda: fns.fk(qd, xd), n),
        "backend": fns.fk.backend_used,
    }
    out["load"] = load()
    return out


TARGETS = {
    "batch_cpu_us_per_pose_2_thread": ("<=", 1.0),
    "fallback_share_now": ("<", 0.05),
    "kernel_now_us_per_pose": ("<=", 1.0),
    "kernel_fk_us_per_pose": ("<=", 0.1),
    "kernel_closed_form_alone_us_per_pose": ("<=", 0.1),
    "fivebar_batch_us_per_pose": ("<=", 0.1),
    "single_fk_function_us": ("<=", 10.0),
}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="small sizes (a smoke run, not a measurement)")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("-o", "--output", default=str(Path(__file__).with_suffix(".json")))
    args = parser.parse_args(argv)
    n_kernel, n_batch, n_five, n_single = (2000, 2000, 2000, 20) if args.quick else (100_000, 200_000, 20_000, 300)
    model = cn.build_model("prs3", PAPER)
    results: dict = {
        "machine": {
            "cpus": os.cpu_count(),
            "platform": platform.platform(),
            "python": platform.python_version(),
            "casadi": ca.__version__,
            "quick": args.quick,
        },
    }
    if compiler_available():
        results["kernel"] = bench_kernel(model, n_kernel, args.rounds)
        results["batch"] = bench_batch(model, n_batch, args.rounds)
    results["fivebar"] = bench_fivebar(n_five, args.rounds)
    results["jansen"] = bench_jansen(360 if args.quick else 36_000, args.rounds)
    results["single"] = bench_single(model, n_single)
    flat = {k: v for part in results.values() for k, v in part.items()}
    results["targets"] = {
        name: {
            "target": f"{kind} {value}",
            "value": flat[name],
            "met": flat[name] <= value if kind == "<=" else flat[name] < value,
        }
        for name, (kind, value) in TARGETS.items()
        if name in flat
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
