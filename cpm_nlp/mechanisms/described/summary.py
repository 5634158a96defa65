"""A mechanism file as text, for ``cpm-nlp describe FILE``: its derived values, its bodies and
joints (a legs file: the graph its legs expand into, `expand`), loops and mobility, and a
legs file's legs (type, location, coordinates, actuated, hinge) and generated closures.

The text is built from the description and its generated closure (the same the solvers use),
and, when a model can be built (the parameters of the file's first example, else its
defaults), with the values at the reference configuration.  Library code: it returns text,
the CLI prints it.
"""

from __future__ import annotations

from typing import Any

import casadi as ca
import numpy as np

from ...core.errors import InputError
from ...core.joints import JOINT_TYPES
from ...core.model import Model
from ...core.options import REQUIRED
from ...core.units import format_quantity
from .builder import family
from .closure import closure_parts
from .expand import GROUND, PLATFORM, expand_legs, expansion_gap
from .generate import Generator
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


def summary_text(d: Description, model: Model | None, source: str) -> str:
    """The text of ``cpm-nlp describe FILE`` after the mechanism's parameters and limits."""
    gen, fns = closure_parts(d)
    where = f"values at the reference configuration of {source}" if model is not None else source
    lines = [f"({where})"] + _derived_lines(d, gen, model)
    if d.is_graph:
        lines += graph_lines(gen, model)
        return "\n".join(lines) + "\n"
    expanded, why = _expanded_graph(d, model)
    if expanded is not None:
        lines.append("the legs as bodies and joints (expanded; the platform is placed by its coordinates):")
        lines += graph_lines(expanded, model, branch=False)
    else:
        lines.append(f"(no bodies-and-joints view: {why})")
    lines += _leg_lines(d, gen, model)
    lines += _closure_lines(fns["row_names"])
    lines += _legs_mobility_lines(d, gen, model, source, len(fns["row_names"]))
    if gen.branch:
        lines.append("branch indicators: " + ", ".join(fns["branch_names"]))
    return "\n".join(lines) + "\n"


def _derived_lines(d: Description, gen: Any, model: Model | None) -> list[str]:
    """The derived values (with the model's values when there is one)."""
    if not d.derived:
        return []
    lines = ["derived values:"]
    for q, (name, _sx, dim) in zip(d.derived, gen.derived):
        shown = _derived_value(model, name, dim)
        text = q.value if isinstance(q.value, str) else str(q.value)
        lines.append(f"  {name:<8} = {shown or text}  ({dim}{'' if not shown else ': ' + text})")
        if q.description:
            lines.append(f"  {'':<8}   {q.description}")
    return lines


def _derived_value(model: Model | None, name: str, dim: str) -> str:
    value = None if model is None else model.derived.get(name)
    if isinstance(value, list):
        return "[" + ", ".join(format_quantity(v, dim, 5) for v in value) + "]"
    return "" if value is None else format_quantity(float(value), dim, 6)


def _leg_lines(d: Description, gen: Generator, model: Model | None) -> list[str]:
    """Each leg: the bodies it runs through and its joints."""
    hinges = _hinges_of(d)
    lines = ["legs (the shorthand; joints base -> platform, at the reference configuration):"]
    if not gen.leg_joints:
        lines.append("  (none: the loops are written as closures)")
    for leg, joints in gen.leg_joints:
        bodies = [GROUND]
        for n, j in enumerate(leg.joints):
            last = n == len(leg.joints) - 1
            bodies.append(j.body or (PLATFORM if last else f"{leg.name}_link{n + 1}"))
            if last and j.type == "distance":
                bodies.insert(-1, f"{leg.name}_rod")
        lines.append(f"  leg {leg.name}: " + " -> ".join(bodies))
        for k, (spec, resolved) in enumerate(zip(leg.joints, joints)):
            lines.append("    " + _joint_line(k, spec, resolved, gen, model, hinges))
    return lines


