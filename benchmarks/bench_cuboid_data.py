"""Issue 23, items 6 and 8: the pantograph cuboid, the Delta cuboid without a closed-form
IK, and a 100 000-pose data file.

    python benchmarks/bench_cuboid_data.py [--quick] [--only pantograph delta data] [--baseline REV]
                                           [-o benchmarks/bench_cuboid_data.json]

Every figure is a median of interleaved runs, CPU time (``time.process_time``: all threads
of this process) and wall time, with a baseline measured in the same run (a ratio) and the
machine's load (``os.getloadavg()``, 1 min) read before and after.

Measurements
  pantograph_cuboid   ``cn.solve`` of problems/pantograph_cuboid.yaml without the
                      certificate (target <= 20 ms CPU); baseline: the previous code, the
                      tree of git revision ``--baseline`` (default: the main commit this
                      work started from), in a second worker process, the two workers'
                      solves interleaved (each worker's own CPU time)
  pantograph_phases   where that solve's CPU time goes (in this process, the same solve,
                      each phase timed around its call): the probe of the region, the
                      cloud of the starts, the start boxes, the IPOPT starts, the check of
                      the box, the paper's eq 32-34 NLP and its check, the rest
  cond_screen         the singularity screen alone (`membership.singular`: the certified
                      bound, Φ_x's condition number where it does not clear) at the poses of
                      a 12 x 12 x 12 grid of that cuboid; baseline: numpy's SVD condition
                      numbers of the same Φ_x (12 x 12); beside it the screen before
                      (``condition_numbers``: one batched inverse, Φ_x given)
  delta_cuboid        ``cn.solve`` of an ``inscribed_cuboid`` of problems/mechanisms/delta.yaml
                      (no closed-form IK; 8 starts, no certificate; target: seconds)
  data_file_*         a 100 000-row CSV of 3-PRS actuator values (tests/hostile/
                      test_hostile_bounded.py builds the same one): reading and checking it
                      (``load_problem``), the solve (``cn.solve``, a batch of 100 000), and
                      the non-finite scan of its result (``nonfinite_paths``); baselines:
                      the value-by-value paths (per-value option checks, the walk of every
                      number), switched on in the same run
"""

from __future__ import annotations

import argparse
import collections
import importlib
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

import cpm_nlp as cn
from cpm_nlp.core import finite, options
from cpm_nlp.core.batch import evaluate_points

ROOT = Path(__file__).resolve().parent.parent
membership = importlib.import_module("cpm_nlp.analysis.workspace.membership")
TARGETS = {"pantograph_cuboid": 0.020, "delta_cuboid": 10.0}
#: the main commit the issue 23 item 6 work started from (the previous code of the pantograph cuboid)
BASELINE = "d042498"
PANTOGRAPH = "problems/pantograph_cuboid.yaml"
#: a worker: one tree's cpm_nlp solving the pantograph cuboid; each line read is a count of
#: solves, answered by their CPU times (this process's, all threads)
WORKER = """
import json, sys, time
import cpm_nlp as cn
problem = cn.load_problem(sys.argv[1], ["inputs.certify=false"])
r = cn.solve(problem)
cn.solve(problem)
print(json.dumps({"volume": r.values["volume"], "iterations": r.solver.iterations}), flush=True)
for line in sys.stdin:
    times = []
    for _ in range(int(line)):
        c, w = time.process_time(), time.perf_counter()
        cn.solve(problem)
        times.append((time.process_time() - c, time.perf_counter() - w))
    print(json.dumps(times), flush=True)
"""


def load() -> float:
    return round(os.getloadavg()[0], 2)


def timed(fn) -> tuple[float, float]:
    c0, w0 = time.process_time(), time.perf_counter()
    fn()
    return time.process_time() - c0, time.perf_counter() - w0


def interleaved(fns: dict, repeats: int) -> dict:
    """Median CPU and wall seconds of each function, run in turn ``repeats`` times after a warm-up."""
    for fn in fns.values():
        fn()
    cpu: dict = {k: [] for k in fns}
    wall: dict = {k: [] for k in fns}
    for _ in range(repeats):
        for k, fn in fns.items():
            c, w = timed(fn)
            cpu[k].append(c)
            wall[k].append(w)
    return {k: {"cpu": statistics.median(cpu[k]), "wall": statistics.median(wall[k])} for k in fns}


