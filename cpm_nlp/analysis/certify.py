"""A certificate that a box of task coordinates lies inside the reachable workspace.

For a mechanism with a closed-form IK (``LoopClosure.ik``: t -> x, q, reach)
every quantity that decides membership (`cpm_nlp.analysis.workspace.membership`)
is an explicit function of the task point t: the reach margin (>= 0: the
mechanism assembles), the limited quantities with declared limits (actuator
strokes, pose coordinates, passive joints), the branch indicators (>= 0) and
Φ_x (regular, condition number below ``SINGULAR_CONDITION``).  The
certificate proves, for **every** point of the box (not samples of it), that

* reach(t) >= 0,
* every bounded quantity v_r(t) lies within [low_r, high_r] (strictly: no
  tolerance), and
* Φ_x(t) is regular with cond₂ below the membership test's threshold,

by branch and bound over sub-boxes:

1. the interval extension of those functions (`IntervalProgram`,
   the CasADi SX graph replayed on intervals with outward rounding) encloses
   their range over each sub-box, vectorised over all sub-boxes of a round;
2. where that enclosure does not prove a bound, the **monotonicity test**
   sharpens it: where the interval Jacobian ∂v_r/∂t_i over the sub-box has one
   sign, the lowest (highest) value of v_r lies on the face t_i = low or
   high, and the function is enclosed over that face instead (exact at a
   corner when v_r is monotone in every coordinate);
3. regularity of every Φ_x over a sub-box: with C ≈ mid(Φ_x)⁻¹,
   ‖I - C·Φ_x‖_∞ <= r < 1 for all Φ_x of the interval matrix (matrix product
   error bounded by γ_n|C||mid|) proves them all regular, and
   cond₂ <= n ‖Φ_x‖_∞ ‖C‖_∞ / (1 - r);
4. a sub-box not proven is split in two along the coordinate with the
   largest smear (|∂v/∂t_i| times its width, over the rows not proven); its
   centre is first evaluated as a degenerate interval: a bound proven
   violated there ends the search with that sub-box as the failing region.

The search ends with ``certified`` when every sub-box is proven; otherwise
with the first sub-box (breadth first) where the proof failed -- either a
point proven outside, or a sub-box below the smallest width (or beyond the
budget of sub-boxes) whose bounds could not be proven -- and the quantity
that could not be proven.  An uncertified box is never reported certified.

The closed-form IK is taken to solve Φ = 0 wherever reach >= 0 (it is the
mechanism's closed form; the tests check FK against IK); the certificate
covers the limits, the assembly condition, the branch and the regularity.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import casadi as ca
import numpy as np

from ..core import progress
from ..core.model import LoopClosure, Model
from ..core.options import Option
from ..core.solver import solvers_of
from .intervals import IntervalProgram, UnsupportedOperation
from .workspace import SINGULAR_CONDITION, limit_bounds, limited_function

log = logging.getLogger(__name__)

#: sub-boxes evaluated in one vectorised round at most
BATCH = 4096
#: the search gives up (uncertified) after this many sub-boxes
MAX_BOXES = 50_000
#: and at sub-boxes narrower than this fraction of the box in every coordinate
MIN_WIDTH = 1e-10
#: sub-box budget of each certificate in the search for the largest certified shrink
SHRINK_BOXES = 5_000
#: unit roundoff of IEEE double
_U = np.finfo(float).eps / 2


@dataclass
class Certificate:
    """Whether every point of a box of task coordinates is in the workspace.

    Attributes
    ----------
    certified
        proven for every point of the box.
    margin
        the smallest proven margin of a bounded quantity over the box (SI of ``binding``; > 0
        only if certified, else None);
    condition
        the proven upper bound of cond₂(Φ_x) over the box (None unless certified).
    boxes
        sub-boxes evaluated;
    depth
        deepest split;
    seconds
        wall time.
    failing_lower, failing_upper
        the first sub-box where the proof failed;
    failing_quantity
        the bound that could not be proven there ("reach" for the assembly condition, "singular"
        for the regularity of Φ_x);
    counterexample
        a point of it proven outside, if one was found.
    """

    certified: bool
    message: str
    margin: float | None = None
    binding: str = ""
    condition: float | None = None
    boxes: int = 0
    depth: int = 0
    seconds: float = 0.0
    failing_lower: np.ndarray | None = None
    failing_upper: np.ndarray | None = None
    failing_quantity: str = ""
    counterexample: np.ndarray | None = None
    details: dict = field(default_factory=dict)

    def region(self, names: list[str] | tuple[str, ...]) -> str:
        """The failing sub-box as text, e.g. ``px in [0.07, 0.071], ...`` (empty if certified)."""
        if self.failing_lower is None:
            return ""
        return ", ".join(
            f"{n} in [{lo:.10g}, {hi:.10g}]" for n, lo, hi in zip(names, self.failing_lower, self.failing_upper)
        )


@dataclass
class _Programs:
    full: IntervalProgram  # (t, p) -> (g, J, phi_x)
    values: IntervalProgram  # (t, p) -> g
    rows: tuple[int, ...]
    names: tuple[str, ...]


def certificate_programs(closure: LoopClosure, rows: tuple[int, ...]) -> _Programs:
    """The interval programs of the certified quantities g = (reach, limited[rows]),
    their Jacobian in t and Φ_x (built once per mechanism type and row set)."""

    def build() -> _Programs:
        c = closure
        fn, names = limited_function(c)
        t, p = ca.SX.sym("t", c.nq), ca.SX.sym("p", c.np)
        x, q, reach = c.ik(t, p)
        g = ca.vertcat(reach, fn(x, q, p)[list(rows)])
        J = ca.densify(ca.jacobian(g, t))
        PX = ca.densify(c.phi_x(x, q, p))
        full = ca.Function(f"{c.name}_certify", [t, p], [g, J, PX], ["t", "p"], ["g", "J", "phi_x"])
        values = ca.Function(f"{c.name}_certify_g", [t, p], [g], ["t", "p"], ["g"])
        return _Programs(
            IntervalProgram(full), IntervalProgram(values), tuple(rows), ("reach",) + tuple(names[r] for r in rows)
        )

    return solvers_of(closure).memo(("certify", tuple(rows)), build)


def _column_major(lo: np.ndarray, hi: np.ndarray, n: int, m: int) -> tuple[np.ndarray, np.ndarray]:
    """(B, n*m) column-major nonzeros of a dense n×m matrix as (B, n, m)."""
    B = lo.shape[0]
    return lo.reshape(B, m, n).transpose(0, 2, 1), hi.reshape(B, m, n).transpose(0, 2, 1)


def regularity(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Whether every matrix of the interval matrices [lo, hi] (B, n, n) is regular, and
    an upper bound of their cond₂ (inf where not proven).

    With C ≈ mid⁻¹: ‖I - C A‖_∞ <= ‖|I - fl(C mid)| + γ|C||mid| + |C| rad‖_∞ = r
    for every A in the interval matrix (γ = (n+2)u/(1 - (n+2)u) bounds the rounding
    of the products and sums, taken twice over); r < 1 proves A regular with
    ‖A⁻¹‖_∞ <= ‖C‖_∞ / (1 - r), and cond₂(A) <= n ‖A‖_∞ ‖A⁻¹‖_∞.
    """
    B, n, _ = lo.shape
    ok = np.all(np.isfinite(lo) & np.isfinite(hi), axis=(1, 2))
    cond = np.full(B, np.inf)
    if not np.any(ok):
        return np.zeros(B, dtype=bool), cond
    lo, hi = lo[ok], hi[ok]
    mid = 0.5 * (lo + hi)
    rad = np.maximum(hi - mid, mid - lo) * (1 + 4 * _U)
    with np.errstate(all="ignore"):
        try:
            C = np.linalg.inv(mid)
        except np.linalg.LinAlgError:  # some singular midpoint: one by one
            C = np.stack([_safe_inv(m) for m in mid])
        gamma = 2 * (n + 2) * _U / (1 - (n + 2) * _U)
        absC = np.abs(C)
        E = np.abs(np.eye(n) - C @ mid) + gamma * (absC @ np.abs(mid)) + absC @ rad
        r = np.max(np.sum(E, axis=2), axis=1) * (1 + 4 * n * _U)
        normA = np.max(np.sum(np.maximum(np.abs(lo), np.abs(hi)), axis=2), axis=1)
        normC = np.max(np.sum(absC, axis=2), axis=1)
        bound = n * normA * normC / (1 - r) * (1 + 8 * n * _U)
    good = np.isfinite(r) & (r < 1.0) & np.isfinite(bound)
    out = np.zeros(B, dtype=bool)
    out[np.flatnonzero(ok)[good]] = True
    cond[np.flatnonzero(ok)[good]] = bound[good]
    return out, cond


