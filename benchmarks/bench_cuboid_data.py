"""Issue 23, items 6 and 8: the pantograph cuboid, the Delta cuboid without a closed-form
IK, and a 100 000-pose data file.

    python benchmarks/bench_cuboid_data.py [--quick] [-o benchmarks/bench_cuboid_data.json]

Every figure is a median of interleaved runs, CPU time (``time.process_time``: all threads
of this process) and wall time, with a baseline measured in the same run (a ratio) and the
machine's load (``os.getloadavg()``, 1 min) read before and after.

Measurements
  pantograph_cuboid   ``cn.solve`` of problems/pantograph_cuboid.yaml without the
                      certificate (target <= 20 ms CPU); baseline: the same with the
                      singularity screen as before (every Φ_x condition number by SVD)
  cond_screen         the screen alone on the Φ_x (12 x 12) of a 12 x 12 x 12 grid of that
                      cuboid; baseline: the screen before (numpy's SVD condition numbers
                      wherever ‖A‖_F^n / |det A| does not clear a matrix: all of them here)
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
import importlib
import json
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

import cpm_nlp as cn
from cpm_nlp.core import finite, options

ROOT = Path(__file__).resolve().parent.parent
membership = importlib.import_module("cpm_nlp.analysis.workspace.membership")
TARGETS = {"pantograph_cuboid": 0.020, "delta_cuboid": 10.0}


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


def svd_screen(PX: np.ndarray) -> np.ndarray:
    """The screen before issue 23: κ₂ ≤ ‖A‖_F^n / |det A|, else numpy's SVD condition number."""
    n = PX.shape[-1]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        bound = np.sqrt(np.sum(PX * PX, axis=(1, 2))) ** n / np.abs(np.linalg.det(PX))
    flagged = ~(bound < 0.5 * membership.SINGULAR_CONDITION)
    finite_ = np.all(np.isfinite(PX), axis=(1, 2))
    bound[flagged & ~finite_] = np.inf
    if np.any(flagged & finite_):
        bound[flagged & finite_] = np.linalg.cond(PX[flagged & finite_])
    return bound


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


def bench_pantograph(repeats: int) -> dict:
    problem = cn.load_problem(ROOT / "problems/pantograph_cuboid.yaml", ["inputs.certify=false"])
    screen = membership.condition_numbers

    def solve(fn):
        membership.condition_numbers = fn
        try:
            return cn.solve(problem)
        finally:
            membership.condition_numbers = screen

    now, old = solve(screen), solve(svd_screen)
    before = load()
    med = interleaved({"now": lambda: solve(screen), "svd": lambda: solve(svd_screen)}, repeats)
    out = {
        "pantograph_cuboid": entry(
            "pantograph_cuboid", med["now"], "the same, every cond(Φ_x) by SVD", med["svd"], before,
            volume=now.values["volume"], volume_svd=old.values["volume"], iterations=now.solver.iterations,
        )
    }  # fmt: skip
    model, c = problem.model, problem.model.closure
    lo = [now.values[f"{t}_min"] for t in c.task]
    hi = [now.values[f"{t}_max"] for t in c.task]
    axes = [np.linspace(a, b, 12) for a, b in zip(lo, hi)]  # 1728 points of the cuboid found
    T = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    fn = membership.task_point_function(c)
    PX = np.asarray(fn.map(T.shape[0])(T.T, np.tile(model.p, (T.shape[0], 1)).T)[5]).T.reshape(-1, c.nx, c.nx)
    a, b = screen(PX), svd_screen(PX)
    before = load()
    med = interleaved({"now": lambda: screen(PX), "svd": lambda: svd_screen(PX)}, repeats * 3)
    out["cond_screen"] = entry(
        "cond_screen", med["now"], "numpy SVD condition numbers", med["svd"], before,
        matrices=int(PX.shape[0]), same_verdicts=bool(np.array_equal(a < 1e10, b < 1e10)),
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
    args = parser.parse_args(argv)
    n = 1 if args.quick else 9
    results = {
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version()},
        "numpy": np.__version__,
        "quick": args.quick,
        **bench_pantograph(n),
        **bench_delta(n),
        **bench_data_file(max(1, n // 3)),
    }
    for name, e in results.items():
        if isinstance(e, dict) and "cpu" in e:
            line = (
                f"{name:<26} CPU {e['cpu'] * 1e3:9.1f} ms  wall {e['wall'] * 1e3:9.1f} ms  "
                f"(x{e['ratio_cpu']:.2f} CPU, x{e['ratio_wall']:.2f} wall of {e['baseline']})"
            )
            if "target" in e:
                line += f"  target {e['target']} s: {e['verdict']}"
            print(f"{line}  load {e['load_before']} -> {e['load_after']}")
    Path(args.output).write_text(json.dumps(results, indent=2, default=float) + "\n")
    print(f"written: {args.output}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