def entry(name: str, value: dict, baseline_name: str, baseline: dict, before: float, **extra) -> dict:
    out = {
        "cpu": value["cpu"],
        "wall": value["wall"],
        "unit": "s",
        "baseline": baseline_name,
        "baseline_cpu": baseline["cpu"],
        "baseline_wall": baseline["wall"],
        "ratio_cpu": value["cpu"] / baseline["cpu"],
        "ratio_wall": value["wall"] / baseline["wall"],
        "load_before": before,
        "load_after": load(),
        **extra,
    }
    if name in TARGETS:
        t = TARGETS[name]
        out["target"] = t
        out["verdict"] = "met" if value["cpu"] <= t else f"MISSED by {value['cpu'] - t:.3g} s ({value['cpu'] / t:.1f}x)"
    return out


def _worker(tree: Path, cache: Path) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=str(tree), CPM_NLP_CACHE=str(cache))
    return subprocess.Popen(
        [sys.executable, "-c", WORKER, str(tree / PANTOGRAPH)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        env=env,
        cwd=tree,
    )


def against_previous(repeats: int, rev: str) -> dict:
    """The pantograph cuboid in two workers, this tree and the tree of ``rev`` (git archive),
    their solves interleaved (3 per turn); medians of each worker's CPU time per solve."""
    with tempfile.TemporaryDirectory() as tmp:
        old = Path(tmp) / "previous"
        old.mkdir()
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev], capture_output=True, check=True)
        subprocess.run(["tar", "-x", "-C", str(old)], input=archive.stdout, check=True)
        workers = {"now": _worker(ROOT, Path(tmp) / "cache-now"), "previous": _worker(old, Path(tmp) / "cache-old")}
        try:
            first = {k: json.loads(w.stdout.readline()) for k, w in workers.items()}
            before = load()
            times: dict = {k: [] for k in workers}
            for _ in range(repeats):
                for k, w in workers.items():
                    w.stdin.write("3\n")
                    w.stdin.flush()
                    times[k] += json.loads(w.stdout.readline())
        finally:
            for w in workers.values():
                w.stdin.close()
                w.wait()
    med = {
        k: {"cpu": statistics.median(c for c, _ in v), "wall": statistics.median(w for _, w in v)}
        for k, v in times.items()
    }
    e = entry("pantograph_cuboid", med["now"], f"the previous code (git {rev})", med["previous"], before)
    e.update(
        solves=len(times["now"]),
        volume=first["now"]["volume"],
        volume_previous=first["previous"]["volume"],
        iterations=first["now"]["iterations"],
        iterations_previous=first["previous"]["iterations"],
    )
    return e


#: the phases of the solve: (module, function, label), each timed around its call
PHASES = (
    ("cpm_nlp.analysis.workspace.cuboid", "probe_region", "probe of the region"),
    ("cpm_nlp.analysis.workspace.cuboid", "_seeds", "cloud of the starts (2000 points)"),
    ("cpm_nlp.analysis.workspace.cuboid", "_start_boxes", "start boxes"),
    ("cpm_nlp.analysis.workspace.cuboid", "_run_starts", "IPOPT starts (working sets)"),
    ("cpm_nlp.analysis.workspace.cuboid", "_exchange_rounds", "check of the box (1663 points)"),
    ("cpm_nlp.mechanisms.pantograph.analysis", "paper_cuboid", "paper's eq 32-34 NLP"),
    ("cpm_nlp.mechanisms.pantograph.analysis", "check_box", "check of the paper's box (1663 points)"),
)