def _closure_lines(row_names: list[str]) -> list[str]:
    """The generated closures, one group per leg."""
    lines = ["closures (generated from the legs by elimination, one group per leg: what the solvers use):"]
    groups: dict[str, list[str]] = {}
    for name in row_names:
        head, _, what = name.partition(": ")
        groups.setdefault(head if what else "closures (expressions)", []).append(what or name)
    for head, rows in groups.items():
        lines.append(f"  {head}: {len(rows)} equation(s): " + "; ".join(rows))
    return lines


def _legs_mobility_lines(d: Description, gen: Generator, model: Model | None, source: str, rows: int) -> list[str]:
    """The actuators, pose coordinates and, with a model, the ranks at the reference configuration."""
    nx, nq = len(gen.x_names), len(gen.q_coords)
    task = list(d.platform.task)
    dependent = [n for n in gen.x_names if n not in task]
    also = "; dependent " + ", ".join(dependent) if dependent else ""
    lines = [
        "mobility:",
        f"  actuators ({nq}): " + ", ".join(c.name for c in gen.q_coords),
        f"  pose coordinates ({nx}): task " + ", ".join(task) + also,
    ]
    if d.platform.fixed:
        lines.append("  fixed by the structure: " + ", ".join(d.platform.fixed))
    if model is None:
        lines.append(f"  {rows} equation(s) for {nx} pose coordinate(s); rank not checked (no model: {source})")
        return lines
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
    return lines


def graph_lines(gen: Any, model: Model | None, branch: bool = True) -> list[str]:
    """``describe`` of a bodies-and-joints file: bodies, joints (in the spanning tree or closing a
    loop), the loops, mobility by rank beside Grübler-Kutzbach, and the assembly of the reference
    configuration (``branch``: and the branch indicators)."""
    info = gen.info
    lines = [f"bodies ({len(info.bodies)}; the ground: {info.ground}):"]
    for body in gen.d.bodies:
        what = f"  -- {body.description}" if body.description else ""
        lines.append(f"  {body.name:<10} points: {', '.join(body.points) or '-'}{what}")
    lines += _graph_joint_lines(gen)
    counts: dict[int, int] = {}
    for _r, _name, loop in gen.loop_rows:
        counts[loop] = counts.get(loop, 0) + 1
    lines.append("loops (a cycle basis: one per joint outside the spanning tree):")
    for number, joint, bodies in info.loops:
        lines.append(f"  loop {number}, closed by {joint}: {' - '.join(bodies)}  ({counts.get(number, 0)} equation(s))")
    lines += _graph_mobility_lines(gen, counts)
    lines.append(_assembly_line(gen, model))
    if gen.branch and branch:
        lines.append("branch indicators: " + ", ".join(b[1] for b in gen.branch))
    if gen.closed_form_summary and branch:
        lines.append(gen.closed_form_summary)
    return lines


def _graph_joint_lines(gen: Any) -> list[str]:
    """Each joint of the graph: its type, bodies, point, role (tree or the loop it closes), coordinates."""
    info = gen.info
    ntree = sum(1 for j in info.joints if j[5])
    lines = [f"joints ({len(info.joints)}; {ntree} in the spanning tree, {len(info.joints) - ntree} closing a loop):"]
    for g, (name, kind, a, b, actuated, tree, loop) in zip(gen.gjoints, info.joints):
        at = g.spec.at if isinstance(g.spec.at, str) else "its coordinates" if kind == "pose" else "(a point)"
        role = "tree" if tree else f"closes loop {loop}"
        coords = (
            f"actuated: {g.spec.actuated}" if actuated else ("coordinates: " + ", ".join(g.names) if g.names else "")
        )
        if not tree and g.spec.coordinates:
            coords = "coordinates: " + ", ".join(g.spec.coordinates)
        lines.append(f"  {name:<6} {kind:<9} {a} -> {b} at {at}  {role}" + (f"  {coords}" if coords else ""))
    return lines


