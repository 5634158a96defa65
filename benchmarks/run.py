"""Speed benchmarks of cpm_nlp (issue 6), measured in one run on this machine.

    python benchmarks/run.py [--quick] [--skip NAMES] [-o benchmarks/results.json]

prints a table and writes JSON.  Every speed is compared with a baseline
measured in the same run (ratios), and with the issue's target where there is
one.  Rates are the best of ``--repeats`` runs (the machine is shared; the best
run is the least disturbed), times of single calls the median of many.

Measurements
  batch_fk_compiled   3-PRS batch FK, compiled kernel, all threads (poses/s): Newton on the
                      task coordinates through the closed-form IK, full Newton as fallback
  batch_fk_full_compiled  the same poses through the full Newton on Φ alone (the formulation
                      before issue 15), for the ratio reduced / full
  batch_fk_1000_1_thread, batch_fk_1000_2_threads  1,000-pose batches (fixed cost per call)
  batch_fk_simd       the reduced kernel as structure-of-arrays C over poses (SIMD experiment)
  batch_fk_map        3-PRS batch FK, CasADi VM through map, all threads
  batch_fk_casadi_thread_map  the kernel through CasADi's own map(n, "thread") (for the record)
  batch_ik_map, batch_ik_casadi_thread_map  closed-form IK (an SX kernel), both ways of threading
  fsolve_casadi       scipy.optimize.fsolve loop on the same equations, Φ and Φ_x as
                      ordinary CasADi Function calls (what a script would write)
  fsolve_buffer       the same loop, Φ and Φ_x through CasADi FunctionBuffers (the
                      fastest way to evaluate them from Python)
  single_fk_newton    one cn.forward_kinematics(model, q, newton) call (µs, median)
  single_fk_ipopt     one cn.forward_kinematics(model, q) call (IPOPT)
  single_fk_function  one call of cn.functions(model).fk on numpy arrays (the embedding
                      Function's direct call into the compiled kernel, issue 23)
  single_fk_function_casadi  the same call on DMs (CasADi's own call, as every call was before)
  casadi_trivial_call one call of a CasADi Function y = x from Python (the floor of the above)
  reproduce           `cpm-nlp reproduce`, end to end in a fresh process (s)
  memory_1m           batch FK of 1,000,000 poses in a fresh process: peak RSS (MB)
  cases               problem files listed in benchmarks/cases.yaml (median s)

The batch rates include every check of every pose (residual, branch, IK round
trip, conditioning, limits, passive joints); the fsolve loops only solve.
The machine's load (os.getloadavg(), 1 minute) is recorded beside every
figure (``load``).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

import casadi as ca
import numpy as np
import scipy
import yaml
from scipy.optimize import fsolve

import cpm_nlp as cn
from cpm_nlp.core.batch import default_threads, evaluate
from cpm_nlp.core.compiled import compiled_function, compiler_available
from cpm_nlp.core.fast_calls import FastFunction
from cpm_nlp.core.kernels import fk_kernel, full_fk_kernel, ik_kernel, shared_values

ROOT = Path(__file__).resolve().parent.parent
PAPER = {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"}
STROKE = 2.3e-3  # m, the actuator range of prs3-ruiz.md Fig. 6

#: targets of issues 6 and 15: name -> (kind, value); kind "min" (at least) or "max" (at most)
TARGETS = {
    "batch_fk_compiled": ("min", 2_000_000.0),
    "ratio_compiled_vs_fsolve_casadi": ("min", 250.0),
    "ratio_compiled_vs_fsolve_buffer": ("min", 250.0),
    "single_fk_newton": ("max", 15.0),
    "single_fk_function": ("max", 10.0),
    "ratio_2_vs_1_threads_at_1000": ("min", 1.0),
    "reproduce": ("max", 60.0),
    "memory_1m": ("max", 1024.0),
}

#: os.getloadavg()[0] when each figure was measured (filled as the run goes)
LOAD: dict[str, float] = {}


def noted(out: dict, name: str, value) -> None:
    """Store a figure and the machine's load beside it."""
    out[name] = value
    LOAD[name] = os.getloadavg()[0]


def actuators(n: int, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-STROKE, STROKE, (n, 3))


def best_rate(fn, n: int, repeats: int) -> float:
    rates = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        rates.append(n / (time.perf_counter() - t0))
    return max(rates)


def median_call(fn, n: int) -> float:
    fn()
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def fsolve_loop(model: cn.Model, q: np.ndarray, buffered: bool) -> np.ndarray:
    c, p = model.closure, model.p
    if buffered:
        phi, phi_x = FastFunction(c.phi), FastFunction(c.phi_x)

        def f(x, qi):
            return phi(x, qi, p)[0]

        def jac(x, qi):
            return phi_x(x, qi, p)[0].reshape(c.nx, c.nx).T

    else:

        def f(x, qi):
            return np.asarray(c.phi(x, qi, p)).ravel()

        def jac(x, qi):
            return np.asarray(c.phi_x(x, qi, p))

    return np.array([fsolve(f, model.x_home, args=(qi,), fprime=jac, xtol=1e-13) for qi in q])


