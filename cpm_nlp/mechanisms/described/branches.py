"""The assembly-branch indicators of a generated closure: the eliminated links' (an assembly
mode of the sub-chain a link closes, or its leg's working mode), the aspect, the ones the
``branch`` section writes as expressions, and the selection the ``branch`` section makes of the
generated ones."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import casadi as ca

from ...core.aspect import ASPECT, ASPECT_DESCRIPTION, ASPECT_MAX_NX, twist_determinant
from ...core.aspect import aspect as aspect_indicator
from ...core.errors import InputError, suggest
from . import expr as ex
from .builder import ClosureBuilder

#: what the generated indicators measure
COSINE = "cosine of the link to the platform joint to its reference direction"
ASSEMBLY = (
    "assembly mode of the sub-chain this link closes: det of its passive Jacobian (a block of Φ_x) "
    "over its value at home"
)
WORKING_R = (
    "working mode: w·((c - a) × (B - c)) of the joint before it (axis w at a) and the link c -> B, "
    "over its value at home"
)
WORKING_PLANAR = (
    "working mode (elbow): the signed area of the triangle (a, c, B) of the joint before it and the "
    "link c -> B, over its value at home"
)
WORKING_P = "working mode: e·(B - c) of the P joint before it (axis e) and the link c -> B, over its value at home"


def elimination_indicators(gen: ClosureBuilder, q: ca.SX) -> None:
    """The indicator of each eliminated link (recorded by `generate.Generator.eliminated`), a mode invariant.

    If the link's rows make a diagonal block of Φ_x (block-triangular form, Dulmage-Mendelsohn)
    holding no other elimination, the link closes a sub-chain of its own (a four-bar's coupler
    with the rocker, a slider-crank's rod with the slider): its indicator is the determinant of
    that block -- the sub-chain's passive Jacobian -- over its value at home.  It changes sign
    only where the sub-chain is singular (the coupler and rocker aligned), i.e. between its
    assembly modes; for a triangle closed at a revolute it is the triangle's orientation, for
    an S-S link the side of the output crank's plane.  Otherwise the link is one of several
    holding the platform, whose assembly mode is the ``aspect``; its indicator is the leg's
    working mode, the closure's rate with respect to the joint before the link over its
    value at home (the Delta's and the five-bar's elbows), changing sign only where the
    leg is stretched or folded (a singularity of the leg).  A link with neither (fixed c and
    a shared block) gets no indicator."""
    if not gen.pending:
        return
    phi = ca.vertcat(*[r[0] for r in gen.rows])
    J = ca.jacobian(phi, gen.x)
    xq, home = ca.vertcat(gen.x, q), ca.vertcat(gen.x_home, *gen.q_home)
    block_of, blocks = {}, []
    if ca.sprank(J.sparsity()) == J.size1() == J.size2():
        nb, rowperm, colperm, rowblock, colblock, *_ = J.sparsity().btf()
        for k in range(nb):
            rows, cols = rowperm[rowblock[k] : rowblock[k + 1]], colperm[colblock[k] : colblock[k + 1]]
            blocks.append((rows, cols))
            block_of.update({r: k for r in rows})
    owners: dict[int, int] = {}
    for _pos, rows, _w, _what in gen.pending:
        ks = {block_of.get(r) for r in rows}
        if len(ks) == 1 and None not in ks:
            k = ks.pop()
            owners[k] = owners.get(k, 0) + 1
    drop = []
    for pos, rows, working, what in gen.pending:
        _v, name, desc = gen.branch[pos]
        ks = {block_of.get(r) for r in rows}
        k = next(iter(ks)) if len(ks) == 1 else None
        value = None
        if k is not None and owners.get(k) == 1 and len(blocks[k][1]) <= ASPECT_MAX_NX:
            brows, bcols = blocks[k]
            d = twist_determinant(phi[brows], ca.vertcat(*[gen.x[j] for j in bcols]), gen.R)
            value, what = d / ca.substitute(d, xq, home), ASSEMBLY
        elif working is not None:
            # over its value at home: polynomial in the pose (an interval proof of outside stays tight)
            value = working / ca.substitute(working, xq, home)
        if value is None:
            drop.append(pos)
            continue
        gen.branch[pos] = (value, name, desc + what)
    gen.branch = [b for k, b in enumerate(gen.branch) if k not in drop]


def branch_expressions(gen: ClosureBuilder, env: Mapping[str, ex.Value]) -> list[tuple[ca.SX, str, str]]:
    """The indicators the ``branch`` section writes as expressions (named ``branch[k]`` unless given
    a name); an item that is a generated indicator's name is a selection, not an expression."""
    spec = gen.d.branch
    items = spec if isinstance(spec, list) else (spec or {}).get("add", []) if isinstance(spec, dict) else []
    base = ("branch",) if isinstance(spec, list) else ("branch", "add")
    names = {b[1] for b in gen.branch} | {ASPECT}  # the aspect indicator is generated after the closures
    out = []
    for k, item in enumerate(items):
        if isinstance(item, str) and item in names and isinstance(spec, list):
            continue
        name, text = next(iter(item.items())) if isinstance(item, dict) else (f"branch[{k}]", item)
        out.append((gen.scalar(text, base + (k,), env), name, f"declared: {text}"))
    return out


def select_branch(gen: ClosureBuilder, added: list[tuple[ca.SX, str, str]]) -> None:
    """Apply the ``branch`` section to the generated indicators (absent: all of them)."""
    spec, generated = gen.d.branch, gen.branch
    names = [b[1] for b in generated]

    def check(name: str, path: tuple) -> None:
        if name not in names:
            raise InputError(
                f"no generated branch indicator {name!r}; they are: {', '.join(names) or 'none'}",
                path=path,
                suggestions=suggest(name, names),
            )

    if spec is None:
        keep = names
    elif isinstance(spec, list):
        keep = [v for v in spec if isinstance(v, str) and v in names]
        if ASPECT in spec and ASPECT not in names:
            check(ASPECT, ("branch", spec.index(ASPECT)))
    else:
        keep = names if spec["keep"] == "all" else [] if spec["keep"] == "none" else spec["keep"]
        for k, name in enumerate(() if isinstance(keep, list) and keep is names else keep):
            check(name, ("branch", "keep", k))
        for k, name in enumerate(spec["remove"]):
            check(name, ("branch", "remove", k))
        keep = [n for n in keep if n not in spec["remove"]]
    gen.branch = [b for b in generated if b[1] in keep] + added
    taken = [b[1] for b in gen.branch]
    dup = sorted({n for n in taken if taken.count(n) > 1})
    if dup:
        raise InputError(f"the branch indicator name {dup[0]!r} is used twice", path=("branch",))


def aspect(gen: ClosureBuilder, q: ca.SX) -> None:
    """The aspect indicator (`cpm_nlp.core.aspect`): negative in an assembly mode across a
    forward singularity from the reference configuration."""
    if gen.x.numel() > ASPECT_MAX_NX:
        return
    phi = ca.vertcat(*[r[0] for r in gen.rows])
    value = aspect_indicator(phi, gen.x, q, gen.R, gen.x_home, ca.vertcat(*gen.q_home))
    gen.branch.append((value, ASPECT, ASPECT_DESCRIPTION))


def graph_indicators(gen: Any, q: ca.SX) -> None:
    """A graph's indicators (``gen``: its `GraphGenerator`): one indicator per
    diagonal block of Φ_x (block-triangular form) that holds loop rows: the sign of the block's
    determinant is the assembly mode of the loops it holds; it is taken as the reference
    configuration's, and scaled by the determinant's size at the drawing."""
    phi = ca.vertcat(*[r[0] for r in gen.rows])
    J = ca.jacobian(phi, gen.x)
    if ca.sprank(J.sparsity()) < J.size1():
        return
    nb, rowperm, colperm, rowblock, colblock, *_ = J.sparsity().btf()
    nloop = sum(1 for r in gen.rows if r[1].startswith("loop "))
    xq = ca.vertcat(gen.x, q)
    draw = ca.vertcat(gen.x_home, *gen.q_home)
    for k in range(nb):
        rows = rowperm[rowblock[k] : rowblock[k + 1]]
        cols = colperm[colblock[k] : colblock[k + 1]]
        loops = sorted({int(gen.rows[r][1].split()[1]) for r in rows if r < nloop})
        if not loops or len(cols) > ASPECT_MAX_NX:
            continue
        d = twist_determinant(phi[rows], ca.vertcat(*[gen.x[c] for c in cols]), None)
        sign = gen.assembler.reference_sign(d)
        scale = ca.fmax(ca.fabs(ca.substitute(d, xq, draw)), 1e-300)
        name = "loop" + "_".join(str(n) for n in loops)
        taken, base, m = {b[1] for b in gen.branch}, name, 2
        while name in taken:  # another block of the same loops (the 3-PRC's platform closes two)
            name, m = f"{base}_block{m}", m + 1
        what = (
            f"assembly mode of loop{'s' if len(loops) > 1 else ''} {', '.join(map(str, loops))}: det of "
            f"{'their' if len(loops) > 1 else 'its'} block of Φ_x, signed as at the reference configuration"
        )
        gen.branch.append((sign * d / scale, name, what))