def _safe_inv(m: np.ndarray) -> np.ndarray:
    try:
        return np.linalg.inv(m)
    except np.linalg.LinAlgError:
        return np.full_like(m, np.nan)


def _monotone_refine(prog: _Programs, p: np.ndarray, L, U, Glo, Ghi, Jlo, Jhi, lo_g, hi_g):
    """Sharpen the enclosures of the rows not proven by the natural extension (in
    place): for each such (box, row, side), the face of the box on which the row's
    extreme lies wherever its partial derivative has one sign, enclosed there by the
    better of the natural extension and the mean-value form."""
    with np.errstate(invalid="ignore"):
        need_lo = ~(Glo >= lo_g) & np.isfinite(lo_g)
        need_hi = ~(Ghi <= hi_g) & np.isfinite(hi_g)
    bl, rl = np.nonzero(need_lo)
    bh, rh = np.nonzero(need_hi)
    if bl.size + bh.size == 0:
        return
    boxes = np.r_[bl, bh]
    rows = np.r_[rl, rh]
    lower_side = np.r_[np.ones(bl.size, dtype=bool), np.zeros(bh.size, dtype=bool)]
    jl, jh = Jlo[boxes, rows, :], Jhi[boxes, rows, :]
    inc, dec = jl > 0.0, jh < 0.0  # NaN: neither
    Lr, Ur = L[boxes].copy(), U[boxes].copy()
    # the minimum lies at t_i = low where increasing, high where decreasing; the maximum the other way
    to_low = np.where(lower_side[:, None], inc, dec)
    to_high = np.where(lower_side[:, None], dec, inc)
    Ur = np.where(to_low, Lr, Ur)
    Lr = np.where(to_high, Ur, Lr)
    P = np.broadcast_to(p, (2 * len(boxes), p.size))
    cr = 0.5 * (Lr + Ur)
    ((vlo, vhi),) = prog.values.evaluate([(np.vstack([Lr, cr]), np.vstack([Ur, cr])), (P, P)])
    n = len(boxes)
    k = np.arange(n)
    # natural extension over the face, and the mean-value form about its centre:
    # g(X') ⊆ g(c') + Σ_i J_i(X)·(X'_i - c'_i), J over X ⊇ X'
    nat_lo, nat_hi = vlo[k, rows], vhi[k, rows]
    c_lo, c_hi = vlo[n + k, rows], vhi[n + k, rows]
    radius = np.maximum(Ur - cr, cr - Lr)
    with np.errstate(invalid="ignore", over="ignore"):
        spread = np.sum(np.maximum(np.abs(jl), np.abs(jh)) * radius, axis=1) * (1 + 4 * (radius.shape[1] + 2) * _U)
        mv_lo, mv_hi = np.nextafter(c_lo - spread, -np.inf), np.nextafter(c_hi + spread, np.inf)
    lo_new, hi_new = np.fmax(nat_lo, mv_lo), np.fmin(nat_hi, mv_hi)
    s, h = lower_side, ~lower_side
    Glo[boxes[s], rows[s]] = np.fmax(Glo[boxes[s], rows[s]], lo_new[s])
    Ghi[boxes[h], rows[h]] = np.fmin(Ghi[boxes[h], rows[h]], hi_new[h])