def phases(problem, repeats: int) -> dict:
    """CPU time of each phase of the solve (medians over ``repeats`` solves), and the rest."""
    spent: dict = collections.defaultdict(float)
    saved = []
    for mod_name, fn_name, label in PHASES:
        mod = importlib.import_module(mod_name)
        fn = getattr(mod, fn_name)
        saved.append((mod, fn_name, fn))

        def timed_call(*args, _fn=fn, _label=label, **kwargs):
            c = time.process_time()
            try:
                return _fn(*args, **kwargs)
            finally:
                spent[_label] += time.process_time() - c

        setattr(mod, fn_name, timed_call)
    per: dict = collections.defaultdict(list)
    try:
        cn.solve(problem)
        before = load()
        for _ in range(repeats):
            spent.clear()
            c = time.process_time()
            cn.solve(problem)
            total = time.process_time() - c
            for _m, _f, label in PHASES:
                per[label].append(spent.get(label, 0.0))
            per["the rest"].append(total - sum(spent.values()))
            per["total"].append(total)
    finally:
        for mod, fn_name, fn in saved:
            setattr(mod, fn_name, fn)
    out = {k: statistics.median(v) for k, v in per.items()}
    return {"unit": "s (CPU, medians)", "load_before": before, "load_after": load(), **out}


def bench_pantograph(repeats: int, rev: str) -> dict:
    problem = cn.load_problem(ROOT / PANTOGRAPH, ["inputs.certify=false"])
    now = cn.solve(problem)
    out = {"pantograph_cuboid": against_previous(repeats, rev), "pantograph_phases": phases(problem, repeats * 3)}
    model, c = problem.model, problem.model.closure
    lo = [now.values[f"{t}_min"] for t in c.task]
    hi = [now.values[f"{t}_max"] for t in c.task]
    axes = [np.linspace(a, b, 12) for a, b in zip(lo, hi)]  # 1728 points of the cuboid found
    T = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    X, Q, _ok = membership.poses(model, T)
    fn = membership.pose_check_function(c)
    PX = evaluate_points(c, membership.POSE_VALUES_KEY, fn, [X, Q], model.p)[2].reshape(-1, c.nx, c.nx)
    a = membership.singular(model, X, Q)
    b = ~(np.linalg.cond(PX) < membership.SINGULAR_CONDITION)
    before = load()
    med = interleaved(
        {
            "now": lambda: membership.singular(model, X, Q),
            "svd": lambda: np.linalg.cond(PX),
            "inverse": lambda: membership.condition_numbers(PX),
        },
        repeats * 3,
    )
    out["cond_screen"] = entry(
        "cond_screen", med["now"], "numpy SVD condition numbers (of Φ_x already evaluated)", med["svd"], before,
        matrices=int(PX.shape[0]), same_verdicts=bool(np.array_equal(a, b)),
        previous_screen_cpu=med["inverse"]["cpu"],  # the screen before: one batched inverse, Φ_x given
    )  # fmt: skip
    return out


