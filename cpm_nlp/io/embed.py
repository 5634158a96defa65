"""CasADi Functions of one model, for composing into your own CasADi code.

``functions(model)`` gives the loop closures, forward and inverse kinematics
and the Jacobians of a model as named CasADi Functions with its parameters,
joint limits and tolerance built in::

    import casadi as ca
    import cpm_nlp as cn

    fns = cn.functions(cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm"}))
    q = ca.MX.sym("q", 3)
    x = fns.fk(q=q, x0=fns.x_home)["x"]          # differentiable (implicit function theorem)
    nlp = {"x": q, "f": -x[3], "g": x[2]}          # ... your own optimization

Every Function takes numbers (numpy arrays) or CasADi symbols: MX for
``fk`` and ``ik`` (they contain a rootfinder), SX or MX for the others.  The
FK is the kernel of every Newton FK in cpm_nlp: for a mechanism with a
closed-form IK, Newton on the task coordinates through the IK from the
first-order guess about ``x0``, else (or where that does not settle the pose)
Newton on Φ from ``x0`` (CasADi ``fast_newton``); its ``status`` output is 0
only where the pose passed every check of cpm_nlp (``cn.status_of(code)``
names it).  (Which formulation answered is reported by the solvers'
``PoseSolution.path`` and ``BatchResult.path(i)``; the Function keeps the
outputs it always had.)  Nothing here prints or keeps global
state; the Functions may be called from several threads.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..core.errors import InputError
from ..core.kernels import FK_OUTPUTS, bake, fk_kernel, ik_kernel, jacobian_kernel
from ..core.model import Model
from ..core.solver import SolverConfig


@dataclass(frozen=True)
class ModelFunctions:
    """The CasADi Functions of one model (its numbers built in).

    phi: ``(x, q) -> phi``, the loop closures Φ (nx residuals);
    fk: ``(q, x0) -> (x, passive, residual, branch_margin, round_trip_error,
        cond1, limit_margin, status)``;
    ik: ``(t) -> (x, q, passive, reach, residual, ..., status)`` (closed form;
        mechanisms without one take ``(t, y0)`` and solve by Newton);
    jacobian: ``(x, q) -> (J, J_inv, Phi_x, Phi_q)``;
    passive: ``(x, q) -> j``, passive joint angles (None if the mechanism has none);
    x_home, q_home: the home pose and joints (the default Newton guess).
    """

    model: Model
    phi: ca.Function
    fk: ca.Function
    ik: ca.Function
    jacobian: ca.Function
    passive: ca.Function | None
    x_home: np.ndarray
    q_home: np.ndarray


def _with_parameters(fn: ca.Function, model: Model, name: str) -> ca.Function:
    """``fn(x, q, p)`` as ``name(x, q)`` with the model's p."""
    c = model.closure
    x, q = ca.SX.sym("x", c.nx), ca.SX.sym("q", c.nq)
    outs = fn(x, q, model.p)
    outs = list(outs) if isinstance(outs, (list, tuple)) else [outs]
    return ca.Function(name, [x, q], outs, ["x", "q"], fn.name_out())


def model_functions(model: Model, solver: SolverConfig | None = None) -> ModelFunctions:
    """The CasADi Functions of a model (``cpm_nlp.functions`` also takes a problem file).

    solver: tolerance and Newton options (abstol, abstolStep, max_iter) built
    into fk and ik (default: ``SolverConfig("newton")``).
    """
    if not isinstance(model, Model):
        raise InputError(f"expected a Model or the path of a problem file, got {type(model).__name__}")
    config = solver or SolverConfig("newton")
    c = model.closure
    name = c.name
    return ModelFunctions(
        model=model,
        phi=_with_parameters(c.phi, model, f"{name}_phi"),
        fk=bake(fk_kernel(c, config), model, config.tolerance, outputs=FK_OUTPUTS),
        ik=bake(ik_kernel(c, config), model, config.tolerance),
        jacobian=bake(jacobian_kernel(c), model, config.tolerance),
        passive=_with_parameters(c.passive, model, f"{name}_passive") if c.passive is not None else None,
        x_home=model.x_home.copy(),
        q_home=model.q_home.copy(),
    )
