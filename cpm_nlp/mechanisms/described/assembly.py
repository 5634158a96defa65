"""The reference configuration of a graph of bodies and joints, assembled from its drawing:
Gauss-Newton on the loops with the actuators at their ``home`` values, for any parameter
values; at the parameters' defaults, the loop rows independent there (`mobility`) and
the signs the branch indicators take there."""

from __future__ import annotations

import logging
import math
from typing import Any

import casadi as ca
import numpy as np

from ...core.errors import InputError
from .graph_tree import loop_bodies
from .mobility import GraphInfo, gruebler, independent_rows, mobility_message

log = logging.getLogger(__name__)

#: the assembly: Gauss-Newton steps, and the residual (over the characteristic length) it reaches
ASSEMBLY_STEPS, ASSEMBLY_TOL = 60, 1e-12


class Assembler:
    """The reference configuration of a graph by assembly from its drawing, and the loops' rank.

    ``assembler(p) -> (x_home, q_home)``: Gauss-Newton (minimum-norm steps, halved until the
    residual falls) on every loop row and the platform rows, from the drawing, with the actuators
    at their drawing values; an [`InputError`][cpm_nlp.core.errors.InputError] when it does not assemble."""

    def __init__(self, gen: Any, q: ca.SX, span: ca.SX) -> None:
        self.gen = gen
        x, p = gen.x, gen.p
        act = gen.actuation()
        rows = ca.vertcat(*[r[0] for r in gen.loop_rows], *[r[0] for r in act], *[r[0] for r in gen.platform_rows])
        self.names = [r[1] for r in gen.loop_rows] + [r[1] for r in act] + [r[1] for r in gen.platform_rows]
        self.nloop = len(gen.loop_rows)
        self.F = ca.Function(
            "assembly_rows",
            [x, q, p],
            [rows, ca.jacobian(rows, x), ca.jacobian(rows, q)],
            ["x", "q", "p"],
            ["r", "r_x", "r_q"],
        )
        self.draw = ca.Function(
            "drawing_pose", [p], [gen.x_home, ca.vertcat(*gen.q_home), span], ["p"], ["x", "q", "span"]
        )
        self.defaults = gen.p_default
        self.info: GraphInfo | None = None
        self._cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    # -- assembly ----------------------------------------------------------------------------
    def solve(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
        x0, q0, span = (np.asarray(v, dtype=float).ravel() for v in self.draw(p))
        x = x0.copy()
        tol = ASSEMBLY_TOL * max(float(span[0]), 1e-9)
        r, J, _Jq = (np.asarray(v, dtype=float) for v in self.F(x, q0, p))
        r = r.ravel()
        start = float(np.max(np.abs(r))) if r.size else 0.0
        steps = 0
        while r.size and np.all(np.isfinite(r)) and np.max(np.abs(r)) > tol and steps < ASSEMBLY_STEPS:
            if not np.all(np.isfinite(J)):  # a derivative that is not finite (a root at 0): no step to take
                break
            step = np.linalg.lstsq(J, -r, rcond=None)[0]
            norm, alpha = float(np.linalg.norm(r)), 1.0
            while alpha > 1e-6:
                trial = x + alpha * step
                rt = np.asarray(self.F(trial, q0, p)[0], dtype=float).ravel()
                if np.all(np.isfinite(rt)) and np.linalg.norm(rt) < norm:
                    break
                alpha /= 2
            else:
                break
            x = trial
            r, J, _Jq = (np.asarray(v, dtype=float) for v in self.F(x, q0, p))
            r = r.ravel()
            steps += 1
        worst = int(np.argmax(np.abs(r))) if r.size else 0
        ok = bool(r.size == 0 or (np.all(np.isfinite(r)) and abs(r[worst]) <= tol))
        moved = x - x0
        status = {
            "assembled": ok,
            "steps": steps,
            "residual_at_drawing": start,
            "residual": float(np.max(np.abs(r))) if r.size else 0.0,
            "worst_row": self.names[worst] if r.size else "",
            "largest_move": (self.gen.x_names[int(np.argmax(np.abs(moved)))], float(np.max(np.abs(moved))))
            if moved.size
            else ("", 0.0),
        }
        return x, q0, status

    def __call__(self, p: Any) -> tuple[np.ndarray, np.ndarray]:
        p = np.asarray(p, dtype=float).ravel()
        key = p.tobytes()
        hit = self._cache.get(key)
        if hit is not None:
            return hit[0].copy(), hit[1].copy()
        x, q, status = self.solve(p)
        if not status["assembled"]:
            raise InputError(
                f"the reference configuration does not assemble from the drawing: after {status['steps']} "
                f"Gauss-Newton step(s) the residual is {status['residual']:.3e} (SI) in {status['worst_row']} "
                f"(at the drawing {status['residual_at_drawing']:.3e})",
                path=("joints",),
                hint="draw the mechanism closer to an assembled configuration on the branch you want, or check "
                "that the links can close with these parameters",
            )
        log.debug("%s: assembled from the drawing in %d step(s)", self.gen.d.name, status["steps"])
        if len(self._cache) < 64:
            self._cache[key] = (x.copy(), q.copy())
        return x, q

    # -- the loops' rank -------------------------------------------------------------------------
    def select_rows(self) -> list[int]:
        """The loop rows independent at the reference configuration (with the parameters'
        defaults), in file order; the mobility and Grübler-Kutzbach counts for ``describe``."""
        gen = self.gen
        x, q, status = self.solve(self.defaults)
        if not status["assembled"]:
            raise self._unassembled(status)
        _r, Jx, _Jq = (np.asarray(v, dtype=float) for v in self.F(x, q, self.defaults))
        cols = gen.tree_columns()
        J = Jx[: self.nloop][:, cols]
        keep = independent_rows(J)
        self.J_ref, self.tree_names = J, [gen.x_names[k] for k in cols]
        self.info = GraphInfo(
            bodies=[b.name for b in gen.d.bodies],
            ground=gen.ground,
            joints=[(g.name, g.type, g.a, g.b, g.spec.actuated is not None, g.tree, g.loop) for g in gen.gjoints],
            loops=[(g.loop, g.name, loop_bodies(gen.parent, g)) for g in gen.gjoints if not g.tree],
            gruebler=gruebler(gen.gjoints, len(gen.d.bodies), gen.d.platform.planar),
            mobility=len(cols) - len(keep),
            dropped=[(int(self.names[k].split()[1]), self.names[k]) for k in range(self.nloop) if k not in keep],
        )
        self.x_ref, self.q_ref = x, q
        return keep

    def _unassembled(self, status: dict[str, Any]) -> InputError:
        """Why the reference configuration does not assemble with the parameters' defaults: the
        actuators lock the loops at the drawing, or the drawing is too far from closing."""
        gen = self.gen
        x0, _q0, _span = (np.asarray(v, dtype=float).ravel() for v in self.draw(self.defaults))
        Jx = np.asarray(self.F(x0, _q0, self.defaults)[1], dtype=float)
        cols = gen.tree_columns()
        try:
            free = len(cols) - int(np.linalg.matrix_rank(Jx[: self.nloop][:, cols]))
        except np.linalg.LinAlgError:  # no rank: the drawing has no value (a point out of reach: NaN)
            free = len(gen.q_coords)
        if free < len(gen.q_coords):  # the actuators lock the loops against each other
            return InputError(
                f"wrong mobility: at the drawing the loops leave {free} degree(s) of freedom, and "
                f"{len(gen.q_coords)} joint(s) are actuated ({', '.join(c.name for c in gen.q_coords)}); "
                "actuate fewer joints (the reference configuration cannot assemble with all of them held)",
                path=("joints",),
            )
        return InputError(
            f"the reference configuration does not assemble from the drawing with the parameters' defaults: "
            f"after {status['steps']} step(s) the residual is {status['residual']:.3e} (SI) in "
            f"{status['worst_row']}",
            path=("joints",),
            hint="draw the mechanism closer to an assembled configuration, or check the link lengths",
        )

    def mobility_message(self) -> str:
        return mobility_message(self.info, self.gen.q_coords, self.J_ref, self.tree_names)

    def reference_sign(self, d: ca.SX) -> float:
        gen = self.gen
        f = ca.Function("block_det", [gen.x, ca.vertcat(*gen.q_syms), gen.p], [d])
        v = float(f(self.x_ref, self.q_ref, self.defaults))
        if not (math.isfinite(v) and v != 0.0):
            raise InputError(
                "the reference configuration is singular: a loop's Jacobian loses rank there (its links are "
                "aligned); draw the mechanism away from the singular configuration",
                path=("joints",),
            )
        return 1.0 if v > 0 else -1.0


__all__ = ["Assembler"]
