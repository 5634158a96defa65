"""A mechanism file as text, for ``cpm-nlp describe FILE``: its derived values, legs (bodies
and joints: type, coordinates, actuated, hinge), loops and mobility.

The text is built from the description and its generated closure (the same the solvers use),
and, when a model can be built (the parameters of the file's first example, else its
defaults), with the values at the reference configuration.  Library code: it returns text,
the CLI prints it.
"""

from __future__ import annotations

from typing import Any

import casadi as ca
import numpy as np

from ...core.joints import JOINT_TYPES
from ...core.model import Model
from ...core.units import format_quantity
from .generate import Generator, closure_parts, family
from .spec import Description, Joint


def _hinges_of(d: Description) -> dict[str, str]:
    """Coordinate name or family -> the name of the declared hinge (``stiffness.hinges``) on it."""
    out: dict[str, str] = {}
    if d.stiffness is None:
        return out
    for hinge, spec in d.stiffness.hinges.items():
        joints = spec.get("joints")
        kind = spec.get("type")
        label = hinge + (f" ({kind})" if kind else "")
        for target in joints.values() if isinstance(joints, dict) else [joints]:
            if isinstance(target, str):
                out[target] = label
    return out


def _vector(value: Any, model: Model | None, gen: Generator, dimension: str) -> str:
    """A location or axis at the reference configuration (display units); without a model, a note."""
    if value is None:
        return "-"
    if model is None:
        return "(with the parameters)"
    v = np.asarray(ca.Function("v", [gen.p], [value])(model.p), dtype=float).ravel() + 0.0  # no -0
    if dimension == "length":
        return "[" + ", ".join(format_quantity(float(e), "length", 5) for e in v) + "]"
    return "[" + ", ".join(f"{e:.4g}" for e in v) + "]"


def _joint_line(k: int, spec: Joint, resolved: Any, gen: Generator, model: Model | None, hinges: dict) -> str:
    parts = [f"{k + 1}. {spec.type:<8}"]
    parts.append(f"at {_vector(resolved.at, model, gen, 'length')}")
    if resolved.to is not None:
        parts.append(f"to {_vector(resolved.to, model, gen, 'length')}")
    if resolved.axis is not None and JOINT_TYPES[spec.type].axis == "given":
        parts.append(f"axis {_vector(resolved.axis, model, gen, 'axis')}")
    names = list(spec.coordinates) or list(resolved.names)
    if spec.actuated:
        parts.append(f"actuated: {spec.actuated}")
    elif names:
        parts.append("coordinates: " + ", ".join(names))
    elif JOINT_TYPES[spec.type].dof:
        parts.append(f"{JOINT_TYPES[spec.type].dof} passive dof (eliminated)")
    keys = [key for name in [*names, spec.actuated or ""] for key in (name, family(name))]
    found = sorted({hinges[key] for key in keys if key in hinges})
    if spec.flexure is not None:
        found.append(f"flexure {spec.flexure.values.get('hinge', '?')}")
    if found:
        parts.append("hinge: " + ", ".join(found))
    return "  ".join(parts)


def summary_text(d: Description, model: Model | None, source: str) -> str:  # noqa: C901 - one section after another
    """The text of ``cpm-nlp describe FILE`` after the mechanism's parameters and limits."""
    gen, fns = closure_parts(d)
    lines: list[str] = []
    where = f"values at the reference configuration of {source}" if model is not None else source
    lines.append(f"({where})")
    if d.derived:
        lines.append("derived values:")
        for q, (name, _sx, dim) in zip(d.derived, gen.derived):
            shown = ""
            if model is not None:
                value = model.derived.get(name)
                if isinstance(value, list):
                    shown = "[" + ", ".join(format_quantity(v, dim, 5) for v in value) + "]"
                elif value is not None:
                    shown = format_quantity(float(value), dim, 6)
            text = q.value if isinstance(q.value, str) else str(q.value)
            lines.append(f"  {name:<8} = {shown or text}  ({dim}{'' if not shown else ': ' + text})")
            if q.description:
                lines.append(f"  {'':<8}   {q.description}")
    hinges = _hinges_of(d)
    lines.append("legs (bodies and joints, base -> platform, at the reference configuration):")
    if not gen.leg_joints:
        lines.append("  (none: the loops are written as closures)")
    for leg, joints in gen.leg_joints:
        bodies = ["base"]
        for n, j in enumerate(leg.joints):
            last = n == len(leg.joints) - 1
            bodies.append(j.body or ("platform" if last else f"{leg.name}.link{n + 1}"))
        lines.append(f"  leg {leg.name}: " + " -> ".join(bodies))
        for k, (spec, resolved) in enumerate(zip(leg.joints, joints)):
            lines.append("    " + _joint_line(k, spec, resolved, gen, model, hinges))
    lines.append("loops (closure equations; one loop per leg: base -> leg -> platform -> base):")
    groups: dict[str, list[str]] = {}
    for name in fns["row_names"]:
        head, _, what = name.partition(": ")
        groups.setdefault(head if what else "closures (expressions)", []).append(what or name)
    for head, rows in groups.items():
        lines.append(f"  {head}: {len(rows)} equation(s): " + "; ".join(rows))
    nx, nq, rows = len(gen.x_names), len(gen.q_coords), len(fns["row_names"])
    task = list(d.platform.task)
    dependent = [n for n in gen.x_names if n not in task]
    lines.append("mobility:")
    lines.append(f"  actuators ({nq}): " + ", ".join(c.name for c in gen.q_coords))
    also = "; dependent " + ", ".join(dependent) if dependent else ""
    lines.append(f"  pose coordinates ({nx}): task " + ", ".join(task) + also)
    if d.platform.fixed:
        lines.append("  fixed by the structure: " + ", ".join(d.platform.fixed))
    if model is None:
        lines.append(f"  {rows} equation(s) for {nx} pose coordinate(s); rank not checked (no model: {source})")
    else:
        c = model.closure
        jx = np.asarray(c.phi_x(model.x_home, model.q_home, model.p), dtype=float)
        jq = np.asarray(c.phi_q(model.x_home, model.q_home, model.p), dtype=float)
        rank_x = int(np.linalg.matrix_rank(jx))
        rank = int(np.linalg.matrix_rank(np.hstack([jx, jq])))
        dof = nx + nq - rank
        lines.append(
            f"  {rows} equation(s) for {nx} pose coordinate(s); at the reference configuration rank Φ_x = "
            f"{rank_x}, rank [Φ_x Φ_q] = {rank}: {dof} degree(s) of freedom"
            + (" (the actuators fix the pose)" if rank_x == nx and dof == nq else "")
        )
    if gen.branch:
        lines.append("branch indicators: " + ", ".join(fns["branch_names"]))
    return "\n".join(lines) + "\n"


def body_graph(d: Description) -> tuple[list[str], list[tuple[str, str, str, bool]]]:
    """The bodies (base, each leg's links, platform) and the joints between them as edges
    (from body, to body, label, actuated), base side first: the graph ``describe --plot`` draws."""
    nodes = ["base"]
    edges: list[tuple[str, str, str, bool]] = []
    for leg in d.legs:
        prev = "base"
        for n, j in enumerate(leg.joints):
            last = n == len(leg.joints) - 1
            body = j.body or ("platform" if last else f"{leg.name}.link{n + 1}")
            if body not in nodes and body != "platform":
                nodes.append(body)
            label = j.type + (f" {j.actuated}" if j.actuated else "")
            edges.append((prev, body, label, j.actuated is not None))
            prev = body
    nodes.append("platform")
    return nodes, edges


__all__ = ["body_graph", "summary_text"]
