"""Peer benchmark (issue 23, item 7): the five-bar and the Delta in Pinocchio and pylinkage
beside cpm_nlp, on the same seeded poses.

    pip install -e .[bench]      # pin (Pinocchio), pylinkage[numba]
    python benchmarks/bench_peers.py [--n 2000] [--single 200] [--repeat 5] [--half 0.25]
        [--json benchmarks/bench_peers.json]

A peer that is not installed is reported as skipped (exit 0).

**Poses.** For each mechanism, ``--n`` actuator vectors ``q = q_home + U(-half, half)`` (rad,
``numpy.random.default_rng(seed)``) about the home pose of problems/mechanisms/five_bar.yaml and
delta.yaml (their default parameters, read from the built model: the peers get the same geometry).
Every solver starts each pose from the home pose (no warm start from the previous pose).

**Agreement.** The output compared is the platform position, in metres: the five-bar's end
effector P = (x, y); the Delta's platform centre (x, y, z).  Reported: max |difference| of each
coordinate over the poses that both solvers solved, against ``cn.forward_kinematics`` /
``cn.batch_forward_kinematics`` (Newton, compiled backend); poses a solver did not solve are
counted, never compared.

**How each peer solves (exactly what is timed).**

* cpm_nlp: single = ``cn.forward_kinematics(model, q, SolverConfig("newton"), backend="compiled")``
  per pose (every check of a single solve included); batch =
  ``cn.batch_forward_kinematics(..., backend="compiled", threads=1)`` on all the poses.
* Pinocchio has no closed-loop FK solver: the model is built programmatically (``pin.Model``,
  ``addJoint``, ``addFrame``) from the mechanism's parameters, as an open tree, and the loop is
  closed by Newton's method on a constraint written here with Pinocchio's kinematics
  (``computeJointJacobians`` + ``updateFramePlacements`` + ``getFrameJacobian``,
  LOCAL_WORLD_ALIGNED), as Pinocchio's closed-chain examples do (constraint value and Jacobian
  from the model, Newton on the passive coordinates, ``pin.integrate``).  Five-bar: cranks and
  elbows as revolute joints (RZ), the constraint P_left - P_right = 0 (x, y), unknowns the two
  elbow angles.  Delta: the arms as revolute joints (RY in each arm's rotated frame), the
  platform a translation joint, each parallelogram the distance constraint
  |elbow_i - platform_point_i| - lb = 0, unknowns the platform translation.  Timed: the whole
  Newton loop from Python (q assembled, the kinematics, the Jacobian, ``numpy.linalg.solve``),
  tolerance 1e-12 m on the constraint, at most 30 steps.  Batch = the same loop over the poses
  (Pinocchio has no batched closed-loop solve).
* pylinkage (planar only: no spatial Delta; the five-bar only).  Single = its objects: two
  ``Crank`` outputs placed at the pose's angles (``pylinkage.cyl_to_cart``), the ``RRRDyad`` at P
  reset to the home P as its hint and ``reload(0)`` (circle-circle intersection, the root
  nearest the hint).  Batch = pylinkage's solver kernels (``solver.joints.solve_revolute``,
  ``geometry.core.cyl_to_cart``, numba-compiled when numba is installed) in one numba loop over
  the poses (a Python loop without numba; the JSON says which).

Times: the median of ``--repeat`` repeats, each in CPU seconds of this process
(``time.process_time``, all threads) and wall seconds, per pose, in µs; the 1-minute load average
(``os.getloadavg()``) is read before and after every figure and stored beside it.  Ratios are
peer / cpm_nlp within this run.
"""

from __future__ import annotations

import argparse
import importlib
import json
import math
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import cpm_nlp as cn  # noqa: E402

NEWTON_TOL = 1e-12  # m, the peers' Newton tolerance on the constraint
NEWTON_STEPS = 30


def _load() -> float:
    return os.getloadavg()[0]