def _batch_margin(Glo, Ghi, lo_g, hi_g, proven, names) -> tuple[float, str]:
    """The smallest margin of the proven sub-boxes of a batch, and the quantity it is of."""
    with np.errstate(invalid="ignore"):
        marg = np.minimum(Glo[proven] - lo_g, hi_g - Ghi[proven])
    marg = np.where(np.isfinite(marg), marg, np.inf)
    k_box, k_row = np.unravel_index(int(np.argmin(marg)), marg.shape)
    return float(marg[k_box, k_row]), names[k_row]


def _violated_centre(prog, p, mid, lo_g, hi_g, names) -> tuple[int, str, str] | None:
    """The first centre of a sub-box where a bound is proven violated: (its index, the
    quantity, the message); None where no centre violates one."""
    Pm = np.broadcast_to(p, (len(mid), p.size))
    ((clo, chi),) = prog.values.evaluate([(mid, mid), (Pm, Pm)])
    with np.errstate(invalid="ignore"):
        violated = (chi < lo_g) | (clo > hi_g)
    out = np.any(violated, axis=1)
    if not np.any(out):
        return None
    k = int(np.flatnonzero(out)[0])
    r = int(np.flatnonzero(violated[k])[0])
    what = "does not assemble (reach < 0)" if r == 0 else f"{names[r]} is outside its limits"
    return k, names[r], f"not certified: at {mid[k].tolist()} the mechanism {what}"


