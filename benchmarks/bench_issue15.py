"""Issue 15 benchmarks: the certified cuboid, the pantograph cuboid and start-up time.

    python benchmarks/bench_issue15.py [--quick] [-o benchmarks/issue15.json]
    python benchmarks/bench_issue15.py --startup [-o benchmarks/startup.json]   # start-up only

Every figure is a median of interleaved runs with a baseline measured in the
same run (a ratio), and the machine's load (os.getloadavg(), 1 min) read
before and after it.  Targets (issue 15): certificate of the pantograph
cuboid <= 2 s; pantograph maximal cuboid <= 20 ms.  Start-up (issue 23, CPU
time of the child process, user + sys, from ``getrusage(RUSAGE_CHILDREN)``):
``cpm-nlp solve problems/prs3_forward_kinematics.yaml`` <= 0.25 s;
``cpm-nlp --help`` <= 0.05 s.

Measurements
  certify_pantograph    certify_box on the pantograph cuboid (s), its sub-boxes;
                        baseline: the dense membership check of the same box
                        (check_box, 1663 points), which samples instead of proving
  certify_printed_34c   the paper's box with eq 34c as printed: fails (s)
  certify_prc3          certify_box on the 3-PRC cuboid (s)
  pantograph_cuboid     cn.solve of problems/pantograph_cuboid.yaml without the
                        certificate (s); baseline: the same with the starts solved
                        one by one (the formulation before issue 15)
  help, solve_prs3_fk   ``python -m cpm_nlp ...`` in a fresh process, CPU seconds
                        (median; wall time beside it); baselines in the same run:
                        ``python -c pass`` (the interpreter with its site hooks) and
                        ``python -c "import numpy, casadi, yaml"`` (what a solve
                        cannot avoid loading); also ``plot --help`` (the plot types
                        listed), numpy and CasADi alone, and ``python -I -S -c pass``
                        (the interpreter without site).  The children run with
                        bytecode caching on (PYTHONDONTWRITEBYTECODE removed from
                        their environment, one warm-up run each), as an installed
                        package runs; the solve with the mechanism file's closure
                        kept in the cache directory by the warm-up run
                        (`cpm_nlp.mechanisms.described.stored`), and
                        ``solve_prs3_fk_cold`` with an emptied cache directory
                        before each run (the first solve after an install or an
                        edit of the file).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import cpm_nlp as cn
from cpm_nlp.analysis import cuboid_ik
from cpm_nlp.analysis import workspace as W
from cpm_nlp.analysis.certify import certify_box
from cpm_nlp.mechanisms.pantograph.analysis import paper_cuboid

ROOT = Path(__file__).resolve().parent.parent
TARGETS = {
    "certify_pantograph": 2.0,
    "pantograph_cuboid": 0.020,
    "solve_prs3_fk": 0.25,  # CPU s (issue 23)
    "help": 0.05,  # CPU s (issue 23)
}


def load() -> float:
    return round(os.getloadavg()[0], 2)


def interleaved(fns: dict, repeats: int) -> dict:
    """Median seconds of each function, run in turn ``repeats`` times (after one warm-up)."""
    for fn in fns.values():
        fn()
    times: dict = {k: [] for k in fns}
    for _ in range(repeats):
        for k, fn in fns.items():
            t0 = time.perf_counter()
            fn()
            times[k].append(time.perf_counter() - t0)
    return {k: statistics.median(v) for k, v in times.items()}


def figure(name: str, value: float, baseline_name: str, baseline: float, before: float, unit: str = "s") -> dict:
    entry = {
        "value": value,
        "unit": unit,
        "baseline": baseline_name,
        "baseline_value": baseline,
        "ratio_to_baseline": value / baseline if baseline else None,
        "load_before": before,
        "load_after": load(),
    }
    if name in TARGETS:
        target = TARGETS[name]
        entry["target"] = target
        entry["verdict"] = "met" if value <= target else f"MISSED by {100 * (value / target - 1):.0f} %"
    return entry


def bench_certify(repeats: int) -> dict:
    out = {}
    problem = cn.load_problem(ROOT / "problems/pantograph_cuboid.yaml", ["inputs.certify=false"])
    model = problem.model
    res = W.inscribed_cuboid(model, problem.solver, starts=8)
    t0 = time.perf_counter()
    first = certify_box(model, res.lower, res.upper)
    first_call = time.perf_counter() - t0  # builds the interval programs of the mechanism type
    before = load()
    med = interleaved(
        {
            "certify": lambda: certify_box(model, res.lower, res.upper),
            "check": lambda: W.check_box(model, res.lower, res.upper, 17),
        },
        repeats,
    )
    out["certify_pantograph"] = figure(
        "certify_pantograph", med["certify"], "check_box (1663 points)", med["check"], before
    )
    out["certify_pantograph"].update(
        certified=first.certified, boxes=first.boxes, margin=first.margin, binding=first.binding, first_call=first_call
    )
    paper = paper_cuboid(model, "printed")
    lo = [paper["k"], -paper["y_hat"], -paper["z_hat"]]
    hi = [paper["x_hat"], paper["y_hat"], paper["z_hat"]]
    before = load()
    med = interleaved(
        {"certify": lambda: certify_box(model, lo, hi), "check": lambda: W.check_box(model, lo, hi, 17)}, repeats
    )
    cert = certify_box(model, lo, hi)
    out["certify_printed_34c"] = figure("certify_printed_34c", med["certify"], "check_box", med["check"], before)
    out["certify_printed_34c"].update(
        certified=cert.certified, boxes=cert.boxes, failing_quantity=cert.failing_quantity,
        failing_region=cert.region(model.closure.task),
    )  # fmt: skip
    prc = cn.load_problem(ROOT / "problems/prc3_cuboid.yaml", ["inputs.certify=false"])
    r3 = W.inscribed_cuboid(prc.model, prc.solver, starts=4)
    before = load()
    med = interleaved(
        {
            "certify": lambda: certify_box(prc.model, r3.lower, r3.upper),
            "check": lambda: W.check_box(prc.model, r3.lower, r3.upper, 17),
        },
        repeats,
    )
    c3 = certify_box(prc.model, r3.lower, r3.upper)
    out["certify_prc3"] = figure("certify_prc3", med["certify"], "check_box", med["check"], before)
    out["certify_prc3"].update(certified=c3.certified, boxes=c3.boxes, margin=c3.margin, binding=c3.binding)
    return out


def bench_cuboid(repeats: int) -> dict:
    problem = cn.load_problem(ROOT / "problems/pantograph_cuboid.yaml", ["inputs.certify=false"])
    joint = cuboid_ik.ClosedFormCuboid.start_all

    def run(together: bool):
        cuboid_ik.ClosedFormCuboid.start_all = joint if together else (lambda self, boxes: (None, 0))  # noqa: ARG005 - the signature of start_all
        try:
            return cn.solve(problem)
        finally:
            cuboid_ik.ClosedFormCuboid.start_all = joint

    a, b = run(True), run(False)
    before = load()
    med = interleaved({"together": lambda: run(True), "one_by_one": lambda: run(False)}, repeats)
    entry = figure("pantograph_cuboid", med["together"], "starts one by one", med["one_by_one"], before)
    entry.update(
        volume=a.values["volume"],
        volume_one_by_one=b.values["volume"],
        iterations=a.solver.iterations,
        iterations_one_by_one=b.solver.iterations,
    )
    model = problem.model
    before = load()
    med = interleaved({"inscribed_cuboid": lambda: W.inscribed_cuboid(model, problem.solver, starts=8)}, repeats)
    entry["inscribed_cuboid_only"] = med["inscribed_cuboid"]
    entry["inscribed_cuboid_only_load"] = (before, load())
    return {"pantograph_cuboid": entry}


#: one BLAS thread, as ``cpm-nlp solve`` sets it before numpy loads (core/blas.py)
CAPPED = {"OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "BLIS_NUM_THREADS": "1"}
LIBS = "import numpy, casadi, yaml"

#: start-up commands, in a fresh process each: (argv after the interpreter, environment added)
STARTUP = {
    "python_isolated": (["-I", "-S", "-c", "pass"], {}),
    "python_bare": (["-c", "pass"], {}),
    "python_numpy": (["-c", "import numpy"], {}),
    "python_casadi": (["-c", "import casadi"], {}),
    "python_numpy_casadi_yaml": (["-c", LIBS], {}),
    # what the solve cannot avoid, as the solve loads it: one BLAS thread, no teardown at exit
    "python_numpy_casadi_yaml_capped": (["-c", f"{LIBS}, os; os._exit(0)"], CAPPED),
    "help": (["-m", "cpm_nlp", "--help"], {}),
    "plot_help": (["-m", "cpm_nlp", "plot", "--help"], {}),
    "solve_prs3_fk": (["-m", "cpm_nlp", "solve", "problems/prs3_forward_kinematics.yaml"], {}),
}


def _child(argv: list[str], env: dict) -> tuple[float, float]:
    """(CPU seconds, user + sys, wall seconds) of one run of the interpreter with ``argv``
    (in the checkout named by ``env["PYTHONPATH"]``)."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    cwd = env["PYTHONPATH"].split(os.pathsep)[0]
    subprocess.run([sys.executable, *argv], cwd=cwd, capture_output=True, check=True, env=env)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime, wall


