"""Where a result leaves its model's validity: the warnings a result carries.

A solve that converged gives numbers; these checks say when those numbers lie
outside what the model behind them describes, so that the result is printed
and stored with a warning instead of as if it were clean
([`ResultWarning`][cpm_nlp.core.result.ResultWarning]; docs/site/howto/read-status.md
and docs/site/reference/flexures.md list the rules and their sources):

* ``stress_above_yield`` / ``stress_above_allowable`` -- a hinge stress above its
  material's yield strength, or above the allowable (design) stress: the linear
  elastic hinge formulas no longer hold (yield), or the design rule is broken;
* ``deflection_beyond_formula`` -- a hinge deflection beyond the range of its
  stiffness formula (`DEFLECTION_LIMITS`);
* ``hinge_geometry`` -- a hinge whose dimensions break its formula's premises
  (`hinge_geometry_warnings`);
* ``beyond_linear_range`` -- compliant forward kinematics whose nonlinear
  deflection differs from the linearised one (C f) by more than
  `LINEAR_RANGE` (10 %);
* ``near_singular`` -- a pose whose loop-closure Jacobian Φ_x (or the
  homogenised input-output Jacobian) has a condition number above
  `NEAR_SINGULAR_CONDITION`.

A warning never changes the status or the numbers: the result stays
``solved`` (exit status 0) and says, in its ``warnings`` list, what to doubt.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.conditioning import NEAR_SINGULAR_CONDITION
from ..core.result import ResultWarning

#: Largest rotation (rad) about any axis of a hinge that its stiffness formula
#: describes, per hinge type.  The formulas (Paros-Weisbord and Lobontiu 2002 ch. 2
#: for the circular notch, Euler-Bernoulli for the leaf spring and the necks) are
#: small-deformation beam theory with a fixed pivot; no source gives one number for
#: their range, so 0.1 rad (5.7 deg) is our engineering choice: there sin(θ) and θ
#: differ by 0.17 % and the notch hinges' pivot shift and stiffening, which Henning,
#: Linß and Zentner (Mech. Sci. 9, 389-404, 2018) compute at 10 deg, are still small.
#: See docs/site/reference/flexures.md.
ROTATION_LIMIT = 0.1
#: Largest translation along a hinge axis (stretch, shear) as a fraction of the
#: hinge's length (the notch's 2r, the leaf's or neck's l): small-deflection beam
#: theory holds while deflections are small against the beam's length; 10 % is our
#: engineering choice (no source gives a number).
TRANSLATION_FRACTION = 0.1
#: hinge type -> (rotation limit [rad], the length translations are measured against)
DEFLECTION_LIMITS = {
    "circular_notch": (ROTATION_LIMIT, lambda d: 2.0 * d["r"]),
    "circular_notch_paros_weisbord": (ROTATION_LIMIT, lambda d: 2.0 * d["r"]),
    "leaf_spring": (ROTATION_LIMIT, lambda d: d["l"]),
    "circular_rod": (ROTATION_LIMIT, lambda d: d["l"]),
    "filleted_rod": (ROTATION_LIMIT, lambda d: d["l"] + 2.0 * d["r"]),
}
_ROTATIONS = ("bend", "bend2", "torsion")
#: Relative difference between the nonlinear and the linearised deflection of the
#: compliant forward kinematics above which the load is beyond the linear range.
LINEAR_RANGE = 0.10
#: Deflections (rad, m) below which the comparison is the solver's rounding, not the load's
#: nonlinearity: the FK tolerance of 1e-10 (relative) leaves 1e-11 rad of noise at no load
#: (a four-bar gave -8.4e-12 rad against a linearised 0, "differ by 100 %")
DEFLECTION_NOISE = {"angle": 1e-9, "length": 1e-12}


def hinge_geometry_warnings(hinges: Iterable[Any], where: str = "hinge") -> list[ResultWarning]:
    """The hinges (``kind``, ``dims``, ``group``) whose geometry breaks their formula.

    Circular notch (t thinnest section, r notch radius, w width along the compliant
    axis; its section at x is w x h(x), h from t at the centre to t + 2r at the ends):

    * t > w: the hinge is thicker than wide, so it bends about its second axis
      (I = t w³/12) more easily than about the compliant one (I = w t³/12): the
      one-axis hinge formula (and the joint it stands for) does not describe it;
    * t + 2r > w: the torsion compliance uses Roark's rectangle constant
      J = a c³ [1/3 - 0.21 (c/a)(1 - c⁴/(12 a⁴))] with a = w the long side and
      c = h(x) (Roark's Formulas for Stress and Strain, 7th ed., Table 10.7 case 4,
      valid for a >= c); where the notch is deeper than the width the formula is
      used outside its range (it overstates the torsion stiffness).

    Leaf spring (t thickness, w width): t > w, as for the notch.
    """
    out: list[ResultWarning] = []
    seen: set[str] = set()
    for h in hinges:
        if h.kind is None or h.group in seen:
            continue
        seen.add(h.group)
        d = h.dims
        at = f"{where} {h.group}"
        if h.kind in ("circular_notch", "circular_notch_paros_weisbord", "leaf_spring") and d["t"] > d["w"]:
            out.append(
                ResultWarning(
                    "hinge_geometry",
                    f"{at}: thickness t = {d['t'] * 1e3:g} mm exceeds the width w = {d['w'] * 1e3:g} mm: it bends "
                    "about its second axis more easily than about its compliant axis, which the hinge formula "
                    "does not describe",
                    at + ": t > w",
                    d["t"],
                    d["w"],
                )
            )
        if h.kind in ("circular_notch", "circular_notch_paros_weisbord") and d["t"] + 2.0 * d["r"] > d["w"]:
            h_end = d["t"] + 2.0 * d["r"]
            out.append(
                ResultWarning(
                    "hinge_geometry",
                    f"{at}: the notch section is {h_end * 1e3:g} mm deep at its ends (t + 2r) but only "
                    f"w = {d['w'] * 1e3:g} mm wide: the torsion formula (Roark's rectangle, width the long side) "
                    "is used outside its range",
                    at + ": t + 2r > w",
                    h_end,
                    d["w"],
                )
            )
    return out


@dataclass
class _Worst:
    ratio: float
    value: float
    limit: float
    text: Any
    points: set[int] = field(default_factory=set)


@dataclass
class Collector:
    """Gathers the warnings of many hinges and points (a batch): one per code and
    place (a hinge group), with the worst value (largest ratio to its limit) and
    how many points broke the limit.  Set ``point`` before the checks of each point."""

    points: int = 1
    point: int = 0
    _found: dict[tuple[str, str], _Worst] = field(default_factory=dict)

    def add(self, code: str, where: str, value: float, limit: float, text: Any) -> None:
        """``text(value, limit)`` -> the message (built once, for the worst case)."""
        key = (code, where)
        ratio = abs(value) / limit if limit > 0 else math.inf
        old = self._found.get(key)
        if old is None:
            old = self._found[key] = _Worst(ratio, value, limit, text)
        elif ratio > old.ratio:
            old.ratio, old.value, old.limit, old.text = ratio, value, limit, text
        old.points.add(self.point)

    def warnings(self) -> list[ResultWarning]:
        out = []
        for (code, where), w in self._found.items():
            msg = w.text(w.value, w.limit)
            if self.points > 1:
                msg += f" (at {len(w.points)} of {self.points} points; the worst shown)"
            out.append(ResultWarning(code, msg, where, float(w.value), float(w.limit)))
        return out

    # -- stresses ------------------------------------------------------------------------------
    def stresses(
        self, hinges: Iterable[Any], stresses: Mapping[str, float | None], sigma_allow: float | None = None
    ) -> None:
        """Each hinge's stress against its material's yield strength, and against the
        allowable: ``sigma_allow`` where the problem gives one, else the material's."""
        for h in hinges:
            s = stresses.get(h.name)
            if s is None or not math.isfinite(s):
                continue
            mat = h.material
            yield_strength = mat.yield_strength if mat is not None else None
            allow = sigma_allow if sigma_allow is not None else (mat.allowable if mat is not None else None)
            where = f"hinge {h.group}"
            if yield_strength is not None and s > yield_strength:
                name = mat.name

                def text(v: float, lim: float, where: str = f"hinge {h.name}", name: str = name) -> str:
                    return (
                        f"{where}: stress {v / 1e6:.4g} MPa above the yield strength of {name} "
                        f"({lim / 1e6:.4g} MPa): the linear elastic model does not hold there"
                    )

                self.add("stress_above_yield", where, s, yield_strength, text)
            elif allow is not None and s > allow:

                def text(v: float, lim: float, where: str = f"hinge {h.name}") -> str:
                    return f"{where}: stress {v / 1e6:.4g} MPa above the allowable stress ({lim / 1e6:.4g} MPa)"

                self.add("stress_above_allowable", where, s, allow, text)

    # -- deflections ---------------------------------------------------------------------------
    def deflections(self, hinge: Any, deflection: Mapping[str, float]) -> None:
        """A hinge's deflection per axis (rad about bend, bend2, torsion; m along axial,
        shear, shear2) against `DEFLECTION_LIMITS` of its type."""
        if hinge.kind not in DEFLECTION_LIMITS:
            return
        rot_limit, length = DEFLECTION_LIMITS[hinge.kind]
        for axis, v in deflection.items():
            if not math.isfinite(v):
                continue
            name = f"hinge {hinge.name}, {axis}"
            if axis in _ROTATIONS:
                if abs(v) > rot_limit:

                    def text(v: float, lim: float, name: str = name, kind: str = hinge.kind) -> str:
                        return (
                            f"{name}: deflection {v:.4g} rad ({math.degrees(v):.3g} deg) beyond the {lim:g} rad "
                            f"the {kind} formula describes (small deflection)"
                        )

                    self.add("deflection_beyond_formula", f"hinge {hinge.group} rotation", v, rot_limit, text)
            else:
                lim = TRANSLATION_FRACTION * float(length(hinge.dims))
                if abs(v) > lim:

                    def text(v: float, lim: float, name: str = name, kind: str = hinge.kind) -> str:
                        return (
                            f"{name}: deflection {v * 1e3:.4g} mm beyond the {lim * 1e3:.4g} mm (10 % of the hinge's "
                            f"length) the {kind} formula describes (small deflection)"
                        )

                    self.add("deflection_beyond_formula", f"hinge {hinge.group} translation", v, lim, text)