def _unproven(row_ok, Glo, Ghi, lo_g, hi_g, names, box) -> tuple[str, str]:
    """What a sub-box left unproven: the first bound not proven (with its enclosure), else
    the regularity of Φ_x."""
    bad_rows = np.flatnonzero(~row_ok[box])
    if not bad_rows.size:
        return "singular", f"cond(Φ_x) not proven below {SINGULAR_CONDITION:g}"
    r = int(bad_rows[0])
    detail = (
        f"enclosure [{Glo[box, r]:.10g}, {Ghi[box, r]:.10g}] over the sub-box, limits [{lo_g[r]:.10g}, {hi_g[r]:.10g}]"
    )
    return names[r], detail


def _split(Lt, Ut, mid, Jlo, Jhi, unproven_rows, smallest, width0):
    """Each sub-box cut in two along the coordinate of largest smear over the rows not proven."""
    w = Ut - Lt
    jmag = np.maximum(np.abs(Jlo), np.abs(Jhi))  # (n, m, d)
    smear = jmag * w[:, None, :]
    with np.errstate(invalid="ignore", divide="ignore"):
        smear = smear / np.sum(smear, axis=2, keepdims=True)
    smear = np.where(np.isfinite(smear), smear, 0.0)
    weight = np.sum(smear * unproven_rows[:, :, None], axis=1) + 1e-3 * w / np.where(width0 > 0, width0, 1.0)
    weight = np.where(w > smallest, weight, -1.0)
    axis = np.argmax(weight, axis=1)
    k = np.arange(len(Lt))
    cut = mid[k, axis]
    L1, U1 = Lt.copy(), Ut.copy()
    U1[k, axis] = cut
    L2, U2 = Lt.copy(), Ut.copy()
    L2[k, axis] = cut
    return L1, U1, L2, U2


def _no_certificate(model: Model, lower: np.ndarray, upper: np.ndarray) -> str | None:
    """Why the box cannot be certified at all (no closed-form IK, an empty box), else None."""
    if model.closure.ik is None:
        return f"{model.closure.name} has no closed-form IK: no certificate"
    if not np.all(upper >= lower):
        return "the box is empty (upper < lower)"
    return None


