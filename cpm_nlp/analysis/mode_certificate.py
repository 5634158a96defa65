"""A certificate that an assembly-mode search missed no real mode in its region.

[`cpm_nlp.analysis.assembly.assembly_modes`][cpm_nlp.analysis.assembly.assembly_modes] is a multi-start search: its
completeness is an estimate.  `certify_modes` proves it, where it can,
by interval branch and bound on the closures Φ(x; q, p) = 0 over the search
region (angles a full turn, lengths home ± reach), with the interval
programs of the cuboid certificate (`IntervalProgram`,
outward rounding) and its regularity test (`regularity`).
Every sub-box is, in the end, one of

* **excluded**: the interval enclosure of some Φ_i over the sub-box does not
  contain 0, so no pose in it closes the loops; or
* **one mode**: every matrix of the interval enclosure of Φ_x over the sub-box
  (widened by `MARGIN`) is regular, so Φ has at most one zero there (the
  mean-value form Φ(a) - Φ(b) = M (a - b) with M in that enclosure), and a mode
  the search found lies in it: that zero is the mode.

When every sub-box is settled the certificate holds: the real modes in the
region are exactly those found.  A sub-box neither excluded nor settled is
split in two along its widest coordinate (lengths divided by the reach); the
search stops uncertified at `MAX_BOXES` sub-boxes (or the caller's
``max_boxes``), or at sub-boxes narrower than `MIN_WIDTH`, and says so.
A mode the search missed is never certified away: its sub-boxes are neither
excluded nor settled, and the budget runs out.

A found mode is taken to be within `MARGIN` (scaled) of its computed
pose: its residual is ~1e-13 and Φ_x is regular there, so the true zero is
far closer.  The sub-boxes are regular in the region's coordinates, which the
closures are periodic in (angles), so the full turn is covered once.

Cost: the number of sub-boxes grows with the dimension and with the
nonlinearity of the closures: seconds for a planar four-bar or five-bar; a
6-6 Stewart-Gough platform (6 coordinates, three of them angles over a full
turn) does not finish within any practical budget (the benchmark records it).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..core import progress
from ..core.model import Model
from ..core.solver import solvers_of
from .assembly import AssemblyModes
from .certify import regularity
from .intervals import IntervalProgram

#: sub-boxes evaluated in one vectorised round at most
BATCH = 4096
#: the search gives up (uncertified) after this many sub-boxes
MAX_BOXES = 200_000
#: and at sub-boxes narrower than this (scaled) in every coordinate
MIN_WIDTH = 1e-9
#: a found mode counts as inside a sub-box within this (scaled) distance; the regularity is
#: proven on the sub-box widened by it
MARGIN = 1e-8


@dataclass
class ModeCertificate:
    """certified: no real mode in the region other than those found; boxes: sub-boxes
    evaluated; excluded, settled: sub-boxes proven empty, and proven to hold only a found
    mode; open: sub-boxes left when the search stopped; seconds: wall time; reason: why
    it stopped uncertified ('' when certified)."""

    certified: bool
    boxes: int
    excluded: int
    settled: int
    open: int
    seconds: float
    reason: str

    def as_dict(self) -> dict:
        return {
            "certified": self.certified,
            "boxes": self.boxes,
            "excluded": self.excluded,
            "settled": self.settled,
            "open": self.open,
            "seconds": self.seconds,
            "reason": self.reason,
        }


def closure_program(model: Model) -> IntervalProgram:
    """``<name>_modes_certify: (x, w) -> (phi, phi_x)`` as an interval program (built once per closure)."""
    c = model.closure

    def build() -> IntervalProgram:
        x, w = ca.SX.sym("x", c.nx), ca.SX.sym("w", c.nq + c.np)
        phi = c.fk_residual(x, w)
        fn = ca.Function(
            f"{c.name}_modes_certify", [x, w], [phi, ca.densify(ca.jacobian(phi, x))], ["x", "w"], ["phi", "phi_x"]
        )
        return IntervalProgram(fn)

    return solvers_of(c).memo(("mode_certificate",), build)


def _stop(boxes: int, max_boxes: int, t0: float, seconds: float | None) -> str:
    """Why the search stops before its next batch (the budget, the time limit), else ""."""
    if boxes >= max_boxes:
        return f"budget of {max_boxes} sub-boxes spent"
    if seconds is not None and time.perf_counter() - t0 > seconds:
        return f"time limit of {seconds:g} s reached"
    return ""


def _near_a_mode(blo: np.ndarray, bhi: np.ndarray, modes: np.ndarray, margin: np.ndarray) -> np.ndarray:
    """Which sub-boxes (widened by the margin) hold a found mode."""
    inside = np.zeros(len(blo), dtype=bool)
    for m in modes:
        inside |= np.all((blo - margin <= m) & (m <= bhi + margin), axis=1)
    return inside


def _halves(split_lo: np.ndarray, split_hi: np.ndarray, widths: np.ndarray) -> tuple[np.ndarray, ...]:
    """Each sub-box cut in two across its widest coordinate (scaled): lower and upper
    corners of the left halves, then of the right ones."""
    k = np.argmax(widths, axis=1)
    rows = np.arange(len(split_lo))
    mid = 0.5 * (split_lo[rows, k] + split_hi[rows, k])
    left_hi, right_lo = split_hi.copy(), split_lo.copy()
    left_hi[rows, k] = mid
    right_lo[rows, k] = mid
    return split_lo, left_hi, right_lo, split_hi


def certify_modes(
    model: Model, found: AssemblyModes, *, max_boxes: int = MAX_BOXES, seconds: float | None = None
) -> ModeCertificate:
    """Prove that the real modes in ``found.region`` are exactly ``found.modes`` (see the module
    docstring); ``seconds``: stop uncertified after this wall time."""
    t0 = time.perf_counter()
    c = model.closure
    prog = closure_program(model)
    scale = np.array([found.details["reach"] if x.kind == "length" else 1.0 for x in c.x])
    w = np.r_[found.q, np.asarray(model.p, dtype=float).ravel()]
    modes = np.array([m.x for m in found.modes]).reshape(-1, c.nx)
    angle = np.array([x.kind == "angle" for x in c.x])
    if len(modes):  # the region's angles are (-pi, pi]; a mode's may be reduced otherwise (none here)
        modes[:, angle] = np.pi - (np.pi - modes[:, angle]) % (2 * np.pi)
    margin = MARGIN * scale
    lo = found.region.lower[None, :].copy()
    hi = found.region.upper[None, :].copy()
    boxes = excluded = settled = 0
    reason = ""
    with progress.task("certifying the assembly modes", max_boxes) as report:
        while len(lo):
            reason = _stop(boxes, max_boxes, t0, seconds)
            if reason:
                break
            take = min(BATCH, len(lo), max_boxes - boxes)
            blo, bhi, lo, hi = lo[:take], hi[:take], lo[take:], hi[take:]
            boxes += take
            report.update(boxes)
            wide = [(blo - margin, bhi + margin), (np.tile(w, (take, 1)), np.tile(w, (take, 1)))]
            (plo, phi), (jlo, jhi) = prog.evaluate(wide)
            with np.errstate(invalid="ignore"):
                empty = np.any((plo > 0) | (phi < 0), axis=1)  # NaN compares False: not proven
            n = c.nx
            regular, _ = regularity(*(a.reshape(take, n, n).transpose(0, 2, 1) for a in (jlo, jhi)))
            done = empty | (regular & _near_a_mode(blo, bhi, modes, margin))
            excluded += int(np.count_nonzero(empty))
            settled += int(np.count_nonzero(done & ~empty))
            split_lo, split_hi = blo[~done], bhi[~done]
            if not len(split_lo):
                continue
            widths = (split_hi - split_lo) / scale
            if np.any(np.max(widths, axis=1) < MIN_WIDTH):
                reason = "a sub-box narrower than the smallest width is neither empty nor one found mode"
                lo = np.vstack([lo, split_lo])
                break
            left_lo, left_hi, right_lo, right_hi = _halves(split_lo, split_hi, widths)
            lo = np.vstack([lo, left_lo, right_lo])
            hi = np.vstack([hi, left_hi, right_hi])
    certified = not len(lo) and not reason
    return ModeCertificate(
        certified=certified,
        boxes=boxes,
        excluded=excluded,
        settled=settled,
        open=int(len(lo)),
        seconds=time.perf_counter() - t0,
        reason=reason,
    )
