"""The declared values of the compliance kinds (`cpm_nlp.kinds.compliance`) and of the
hinge models that solve them (`hinge_models`): each value with its
[`Output`][cpm_nlp.core.result.Output], written once for both.

A value of a hinge group (its largest stress) is one member of a declared family
(`stress_outputs`): the groups are the problem's hinges, known only once its inputs are read.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..core.model import Coordinate, LoopClosure
from ..core.outputs import Output, Values, matrix, vector
from ..core.result import ResultWarning
from ..core.units import result_unit
from . import validity
from .compliance import HingeSet, StaticPoint
from .hinge_chains import SixAxisModel


def stress_outputs(suffix: str = "") -> list[Output]:
    """The largest stress over every hinge, and that of each hinge group: a family, one output
    per group of the problem's hinges (``suffix`` appended to both names)."""
    return [
        Output("stress_max" + suffix, "stress"),
        Output(f"stress_{{group}}{suffix}", "stress", per="hinge group with a flexure type"),
    ]


def peak_outputs(suffix: str = "") -> list[Output]:
    """The largest peak stress (K_t × nominal) over every hinge, that of each hinge group, and
    each group's stress-concentration factor K_t (`kt`): two families."""
    per = "hinge group with a flexure type"
    return [
        Output("stress_peak_max" + suffix, "stress"),
        Output(f"stress_peak_{{group}}{suffix}", "stress", per=per),
        Output("Kt_{group}", "dimensionless", per=per),
    ]


def stress_groups(hs: HingeSet) -> list[str]:
    """The hinge groups with a stress: those of a flexure type, in name order."""
    return sorted({h.group for h in hs.hinges if h.kind is not None})


def stress_values(hs: HingeSet, points: list[StaticPoint | None], batch: bool, suffix: str = "") -> Values:
    """The largest nominal stress (and each hinge group's) per point, beside the peak stress
    K_t × nominal (and each group's), and each group's K_t (the largest of its hinges')."""
    groups = stress_groups(hs)
    largest, family = stress_outputs(suffix)
    peak_largest, peak_family, kt_family = peak_outputs(suffix)
    cols: dict[Output, list] = {largest: []}
    cols.update({family.member(group=g): [] for g in groups})
    cols[peak_largest] = []
    cols.update({peak_family.member(group=g): [] for g in groups})
    for sp in points:
        if sp is None:
            for v in cols.values():
                v.append(None)
            continue
        cols[largest].append(sp.stress_max)
        peaks = list(hs.peaks(sp.stresses).values())
        cols[peak_largest].append(max((p for p in peaks if p is not None), default=None))
        for g in groups:
            vals = [s for h, s in zip(hs.hinges, sp.stresses.values()) if h.group == g and s is not None]
            cols[family.member(group=g)].append(max(vals) if vals else None)
            pk = [p for h, p in zip(hs.hinges, peaks) if h.group == g and p is not None]
            cols[peak_family.member(group=g)].append(max(pk) if pk else None)
    out = Values().add_all((o, v if batch else v[0]) for o, v in cols.items())
    kts = {g: max(h.kt for h in hs.hinges if h.group == g and h.kind is not None) for g in groups}
    return out.add_all((kt_family.member(group=g), kts[g]) for g in groups)


def coordinate_list(coords: Sequence[Coordinate]) -> str:
    """The coordinates with their units, as the unit text of a list of them."""
    return ", ".join(f"{x.name} [{result_unit(x.kind)}]" for x in coords)


def force_output(name: str, coord: Coordinate) -> Output:
    """A force on a length coordinate, a moment on an angle."""
    return Output(name, "force" if coord.kind == "length" else "moment")


def compliance_output(c: LoopClosure) -> Output:
    """The output compliance C (rows and columns the pose coordinates)."""
    units = f"{result_unit('compliance')}, {result_unit('rotational_compliance')} and mixed"
    return matrix("C", f"rows and columns {coordinate_list(c.x)}; {units}")


def diagonal_output(x: Coordinate) -> Output:
    """A diagonal entry of C: a compliance along a length, a rotational one about an angle."""
    return Output(f"C_{x.name}", "compliance" if x.kind == "length" else "rotational_compliance")


def compliance_matrix(c: LoopClosure, C: np.ndarray, linear: np.ndarray) -> Values:
    """The output compliance C and the linear deflection C f."""
    out = Values().add(compliance_output(c), C.tolist())
    return out.add(vector("deflection_linear", coordinate_list(c.x)), linear.tolist())


def diagonal_compliance(c: LoopClosure, C: np.ndarray) -> Values:
    """The diagonal of C, one value per pose coordinate."""
    return Values().add_all((diagonal_output(x), float(C[i, i])) for i, x in enumerate(c.x))


def deflection_values(c: LoopClosure, d: np.ndarray) -> Values:
    """The deflection under the load, as a list and per pose coordinate."""
    out = Values().add(vector("deflection", coordinate_list(c.x)), d.tolist())
    return out.add_all((Output(f"d_{x.name}", x.kind), float(d[i])) for i, x in enumerate(c.x))


def largest(stresses: Mapping[str, float | None]) -> float | None:
    return max((v for v in stresses.values() if v is not None), default=None)


def point_warnings(hs: HingeSet, points: list[StaticPoint | None], sigma: float | None = None) -> list[ResultWarning]:
    """The hinges' geometry, stresses and deflections at the solved points (`validity`)."""
    pts = [
        None if sp is None else (sp.stresses, validity.hinge_deflections(hs.hinges, sp.theta, hs.theta0))
        for sp in points
    ]
    return validity.hinge_warnings(hs.hinges, pts, sigma)


def six_axis_warnings(sm: SixAxisModel, zs: list[np.ndarray]) -> list[ResultWarning]:
    """Geometry, stresses and deflections of the six-axis model's hinges at the equilibria ``zs``."""
    pts = [(sm.stresses(z), validity.six_axis_deflections(sm.frames, z)) for z in zs]
    return validity.hinge_warnings(sm.hs.hinges, pts)


def linear_range(c: LoopClosure, d: np.ndarray, linear: np.ndarray) -> list[ResultWarning]:
    """Where the nonlinear and the linear deflection differ (`linear_range_warnings`)."""
    return validity.linear_range_warnings(d, linear, c.x_names, [x.kind for x in c.x])