def bench_startup(repeats: int, before_checkout: str | None = None) -> dict:
    """Start-up CPU time of the CLI beside its baselines, interleaved (issue 23);
    ``before_checkout``: another checkout (e.g. ``git archive`` of the commit before a
    change) whose ``--help`` and solve run in the same interleaving (``*_before``)."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "PYTHONPATH")}
    env["PYTHONPATH"] = str(ROOT)
    runs = dict(STARTUP)
    # the same solve with an empty cache directory before each run: the closure generated again
    cold = Path(tempfile.mkdtemp(prefix="cpm_nlp_cold_cache_"))
    runs["solve_prs3_fk_cold"] = (STARTUP["solve_prs3_fk"][0], {"CPM_NLP_CACHE": str(cold)})
    if before_checkout:
        other = {"PYTHONPATH": str(Path(before_checkout).resolve())}
        runs["help_before"] = (STARTUP["help"][0], other)
        runs["solve_prs3_fk_before"] = (STARTUP["solve_prs3_fk"][0], other)
        runs["plot_help_before"] = (STARTUP["plot_help"][0], other)
    for argv, extra in runs.values():  # warm-up: bytecode written, files in the page cache
        _child(argv, {**env, **extra})
    cpu: dict = {k: [] for k in runs}
    wall: dict = {k: [] for k in runs}
    before = load()
    for _ in range(repeats):
        for k, (argv, extra) in runs.items():
            if k == "solve_prs3_fk_cold":
                shutil.rmtree(cold, ignore_errors=True)
            c, w = _child(argv, {**env, **extra})
            cpu[k].append(c)
            wall[k].append(w)
    after = load()
    shutil.rmtree(cold, ignore_errors=True)
    med = {k: statistics.median(v) for k, v in cpu.items()}
    out: dict = {}
    for k in runs:
        out[k] = {
            "cpu": med[k],
            "cpu_min": min(cpu[k]),
            "wall": statistics.median(wall[k]),
            "unit": "s",
            "command": " ".join([*(f"{n}={v}" for n, v in runs[k][1].items()), "python", *runs[k][0]]),
            "load_before": before,
            "load_after": after,
        }
    libs, bare = med["python_numpy_casadi_yaml_capped"], med["python_bare"]
    for name, base, base_name in (
        ("help", bare, "python -c pass"),
        ("solve_prs3_fk", libs, "python -c 'import numpy, casadi, yaml' (one BLAS thread, no teardown)"),
    ):
        entry = out[name]
        target = TARGETS[name]
        over = entry["cpu"] - target
        entry.update(
            value=entry["cpu"],
            baseline=base_name,
            baseline_value=base,
            ratio_to_baseline=entry["cpu"] / base,
            above_baseline=entry["cpu"] - base,
            target=target,
            verdict="met" if over <= 0 else f"MISSED by {over * 1e3:.0f} ms ({100 * over / target:.0f} %)",
            baseline_verdict="the baseline alone is within the target"
            if base <= target
            else f"the baseline alone misses the target by {(base - target) * 1e3:.0f} ms",
        )
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="few repeats (a smoke run, not a measurement)")
    parser.add_argument("--startup", action="store_true", help="only the start-up figures (issue 23)")
    parser.add_argument("--before", metavar="DIR", help="start-up: also run --help and the solve from this checkout")
    parser.add_argument("--repeats", type=int, default=9, help="start-up: interleaved runs of each command (default 9)")
    parser.add_argument("-o", "--output", default=None, help="JSON file (default: issue15.json, startup.json)")
    args = parser.parse_args(argv)
    args.output = args.output or str(Path(__file__).parent / ("startup.json" if args.startup else "issue15.json"))
    n = 2 if args.quick else 11
    results = {
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version()},
        "numpy": np.__version__,
        "quick": args.quick,
        **({} if args.startup else bench_certify(n)),
        **({} if args.startup else bench_cuboid(n)),
        **bench_startup(n if args.quick else args.repeats, args.before),
    }
    for name, e in results.items():
        if isinstance(e, dict) and "cpu" in e:
            line = f"{name:<26} CPU {e['cpu'] * 1e3:8.1f} ms (min {e['cpu_min'] * 1e3:.1f}, wall {e['wall'] * 1e3:.1f})"
            if "target" in e:
                line += f"  target {e['target'] * 1e3:.0f} ms: {e['verdict']}"
                line += f"; {e['above_baseline'] * 1e3:+.1f} ms over {e['baseline']}"
            print(f"{line}  load {e['load_before']} -> {e['load_after']}")
        elif isinstance(e, dict) and "value" in e:
            print(
                f"{name:<22} {e['value'] * 1e3:10.2f} ms  (x{e['ratio_to_baseline']:.2f} of {e['baseline']})  "
                f"target {e.get('target', '-')}: {e.get('verdict', '')}  load {e['load_before']} -> {e['load_after']}"
            )
    Path(args.output).write_text(json.dumps(results, indent=2, default=float) + "\n")
    print(f"written: {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