def _peer(module: str, package: str):
    """The imported peer module, or None (printed: not installed, skipped)."""
    try:
        return importlib.import_module(module)
    except ImportError:
        print(f"{package} is not installed ({module} cannot be imported): skipped (pip install -e .[bench])")
        return None


def _time(fn, repeat: int, count: int) -> dict:
    """Median CPU and wall µs per pose of ``fn()`` (which handles ``count`` poses), with the load."""
    fn()  # warm: JIT, solvers, kernels
    cpu, wall = [], []
    load_before = _load()
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        cpu.append((time.process_time() - c0) / count * 1e6)
        wall.append((time.perf_counter() - t0) / count * 1e6)
    return {
        "cpu_us_per_pose": statistics.median(cpu),
        "wall_us_per_pose": statistics.median(wall),
        "poses": count,
        "repeat": repeat,
        "load_1min": [load_before, _load()],
    }


# ---------------------------------------------------------------- cpm_nlp


def cpm_solve(model, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """cpm_nlp's batch FK (compiled, one thread): positions (N, nx) and solved flags."""
    res = cn.batch_forward_kinematics(model, qs, cn.SolverConfig("newton"), backend="compiled", threads=1)
    return np.asarray(res.x, dtype=float), np.asarray(res.ok, dtype=bool)


def _cpm_timings(model, qs: np.ndarray, single: int, repeat: int) -> dict:
    newton = cn.SolverConfig("newton")

    def singles():
        for q in qs[:single]:
            cn.forward_kinematics(model, q, newton, backend="compiled")

    return {
        "single": _time(singles, repeat, single),
        "batch": _time(lambda: cpm_solve(model, qs), repeat, len(qs)),
    }


# ---------------------------------------------------------------- Pinocchio


class PinocchioLoop:
    """A mechanism as Pinocchio's open tree plus a loop-closure constraint solved by Newton.

    ``actuated``: the configuration indices the actuators set; ``unknown``: the velocity
    indices Newton solves for; ``constraint(data)`` returns the constraint value and its
    Jacobian (rows: the constraint, columns: the model's velocity) from the current data.
    """

    def __init__(self, pin, model, q_home, actuated, unknown, constraint, output):
        self.pin, self.model, self.data = pin, model, model.createData()
        self.q_home, self.actuated, self.unknown = q_home, list(actuated), list(unknown)
        self.constraint, self.output = constraint, output
        self.steps = 0  # Newton steps taken (kinematics evaluations - solves), all solves

    def kinematics(self, q: np.ndarray) -> None:
        """One evaluation of the kinematics a Newton step needs (timed alone, below)."""
        self.pin.computeJointJacobians(self.model, self.data, q)
        self.pin.updateFramePlacements(self.model, self.data)

    def solve(self, q_act: np.ndarray) -> tuple[np.ndarray, bool]:
        pin, model, data = self.pin, self.model, self.data
        q = self.q_home.copy()
        q[self.actuated] = q_act
        dv = np.zeros(model.nv)
        for _ in range(NEWTON_STEPS):
            pin.computeJointJacobians(model, data, q)  # placements and joint Jacobians
            pin.updateFramePlacements(model, data)
            c, jac = self.constraint(data)
            if np.max(np.abs(c)) < NEWTON_TOL:
                return self.output(data, q), True
            dv[:] = 0.0
            try:
                dv[self.unknown] = np.linalg.solve(jac[:, self.unknown], -c)
            except np.linalg.LinAlgError:
                break
            q = pin.integrate(model, q, dv)
            self.steps += 1
        return self.output(data, q), False

    def solve_all(self, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        xs, ok = [], []
        for q in qs:
            x, good = self.solve(q)
            xs.append(x)
            ok.append(good)
        return np.array(xs), np.array(ok)


def _translation(pin, xyz) -> object:
    return pin.SE3(np.eye(3), np.asarray(xyz, dtype=float))


def pinocchio_five_bar(pin, model) -> PinocchioLoop:
    """The five-bar of five_bar.yaml: cranks at A1 = (-d/2, 0), A2 = (d/2, 0), elbows at the
    crank tips (l1), P at l2 from each elbow; the loop closes P_left = P_right."""
    d, l1, l2 = (model.parameters[k] for k in ("d", "l1", "l2"))
    m = pin.Model()
    frames = {}
    for side, ax in (("left", -d / 2), ("right", d / 2)):
        crank = m.addJoint(0, pin.JointModelRZ(), _translation(pin, [ax, 0, 0]), f"crank_{side}")
        elbow = m.addJoint(crank, pin.JointModelRZ(), _translation(pin, [l1, 0, 0]), f"elbow_{side}")
        frames[side] = m.addFrame(pin.Frame(f"P_{side}", elbow, _translation(pin, [l2, 0, 0]), pin.FrameType.OP_FRAME))
    cranks = [m.joints[m.getJointId(f"crank_{s}")].idx_q for s in ("left", "right")]
    elbows = [m.joints[m.getJointId(f"elbow_{s}")].idx_q for s in ("left", "right")]
    # home: the cranks at q_home, each elbow's angle relative to its crank pointing at P_home
    q_home = pin.neutral(m)
    p_home = model.x_home
    for k, ax in enumerate((-d / 2, d / 2)):
        a = model.q_home[k]
        elbow_xy = np.array([ax + l1 * math.cos(a), l1 * math.sin(a)])
        q_home[cranks[k]] = a
        q_home[elbows[k]] = math.atan2(p_home[1] - elbow_xy[1], p_home[0] - elbow_xy[0]) - a
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED

    def constraint(data):
        c = data.oMf[frames["left"]].translation[:2] - data.oMf[frames["right"]].translation[:2]
        jac = (
            pin.getFrameJacobian(m, data, frames["left"], lwa)[:2]
            - pin.getFrameJacobian(m, data, frames["right"], lwa)[:2]
        )
        return c, jac

    def output(data, _q):
        return data.oMf[frames["left"]].translation[:2].copy()

    return PinocchioLoop(pin, m, q_home, cranks, elbows, constraint, output)


def pinocchio_delta(pin, model) -> PinocchioLoop:
    """The Delta of delta.yaml: arm i about the tangent (y of its frame turned by 2 pi (i-1)/3
    about z) at rb, elbow at la, platform point at rp on a translation joint; each parallelogram
    the distance lb between its elbow and its platform point."""
    rb, rp, la, lb = (model.parameters[k] for k in ("rb", "rp", "la", "lb"))
    m = pin.Model()
    elbows, points, arms = [], [], []
    for i in range(3):
        turn = pin.utils.rotate("z", 2 * math.pi * i / 3)
        arm = m.addJoint(0, pin.JointModelRY(), pin.SE3(turn, turn @ np.array([rb, 0.0, 0.0])), f"arm{i + 1}")
        arms.append(m.joints[arm].idx_q)
        elbow = pin.Frame(f"elbow{i + 1}", arm, _translation(pin, [la, 0, 0]), pin.FrameType.OP_FRAME)
        elbows.append(m.addFrame(elbow))
    platform_joint = m.addJoint(0, pin.JointModelTranslation(), pin.SE3.Identity(), "platform")
    for i in range(3):
        turn = pin.utils.rotate("z", 2 * math.pi * i / 3)
        placement = pin.SE3(np.eye(3), turn @ np.array([rp, 0.0, 0.0]))
        points.append(m.addFrame(pin.Frame(f"point{i + 1}", platform_joint, placement, pin.FrameType.OP_FRAME)))
    iv = m.joints[platform_joint].idx_v
    iq = m.joints[platform_joint].idx_q
    q_home = pin.neutral(m)
    q_home[arms] = model.q_home
    q_home[iq : iq + 3] = model.x_home
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED

    def constraint(data):
        c = np.empty(3)
        jac = np.empty((3, m.nv))
        for i in range(3):
            r = data.oMf[elbows[i]].translation - data.oMf[points[i]].translation
            dist = np.linalg.norm(r)
            c[i] = dist - lb
            dj = pin.getFrameJacobian(m, data, elbows[i], lwa)[:3] - pin.getFrameJacobian(m, data, points[i], lwa)[:3]
            jac[i] = (r / dist) @ dj
        return c, jac

    def output(_data, q):
        return q[iq : iq + 3].copy()

    return PinocchioLoop(pin, m, q_home, arms, range(iv, iv + 3), constraint, output)


# ---------------------------------------------------------------- pylinkage


class PylinkageFiveBar:
    """The five-bar with pylinkage: two cranks and an RRR dyad (circle-circle intersection) at P."""

    def __init__(self, pl, model):
        d, l1, l2 = (model.parameters[k] for k in ("d", "l1", "l2"))
        self.pl, self.l1, self.l2 = pl, l1, l2
        self.a1 = pl.Ground(-d / 2, 0.0, name="A1")
        self.a2 = pl.Ground(d / 2, 0.0, name="A2")
        self.c1 = pl.Crank(self.a1, l1, initial_angle=float(model.q_home[0]), name="crank1")
        self.c2 = pl.Crank(self.a2, l1, initial_angle=float(model.q_home[1]), name="crank2")
        self.hint = (float(model.x_home[0]), float(model.x_home[1]))
        self.p = pl.RRRDyad(self.c1.output, self.c2.output, l2, l2, x=self.hint[0], y=self.hint[1], name="P")

    def solve(self, q: np.ndarray) -> tuple[np.ndarray, bool]:
        pl = self.pl
        self.c1.x, self.c1.y = pl.cyl_to_cart(self.l1, float(q[0]), self.a1.x, self.a1.y)
        self.c2.x, self.c2.y = pl.cyl_to_cart(self.l1, float(q[1]), self.a2.x, self.a2.y)
        self.p.x, self.p.y = self.hint
        try:
            self.p.reload(0)
        except pl.UnbuildableError:
            return np.array([math.nan, math.nan]), False
        return np.array([self.p.x, self.p.y]), True

    def solve_all(self, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        out = [self.solve(q) for q in qs]
        return np.array([x for x, _ in out]), np.array([ok for _, ok in out])


def pylinkage_batch(model):
    """A batch over poses with pylinkage's solver kernels (in a numba loop when numba is there):
    a function qs -> (positions, ok), and whether it is numba-compiled."""
    from pylinkage._numba_compat import HAS_NUMBA, njit
    from pylinkage.geometry.core import cyl_to_cart
    from pylinkage.solver.joints import solve_revolute

    d, l1, l2 = (model.parameters[k] for k in ("d", "l1", "l2"))
    hx, hy = float(model.x_home[0]), float(model.x_home[1])

    @njit(cache=False)
    def loop(qs, out):
        for k in range(qs.shape[0]):
            e1x, e1y = cyl_to_cart(l1, qs[k, 0], -d / 2, 0.0)
            e2x, e2y = cyl_to_cart(l1, qs[k, 1], d / 2, 0.0)
            out[k, 0], out[k, 1] = solve_revolute(hx, hy, e1x, e1y, l2, e2x, e2y, l2)

    def batch(qs):
        out = np.empty((qs.shape[0], 2))
        loop(np.ascontiguousarray(qs, dtype=float), out)
        return out, ~np.isnan(out).any(axis=1)

    return batch, HAS_NUMBA


class PylinkageJansen:
    """Jansen's leg (problems/mechanisms/jansen.yaml) in pylinkage: the frame pivot, a ``Crank`` and
    five ``RRRDyad`` (Y, D, W, E, F), each hinted at the file's reference configuration; pylinkage's
    own simulation (``Linkage.step``, one crank step per pose, each dyad's root nearest the step
    before) over the whole turn.  The poses are the crank angles 1, 2, ..., 360 deg (k * 360/n)."""

    def __init__(self, pl, model, n: int):
        P = model.parameters
        a, b, c, d, e, f, g, h, i, j, k, l, m = (P[x] for x in "abcdefghijklm")
        pts = _jansen_hints(model)
        self.pl, self.n = pl, n
        O, Z = pl.Ground(0.0, 0.0, name="O"), pl.Ground(-a, -l, name="Z")
        cr = pl.Crank(O, m, angular_velocity=2 * math.pi / n, initial_angle=0.0, name="crank")
        Y = pl.RRRDyad(cr.output, Z, j, b, x=pts["Y"][0], y=pts["Y"][1], name="Y")
        D = pl.RRRDyad(Z, Y, d, e, x=pts["D"][0], y=pts["D"][1], name="D")
        W = pl.RRRDyad(cr.output, Z, k, c, x=pts["W"][0], y=pts["W"][1], name="W")
        E = pl.RRRDyad(D, W, f, g, x=pts["E"][0], y=pts["E"][1], name="E")
        F = pl.RRRDyad(W, E, i, h, x=pts["F"][0], y=pts["F"][1], name="F")
        self.linkage = pl.Linkage([O, Z, cr, Y, D, W, E, F])
        self.init = self.linkage.get_coords()

    def cycle(self) -> tuple[np.ndarray, np.ndarray]:
        self.linkage.set_coords(self.init)
        feet = np.array([s[-1] for s in self.linkage.step(iterations=self.n, dt=1)], dtype=float)
        return feet, ~np.isnan(feet).any(axis=1)


def _jansen_hints(model) -> dict:
    """The reference configuration's joints from the file's derived values (Yr, Dr, Wr, Er, Fr)."""
    return {n: tuple(np.asarray(model.derived[f"{n}r"], dtype=float).ravel()[:2]) for n in "YDWEF"}


def run_jansen(args, peers: dict) -> dict:
    """Jansen's leg over a full crank turn: cpm_nlp's batch FK (closed-form dyads, every check)
    against pylinkage's simulation of the same leg, the foot compared."""
    model = cn.build_model("jansen", {})
    n = args.jansen_n
    qs = (np.arange(1, n + 1) * 2 * math.pi / n)[:, None]
    names = list(model.closure.passive_names)
    cols = [names.index("foot_x"), names.index("foot_y")]

    def cpm_feet():
        res = cn.batch_forward_kinematics(model, qs, cn.SolverConfig("newton"), backend="compiled", threads=1)
        return np.asarray(res.passive[:, cols], dtype=float), np.asarray(res.ok, dtype=bool)

    feet, ok = cpm_feet()
    out: dict = {
        "mechanism_file": "problems/mechanisms/jansen.yaml",
        "parameters_SI": dict(model.parameters),
        "poses": n,
        "poses_are": "crank angles k * 360/n deg, k = 1..n (one turn)",
        "cpm_nlp": {"solved": int(ok.sum()), **_cpm_timings(model, qs, args.single, args.repeat)},
        "peers": {},
    }
    pl = peers.get("pylinkage")
    if pl is None:
        out["peers"]["pylinkage"] = {"skipped": "pylinkage is not installed"}
        return out
    leg = PylinkageJansen(pl, model, n)
    pf, pok = leg.cycle()
    agree = _agreement(feet, ok, pf, pok, ["foot_x", "foot_y"])
    agree["output"] = "the foot F (foot_x, foot_y), m"
    entry = {
        "agreement": agree,
        "single": _time(leg.cycle, args.repeat, n),
        "batch": _time(leg.cycle, args.repeat, n),
        "what": "Linkage.step over the turn (its own simulation: each dyad from the previous step's root); "
        "single = batch = the same simulation (pylinkage has no per-pose solve of a multi-dyad leg here)",
    }
    entry["ratio_single"] = _ratio(entry["single"], out["cpm_nlp"]["single"])
    entry["ratio_batch"] = _ratio(entry["batch"], out["cpm_nlp"]["batch"])
    out["peers"]["pylinkage"] = entry
    return out


# ---------------------------------------------------------------- comparison


def _agreement(ref: np.ndarray, ref_ok: np.ndarray, x: np.ndarray, ok: np.ndarray, names) -> dict:
    both = ref_ok & ok
    diff = np.abs(x[both] - ref[both]) if both.any() else np.zeros((0, len(names)))
    return {
        "output": f"platform position ({', '.join(names)}), m",
        "compared_poses": int(both.sum()),
        "solved_by_peer": int(ok.sum()),
        "solved_by_cpm_nlp": int(ref_ok.sum()),
        "max_abs_diff_m": {n: float(diff[:, k].max()) if len(diff) else None for k, n in enumerate(names)},
        "max_abs_diff_m_all": float(diff.max()) if diff.size else None,
    }


def _ratio(peer: dict, cpm: dict) -> dict:
    return {k: peer[k] / cpm[k] for k in ("cpu_us_per_pose", "wall_us_per_pose")}


def run_mechanism(name: str, args, peers: dict) -> dict:
    model = cn.build_model(name, {})
    rng = np.random.default_rng(args.seed)
    qs = model.q_home + rng.uniform(-args.half, args.half, (args.n, model.closure.nq))
    names = list(model.closure.x_names)
    x_ref, ok_ref = cpm_solve(model, qs)
    out: dict = {
        "mechanism_file": f"problems/mechanisms/{name}.yaml",
        "parameters_SI": dict(model.parameters),
        "poses": args.n,
        "seed": args.seed,
        "q_half_width_rad": args.half,
        "cpm_nlp": {"solved": int(ok_ref.sum()), **_cpm_timings(model, qs, args.single, args.repeat)},
        "peers": {},
    }
    cpm = out["cpm_nlp"]
    pin = peers.get("pinocchio")
    if pin is not None:
        loop = pinocchio_five_bar(pin, model) if name == "five_bar" else pinocchio_delta(pin, model)
        x, ok = loop.solve_all(qs)
        q_home = loop.q_home
        entry = {
            "agreement": _agreement(x_ref, ok_ref, x, ok, names),
            "newton_steps_per_pose": loop.steps / len(qs),
            # one computeJointJacobians + updateFramePlacements (Pinocchio's C++ part of a step)
            "kinematics_only": _time(
                lambda: [loop.kinematics(q_home) for _ in range(args.single)], args.repeat, args.single
            ),
            "single": _time(lambda: [loop.solve(q) for q in qs[: args.single]], args.repeat, args.single),
            "batch": _time(lambda: loop.solve_all(qs), args.repeat, len(qs)),
            "what": "Newton on the loop constraint with Pinocchio's kinematics, a Python loop",
        }
        entry["ratio_single"] = _ratio(entry["single"], cpm["single"])
        entry["ratio_batch"] = _ratio(entry["batch"], cpm["batch"])
        out["peers"]["pinocchio"] = entry
    else:
        out["peers"]["pinocchio"] = {"skipped": "pin (Pinocchio) is not installed"}
    pl = peers.get("pylinkage")
    if name != "five_bar":
        out["peers"]["pylinkage"] = {"skipped": "pylinkage is planar: no spatial Delta"}
    elif pl is not None:
        linkage = PylinkageFiveBar(pl, model)
        x, ok = linkage.solve_all(qs)
        batch, jit = pylinkage_batch(model)
        xb, okb = batch(qs)
        entry = {
            "agreement": _agreement(x_ref, ok_ref, x, ok, names),
            "agreement_batch": _agreement(x_ref, ok_ref, xb, okb, names),
            "single": _time(lambda: [linkage.solve(q) for q in qs[: args.single]], args.repeat, args.single),
            "batch": _time(lambda: batch(qs), args.repeat, len(qs)),
            "batch_numba": bool(jit),
            "what": "single: Crank/RRRDyad objects, RRRDyad.reload; batch: solver kernels in one "
            + ("numba loop" if jit else "Python loop (numba not installed)"),
        }
        entry["ratio_single"] = _ratio(entry["single"], cpm["single"])
        entry["ratio_batch"] = _ratio(entry["batch"], cpm["batch"])
        out["peers"]["pylinkage"] = entry
    else:
        out["peers"]["pylinkage"] = {"skipped": "pylinkage is not installed"}
    return out


def _print(name: str, res: dict) -> None:
    cpm = res["cpm_nlp"]
    where = res.get("poses_are") or f"q_home +- {res['q_half_width_rad']} rad, seed {res['seed']}"
    print(f"\n{name} ({res['poses']} poses, {where})")
    print(f"{'solver':28s} {'single CPU/wall us':>22s} {'batch CPU/wall us':>22s} {'load':>12s}  max|dx| m")

    def row(label, e, agree):
        s, b = e["single"], e["batch"]
        print(
            f"{label:28s} {s['cpu_us_per_pose']:10.2f} /{s['wall_us_per_pose']:9.2f} "
            f"{b['cpu_us_per_pose']:10.3f} /{b['wall_us_per_pose']:9.3f} "
            f"{s['load_1min'][0]:5.1f}-{b['load_1min'][1]:5.1f}  {agree}"
        )

    row("cpm_nlp", cpm, "(reference)")
    for peer, e in res["peers"].items():
        if "skipped" in e:
            print(f"{peer:28s} skipped: {e['skipped']}")
            continue
        a = e["agreement"]
        row(peer, e, f"{a['max_abs_diff_m_all']:.2e} ({a['compared_poses']} poses)")
        r = e["ratio_single"]["cpu_us_per_pose"], e["ratio_batch"]["cpu_us_per_pose"]
        print(f"{'':28s} ratio to cpm_nlp (CPU): single {r[0]:.2f}x, batch {r[1]:.2f}x")
        if "kinematics_only" in e:
            k = e["kinematics_only"]["cpu_us_per_pose"]
            print(f"{'':28s} {e['newton_steps_per_pose']:.2f} Newton steps per pose; kinematics alone {k:.2f} us CPU")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=2000, help="poses per mechanism (batch, agreement)")
    ap.add_argument("--single", type=int, default=200, help="poses timed as single solves")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--half", type=float, default=0.25, help="half-width of the actuator box about home, rad")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--mechanisms", default="five_bar,delta,jansen")
    ap.add_argument("--jansen-n", type=int, default=360, help="crank angles over Jansen's turn")
    ap.add_argument("--json", type=Path, default=ROOT / "benchmarks" / "bench_peers.json")
    args = ap.parse_args(argv)
    args.single = max(1, min(args.single, args.n))
    peers = {"pinocchio": _peer("pinocchio", "pin (Pinocchio)"), "pylinkage": _peer("pylinkage", "pylinkage")}
    versions = {k: getattr(v, "__version__", "?") for k, v in peers.items() if v is not None}
    load_before = os.getloadavg()
    results = {}
    for m in args.mechanisms.split(","):
        results[m] = run_jansen(args, peers) if m == "jansen" else run_mechanism(m, args, peers)
    out = {
        "issue": 23,
        "item": "7: a peer benchmark",
        "versions": {"cpm_nlp": cn.__version__, "numpy": np.__version__, **versions},
        "mechanisms": results,
        "loadavg_before": load_before,
        "loadavg_after": os.getloadavg(),
        "machine": platform.platform(),
        "python": platform.python_version(),
        "cpus": os.cpu_count(),
    }
    for m, res in results.items():
        _print(m, res)
    args.json.write_text(json.dumps(out, indent=2) + "\n")
    print(f"\nwritten: {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