def bench_delta(repeats: int) -> dict:
    doc = {
        "problem": "inscribed_cuboid",
        "mechanism": {"file": str(ROOT / "problems/mechanisms/delta.yaml")},
        "inputs": {"starts": 8, "seed": 0, "certify": False},
    }
    problem = cn.problem_from_dict(doc)
    runs = []

    def solve():
        runs.append(cn.solve(problem))

    before = load()
    med = interleaved({"delta": solve}, max(1, repeats // 3))
    r = runs[-1]
    e = entry("delta_cuboid", med["delta"], "itself", med["delta"], before)
    e.update(status=r.status.value, volume=r.values["volume"], iterations=r.solver.iterations)
    return {"delta_cuboid": e}


def _data_file(folder: Path) -> Path:
    rng = np.random.default_rng(0)  # as tests/hostile/test_hostile_bounded.py
    q = rng.uniform(-2e-3, 2e-3, (100_000, 3))
    with open(folder / "poses.csv", "w") as fh:
        fh.write("s1 [m], s2, s3 [mm]\n")
        np.savetxt(fh, q * [1, 1, 1e3], delimiter=",")
    doc = yaml.safe_load((ROOT / "problems/prs3_forward_kinematics.yaml").read_text())
    doc["inputs"] = {"data": "poses.csv"}
    doc["solver"] = "newton"
    target = folder / "batch.yaml"
    target.write_text(yaml.safe_dump(doc))
    return target


def _walk_value_by_value(value, name):
    """The non-finite scan before issue 23: every number of every list visited in Python."""
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _walk_value_by_value(v, f"{name}.{k}")
    elif isinstance(value, np.ndarray) and value.dtype.kind in "fc":
        bad = np.argwhere(~np.isfinite(value))
        if bad.size:
            yield name + "".join(f"[{int(i)}]" for i in bad[0])
    elif isinstance(value, (list, tuple, np.ndarray)):
        for i, v in enumerate(value):
            yield from _walk_value_by_value(v, f"{name}[{i}]")
    elif isinstance(value, (float, np.floating, complex, np.complexfloating)) and not np.isfinite(value):
        yield name


def bench_data_file(repeats: int) -> dict:
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        path = _data_file(Path(tmp))
        fast_list = options.FAST_LIST

        def read(per_value: bool):
            options.FAST_LIST = sys.maxsize if per_value else fast_list
            try:
                return cn.load_problem(path)
            finally:
                options.FAST_LIST = fast_list

        before = load()
        med = interleaved({"now": lambda: read(False), "per_value": lambda: read(True)}, repeats)
        out["data_file_read"] = entry("data_file_read", med["now"], "per-value option checks", med["per_value"], before)
        problem = read(False)
        result = cn.solve(problem)
        values = dict(result.values)
        before = load()
        med = interleaved(
            {
                "now": lambda: finite.nonfinite_paths(values),
                "walk": lambda: [next(_walk_value_by_value(v, k), None) for k, v in values.items()],
            },
            repeats,
        )
        out["data_file_nonfinite_scan"] = entry(
            "data_file_nonfinite_scan", med["now"], "the walk of every number", med["walk"], before
        )
        before = load()
        med = interleaved({"solve": lambda: cn.solve(problem)}, max(1, repeats // 2))
        out["data_file_solve"] = entry(
            "data_file_solve", med["solve"], "itself", med["solve"], before, status=result.status.value,
            message=result.message,
        )  # fmt: skip
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="few repeats (a smoke run, not a measurement)")
    parser.add_argument("-o", "--output", default=str(Path(__file__).parent / "bench_cuboid_data.json"))
    parser.add_argument(
        "--only",
        nargs="+",
        choices=("pantograph", "delta", "data"),
        help="run these measurements only; the others are kept from the output file",
    )
    parser.add_argument("--baseline", default=BASELINE, help="git revision of the previous code (pantograph)")
    args = parser.parse_args(argv)
    n = 1 if args.quick else 9
    only = set(args.only or ("pantograph", "delta", "data"))
    results = json.loads(Path(args.output).read_text()) if args.only and Path(args.output).exists() else {}
    results |= {
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version()},
        "numpy": np.__version__,
        "quick": args.quick,
    }
    if "pantograph" in only:
        results |= bench_pantograph(n, args.baseline)
    if "delta" in only:
        results |= bench_delta(n)
    if "data" in only:
        results |= bench_data_file(max(1, n // 3))
    for name, e in results.items():
        if isinstance(e, dict) and "cpu" in e:
            wall = f"  wall {e['wall'] * 1e3:9.1f} ms" if "wall" in e else ""
            ratio = f", x{e['ratio_wall']:.2f} wall" if "ratio_wall" in e else ""
            line = f"{name:<26} CPU {e['cpu'] * 1e3:9.1f} ms{wall}"
            line += f"  (x{e['ratio_cpu']:.2f} CPU{ratio} of {e['baseline']})"
            if "target" in e:
                line += f"  target {e['target']} s: {e['verdict']}"
            print(f"{line}  load {e['load_before']} -> {e['load_after']}")
        elif name == "pantograph_phases":
            print("  where the pantograph cuboid's CPU time goes:")
            for k, v in e.items():
                if isinstance(v, float) and not k.startswith("load"):
                    print(f"    {k:<40} {v * 1e3:7.1f} ms")
    Path(args.output).write_text(json.dumps(results, indent=2, default=float) + "\n")
    print(f"written: {args.output}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
