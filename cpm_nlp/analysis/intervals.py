"""Interval evaluation of CasADi SX functions, vectorised over many boxes.

`IntervalProgram` walks the algorithm of a ``ca.Function`` (built from
SX) once, op by op (``instruction_id`` / ``instruction_input`` /
``instruction_output`` / ``instruction_constant``), and replays it on interval
operands: every work register holds two numpy arrays (lower and upper ends)
of shape (B,), one entry per box, so a batch of B boxes costs one pass over
the instructions.

Rigour (outward rounding):

* +, -, *, /, sqrt and sq are correctly rounded in IEEE double arithmetic;
  their ends are moved one ulp outward (``np.nextafter``);
* sin, cos, tan, atan, atan2, acos, asin, exp, log, pow come from the C
  library, which is not correctly rounded but accurate to an ulp or two
  (glibc documents at most 1-2 ulp for these); their ends are moved
  `LIBM_ULPS` ulps outward;
* fmin, fmax, neg, twice, fabs and assignments are exact and not widened;
* a function undefined somewhere in its interval argument (acos outside
  [-1, 1], sqrt or log of a negative number, division by an interval that
  contains zero) gives NaN or an infinite interval, never a finite interval
  that could be mistaken for a proof; callers treat NaN as "not proven".

The enclosure is the natural interval extension; `cpm_nlp.analysis.certify`
sharpens it with a monotonicity test (the interval Jacobian).
"""

from __future__ import annotations

import math
from typing import Any

import casadi as ca
import numpy as np

#: values (nodes × boxes) held at a time by `IntervalProgram.evaluate`
MAX_VALUES = 4_000_000
#: ulps by which the ends of a C-library function value are moved outward
LIBM_ULPS = 4

_INF = np.inf
_TWO_PI = 2.0 * math.pi


def _down(a: np.ndarray) -> np.ndarray:
    return np.nextafter(a, -_INF)


def _up(a: np.ndarray) -> np.ndarray:
    return np.nextafter(a, _INF)


def _widen(lo: np.ndarray, hi: np.ndarray, lower_bound: float = -_INF, upper_bound: float = _INF):
    """Move the ends LIBM_ULPS ulps outward, clipped to the function's known range."""
    with np.errstate(invalid="ignore"):
        lo = np.where(np.isfinite(lo), lo - LIBM_ULPS * np.spacing(np.abs(lo)), lo)
        hi = np.where(np.isfinite(hi), hi + LIBM_ULPS * np.spacing(np.abs(hi)), hi)
    return np.maximum(lo, lower_bound), np.minimum(hi, upper_bound)


def _mul(alo, ahi, blo, bhi):
    with np.errstate(invalid="ignore", over="ignore"):
        p = np.stack([alo * blo, alo * bhi, ahi * blo, ahi * bhi])
        return _down(p.min(axis=0)), _up(p.max(axis=0))


