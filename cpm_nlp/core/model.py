"""Mechanisms as symbolic loop closures.

A mechanism type is a [`LoopClosure`][cpm_nlp.core.model.LoopClosure]: the CasADi equations
Φ(x, q; p) = 0 with

* x -- platform pose plus any passive coordinates, size nx,
* q -- actuated joints, size nq,
* p -- geometry parameters, size np,

and, optionally, a closed-form inverse kinematics, the passive joint angles
and an assembly-branch indicator.  Everything else -- Φ_x, Φ_q, the forward
and inverse Jacobians -- is derived from Φ by algorithmic differentiation,
once per mechanism type.

A [`Model`][cpm_nlp.core.model.Model] is a mechanism type with numbers: parameter values and joint
limits (Pinocchio's split: the model holds constants, algorithms in
`cpm_nlp.core.kinematics` are free functions over it).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from .solver import SolverConfig, SquareSolver, solvers_of


@dataclass(frozen=True)
class Coordinate:
    """A named scalar coordinate.

    Attributes
    ----------
    kind
        physical dimension ("length" or "angle").
    family
        joints of the same kind share limits (s1, s2, s3 -> "s").
    """

    name: str
    kind: str
    description: str = ""
    family: str = ""

    @property
    def group(self) -> str:
        return self.family or self.name


def _names(coords: Sequence[Coordinate]) -> list[str]:
    return [c.name for c in coords]


class LoopClosure:
    """Symbolic description of one mechanism type.

    Parameters
    ----------
    name
        mechanism type, e.g. "prs3".
    x, q
        coordinates of the pose (nx) and of the actuators (nq).
    parameters
        names of the geometry parameters p (np), in order.
    phi
        ``ca.Function("phi", [x, q, p], [phi], ["x", "q", "p"], ["phi"])``,
        nx residuals, each in ``residual_unit``.
    task
        names (in x) of the nq independent output coordinates.
    ik
        optional closed form, ``("ik", [t, p], [x, q, reach])``; ``reach < 0``
        when the pose cannot be assembled.
    passive
        optional ``("passive", [x, q, p], [j])`` with one entry per
        ``passive_coords``.
    branch
        optional ``("branch", [x, q, p], [g])``: all g > 0 on the assembly
        branch the model designates.
    home
        ``p -> (x_home, q_home)`` (numpy), the reference configuration and the
        default initial guess.
    bounds
        ``p -> (x_lower, x_upper)`` (numpy) used by IPOPT to stay on the branch.
    offsets
        input/output names for coordinates measured from the home pose,
        e.g. ``{"dz": "pz"}`` (dz = pz - pz_home).
    branch_names, branch_descriptions
        optional name and meaning of each branch indicator (a ``wrong_branch``
        message names the one that failed); default ``g[k]``.
    frame
        optional ``("frame", [x, p], [R, position])``: the platform's rotation
        matrix (3 x 3) and position (3); assembly modes are told apart on it
        (not on angles, which alias).
    fk_closed
        optional closed-form FK of the whole closure, ``("fk_closed", [q, x0, p], [x, disc, side])``
        (planar dyads: `cpm_nlp.mechanisms.described.dyads`, ``graph_dyads``); ``disc < 0``
        where it cannot assemble the pose, ``side <= 0`` where the guess x0 lies in another assembly
        than the one it takes (x0 also picks the turn of an angle).  The FK kernel tries it first
        and keeps it only where the pose checks pass (`cpm_nlp.core.kernels.fk_kernel`).
    fk_seed
        optional ``("fk_seed", [q, x0, p], [x0_seed])``: where only part of the closure is solved
        in closed form (some dyads before a group they cannot place), the guess Newton starts from
        -- those coordinates in closed form, the others x0's (x0 itself where a dyad does not
        assemble or x0 lies in another assembly); Newton's status stands.
    """

    def __init__(
        self,
        name: str,
        *,
        x: Sequence[Coordinate],
        q: Sequence[Coordinate],
        parameters: Sequence[str],
        phi: ca.Function,
        task: Sequence[str],
        home: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
        bounds: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
        ik: ca.Function | None = None,
        passive: ca.Function | None = None,
        passive_coords: Sequence[Coordinate] = (),
        branch: ca.Function | None = None,
        offsets: Mapping[str, str] | None = None,
        residual_unit: str = "m",
        branch_names: Sequence[str] = (),
        branch_descriptions: Sequence[str] = (),
        frame: ca.Function | None = None,
        loops: ca.Function | None = None,
        fk_closed: ca.Function | None = None,
        fk_seed: ca.Function | None = None,
    ) -> None:
        self.name = name
        self.fk_closed = fk_closed
        self.fk_seed = fk_seed
        #: every closure equation (m >= nx rows), when phi holds a square combination of them (an
        #: overconstrained linkage's normal equations): a pose is checked against these too, and the
        #: closure's conditioning is that of their Jacobian (`cond_matrix`); None: phi's own
        self.loops = loops
        self.x = tuple(x)
        self.q = tuple(q)
        self.parameters = tuple(parameters)
        self.task = tuple(task)
        self.phi = phi
        self.ik = ik
        self.passive = passive
        self.passive_coords = tuple(passive_coords)
        self.branch = branch
        self.home = home
        self.bounds = bounds
        self.residual_unit = residual_unit
        self.offsets = dict(offsets or {})
        nb = branch.size1_out(0) if branch is not None else 0
        self.branch_names = tuple(branch_names) or tuple(f"g[{k}]" for k in range(nb))
        self.branch_descriptions = tuple(branch_descriptions) or ("",) * nb
        if len(self.branch_names) != nb or len(self.branch_descriptions) != nb:
            raise ValueError(f"{name}: {nb} branch indicators, {len(self.branch_names)} names")
        self.frame = frame
        self.nx, self.nq, self.np = len(self.x), len(self.q), len(self.parameters)
        x_names = _names(self.x)
        missing = [t for t in self.task if t not in x_names]
        if missing or len(self.task) != self.nq:
            raise ValueError(f"{name}: task coordinates {self.task} must be {self.nq} names of x")
        self.task_index = np.array([x_names.index(t) for t in self.task], dtype=int)
        self.dep_index = np.array([i for i in range(self.nx) if i not in set(self.task_index)], dtype=int)
        if phi.size1_out(0) != self.nx:
            raise ValueError(f"{name}: phi has {phi.size1_out(0)} rows, expected nx = {self.nx}")
        self._derive()

    # -- AD-derived functions ------------------------------------------------
    def _derive(self) -> None:
        """The AD-derived functions every solve uses, now: Φ_x, Φ_q and the FK residual; the
        others (`cond_matrix`, `phi_y`, `jacobian`, `inverse_jacobian`, `ik_residual`) are
        made on first use (about 2 ms of symbolic work a forward-kinematics solve never needs;
        issue 23, start-up)."""
        x = ca.SX.sym("x", self.nx)
        q = ca.SX.sym("q", self.nq)
        p = ca.SX.sym("p", self.np)
        phi = self.phi(x, q, p)
        phi_x = ca.jacobian(phi, x)
        phi_q = ca.jacobian(phi, q)
        self._symbols = (x, q, p, phi_x, phi_q)
        io = (["x", "q", "p"],)
        self.phi_x = ca.Function("phi_x", [x, q, p], [phi_x], *io, ["phi_x"])
        self.phi_q = ca.Function("phi_q", [x, q, p], [phi_q], *io, ["phi_q"])
        # residuals in the solver layout: FK unknown x, known (q, p); IK unknown (x_dep, q), known (t, p)
        w_fk = ca.SX.sym("w", self.nq + self.np)
        self.fk_residual = ca.Function(
            "fk_residual", [x, w_fk], [self.phi(x, w_fk[: self.nq], w_fk[self.nq :])], ["x", "w"], ["phi"]
        )

    @functools.cached_property
    def cond_matrix(self) -> ca.Function:
        """The matrix whose 2-norm condition number says how near a singularity the pose is: Φ_x, or
        for normal equations (phi = Aᵀ e with e every closure equation, where Φ_x ≈ e_xᵀ e_x up to
        scaling squares the condition number) the Jacobian e_x of every closure equation -- the
        same measure as a square closure's, which is its own e."""
        x, q, p, phi_x, _phi_q = self._symbols
        cond_x = phi_x if self.loops is None else ca.jacobian(self.loops(x, q, p), x)
        return ca.Function("cond_matrix", [x, q, p], [cond_x], ["x", "q", "p"], ["cond_x"])

    @functools.cached_property
    def _inverse_blocks(self) -> tuple[ca.SX, ca.SX]:
        """Φ_y = ∂Φ/∂(x_dep, q) and dy/dt: the inverse problem's unknowns y given the task coordinates t."""
        _x, _q, _p, phi_x, phi_q = self._symbols
        phi_t = phi_x[:, list(self.task_index)]
        phi_y = ca.horzcat(phi_x[:, list(self.dep_index)], phi_q)
        return phi_y, -ca.solve(phi_y, phi_t)

    @functools.cached_property
    def phi_y(self) -> ca.Function:
        x, q, p, _phi_x, _phi_q = self._symbols
        return ca.Function("phi_y", [x, q, p], [self._inverse_blocks[0]], ["x", "q", "p"], ["phi_y"])

    @functools.cached_property
    def jacobian(self) -> ca.Function:
        """The forward Jacobian by the implicit function theorem: dx/dq = -Φ_x⁻¹ Φ_q."""
        x, q, p, phi_x, phi_q = self._symbols
        return ca.Function("jacobian", [x, q, p], [-ca.solve(phi_x, phi_q)], ["x", "q", "p"], ["J"])

    @functools.cached_property
    def inverse_jacobian(self) -> ca.Function:
        x, q, p, _phi_x, _phi_q = self._symbols
        jac_inv = self._inverse_blocks[1][len(self.dep_index) :, :]
        return ca.Function("inverse_jacobian", [x, q, p], [jac_inv], ["x", "q", "p"], ["J_inv"])

    @functools.cached_property
    def ik_residual(self) -> ca.Function:
        nd = len(self.dep_index)
        y = ca.SX.sym("y", nd + self.nq)
        w_ik = ca.SX.sym("w", self.nq + self.np)
        x_full = self.assemble_x(w_ik[: self.nq], y[:nd])
        return ca.Function("ik_residual", [y, w_ik], [self.phi(x_full, y[nd:], w_ik[self.nq :])], ["y", "w"], ["phi"])

    def assemble_x(self, t: Any, d: Any) -> Any:
        """x from its task part t and dependent part d (symbolic or numeric)."""
        parts: list[Any] = [None] * self.nx
        for k, i in enumerate(self.task_index):
            parts[i] = t[k]
        for k, i in enumerate(self.dep_index):
            parts[i] = d[k]
        if isinstance(t, (ca.SX, ca.MX)) or isinstance(d, (ca.SX, ca.MX)):
            return ca.vertcat(*parts)
        return np.array([float(v) for v in parts])

    # -- solvers (built once per configuration, held by core.solver.solvers_of) ----
    def fk_solver(self, config: SolverConfig) -> SquareSolver:
        return solvers_of(self).get(
            "fk", config, lambda: SquareSolver(f"{self.name}_fk", self.fk_residual, self.nx, self.nq + self.np, config)
        )

    def ik_solver(self, config: SolverConfig) -> SquareSolver:
        ny = len(self.dep_index) + self.nq
        return solvers_of(self).get(
            "ik", config, lambda: SquareSolver(f"{self.name}_ik", self.ik_residual, ny, self.nq + self.np, config)
        )

    @property
    def x_names(self) -> list[str]:
        return _names(self.x)

    @property
    def q_names(self) -> list[str]:
        return _names(self.q)

    @property
    def passive_names(self) -> list[str]:
        return _names(self.passive_coords)


