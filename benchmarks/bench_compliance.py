"""Speed of the compliance method (issue 12): per pose, on the 3-PRS with the
hinges of prs3-ruiz.md section 5.

    python benchmarks/bench_compliance.py [--repeats 200] [--json benchmarks/bench_compliance.json]

* **forces** -- actuator forces, K_q and hinge stresses at one solved pose
  (:func:`cpm_nlp.analysis.compliance.static_point`); target <= 1 ms;
* **compliance** -- the same plus the 6x6 output compliance J (K_q + K_a)⁻¹ Jᵀ;
  target <= 2 ms;
* **compliant_fk** -- the loaded pose under a 1 N load by IPOPT (warm, the
  solver built); target <= 20 ms.
* **six_axis_compliance** -- the six-axis hinge model
  (:mod:`cpm_nlp.analysis.hinge_chains`): from the rigid pose, the chains'
  variables fitted to it, the unloaded equilibrium at the
  commanded actuators (Newton on the KKT) and the 6x6 compliance there, with
  the actuators held; target <= 2 ms;
* **six_axis_fk** -- the six-axis loaded pose under 1 N in x, y, z by IPOPT from
  the unloaded equilibrium (warm); target <= 20 ms.
* **six_axis_compliance_flexible_legs** -- six_axis_compliance with the three legs as
  Timoshenko beams (10 x 10 mm^2, 4 distributed elements each: 72 more variables;
  :mod:`cpm_nlp.analysis.beams`); target <= 10 ms (issue 25), CPU time as well
  (``cpu_seconds``, time.process_time, the figure the target is read against);
  ``..._1_element`` with one element per leg (the same linear compliance: a
  distributed element is exact).
* **six_axis_compliance_uncapped** -- six_axis_compliance with the BLAS threads
  left as they are (the functions without their ``one_blas_thread`` cap,
  :mod:`cpm_nlp.core.blas`); ``blas_cap_speedup`` is its time over the capped one,
  measured in the same run at the same load.

Each figure is the median of ``repeats`` calls (wall time ``seconds`` and CPU time
``cpu_seconds``; ``met`` reads the CPU time, which the other sessions on a shared
machine do not inflate); the baseline in the same run is
one rigid forward kinematics by Newton (the cheapest solve the toolkit does at a
pose), so the ratios stay comparable when the machine is loaded.  The load
average (os.getloadavg) is recorded beside each figure.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from cpm_nlp.analysis import compliance as cm  # noqa: E402
from cpm_nlp.analysis.hinge_chains import six_axis_model  # noqa: E402
from cpm_nlp.core.kinematics import forward_kinematics  # noqa: E402
from cpm_nlp.core.solver import SolverConfig  # noqa: E402
from cpm_nlp.mechanisms.registry import build_model  # noqa: E402

TARGETS = {
    "forces": 1e-3,
    "compliance": 2e-3,
    "compliant_fk": 20e-3,
    "six_axis_compliance": 2e-3,
    "six_axis_fk": 20e-3,
    "six_axis_compliance_flexible_legs": 10e-3,
}


def _median(fn, repeats: int) -> tuple[float, float, tuple[float, float, float]]:
    """Median wall time and median CPU time (time.process_time) of ``repeats`` calls, and the load."""
    fn()
    times, cpu = [], []
    for _ in range(repeats):
        t, c = time.perf_counter(), time.process_time()
        fn()
        cpu.append(time.process_time() - c)
        times.append(time.perf_counter() - t)
    return statistics.median(times), statistics.median(cpu), os.getloadavg()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=200)
    ap.add_argument("--json", default=str(ROOT / "benchmarks" / "bench_compliance.json"))
    args = ap.parse_args(argv)
    m = build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"})
    hs = cm.hinge_set(m, None)
    newton = SolverConfig(method="newton")
    q = np.array([0.9e-3, -0.4e-3, 0.6e-3])
    sol = forward_kinematics(m, q, newton)
    ka = np.zeros(3)
    f = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
    sp = cm.static_point(m, hs, sol.x, sol.q)
    sm = six_axis_model(m, hs)
    z0 = sm.start(sol.x, sol.q)

    def six_compliance():
        ok, z, lam, _ = sm.newton(sm.start(sol.x, sol.q), np.zeros(6), q, None, None)
        return sm.compliance(z, lam, None, None)

    raw = type(sm)  # the methods without their one-BLAS-thread cap (functools.wraps keeps them)

    def six_compliance_uncapped():
        z1 = raw.start.__wrapped__(sm, sol.x, sol.q)
        ok, z, lam, _ = raw.newton.__wrapped__(sm, z1, np.zeros(6), q, None, None)
        return raw.compliance.__wrapped__(sm, z, lam, None, None)

    _, z_u, _, _ = sm.newton(z0, np.zeros(6), q, None, None)

    def flexible(n: int):
        legs = {"leg": {"between": ["alpha", "beta_m"], "section": {"b": "10 mm", "h": "10 mm"}, "elements": n}}
        hs_f = cm.hinge_set(m, None, bodies=legs)
        sm_f = six_axis_model(m, hs_f)

        def run():
            ok, z, lam, _ = sm_f.newton(sm_f.start(sol.x, sol.q), np.zeros(6), q, None, None)
            return sm_f.compliance(z, lam, None, None)

        return run

    cases = {
        "baseline_fk_newton": lambda: forward_kinematics(m, q, newton),
        "forces": lambda: cm.static_point(m, hs, sol.x, sol.q),
        "compliance": lambda: cm.output_compliance(cm.static_point(m, hs, sol.x, sol.q), ka),
        "compliant_fk": lambda: cm.compliant_fk(m, hs, sol.x, sol.q, sp.F, f, ka),
        "six_axis_compliance": six_compliance,
        "six_axis_fk": lambda: sm.ipopt(z_u, f, q, None, None),
        "six_axis_compliance_uncapped": six_compliance_uncapped,
        "six_axis_compliance_flexible_legs": flexible(4),
        "six_axis_compliance_flexible_legs_1_element": flexible(1),
    }
    out = {}
    for name, fn in cases.items():
        reps = max(5, args.repeats // 10) if name in ("compliant_fk", "six_axis_fk") else args.repeats
        sec, cpu, load = _median(fn, reps)
        out[name] = {"seconds": sec, "cpu_seconds": cpu, "load": list(load)}
    base = out["baseline_fk_newton"]["seconds"]
    print(f"{'case':<44} {'median':>10} {'cpu':>10} {'/ FK':>8} {'target':>8}  load")
    for name, rec in out.items():
        rec["ratio_to_baseline"] = rec["seconds"] / base
        target = TARGETS.get(name)
        if target:
            rec["target_seconds"] = target
            rec["met"] = rec["cpu_seconds"] <= target  # CPU time: a shared machine inflates the wall time
        t = f"{target * 1e3:.0f} ms" if target else ""
        print(
            f"{name:<44} {rec['seconds'] * 1e3:8.3f} ms {rec['cpu_seconds'] * 1e3:7.3f} ms "
            f"{rec['ratio_to_baseline']:8.2f} {t:>8}  " + ", ".join(f"{v:.2f}" for v in rec["load"])
        )
    speedup = out["six_axis_compliance_uncapped"]["seconds"] / out["six_axis_compliance"]["seconds"]
    out["blas_cap_speedup"] = {"ratio": speedup, "load": list(os.getloadavg())}
    print(f"one BLAS thread: six-axis compliance {speedup:.2f} x faster than with the default threads")
    Path(args.json).write_text(json.dumps(out, indent=2))
    print("written:", args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