def _div(alo, ahi, blo, bhi):
    zero = (blo <= 0.0) & (bhi >= 0.0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        p = np.stack([alo / blo, alo / bhi, ahi / blo, ahi / bhi])
        lo, hi = _down(p.min(axis=0)), _up(p.max(axis=0))
    return np.where(zero, -_INF, lo), np.where(zero, _INF, hi)


def _sq(lo, hi):
    a, b = lo * lo, hi * hi
    straddle = (lo <= 0.0) & (hi >= 0.0)
    low = np.where(straddle, 0.0, np.minimum(a, b))
    return np.maximum(_down(low), 0.0), _up(np.maximum(a, b))


def _sqrt(lo, hi):
    with np.errstate(invalid="ignore"):
        r_lo, r_hi = np.maximum(_down(np.sqrt(lo)), 0.0), _up(np.sqrt(hi))
    bad = lo < 0.0
    return np.where(bad, np.nan, r_lo), np.where(bad, np.nan, r_hi)


def _contains(lo, hi, point, period):
    """Whether [lo, hi] contains point + k·period for some integer k (with slack:
    a point reported contained when it is not only widens the enclosure)."""
    k = np.ceil((lo - point) / period - 1e-12)
    return point + k * period <= hi + 1e-12 * (1.0 + np.abs(hi))


def _cos(lo, hi):
    with np.errstate(invalid="ignore"):
        a, b = np.cos(lo), np.cos(hi)
        r_lo, r_hi = _widen(np.minimum(a, b), np.maximum(a, b), -1.0, 1.0)
        full = ~(hi - lo < _TWO_PI)
        r_hi = np.where(_contains(lo, hi, 0.0, _TWO_PI) | full, 1.0, r_hi)
        r_lo = np.where(_contains(lo, hi, math.pi, _TWO_PI) | full, -1.0, r_lo)
    nan = np.isnan(lo) | np.isnan(hi)
    return np.where(nan, np.nan, r_lo), np.where(nan, np.nan, r_hi)


def _sin(lo, hi):
    with np.errstate(invalid="ignore"):
        a, b = np.sin(lo), np.sin(hi)
        r_lo, r_hi = _widen(np.minimum(a, b), np.maximum(a, b), -1.0, 1.0)
        full = ~(hi - lo < _TWO_PI)
        r_hi = np.where(_contains(lo, hi, 0.5 * math.pi, _TWO_PI) | full, 1.0, r_hi)
        r_lo = np.where(_contains(lo, hi, -0.5 * math.pi, _TWO_PI) | full, -1.0, r_lo)
    nan = np.isnan(lo) | np.isnan(hi)
    return np.where(nan, np.nan, r_lo), np.where(nan, np.nan, r_hi)


def _tan(lo, hi):
    with np.errstate(invalid="ignore"):
        pole = ~(hi - lo < math.pi) | _contains(lo, hi, 0.5 * math.pi, math.pi)
        r_lo, r_hi = _widen(np.tan(lo), np.tan(hi))
    return np.where(pole, -_INF, r_lo), np.where(pole, _INF, r_hi)


def _monotone(fn, lo, hi, increasing=True, lower_bound=-_INF, upper_bound=_INF, domain=(-_INF, _INF)):
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        a, b = fn(lo), fn(hi)
        r_lo, r_hi = _widen(a, b, lower_bound, upper_bound) if increasing else _widen(b, a, lower_bound, upper_bound)
    bad = (lo < domain[0]) | (hi > domain[1])
    return np.where(bad, np.nan, r_lo), np.where(bad, np.nan, r_hi)


def _atan2(ylo, yhi, xlo, xhi):
    """atan2(y, x) over a box: the range is attained at its corners whenever the box
    lies in an open half plane x > 0, y > 0 or y < 0 (atan2 is monotone in each
    argument there); else [-π, π]."""
    with np.errstate(invalid="ignore"):
        c = np.stack([np.arctan2(ylo, xlo), np.arctan2(ylo, xhi), np.arctan2(yhi, xlo), np.arctan2(yhi, xhi)])
        lo, hi = _widen(c.min(axis=0), c.max(axis=0), -math.pi, math.pi)
    half = (xlo > 0.0) | (ylo > 0.0) | (yhi < 0.0)
    # on y < 0 with x <= 0 the values are near -π, on y > 0 near π: no branch cut is crossed
    return np.where(half, lo, -math.pi), np.where(half, hi, math.pi)


def _cmp(certain, impossible):
    """A comparison as an interval of {0, 1}."""
    return np.where(certain, 1.0, 0.0), np.where(impossible, 0.0, 1.0)


def _pow(alo, ahi, blo, bhi):
    """x^y for x > 0 as exp(y log x); NaN where x may be <= 0."""
    llo, lhi = _monotone(np.log, alo, ahi)
    plo, phi = _mul(llo, lhi, blo, bhi)
    r_lo, r_hi = _monotone(np.exp, plo, phi, lower_bound=0.0)
    bad = ~(alo > 0.0)
    return np.where(bad, np.nan, r_lo), np.where(bad, np.nan, r_hi)


def _constpow(alo, ahi, e: float):
    """x^e for a constant e: integer e on any x, else x >= 0."""
    if e == int(e):
        n = int(e)
        if n == 0:
            return np.ones_like(alo), np.ones_like(alo)
        if n < 0:
            plo, phi = _constpow(alo, ahi, -n)
            return _div(np.ones_like(alo), np.ones_like(alo), plo, phi)
        with np.errstate(over="ignore", invalid="ignore"):
            a, b = alo**n, ahi**n
            if n % 2:
                return _widen(a, b)
            straddle = (alo <= 0.0) & (ahi >= 0.0)
            lo, hi = _widen(np.where(straddle, 0.0, np.minimum(a, b)), np.maximum(a, b), 0.0)
            return lo, hi
    with np.errstate(invalid="ignore"):
        a, b = np.power(alo, e), np.power(ahi, e)
        lo, hi = _widen(a, b, 0.0) if e > 0 else _widen(b, a, 0.0)
    bad = alo < 0.0
    return np.where(bad, np.nan, lo), np.where(bad, np.nan, hi)


class UnsupportedOperation(ValueError):
    """The function uses an operation without an interval version here."""


def _unary(op: int):
    table = {
        ca.OP_NEG: lambda lo, hi: (-hi, -lo),
        ca.OP_TWICE: lambda lo, hi: (2.0 * lo, 2.0 * hi),
        ca.OP_SQ: _sq,
        ca.OP_SQRT: _sqrt,
        ca.OP_SIN: _sin,
        ca.OP_COS: _cos,
        ca.OP_TAN: _tan,
        ca.OP_ATAN: lambda lo, hi: _monotone(np.arctan, lo, hi, True, -0.5 * math.pi, 0.5 * math.pi),
        ca.OP_ASIN: lambda lo, hi: _monotone(np.arcsin, lo, hi, True, -0.5 * math.pi, 0.5 * math.pi, (-1.0, 1.0)),
        ca.OP_ACOS: lambda lo, hi: _monotone(np.arccos, lo, hi, False, 0.0, math.pi, (-1.0, 1.0)),
        ca.OP_EXP: lambda lo, hi: _monotone(np.exp, lo, hi, True, 0.0),
        ca.OP_LOG: lambda lo, hi: _monotone(np.log, lo, hi, True, domain=(0.0, _INF)),
        ca.OP_INV: lambda lo, hi: _div(np.ones_like(lo), np.ones_like(lo), lo, hi),
        ca.OP_FABS: lambda lo, hi: (
            np.where((lo <= 0.0) & (hi >= 0.0), 0.0, np.minimum(np.abs(lo), np.abs(hi))),
            np.maximum(np.abs(lo), np.abs(hi)),
        ),
        ca.OP_NOT: lambda lo, hi: (1.0 - hi, 1.0 - lo),
    }
    return table.get(op)


def _binary(op: int):
    table = {
        ca.OP_ADD: lambda alo, ahi, blo, bhi: (_down(alo + blo), _up(ahi + bhi)),
        ca.OP_SUB: lambda alo, ahi, blo, bhi: (_down(alo - bhi), _up(ahi - blo)),
        ca.OP_MUL: _mul,
        ca.OP_DIV: _div,
        ca.OP_FMIN: lambda alo, ahi, blo, bhi: (np.minimum(alo, blo), np.minimum(ahi, bhi)),
        ca.OP_FMAX: lambda alo, ahi, blo, bhi: (np.maximum(alo, blo), np.maximum(ahi, bhi)),
        ca.OP_ATAN2: _atan2,
        ca.OP_POW: _pow,
        ca.OP_LE: lambda alo, ahi, blo, bhi: _cmp(ahi <= blo, alo > bhi),
        ca.OP_LT: lambda alo, ahi, blo, bhi: _cmp(ahi < blo, alo >= bhi),
        ca.OP_AND: lambda alo, ahi, blo, bhi: (np.minimum(alo, blo), np.minimum(ahi, bhi)),
        ca.OP_OR: lambda alo, ahi, blo, bhi: (np.maximum(alo, blo), np.maximum(ahi, bhi)),
        ca.OP_IF_ELSE_ZERO: lambda clo, chi, blo, bhi: (
            np.where(clo >= 1.0, blo, np.where(chi <= 0.0, 0.0, np.minimum(blo, 0.0))),
            np.where(clo >= 1.0, bhi, np.where(chi <= 0.0, 0.0, np.maximum(bhi, 0.0))),
        ),
    }
    return table.get(op)


_OP_NAMES = {getattr(ca, n): n for n in dir(ca) if n.startswith("OP_")}


def _group_function(key: tuple) -> Any:
    """The interval version of a group's operation: ("constpow", e), ("u", op) or ("b", op)."""
    if key[0] == "constpow":
        e = key[1]
        return lambda lo, hi: _constpow(lo, hi, e)
    return _unary(key[1]) if key[0] == "u" else _binary(key[1])


class _Trace:
    """The instructions of an SX function replayed as single-assignment nodes: each node's
    depth in the graph (``level``), the constants, inputs, outputs and operations."""

    def __init__(self, fn: ca.Function) -> None:
        self.fn = fn
        self.reg: dict[int, int] = {}  # work register -> current node
        self.level: list[int] = []
        self.const: dict[int, float] = {}
        self.inputs: list[tuple[int, int, int]] = []  # (node, input, nz)
        self.outputs: list[tuple[int, int, int]] = []  # (node, output, nz)
        self.ops: list[tuple] = []  # (key, node, args)
        moves = {
            ca.OP_INPUT: self._input,
            ca.OP_OUTPUT: self._output,
            ca.OP_CONST: self._const,
            ca.OP_ASSIGN: self._assign,
        }
        for k in range(fn.n_instructions()):
            op = fn.instruction_id(k)
            ins, outs = fn.instruction_input(k), fn.instruction_output(k)
            if op in moves:
                moves[op](k, ins, outs)
            else:
                self._operation(op, ins, outs)

    def _new(self, lvl: int, register: int) -> int:
        self.level.append(lvl)
        self.reg[register] = len(self.level) - 1
        return self.reg[register]

    def _input(self, _k: int, ins: list, outs: list) -> None:
        self.inputs.append((self._new(0, outs[0]), ins[0], ins[1]))

    def _output(self, _k: int, ins: list, outs: list) -> None:
        self.outputs.append((self.reg[ins[0]], outs[0], outs[1]))

    def _const(self, k: int, _ins: list, outs: list) -> None:
        self.const[self._new(0, outs[0])] = float(self.fn.instruction_constant(k))

    def _assign(self, _k: int, ins: list, outs: list) -> None:
        self.reg[outs[0]] = self.reg[ins[0]]

    def _operation(self, op: int, ins: list, outs: list) -> None:
        """A unary or binary operation, a power by a constant; else no interval version."""
        if op == ca.OP_CONSTPOW and self.reg[ins[1]] in self.const:
            key, args = ("constpow", self.const[self.reg[ins[1]]]), (self.reg[ins[0]],)
        elif _unary(op) is not None:
            key, args = ("u", op), (self.reg[ins[0]],)
        elif _binary(op) is not None or op == ca.OP_CONSTPOW:
            key, args = ("b", ca.OP_POW if op == ca.OP_CONSTPOW else op), (self.reg[ins[0]], self.reg[ins[1]])
        else:
            raise UnsupportedOperation(f"{self.fn.name()}: no interval version of {_OP_NAMES.get(op, op)}")
        node = self._new(max(self.level[a] for a in args) + 1, outs[0])
        self.ops.append((key, node, args))


class IntervalProgram:
    """A ``ca.Function`` (SX) compiled to layers of interval operations.

    ``evaluate(inputs)`` takes, per input of the function, a pair (lo, hi) of
    arrays (B, n_in) and returns per output a pair (lo, hi) of arrays (B, n_out)
    enclosing the output over every point of the boxes.  Raises
    `UnsupportedOperation` at construction if the function uses an
    operation without an interval version.

    The instructions are renamed to single-assignment nodes and grouped by
    depth in the graph and operation: one numpy call evaluates every node of a
    group for every box (a few hundred calls for a graph of thousands of
    instructions).  ``nodes`` is the number of values held per box.
    """

    def __init__(self, fn: ca.Function):
        if not fn.is_a("SXFunction"):
            raise UnsupportedOperation(f"{fn.name()}: interval evaluation needs an SX function")
        self.name = fn.name()
        self.n_out = [fn.nnz_out(k) for k in range(fn.n_out())]
        t = _Trace(fn)
        level, const = t.level, t.const
        self.nodes = len(level)
        self.const_nodes = np.array(sorted(const), dtype=int)
        self.const_values = np.array([const[n] for n in sorted(const)])
        self.inputs = [
            (
                np.array([n for n, i, _ in t.inputs if i == j], dtype=int),
                np.array([z for _, i, z in t.inputs if i == j], dtype=int),  # int even when empty (no parameters)
            )
            for j in range(fn.n_in())
        ]
        self.outputs = [
            (
                np.array([n for n, o, _ in t.outputs if o == j], dtype=int),
                np.array([z for _, o, z in t.outputs if o == j], dtype=int),
            )
            for j in range(fn.n_out())
        ]
        groups: dict[tuple, list] = {}
        for key, node, args in t.ops:
            groups.setdefault((level[node], key), []).append((node, args))
        self.groups = []
        for (_lvl, key), members in sorted(groups.items(), key=lambda kv: kv[0][0]):
            out = np.array([n for n, _ in members], dtype=int)
            args = tuple(np.array([a[i] for _, a in members], dtype=int) for i in range(len(members[0][1])))
            self.groups.append((_group_function(key), out, args))

    def evaluate(self, inputs: list[tuple[np.ndarray, np.ndarray]]) -> list[tuple[np.ndarray, np.ndarray]]:
        B = np.asarray(inputs[0][0]).shape[0]
        chunk = max(1, MAX_VALUES // max(self.nodes, 1))
        if B > chunk:  # bounded memory: nodes × boxes values at a time
            parts = [
                self.evaluate([(lo[k : k + chunk], hi[k : k + chunk]) for lo, hi in inputs]) for k in range(0, B, chunk)
            ]
            return [
                (np.vstack([p[j][0] for p in parts]), np.vstack([p[j][1] for p in parts])) for j in range(len(parts[0]))
            ]
        lo = np.empty((self.nodes, B))
        hi = np.empty((self.nodes, B))
        lo[self.const_nodes] = self.const_values[:, None]
        hi[self.const_nodes] = self.const_values[:, None]
        for (nodes, nz), (ilo, ihi) in zip(self.inputs, inputs):
            lo[nodes] = np.asarray(ilo, dtype=float)[:, nz].T
            hi[nodes] = np.asarray(ihi, dtype=float)[:, nz].T
        for f, out, args in self.groups:
            if len(args) == 1:
                lo[out], hi[out] = f(lo[args[0]], hi[args[0]])
            else:
                a, b = args
                lo[out], hi[out] = f(lo[a], hi[a], lo[b], hi[b])
        result = []
        for (nodes, nz), n in zip(self.outputs, self.n_out):
            olo, ohi = np.full((B, n), np.nan), np.full((B, n), np.nan)
            olo[:, nz], ohi[:, nz] = lo[nodes].T, hi[nodes].T
            result.append((olo, ohi))
        return result