def certify_box(
    model: Model,
    lower,
    upper,
    *,
    max_boxes: int = MAX_BOXES,
    min_width: float = MIN_WIDTH,
) -> Certificate:
    """Prove that every point of the box [lower, upper] (task coordinates, SI) lies
    in the reachable workspace, or name the first sub-box where that could not be
    proven (see the module docstring).  Needs a closed-form IK."""
    t0 = time.perf_counter()
    c = model.closure
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    why_not = _no_certificate(model, lower, upper)
    if why_not is not None:
        return Certificate(False, why_not, seconds=time.perf_counter() - t0)
    lo_all, hi_all = limit_bounds(model)
    rows = tuple(int(r) for r in np.flatnonzero(np.isfinite(lo_all) | np.isfinite(hi_all)))
    try:
        prog = certificate_programs(c, rows)
    except UnsupportedOperation as exc:
        return Certificate(False, f"no certificate: {exc}", seconds=time.perf_counter() - t0)
    lo_g = np.r_[0.0, lo_all[list(rows)]]
    hi_g = np.r_[np.inf, hi_all[list(rows)]]
    names = prog.names
    d, nx, m = c.nq, c.nx, len(lo_g)
    p = model.p
    width0 = np.maximum(upper - lower, 0.0)
    smallest = min_width * np.where(width0 > 0, width0, 1.0)
    pending_L, pending_U, pending_depth = lower[None, :], upper[None, :], np.zeros(1, dtype=int)
    boxes, depth = 0, 0
    margin, binding, cond_max = np.inf, "", 0.0

    def fail(message, k, L, U, quantity, point=None) -> Certificate:
        return Certificate(
            False,
            message,
            boxes=boxes,
            depth=depth,
            seconds=time.perf_counter() - t0,
            failing_lower=L[k].copy(),
            failing_upper=U[k].copy(),
            failing_quantity=quantity,
            counterexample=point,
        )

    report = progress.task("certificate", max_boxes)  # sub-boxes of the budget; Ctrl-C between batches
    while len(pending_L):
        report.update(boxes)
        L, U, D = pending_L[:BATCH], pending_U[:BATCH], pending_depth[:BATCH]
        rest = (pending_L[BATCH:], pending_U[BATCH:], pending_depth[BATCH:])
        B = len(L)
        boxes += B
        depth = max(depth, int(D.max()))
        P = np.broadcast_to(p, (B, p.size))
        (Glo, Ghi), (Jlo, Jhi), (Plo, Phi) = prog.full.evaluate([(L, U), (P, P)])
        Jlo, Jhi = _column_major(Jlo, Jhi, m, d)
        _monotone_refine(prog, p, L, U, Glo, Ghi, Jlo, Jhi, lo_g, hi_g)
        with np.errstate(invalid="ignore"):
            row_ok = (Glo >= lo_g) & (Ghi <= hi_g)
        regular, cond = regularity(*_column_major(Plo, Phi, nx, nx))
        regular &= cond < SINGULAR_CONDITION
        proven = np.all(row_ok, axis=1) & regular
        if np.any(proven):
            batch_margin, batch_binding = _batch_margin(Glo, Ghi, lo_g, hi_g, proven, names)
            if batch_margin < margin:
                margin, binding = batch_margin, batch_binding
            cond_max = max(cond_max, float(np.max(cond[proven])))
        todo = np.flatnonzero(~proven)
        if not todo.size:
            pending_L, pending_U, pending_depth = rest
            continue
        # the centres of the sub-boxes not proven: a bound proven violated there ends the search
        Lt, Ut = L[todo], U[todo]
        mid = 0.5 * (Lt + Ut)
        violated = _violated_centre(prog, p, mid, lo_g, hi_g, names)
        if violated is not None:
            k, quantity, message = violated
            return fail(message, k, Lt, Ut, quantity, mid[k].copy())
        small = np.all(Ut - Lt <= smallest, axis=1)
        if np.any(small) or boxes + 2 * todo.size > max_boxes:
            k = int(np.flatnonzero(small)[0]) if np.any(small) else 0
            why = "the smallest sub-box width" if np.any(small) else f"the budget of {max_boxes} sub-boxes"
            quantity, detail = _unproven(row_ok, Glo, Ghi, lo_g, hi_g, names, todo[k])
            return fail(f"not certified: {quantity} not proven within {why} ({detail})", k, Lt, Ut, quantity)
        L1, U1, L2, U2 = _split(Lt, Ut, mid, Jlo[todo], Jhi[todo], ~row_ok[todo], smallest, width0)
        Dn = D[todo] + 1
        pending_L = np.vstack([rest[0], L1, L2])
        pending_U = np.vstack([rest[1], U1, U2])
        pending_depth = np.r_[rest[2], Dn, Dn]
    return Certificate(
        True,
        f"certified: every point of the box is in the workspace ({boxes} sub-boxes, smallest margin "
        f"{margin:.3g} of {binding}, cond(Φ_x) <= {cond_max:.3g})",
        margin=margin,
        binding=binding,
        condition=cond_max,
        boxes=boxes,
        depth=depth,
        seconds=time.perf_counter() - t0,
    )