@dataclass
class Model:
    """A mechanism with numbers.

    Attributes
    ----------
    closure
        the symbolic mechanism type.
    parameters
        geometry, SI, in the order of ``closure.parameters``.
    limits
        joint limits ``name -> (low, high)`` (SI) for actuators and passive joints; a family
        name ("s", "alpha") applies to all its members.
    derived
        quantities that follow from the parameters (e.g. the 3-PRS actuator circle radius a),
        reported with results; a vector (a mechanism file's derived point) is a list of floats
        under its name.
    """

    closure: LoopClosure
    parameters: Mapping[str, float]
    limits: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    derived: Mapping[str, float | list[float]] = field(default_factory=dict)
    dimensions: Mapping[str, str] = field(default_factory=dict)  # of parameters and derived values
    #: length that converts angle rates to length rates in conditioning measures
    characteristic_length: float = 1.0
    #: the `Mechanism` declaration the model was built from (its
    #: parts), set by `Mechanism.model`; None for
    #: a model built by hand on its closure
    mechanism: Any = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        missing = [n for n in self.closure.parameters if n not in self.parameters]
        if missing:
            raise ValueError(f"{self.closure.name}: missing parameters {missing}")
        self.p = np.array([float(self.parameters[n]) for n in self.closure.parameters])
        self.x_home, self.q_home = (np.asarray(v, dtype=float) for v in self.closure.home(self.p))
        self.x_lower, self.x_upper = (np.asarray(v, dtype=float) for v in self.closure.bounds(self.p))

    @property
    def name(self) -> str:
        return self.closure.name

    def limit_of(self, coord: Coordinate) -> tuple[float, float] | None:
        """Declared limits of a coordinate (its own, else its family's)."""
        if coord.name in self.limits:
            return self.limits[coord.name]
        return self.limits.get(coord.family) if coord.family else None

    def task_of(self, x: np.ndarray) -> np.ndarray:
        return np.asarray(x, dtype=float)[self.closure.task_index]
