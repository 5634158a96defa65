"""Generated problems of every generic kind for any mechanism (tests/conformance/test_conformance.py).

A *subject* is a mechanism as a problem file names it (its ``mechanism:`` section, from its
first shipped problem file, or a mechanism file of the corpus) and the model built from it.
For each generic kind the suite writes a minimal problem from the subject's home pose: small
moves about home, strokes about the home actuators where the mechanism declares none, a few
starts and samples.  Nothing here knows a particular mechanism.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

import cpm_nlp as cn
from cpm_nlp.mechanisms.registry import section_model
from cpm_nlp.problems.registry import GENERIC
from cpm_nlp.problems.shipped import shipped_problems_dir

#: every generic kind (cpm_nlp.problems.registry.GENERIC), in a fixed order
GENERIC_KINDS = tuple(sorted(GENERIC))
#: half-width of a generated stroke about the home actuators: a fraction of the
#: mechanism's size (:func:`size`) for a length actuator, an angle for a rotary one
STROKE_FRACTION = 0.02
STROKE_ANGLE = np.radians(10.0)
#: the moves about home of the generated poses: that fraction of the stroke
MOVE = 0.3


@dataclass
class Subject:
    """A mechanism as a problem file names it, and its model with strokes on every actuator."""

    name: str
    section: dict[str, Any]  # the problem file's mechanism section, strokes added
    base_dir: Path | None
    model: cn.Model = field(repr=False)
    generated_strokes: tuple[str, ...] = ()  # the limit keys added here

    def problem(self, kind: str, inputs: dict[str, Any], solver: Any = None) -> cn.Problem:
        data: dict[str, Any] = {"problem": kind, "mechanism": copy.deepcopy(self.section), "inputs": inputs}
        if solver is not None:
            data["solver"] = solver
        return cn.problem_from_dict(data, file=f"<conformance {self.name} {kind}>", base_dir=self.base_dir)

    # -- poses about home ------------------------------------------------------------------

    def stroke(self) -> tuple[np.ndarray, np.ndarray]:
        """Per actuator: its declared stroke, else home plus or minus :func:`half_stroke`."""
        m = self.model
        lo, hi = [], []
        for k, coord in enumerate(m.closure.q):
            lim = m.limit_of(coord)
            half = half_stroke(m, coord)
            lo.append(m.q_home[k] - half if lim is None else lim[0])
            hi.append(m.q_home[k] + half if lim is None else lim[1])
        return np.array(lo), np.array(hi)

    @property
    def has_strokes(self) -> bool:
        return all(self.model.limit_of(q) is not None for q in self.model.closure.q)

    def actuators_near_home(self, count: int, seed: int) -> np.ndarray:
        """``count`` seeded actuator vectors about home: uniform in the strokes (cut to home
        plus or minus :func:`half_stroke`) shrunk towards the home actuators by :data:`MOVE`."""
        lo, hi = self.stroke()
        m = self.model
        q0 = m.q_home
        half = np.array([half_stroke(m, co) for co in m.closure.q])
        lo, hi = np.maximum(lo, q0 - half), np.minimum(hi, q0 + half)
        rng = np.random.default_rng(seed)
        return q0 + MOVE * ((lo - q0) + (hi - lo) * rng.random((count, q0.size)))


def size(model: cn.Model) -> float:
    """The mechanism's size: its largest length parameter (else its characteristic length)."""
    lengths = [abs(v) for k, v in model.parameters.items() if model.dimensions.get(k) == "length"]
    return max(lengths, default=model.characteristic_length)


def half_stroke(model: cn.Model, coord: cn.Coordinate) -> float:
    """Half of a generated stroke: :data:`STROKE_FRACTION` of the size for a length
    actuator, :data:`STROKE_ANGLE` for a rotary one."""
    return STROKE_FRACTION * size(model) if coord.kind == "length" else STROKE_ANGLE