def largest_certified_shrink(
    model: Model, lower, upper, *, steps: int = 20, max_boxes: int = MAX_BOXES
) -> tuple[float, Certificate]:
    """The largest factor s (to 2^-steps) by which the box, shrunk about its centre,
    is certified, with that box's certificate; (0, the last failure) if none is."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    mid, half = 0.5 * (lower + upper), 0.5 * (upper - lower)
    good, bad = 0.0, 1.0
    best: Certificate | None = None
    last: Certificate | None = None
    for _ in range(steps):
        f = 0.5 * (good + bad)
        cert = certify_box(model, mid - f * half, mid + f * half, max_boxes=max_boxes)
        if cert.certified:
            good, best = f, cert
        else:
            bad, last = f, cert
    return (good, best) if best is not None else (0.0, last)


# -- what the inscribed_cuboid kind reports ------------------------------------------------------

#: the input that asks for the certificate of the cuboid found
CERTIFY_OPTION = Option(
    "certify",
    "bool",
    "prove by interval branch and bound that every point of the cuboid found is in the workspace "
    "(mechanisms with a closed-form IK); if that fails, also find the largest certified shrink of it",
    default=True,
)

#: the values of `certificate_values` and their dimensions
CERTIFICATE_DIMENSIONS: Mapping[str, str] = MappingProxyType(
    {
        "certified": "text",
        "certified_margin": "si",
        "certified_binding": "text",
        "certificate_boxes": "dimensionless",
        "certificate_seconds": "time",
        "certificate_failing": "text",
        "certificate_quantity": "text",
        "certified_shrink": "dimensionless",
        "certified_volume_ratio": "dimensionless",
        "certificate": "text",
    }
)
CERTIFICATE_NAMES = tuple(CERTIFICATE_DIMENSIONS)


def certificate_values(model: Model, lower, upper, enabled: bool = True) -> tuple[dict, dict]:
    """The certificate of the box [lower, upper] as result values and their dimensions:
    ``certified`` (True/False; None when not requested or without a closed-form IK),
    the proven margin and its quantity, sub-boxes, seconds, and, when not certified,
    the failing sub-box and quantity and the largest certified shrink factor about
    the centre (``certified_shrink``; ``certified_volume_ratio`` = its d-th power)."""
    dims = dict(CERTIFICATE_DIMENSIONS)
    values: dict = {k: None for k in CERTIFICATE_NAMES}
    c = model.closure
    if not enabled or lower is None:
        return values, dims
    if c.ik is None:
        values["certificate"] = f"no certificate: {c.name} has no closed-form IK"
        return values, dims
    cert = certify_box(model, lower, upper)
    values.update(
        certified=cert.certified,
        certificate_boxes=cert.boxes,
        certificate_seconds=cert.seconds,
        certificate=cert.message,
    )
    if cert.certified:
        values.update(certified_margin=cert.margin, certified_binding=cert.binding)
        values.update(certified_shrink=1.0, certified_volume_ratio=1.0)
        return values, dims
    values.update(certificate_failing=cert.region(c.task), certificate_quantity=cert.failing_quantity)
    if cert.failing_lower is not None:  # a search that could run: the largest certified shrink
        shrink, best = largest_certified_shrink(model, lower, upper, max_boxes=SHRINK_BOXES)
        values.update(certified_shrink=shrink, certified_volume_ratio=shrink**c.nq)
        if best is not None and best.certified:
            values.update(certified_margin=best.margin, certified_binding=best.binding)
            values["certificate"] += f"; shrunk by a factor {shrink:.6g} about its centre it is certified"
    return values, dims