def casadi_thread_map_rate(kern, model: cn.Model, per_pose: list[np.ndarray], repeats: int) -> float:
    """Poses/s of ``kern.function.map(n, "thread", threads)`` (one FunctionBuffer, no Python threads)."""
    n = per_pose[0].shape[0]
    tmap = kern.function.map(n, "thread", default_threads())
    args = [np.broadcast_to(a, (n, np.size(a) if a.ndim == 1 else a.shape[1])) for a in per_pose]
    args += [np.broadcast_to(v, (n, v.size)) for v in shared_values(kern, model, 1e-10)]
    args = [np.ascontiguousarray(a) for a in args]
    outs = [np.empty(tmap.nnz_out(k)) for k in range(tmap.n_out())]
    buf, call = tmap.buffer()
    for k, a in enumerate(args):
        buf.set_arg(k, memoryview(a.reshape(-1)))
    for k, a in enumerate(outs):
        buf.set_res(k, memoryview(a))
    return best_rate(call, n, repeats)


def bench_batch(model: cn.Model, quick: bool, repeats: int) -> dict:
    out: dict = {"threads": default_threads()}
    n_c, n_m, n_f = (20_000, 5_000, 200) if quick else (400_000, 100_000, 2_000)
    if compiler_available():
        q = actuators(n_c)
        t0 = time.perf_counter()
        cn.batch_forward_kinematics(model, q[:10], backend="compiled")
        out["compile_or_load_seconds"] = time.perf_counter() - t0
        res = cn.batch_forward_kinematics(model, q, backend="compiled")
        out["compiled_statuses"] = res.counts()
        out["compiled_reduced_share"] = float(np.mean(res.path_codes == 0))
        noted(
            out,
            "batch_fk_compiled",
            best_rate(lambda: cn.batch_forward_kinematics(model, q, backend="compiled"), n_c, repeats),
        )
        noted(
            out,
            "batch_fk_compiled_1_thread",
            best_rate(
                lambda: cn.batch_forward_kinematics(model, q[: n_c // 4], backend="compiled", threads=1),
                n_c // 4,
                repeats,
            ),
        )
        # the full Newton on Φ alone (the formulation before issue 15), same poses, same run
        full = full_fk_kernel(model.closure, cn.SolverConfig("newton"))
        fn = compiled_function(model.closure, full)
        args = [q, model.x_home, *shared_values(full, model, 1e-10)]
        noted(out, "batch_fk_full_compiled", best_rate(lambda: evaluate(fn, args), n_c, repeats))
        noted(out, "ratio_reduced_vs_full", out["batch_fk_compiled"] / out["batch_fk_full_compiled"])
        # fixed cost per call: 1,000 poses on 1 and on 2 threads (persistent pool)
        q1k = q[:1000]
        for threads in (1, 2):
            noted(
                out,
                f"batch_fk_1000_{threads}_thread{'s' if threads > 1 else ''}",
                best_rate(
                    lambda threads=threads: cn.batch_forward_kinematics(
                        model, q1k, backend="compiled", threads=threads
                    ),
                    1000,
                    20 * repeats,
                ),
            )
        noted(out, "ratio_2_vs_1_threads_at_1000", out["batch_fk_1000_2_threads"] / out["batch_fk_1000_1_thread"])
    else:
        out["note_compiled"] = "no C compiler on this machine: compiled path not measured"
    q = actuators(n_m, 1)
    noted(out, "batch_fk_map", best_rate(lambda: cn.batch_forward_kinematics(model, q, backend="map"), n_m, repeats))
    noted(
        out,
        "batch_fk_map_1_thread",
        best_rate(
            lambda: cn.batch_forward_kinematics(model, q[: n_m // 4], backend="map", threads=1), n_m // 4, repeats
        ),
    )
    # CasADi's own threaded map of the same kernel (why cpm_nlp threads over chunks itself)
    n_t = n_m // 4
    kern = fk_kernel(model.closure, cn.SolverConfig("newton"))
    noted(out, "batch_fk_casadi_thread_map", casadi_thread_map_rate(kern, model, [q[:n_t], model.x_home], repeats))
    # closed-form IK (an SX kernel) on the map path, both ways of threading
    t = np.column_stack([model.derived["pz0"] + q[:, 0], q[:, 1], q[:, 2]])
    noted(out, "batch_ik_map", best_rate(lambda: cn.batch_inverse_kinematics(model, t, backend="map"), n_m, repeats))
    noted(
        out,
        "batch_ik_casadi_thread_map",
        casadi_thread_map_rate(ik_kernel(model.closure), model, [t[:n_t]], repeats),
    )
    qf = actuators(n_f, 2)
    noted(out, "fsolve_buffer", best_rate(lambda: fsolve_loop(model, qf, True), n_f, 1))
    noted(out, "fsolve_casadi", best_rate(lambda: fsolve_loop(model, qf[: n_f // 2], False), n_f // 2, 1))
    # the baseline solves the same equations: its poses agree with the batch's
    batch = cn.batch_forward_kinematics(model, qf[:200])
    x_fs = fsolve_loop(model, qf[:200], True)
    out["fsolve_vs_batch_max_abs_difference"] = float(np.max(np.abs(x_fs[batch.ok] - batch.x[batch.ok])))
    for base in ("fsolve_casadi", "fsolve_buffer"):
        if "batch_fk_compiled" in out:
            noted(out, f"ratio_compiled_vs_{base}", out["batch_fk_compiled"] / out[base])
        noted(out, f"ratio_map_vs_{base}", out["batch_fk_map"] / out[base])
    return out


def bench_single(model: cn.Model, quick: bool) -> dict:
    q = np.array([1e-3, 0.5e-3, -0.3e-3])
    newton = cn.SolverConfig("newton")
    fns = cn.functions(model)
    n = 200 if quick else 3000
    y = ca.SX.sym("y")
    trivial = ca.Function("trivial", [y], [y], ["y"], ["z"])
    out: dict = {}
    noted(out, "single_fk_newton", 1e6 * median_call(lambda: cn.forward_kinematics(model, q, newton), n))
    out["single_fk_newton_path"] = cn.forward_kinematics(model, q, newton).path
    noted(out, "single_fk_ipopt", 1e6 * median_call(lambda: cn.forward_kinematics(model, q), max(50, n // 10)))
    noted(out, "single_fk_function", 1e6 * median_call(lambda: fns.fk(q, model.x_home), n))
    qd, xd = ca.DM(q), ca.DM(model.x_home)
    noted(out, "single_fk_function_casadi", 1e6 * median_call(lambda: fns.fk(qd, xd), n))
    noted(out, "casadi_trivial_call", 1e6 * median_call(lambda: trivial(1.0), n))
    return out


def bench_reproduce(repeats: int) -> dict:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        run = subprocess.run(
            [sys.executable, "-m", "cpm_nlp.cli.main", "reproduce"],
            cwd=ROOT,
            capture_output=True,
            text=True,
            check=False,
        )
        times.append(time.perf_counter() - t0)
    LOAD["reproduce"] = os.getloadavg()[0]
    return {"reproduce": statistics.median(times), "reproduce_exit": run.returncode}


MEMORY_SCRIPT = """
import json, resource, time, numpy as np, cpm_nlp as cn
model = cn.build_model("prs3", {params!r})
q = np.random.default_rng(3).uniform(-{stroke}, {stroke}, ({n}, 3))
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
t0 = time.perf_counter()
res = cn.batch_forward_kinematics(model, q, backend={backend!r})
seconds = time.perf_counter() - t0
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps({{"peak_mb": peak / 1024, "before_mb": before / 1024, "seconds": seconds,
                   "solved": int(res.ok.sum()), "n": len(res)}}))
"""


def bench_memory(quick: bool) -> dict:
    n = 20_000 if quick else 1_000_000
    backend = "compiled" if compiler_available() else "map"
    script = MEMORY_SCRIPT.format(params=PAPER, stroke=STROKE, n=n, backend=backend)
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    data = json.loads(run.stdout)
    LOAD["memory_1m"] = os.getloadavg()[0]
    return {
        "memory_1m": data["peak_mb"],
        "memory_1m_before_mb": data["before_mb"],
        "memory_1m_seconds": data["seconds"],
        "memory_1m_poses": data["n"],
        "memory_1m_backend": backend,
    }


def bench_cases(quick: bool) -> list[dict]:
    spec = yaml.safe_load((Path(__file__).parent / "cases.yaml").read_text())
    out = []
    for case in spec["cases"]:
        path = ROOT / case["file"]
        entry = {"name": case["name"], "file": case["file"], "target_seconds": case.get("target_seconds")}
        if not path.exists():
            entry["note"] = f"skipped: {case['file']} is not in this checkout (yet)"
            out.append(entry)
            continue
        problem = cn.load_problem(path, case.get("set", []))
        t0 = time.perf_counter()
        result = cn.solve(problem)
        if quick:  # a smoke run: the one solve's time (with its first-call costs), no median
            entry["seconds"] = time.perf_counter() - t0
        else:
            entry["seconds"] = median_call(lambda problem=problem: cn.solve(problem), int(case.get("repeats", 5)))
        entry["load"] = os.getloadavg()[0]
        entry["status"] = result.status.value
        out.append(entry)
    return out


def verdict(name: str, value: float) -> str:
    if name not in TARGETS:
        return ""
    kind, target = TARGETS[name]
    if kind == "min":
        return "met" if value >= target else f"MISSED by {100 * (1 - value / target):.0f} % (x{target / value:.2f})"
    return "met" if value <= target else f"MISSED by {100 * (value / target - 1):.0f} %"


UNITS = {
    "batch_fk_compiled": "poses/s",
    "batch_fk_compiled_1_thread": "poses/s",
    "batch_fk_full_compiled": "poses/s",
    "batch_fk_1000_1_thread": "poses/s",
    "batch_fk_1000_2_threads": "poses/s",
    "batch_fk_simd": "poses/s",
    "batch_fk_simd_1_thread": "poses/s",
    "casadi_trivial_call": "µs",
    "batch_fk_map": "poses/s",
    "batch_fk_casadi_thread_map": "poses/s",
    "batch_fk_map_1_thread": "poses/s",
    "batch_ik_map": "poses/s",
    "batch_ik_casadi_thread_map": "poses/s",
    "fsolve_casadi": "poses/s",
    "fsolve_buffer": "poses/s",
    "single_fk_newton": "µs",
    "single_fk_ipopt": "µs",
    "single_fk_function": "µs",
    "single_fk_function_casadi": "µs",
    "reproduce": "s",
    "memory_1m": "MB peak RSS",
    "memory_1m_seconds": "s",
}


def table(results: dict) -> str:
    rows = [("measurement", "value", "unit", "target", "verdict", "load")]
    flat = {**results["batch"], **results["single"], **results["reproduce"], **results["memory"]}
    for name, value in flat.items():
        skipped = name == "threads" or name.endswith(("_exit", "_mb", "_poses", "difference"))
        if not isinstance(value, (int, float)) or skipped:
            continue
        unit = UNITS.get(name, "x" if name.startswith("ratio") else "")
        target = ""
        if name in TARGETS:
            kind, t = TARGETS[name]
            target = (">= " if kind == "min" else "<= ") + f"{t:,.0f}"
        text = f"{value:,.0f}" if value >= 1e4 else f"{value:,.1f}" if value >= 10 else f"{value:.3g}"
        load = results.get("load", {}).get(name)
        rows.append((name, text, unit, target, verdict(name, value), "" if load is None else f"{load:.2f}"))
    for case in results["cases"]:
        target = f"<= {case['target_seconds']} s" if case.get("target_seconds") else ""
        if "seconds" in case:
            v = case["seconds"]
            ok = "" if not case.get("target_seconds") else ("met" if v <= case["target_seconds"] else "MISSED")
            load = f"{case['load']:.2f}" if "load" in case else ""
            rows.append(
                (f"case: {case['name']}", f"{v * 1e3:,.2f}", "ms", target, f"{case['status']} {ok}".strip(), load)
            )
        else:
            rows.append((f"case: {case['name']}", "-", "", target, case["note"], ""))
    widths = [max(len(r[i]) for r in rows) for i in range(6)]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="small sizes (a smoke run, not a measurement)")
    parser.add_argument("--repeats", type=int, default=3, help="runs per rate (the best is kept)")
    parser.add_argument("--skip", default="", help="comma-separated: batch, single, reproduce, memory, cases")
    parser.add_argument("-o", "--output", default=str(Path(__file__).parent / "results.json"))
    args = parser.parse_args(argv)
    skip = {s.strip() for s in args.skip.split(",") if s.strip()}
    model = cn.build_model("prs3", PAPER)
    results: dict = {
        "machine": {
            "cpus": os.cpu_count(),
            "threads_used": default_threads(),
            "platform": platform.platform(),
            "python": platform.python_version(),
            "casadi": ca.__version__,
            "numpy": np.__version__,
            "scipy": scipy.__version__,
            "quick": args.quick,
        },
        "batch": {} if "batch" in skip else bench_batch(model, args.quick, args.repeats),
        "single": {} if "single" in skip else bench_single(model, args.quick),
        "reproduce": {} if "reproduce" in skip else bench_reproduce(1 if args.quick else 3),
        "memory": {} if "memory" in skip else bench_memory(args.quick),
        "cases": [] if "cases" in skip else bench_cases(args.quick),
    }
    flat = {**results["batch"], **results["single"], **results["reproduce"], **results["memory"]}
    results["load"] = dict(LOAD)
    results["targets"] = {
        name: {
            "target": TARGETS[name][1],
            "kind": TARGETS[name][0],
            "value": flat[name],
            "verdict": verdict(name, flat[name]),
            "load": LOAD.get(name),
        }
        for name in TARGETS
        if name in flat
    }
    print(table(results))
    Path(args.output).write_text(json.dumps(results, indent=2) + "\n")
    print(f"\nwritten: {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