def _stroke_limits(mech: cn.Mechanism, model: cn.Model) -> dict[str, list[float]]:
    """Strokes for the actuators without one, where the mechanism has a limit key for them
    (the actuator's family or its own name): home plus or minus :func:`half_stroke`.  A
    family whose members' home values differ by more than that gets none (one range for
    all would be no small stroke about home)."""
    keys = {o.name for o in mech.limits if o.shape == "range"}
    groups: dict[str, list[tuple[float, float]]] = {}
    for k, coord in enumerate(model.closure.q):
        key = coord.group if coord.group in keys else coord.name
        if model.limit_of(coord) is None and key in keys:
            groups.setdefault(key, []).append((float(model.q_home[k]), half_stroke(model, coord)))
    out = {}
    for key, members in groups.items():
        homes = [h for h, _ in members]
        half = members[0][1]
        if max(homes) - min(homes) <= half:
            out[key] = [min(homes) - half, max(homes) + half]
    return out


def _model(section: dict[str, Any], base_dir: Path | None) -> cn.Model:
    """The model a problem file's mechanism section builds."""
    return section_model(section, base_dir)


def subject(name: str, section: dict[str, Any], base_dir: Path | None) -> Subject:
    """The subject of a mechanism section, strokes added where the mechanism has a key for them."""
    mech_model = _model(section, base_dir)
    mech = mech_model.mechanism
    added = _stroke_limits(mech, mech_model)
    section = copy.deepcopy(section)
    if added:
        section["limits"] = {**(section.get("limits") or {}), **added}
    return Subject(name, section, base_dir, _model(section, base_dir), tuple(added))


def shipped_subject(name: str) -> Subject:
    """A registered mechanism as its first shipped problem file names it (else by type)."""
    mech = cn.mechanism_type(name)
    files = [Path(f) if Path(f).is_absolute() else shipped_problems_dir() / f for f in mech.problem_files]
    if not files:
        return subject(name, {"type": name}, None)
    raw = yaml.safe_load(files[0].read_text(encoding="utf-8"))
    return subject(name, raw["mechanism"], files[0].parent)


def is_mechanism_file(path: Path) -> bool:
    """A mechanism file: a mapping with a ``name`` and ``legs``, ``closures`` or ``bodies`` at the top."""
    try:
        raw = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError):
        return False
    return isinstance(raw, dict) and "name" in raw and any(k in raw for k in ("legs", "closures", "bodies"))


def corpus_files(folder: Path) -> list[Path]:
    """The mechanism files of a folder (none if it is absent), sorted."""
    if not folder.is_dir():
        return []
    return [p for p in sorted(folder.glob("*.yaml")) if is_mechanism_file(p)]


def file_subject(path: Path) -> Subject:
    """A mechanism file as a problem file names it inline (``mechanism: {description: ...}``),
    renamed ``corpus_<name>`` so that it never replaces a shipped mechanism of its name."""
    raw = yaml.safe_load(path.read_text(encoding="utf-8"))
    if not str(raw["name"]).startswith("corpus_"):
        raw["name"] = f"corpus_{raw['name']}"
    return subject(raw["name"], {"description": raw}, path.parent)


# -- a minimal problem of each kind ----------------------------------------------------------


#: stiffness of the generated springs (N/m or N*m/rad)
SPRING = 100.0


def generated_hinges(s: Subject) -> bool:
    """Whether the compliance kinds get generated springs (the mechanism declares no stiffness)."""
    mech = s.model.mechanism
    return mech is None or mech.part(cn.JointStiffness) is None


def _hinges(s: Subject) -> dict[str, Any] | None:
    """Hinges for the compliance kinds where the mechanism declares no stiffness: one
    linear spring of stiffness :data:`SPRING` on each actuator."""
    if not generated_hinges(s):
        return None
    return {f"spring_{q}": {"joints": q, "k": SPRING} for q in s.model.closure.q_names}


def design_parameter(s: Subject) -> str | None:
    """A length parameter of the closure to vary in the generic synthesis."""
    m = s.model
    declared = {o.name: o for o in m.mechanism.parameters}
    lengths = [n for n in m.closure.parameters if declared.get(n) is not None and declared[n].kind == "length"]
    positive = [n for n in lengths if m.parameters.get(n, 0.0) > 0]
    # a length, else a change of length about 0 (Jansen's dr1: the crank drawn at its length)
    return (positive or lengths or [None])[0]