def hinge_deflections(hinges: Iterable[Any], theta: np.ndarray, theta0: np.ndarray) -> dict[str, dict[str, float]]:
    """The deflection per axis of each pseudo-rigid-body hinge (``axes``: axis -> index
    in the joint vector)."""
    dev = np.asarray(theta, dtype=float) - np.asarray(theta0, dtype=float)
    return {h.name: {a: float(dev[i]) for a, i in h.axes.items()} for h in hinges}


def six_axis_deflections(frames: Iterable[Any], z: np.ndarray) -> dict[str, dict[str, float]]:
    """The deflection per axis of each hinge of the six-axis model (``variables``:
    axis -> (index in z, rest value))."""
    return {fr.name: {a: float(z[zi] - r0) for a, (zi, r0) in fr.variables.items()} for fr in frames}


def check_hinges(
    collector: Collector,
    hinges: Sequence[Any],
    stresses: Mapping[str, float | None],
    deflections: Mapping[str, Mapping[str, float]],
    sigma_allow: float | None = None,
) -> None:
    """Stresses and deflections of the hinges at one point."""
    collector.stresses(hinges, stresses, sigma_allow)
    for h in hinges:
        if h.name in deflections:
            collector.deflections(h, deflections[h.name])


def linear_range_warnings(
    nonlinear: np.ndarray, linear: np.ndarray, names: Sequence[str], kinds: Sequence[str]
) -> list[ResultWarning]:
    """Compliant FK: the loaded pose's deflection against C f.  Lengths and angles
    apart, the relative difference of the two deflection vectors,
    |d - C f| / max(|d|, |C f|) (2-norms), against `LINEAR_RANGE`; the warning
    names the coordinate that differs most in the worse group."""
    d, lin = np.asarray(nonlinear, dtype=float), np.asarray(linear, dtype=float)
    worst: tuple[float, int] | None = None
    for kind in sorted(set(kinds)):
        idx = [i for i, k in enumerate(kinds) if k == kind]
        size = max(float(np.linalg.norm(d[idx])), float(np.linalg.norm(lin[idx])))
        if not size > DEFLECTION_NOISE.get(kind, 0.0):  # rounding of the solves, not a deflection
            continue
        rel = float(np.linalg.norm(d[idx] - lin[idx])) / size
        i = idx[int(np.argmax(np.abs(d[idx] - lin[idx])))]
        if worst is None or rel > worst[0]:
            worst = (rel, i)
    if worst is None or not worst[0] > LINEAR_RANGE:
        return []
    rel, i = worst
    unit, k = ("rad", 1.0) if kinds[i] == "angle" else ("mm", 1e3)
    return [
        ResultWarning(
            "beyond_linear_range",
            f"the load is beyond the linear range: the deflection of {names[i]} is {d[i] * k:.4g} {unit}, the "
            f"linearised C f gives {lin[i] * k:.4g} {unit} (the deflections differ by {rel:.0%}, more than "
            f"{LINEAR_RANGE:.0%})",
            f"d_{names[i]}",
            float(rel),
            LINEAR_RANGE,
        )
    ]


def near_singular_warning(cond: float, what: str, where: str, points: str = "") -> ResultWarning | None:
    """A warning when ``cond`` is above `NEAR_SINGULAR_CONDITION` (None otherwise)."""
    if not cond > NEAR_SINGULAR_CONDITION:
        return None
    return ResultWarning(
        "near_singular",
        f"the pose is near a singularity: cond({what}) = {cond:.3g} > {NEAR_SINGULAR_CONDITION:g}{points}; the "
        "values are sensitive to the smallest error in the inputs",
        where,
        float(cond),
        NEAR_SINGULAR_CONDITION,
    )


def hinge_warnings(
    hinges: Sequence[Any],
    points: Sequence[tuple[Mapping[str, float | None], Mapping[str, Mapping[str, float]]] | None],
    sigma_allow: float | None = None,
) -> list[ResultWarning]:
    """The hinges' geometry, then their stresses and deflections at every point
    (``(stresses, deflections)``, None for a point not solved)."""
    col = Collector(points=sum(1 for p in points if p is not None))
    for k, p in enumerate(points):
        if p is not None:
            col.point = k
            check_hinges(col, hinges, p[0], p[1], sigma_allow)
    return hinge_geometry_warnings(hinges) + col.warnings()