def _graph_mobility_lines(gen: Any, counts: dict[int, int]) -> list[str]:
    """Mobility by rank beside Grübler-Kutzbach, the rows that repeat others, the pose coordinates."""
    info = gen.info
    nq = len(gen.q_coords)
    lines = [
        "mobility:",
        f"  rank of the loops' Jacobian at the reference configuration: {info.mobility} degree(s) of freedom; "
        f"Grübler-Kutzbach: {info.gruebler}; actuated: {nq} ({', '.join(c.name for c in gen.q_coords)})",
    ]
    if info.dropped:
        by_loop: dict[int, int] = {}
        for loop, _name in info.dropped:
            by_loop[loop] = by_loop.get(loop, 0) + 1
        which = ", ".join(f"loop {k} ({n} of {counts[k]})" for k, n in sorted(by_loop.items()))
        lines.append(
            f"  the two disagree: equations repeat one another at the reference configuration in {which}: "
            "overconstrained (Φ holds the normal equations of every loop equation; a pose is checked against each)"
            if info.mobility != info.gruebler
            else f"  equations that repeat others at the reference configuration: {which}"
        )
    elif info.mobility != info.gruebler:
        lines.append("  the two disagree: a loop's joints are arranged so that they move more than counted")
    task = list(gen.d.platform.task)
    dependent = [n for n in gen.x_names if n not in task]
    lines.append(f"  pose coordinates ({len(gen.x_names)}): task {', '.join(task)}; dependent {', '.join(dependent)}")
    return lines


def _assembly_line(gen: Any, model: Model | None) -> str:
    """How the reference configuration assembles from the drawing (the model's parameters, else the defaults)."""
    p = np.asarray(model.p, dtype=float) if model is not None else gen.p_default
    _x, _q, status = gen.assembler.solve(p)
    move_name, move = status["largest_move"]
    return "reference configuration: " + (
        f"assembled from the drawing in {status['steps']} Gauss-Newton step(s): residual "
        f"{status['residual_at_drawing']:.3g} at the drawing, {status['residual']:.3g} assembled (SI); "
        f"largest move {move_name} by {move:.4g}"
        if status["assembled"]
        else f"does not assemble from the drawing: residual {status['residual']:.3g} in {status['worst_row']}"
    )


def _expanded_graph(d: Description, model: Model | None) -> tuple[Any, str]:
    """The graph generator of a legs file's expansion, with the model's parameters (or the
    defaults); None and why when there is none."""
    gap = expansion_gap(d)
    if gap is not None:
        return None, f"it has no bodies-and-joints equivalent yet: {gap}"
    values = dict(zip([p.name for p in d.parameters], np.asarray(model.p, dtype=float))) if model is not None else {}
    missing = [p.name for p in d.parameters if p.default is REQUIRED and p.name not in values]
    if missing:
        return None, f"the loops' rank needs a value of {', '.join(missing)} (give them in an example problem)"
    try:
        gen, _fns = closure_parts(expand_legs(d, values))
    except InputError as exc:
        return None, exc.render()
    return gen, ""


def body_graph(d: Description) -> tuple[list[str], list[tuple[str, str, str, bool]]]:
    """The bodies (base, each leg's links, platform) and the joints between them as edges
    (from body, to body, label, actuated), base side first: the graph ``describe --plot`` draws.
    A bodies-and-joints file: its bodies (the ground first) and every joint, named; a legs file:
    the bodies and joints its legs expand into (the platform, placed by its coordinates, is not
    joined to the ground by an edge)."""
    if d.legs and expansion_gap(d) is None:
        d = expand_legs(d)
    if d.is_graph:
        ground = next(b.name for b in d.bodies if b.name in ("ground", "base"))
        nodes = [ground] + [b.name for b in d.bodies if b.name != ground]
        edges = [
            (
                j.between[0],
                j.between[1],
                f"{j.name} {j.type}" + (f" {j.actuated}" if j.actuated else ""),
                j.actuated is not None,
            )
            for j in d.joints
        ]
        return nodes, edges
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
