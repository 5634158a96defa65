"""Issue 15 benchmarks: the certified cuboid, the pantograph cuboid and start-up time.

    python benchmarks/bench_issue15.py [--quick] [-o benchmarks/issue15.json]

Every figure is a median of interleaved runs with a baseline measured in the
same run (a ratio), and the machine's load (os.getloadavg(), 1 min) read
before and after it.  Targets (issue 15): certificate of the pantograph
cuboid <= 2 s; pantograph maximal cuboid <= 20 ms; ``cpm-nlp solve
problems/prs3_forward_kinematics.yaml`` <= 0.3 s; ``cpm-nlp --help`` <= 0.1 s.

Measurements
  certify_pantograph    certify_box on the pantograph cuboid (s), its sub-boxes;
                        baseline: the dense membership check of the same box
                        (check_box, 1663 points), which samples instead of proving
  certify_printed_34c   the paper's box with eq 34c as printed: fails (s)
  certify_prc3          certify_box on the 3-PRC cuboid (s)
  pantograph_cuboid     cn.solve of problems/pantograph_cuboid.yaml without the
                        certificate (s); baseline: the same with the starts solved
                        one by one (the formulation before issue 15)
  help, solve_prs3_fk   the CLI in a fresh process (s); baselines: ``python -c pass``
                        and ``python -c "import numpy, casadi, yaml"`` (what a solve
                        cannot avoid loading)
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
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
    "solve_prs3_fk": 0.3,
    "help": 0.1,
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


def bench_startup(repeats: int) -> dict:
    exe = shutil.which("cpm-nlp") or str(Path(sys.executable).parent / "cpm-nlp")
    cmds = {
        "bare": [sys.executable, "-c", "pass"],
        "libs": [sys.executable, "-c", "import numpy, casadi, yaml"],
        "help": [exe, "--help"],
        "solve_prs3_fk": [exe, "solve", "problems/prs3_forward_kinematics.yaml"],
    }

    def runner(cmd):
        return lambda: subprocess.run(cmd, cwd=ROOT, capture_output=True, check=True)

    before = load()
    med = interleaved({k: runner(c) for k, c in cmds.items()}, repeats)
    LIBS = "python -c 'import numpy, casadi, yaml'"  # noqa: N806
    return {
        "help": figure("help", med["help"], "python -c pass", med["bare"], before),
        "solve_prs3_fk": figure("solve_prs3_fk", med["solve_prs3_fk"], LIBS, med["libs"], before),
        "python_bare": med["bare"],
        "python_numpy_casadi_yaml": med["libs"],
    }  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="few repeats (a smoke run, not a measurement)")
    parser.add_argument("-o", "--output", default=str(Path(__file__).parent / "issue15.json"))
    args = parser.parse_args(argv)
    n = 2 if args.quick else 11
    results = {
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version()},
        "numpy": np.__version__,
        "quick": args.quick,
        **bench_certify(n),
        **bench_cuboid(n),
        **bench_startup(n if args.quick else 9),
    }
    for name, e in results.items():
        if isinstance(e, dict) and "value" in e:
            print(
                f"{name:<22} {e['value'] * 1e3:10.2f} ms  (x{e['ratio_to_baseline']:.2f} of {e['baseline']})  "
                f"target {e.get('target', '-')}: {e.get('verdict', '')}  load {e['load_before']} -> {e['load_after']}"
            )
    Path(args.output).write_text(json.dumps(results, indent=2, default=float) + "\n")
    print(f"written: {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