def inputs_of(s: Subject, kind: str, poses: dict[str, np.ndarray]) -> dict[str, Any] | None:  # noqa: C901 - one case per kind
    """The inputs of a minimal problem of ``kind``; ``poses``: "q" (actuators about home,
    (n, nq)) and "t" (their task values); None where the suite gives none."""
    c = s.model.closure
    q, t = poses["q"], poses["t"]
    act = lambda Q: {n: Q[:, k].tolist() for k, n in enumerate(c.q_names)}  # noqa: E731
    task = lambda T: {n: T[:, k].tolist() for k, n in enumerate(c.task)}  # noqa: E731
    hinges = _hinges(s)
    hinge_in = {} if hinges is None else {"hinges": hinges}
    if kind == "forward_kinematics":
        return act(q)
    if kind == "inverse_kinematics":
        return task(t)
    if kind == "jacobian":
        return {n: float(q[0, k]) for k, n in enumerate(c.q_names)}
    if kind == "joint_requirements":
        lo, hi = t.min(axis=0), t.max(axis=0)
        return {n: [float(lo[k]), float(hi[k])] for k, n in enumerate(c.task)}
    if kind == "workspace":
        return task(np.vstack([s.model.task_of(s.model.x_home), far_point(s)]))
    if kind == "actuator_workspace":
        return {"samples": 3, "quadrature": 3 if c.nq <= 3 else 2}
    if kind == "inscribed_cuboid":
        coarse = len(c.task) > 3  # 6-D: 2^6 samples, 3^6 - 1 + 3^6 check points
        return {"starts": 2, "seed": 0, "samples_per_edge": 2 if coarse else 3, "check_per_edge": 3 if coarse else 5}
    if kind == "synthesis":
        if s.model.mechanism.part(cn.SynthesisFormulation) is not None:
            return None  # the mechanism's own formulation: its shipped example
        name = design_parameter(s)
        v = s.model.parameters[name]
        span = 0.05 * abs(v) if v else 1e-4  # 5 %, or 0.1 mm about a change of length of 0
        return {"design": {name: [v - span, v + span]}, "starts": 1, "samples_per_edge": 2, "check_per_edge": 3}
    if kind == "actuator_forces":
        h = central_step(s)
        Q = np.vstack([q[0], q[0] + np.diag(h), q[0] - np.diag(h)])
        return {**act(Q), **hinge_in}
    if kind == "platform_compliance":
        return {**{n: float(q[0, k]) for k, n in enumerate(c.q_names)}, "k_actuator": 0.0, **hinge_in}
    if kind == "natural_frequencies":
        return {**{n: float(q[0, k]) for k, n in enumerate(c.q_names)}, "masses": masses(s), **hinge_in}
    if kind == "dynamics":
        dm = s.model.mechanism.part(cn.DynamicsModel)
        return {"material": "Al 7075-T6", **{m: 0.01 for m, _ in dm.masses}}
    return None


def central_step(s: Subject) -> np.ndarray:
    """A central-difference step per actuator: 1e-6 of its stroke."""
    lo, hi = s.stroke()
    return 1e-6 * (hi - lo)


def masses(s: Subject) -> dict[str, float]:
    """A mass (0.1 kg) on every translational task coordinate and an inertia
    (1e-4 kg m^2) on every rotational one."""
    c = s.model.closure
    return {c.x[i].name: (0.1 if c.x[i].kind == "length" else 1e-4) for i in c.task_index}


def far_point(s: Subject) -> np.ndarray:
    """Home moved by 100 sizes (:func:`size`) along the first translational task
    coordinate (by 10 rad along the first task coordinate if none is a length)."""
    c = s.model.closure
    t = s.model.task_of(s.model.x_home).copy()
    kinds = [c.x[i].kind for i in c.task_index]
    k = kinds.index("length") if "length" in kinds else 0
    t[k] += 100 * size(s.model) if kinds[k] == "length" else 10.0
    return t
