"""Expressions of mechanism files, parsed safely into CasADi.

An expression is a string such as ``"b + L*cos(alpha0)"`` or
``"[a*cos(g), a*sin(g), 0]"`` over declared symbols (parameters, derived
values, pose and actuator coordinates).  It is parsed with Python's
`ast` and walked with a strict whitelist -- numbers, names, ``+ - * / **``
(``^`` is read as a power), unary minus, calls of the functions in
`FUNCTIONS`, ``[a, b, c]`` vectors and ``v[0]`` indexing -- and never
evaluated by Python: every other construct (attributes, comparisons,
lambdas, keywords, strings ...) is an error that names its column.

A number may carry a unit of length or angle (``l + 3 mm``, ``th0 + 1 deg``,
``-22.22 mm``): it is one value, converted to SI when the file is read.

Each value carries a physical dimension, the exponents of length and of
angle, so that an angle where a length is expected ("[a, 0, alpha0]" as a
location) is an error, not a silent mix.  The rule (docs/site/guide/mechanism-files.md,
"Units and dimensions"): a number without a unit is *bare* and read in SI
(m, rad), like a problem file's bare number: it takes the dimension of what
it is added to (``l + 0.01`` is l + 10 mm).  Angles and dimensionless values
(``pi/2``, ``cos(a)``) may be added (radians are dimensionless in SI); lengths
may not be added to either.
"""

from __future__ import annotations

import ast
import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import casadi as ca

from ...core.errors import InputError, suggest
from ...core.finite import LARGEST, too_large
from ...core.units import DIMENSIONS as UNIT_DIMENSIONS
from ...core.units import FAST_UNITS, parse_quantity

#: dimension of a value: (length exponent, angle exponent); None for a plain number that adapts
Dim = tuple[float, float] | None

LENGTH: Dim = (1.0, 0.0)
ANGLE: Dim = (0.0, 1.0)
NUMBER: Dim = (0.0, 0.0)
#: dimension names of mechanism files and declared options -> Dim
DIMENSION_OF = {"length": LENGTH, "angle": ANGLE, "dimensionless": NUMBER}


class ExpressionError(Exception):
    """A bad expression: the message, and the 1-based column in the string as written."""

    def __init__(self, message: str, column: int) -> None:
        self.message, self.column = message, column
        super().__init__(f"column {column}: {message}")


def describe(dim: Dim) -> str:
    if dim is None:
        return "a plain number"
    length, angle = dim
    if length == 0:
        return "an angle" if angle else "a plain number"
    if length == 1 and angle == 0:
        return "a length"
    return f"a quantity of dimension length^{length:g}" + (f" angle^{angle:g}" if angle else "")


def compatible(a: Dim, b: Dim) -> bool:
    """Dimensions that may be added or compared: equal length exponents (angles are radians)."""
    return a is None or b is None or a[0] == b[0]


def dimensioned(dim: Dim) -> bool:
    """A dimension a bare number may not be added to: a length, an angle (or a power of them)."""
    return dim is not None and (dim[0] != 0 or dim[1] != 0)


def unit_hint(dim: Dim, number: str = "") -> str:
    """How to write a number of ``dim`` with its unit: ``write its unit, e.g. 0.01 m or 10 mm``."""
    n = number or "3"
    if dim == LENGTH:
        return f"write its unit, e.g. '{n} m' or '{n} mm'"
    if dim == ANGLE:
        return f"write its unit, e.g. '{n} rad' or '{n} deg'"
    return "write its unit (e.g. '(10 mm)^2')"


@dataclass(frozen=True)
class Value:
    """A CasADi expression (scalar or column vector) and its dimension."""

    sx: ca.SX
    dim: Dim

    @property
    def size(self) -> int:
        return int(self.sx.numel())


def _mul(a: Dim, b: Dim, sign: float = 1.0) -> Dim:
    if a is None:
        return b if sign > 0 or b is None else (-b[0], -b[1])
    if b is None:
        return a
    return (a[0] + sign * b[0], a[1] + sign * b[1])


def _same(name: str, args: list[Value], col: int) -> Dim:
    dims = [a.dim for a in args if a.dim is not None]
    for d in dims[1:]:
        if not compatible(dims[0], d):
            raise ExpressionError(
                f"{name}() needs arguments of one dimension, got {describe(dims[0])} and {describe(d)}", col
            )
    return dims[0] if dims else None


def _trig(name: str, args: list[Value], col: int) -> Dim:
    d = args[0].dim
    if d is not None and d[0] != 0:
        raise ExpressionError(f"{name}() takes an angle or a plain number, got {describe(d)}", col)
    return NUMBER


def _inverse_trig(name: str, args: list[Value], col: int) -> Dim:
    _trig(name, args, col)
    return ANGLE


def _atan2(name: str, args: list[Value], col: int) -> Dim:
    _same(name, args, col)
    return ANGLE


def _sqrt(_name: str, args: list[Value], _col: int) -> Dim:
    d = args[0].dim
    return None if d is None else (d[0] / 2, d[1] / 2)


def _product(_name: str, args: list[Value], _col: int) -> Dim:
    return _mul(args[0].dim, args[1].dim)


def _unitless(_name: str, _args: list[Value], _col: int) -> Dim:
    return NUMBER


def _first(_name: str, args: list[Value], _col: int) -> Dim:
    return args[0].dim


def _select(i, *values):
    return values[int(i) - 1]


#: name -> (number of arguments (None: any >= 1), CasADi implementation, dimension rule, vector arguments)
FUNCTIONS: dict[str, tuple[int | None, Callable, Callable, bool]] = {
    "sin": (1, ca.sin, _trig, False),
    "cos": (1, ca.cos, _trig, False),
    "tan": (1, ca.tan, _trig, False),
    "asin": (1, ca.asin, _inverse_trig, False),
    "acos": (1, ca.acos, _inverse_trig, False),
    "atan": (1, ca.atan, _inverse_trig, False),
    "atan2": (2, ca.atan2, _atan2, False),
    "sqrt": (1, ca.sqrt, _sqrt, False),
    "exp": (1, ca.exp, _trig, False),
    "log": (1, ca.log, _trig, False),
    "abs": (1, ca.fabs, _first, False),
    "min": (2, ca.fmin, _same, False),
    "max": (2, ca.fmax, _same, False),
    "hypot": (2, lambda a, b: ca.sqrt(a**2 + b**2), _same, False),
    "norm": (1, ca.norm_2, _first, True),
    "dot": (2, ca.dot, _product, True),
    "cross": (2, ca.cross, _product, True),
    "unit": (1, lambda v: v / ca.norm_2(v), _unitless, True),
}
#: constants every expression knows
CONSTANTS = {"pi": math.pi}
#: the names an expression may not use for a symbol of its own
RESERVED = set(FUNCTIONS) | set(CONSTANTS) | {"select"}
#: Longest expression (characters) and deepest nesting of brackets in one (documented in
#: docs/site/guide/mechanism-files.md; the longest shipped expression has about 120 characters)
MAX_LENGTH, MAX_NESTING = 2000, 32


def _translate(text: str) -> tuple[str, list[int]]:
    """``^`` -> ``**``, and the map from columns of the result to columns of the text."""
    out, cols = [], []
    for i, ch in enumerate(text):
        if ch == "^":
            out.append("**")
            cols += [i, i]
        else:
            out.append(ch)
            cols.append(i)
    cols.append(len(text))
    return "".join(out), cols


class _Evaluator:
    def __init__(
        self, symbols: Mapping[str, Value], cols: list[int], units: Mapping[str, Value] | None = None, text: str = ""
    ) -> None:
        self.symbols = symbols
        self.cols = cols
        #: the expression as written (for quoting a part of it in a message)
        self.text = text
        #: placeholder name -> the value of a number with its unit (see `_units`)
        self.units = units or {}

    def col(self, node: ast.AST) -> int:
        off = getattr(node, "col_offset", 0) or 0
        return self.cols[min(off, len(self.cols) - 1)] + 1

    def written(self, node: ast.AST) -> str:
        """A part of the expression as written (``l2^2 - cx^2``, ``(1 m)^2`` with its unit)."""
        start, end = getattr(node, "col_offset", None), getattr(node, "end_col_offset", None)
        if start is None or end is None or not self.text or end < 1:
            return _source(node)
        first = self.cols[min(start, len(self.cols) - 1)]
        last = self.cols[min(end - 1, len(self.cols) - 1)]
        return self.text[first : last + 1].strip() or _source(node)

    def culprit(self, node: ast.AST, args: list[Value]) -> str:
        """The argument that made a function's value not finite, with its value:
        ``: l2^2 - cx^2 = -0.000825 m^2`` (``sqrt``, ``log``, ``asin``, ``acos``, ``exp``),
        and the divisor of a division by zero."""
        if isinstance(node, ast.Call) and len(node.args) == 1 and args and (x := _number(args[0])) is not None:
            arg, dim = node.args[0], args[0].dim
        elif isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div) and len(args) == 2 and _number(args[1]) == 0:
            arg, x, dim = node.right, 0.0, args[1].dim
        else:
            return ""
        if isinstance(arg, ast.Constant):  # sqrt(-1): the number is in the expression already
            return ""
        unit = si_text(dim)
        return f": {self.written(arg)} = {x:.4g}" + (f" {unit}" if unit else "")

    def fail(self, node: ast.AST, message: str) -> ExpressionError:
        return ExpressionError(message, self.col(node))

    def eval(self, node: ast.AST) -> Value:
        method = getattr(self, "_" + type(node).__name__, None)
        if method is None:
            raise self.fail(node, f"{_construct(node)} is not allowed in an expression")
        return method(node)

    def _Expression(self, node: ast.Expression) -> Value:
        return self.eval(node.body)

    def _Constant(self, node: ast.Constant) -> Value:
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise self.fail(node, f"expected a number, got {node.value!r}")
        if isinstance(node.value, int) and abs(node.value) > LARGEST:
            raise self.fail(node, too_large(node.value))
        if not math.isfinite(node.value):
            raise self.fail(node, f"a number beyond the largest float (about {LARGEST:.3g}) is not finite")
        return Value(ca.SX(float(node.value)), None)

    def finite(self, node: ast.AST, result: Value, args: list[Value], what: str) -> Value:
        """``result``, or an error naming the operation when it is a known number that is
        not finite (``1/0``, ``b/0``, ``sqrt(-1)``, ``exp(1000)``; with every symbol a
        number, as `diagnose` evaluates, any operation on them)."""
        # the structural non-zeros in one call (a structural zero is finite): indexing each
        # entry costs CasADi's Python overloads a few microseconds apiece (issue 23, start-up)
        for e in result.sx.nonzeros():
            if e.is_constant() and not math.isfinite(float(ca.DM(e))):
                raise self.fail(node, f"{_why(what, args)}{self.culprit(node, args)} (the value is {_text(e)})")
        return result

    def _Name(self, node: ast.Name) -> Value:
        if node.id in self.units:
            return self.units[node.id]
        if node.id in self.symbols:
            return self.symbols[node.id]
        if node.id in CONSTANTS:
            return Value(ca.SX(CONSTANTS[node.id]), NUMBER)
        known = list(self.symbols) + list(CONSTANTS)
        hint = suggest(node.id, known)
        more = f"; did you mean {' or '.join(repr(h) for h in hint)}?" if hint else ""
        raise self.fail(node, f"unknown symbol {node.id!r}{more}")

    def _UnaryOp(self, node: ast.UnaryOp) -> Value:
        v = self.eval(node.operand)
        if isinstance(node.op, ast.USub):
            return Value(-v.sx, v.dim)
        if isinstance(node.op, ast.UAdd):
            return v
        raise self.fail(node, f"the operator {_construct(node.op)} is not allowed")

    def _BinOp(self, node: ast.BinOp) -> Value:
        a, b = self.eval(node.left), self.eval(node.right)
        rule = _BINARY.get(type(node.op))
        if rule is None:
            raise self.fail(node, f"the operator {_construct(node.op)} is not allowed (use + - * / ^)")
        return rule(self, node, a, b)

    def _add(self, node: ast.BinOp, a: Value, b: Value) -> Value:
        """a + b or a - b: the same dimension (an angle plus a plain number is an angle), the same size or a scalar."""
        add = isinstance(node.op, ast.Add)
        if not compatible(a.dim, b.dim):
            known = [v for v in (a, b) if v.dim == NUMBER and bool(v.sx.is_constant())]
            hint = f"; {unit_hint(a.dim if a.dim != NUMBER else b.dim)}" if known else ""
            raise self.fail(
                node, f"cannot {'add' if add else 'subtract'} {describe(a.dim)} and {describe(b.dim)}{hint}"
            )
        if a.size != b.size and 1 not in (a.size, b.size):
            raise self.fail(node, f"vectors of sizes {a.size} and {b.size} do not add")
        dim = a.dim if dimensioned(a.dim) or b.dim is None else b.dim
        return self.finite(node, Value(a.sx + b.sx if add else a.sx - b.sx, dim), [a, b], "+" if add else "-")

    def _multiply(self, node: ast.BinOp, a: Value, b: Value) -> Value:
        """a * b or a / b: at most one vector, never a divisor."""
        if a.size > 1 and b.size > 1:
            raise self.fail(node, "a product of two vectors: use dot() or cross()")
        if isinstance(node.op, ast.Div) and b.size > 1:
            raise self.fail(node, "division by a vector")
        if isinstance(node.op, ast.Mult):
            return self.finite(node, Value(a.sx * b.sx, _mul(a.dim, b.dim)), [a, b], "*")
        return self.finite(node, Value(a.sx / b.sx, _mul(a.dim, b.dim, -1.0)), [a, b], "/")

    def _power(self, node: ast.BinOp, a: Value, b: Value) -> Value:
        """a ^ e: e a plain number, a a scalar."""
        if not (isinstance(node.right, ast.Constant) or _is_negated_constant(node.right)):
            raise self.fail(node.right, "an exponent must be a plain number")
        e = float(ca.DM(b.sx))
        if b.dim is not None and b.dim != NUMBER:
            raise self.fail(node.right, "an exponent must be a plain number")
        dim = None if a.dim is None else (a.dim[0] * e, a.dim[1] * e)
        if a.size > 1:
            raise self.fail(node, "a power of a vector")
        return self.finite(node, Value(a.sx**e, dim), [a, b], "^")

    def _List(self, node: ast.List | ast.Tuple) -> Value:
        if not node.elts:
            raise self.fail(node, "an empty vector")
        items = [self.eval(e) for e in node.elts]
        dim: Dim = None
        for e, v in zip(node.elts, items):
            if v.size != 1:
                raise self.fail(e, "a vector's elements must be scalars")
            if _adapts(v):  # a number without a unit: SI, of the vector's dimension
                continue
            if not compatible(dim, v.dim):
                raise self.fail(e, f"a vector mixes {describe(dim)} and {describe(v.dim)}")
            dim = dim if dim is not None else v.dim
        if dim is None and any(v.dim is not None for v in items):
            dim = NUMBER  # numbers only, some of them dimensionless (cos(pi/6)): adapts as a whole (see adapts)
        return Value(ca.vertcat(*[v.sx for v in items]), dim)

    _Tuple = _List

    def _Subscript(self, node: ast.Subscript) -> Value:
        v = self.eval(node.value)
        index = node.slice
        if not isinstance(index, ast.Constant) or not isinstance(index.value, int) or isinstance(index.value, bool):
            raise self.fail(index, "an index must be a whole number (v[0] is the first element)")
        if not 0 <= index.value < v.size:
            raise self.fail(index, f"index {index.value} out of range for a vector of {v.size}")
        return Value(v.sx[index.value], v.dim)

    def _Call(self, node: ast.Call) -> Value:
        if not isinstance(node.func, ast.Name):
            raise self.fail(node, "only calls of named functions are allowed")
        name = node.func.id
        if node.keywords or any(isinstance(a, ast.Starred) for a in node.args):
            raise self.fail(node, f"{name}() takes plain arguments only")
        if name == "select":
            return self._select(node)
        if name not in FUNCTIONS:
            hint = suggest(name, list(FUNCTIONS) + ["select"])
            more = f"; did you mean {' or '.join(repr(h) for h in hint)}?" if hint else ""
            raise self.fail(node.func, f"unknown function {name!r}{more}")
        nargs, impl, rule, vector = FUNCTIONS[name]
        if len(node.args) != nargs:
            raise self.fail(node, f"{name}() takes {nargs} argument(s), got {len(node.args)}")
        args = [self.eval(a) for a in node.args]
        self._check_sizes(node, name, args, vector)
        dim = rule(name, args, self.col(node))
        return self.finite(node, Value(impl(*[a.sx for a in args]), dim), args, name)

    def _check_sizes(self, node: ast.Call, name: str, args: list[Value], vector: bool) -> None:
        """A function of scalars takes scalars; cross() vectors of 3, dot() two of one size."""
        for a, arg in zip(node.args, args):
            if vector and arg.size != 3 and name == "cross":
                raise self.fail(a, "cross() takes vectors of 3 elements")
            if not vector and arg.size != 1:
                raise self.fail(a, f"{name}() takes scalars; got a vector of {arg.size}")
        if name == "dot" and args[0].size != args[1].size:
            raise self.fail(node, f"dot() takes two vectors of one size, got {args[0].size} and {args[1].size}")

    def _select(self, node: ast.Call) -> Value:
        """select(i, a, b, ...): the i-th (from 1) of the values, i a plain number known when the file is read."""
        if len(node.args) < 2:
            raise self.fail(node, "select(i, a, b, ...) needs an index and at least one value")
        i = self.eval(node.args[0])
        if not i.sx.is_constant():
            raise self.fail(node.args[0], "select()'s index must be known when the file is read (a leg index)")
        k = float(ca.DM(i.sx))
        if not k.is_integer() or not 1 <= k <= len(node.args) - 1:
            raise self.fail(node.args[0], f"select() index {k:g} is not in 1..{len(node.args) - 1}")
        return self.eval(node.args[int(k)])


#: the binary operators an expression may use, each with its rule (dimensions, sizes)
_BINARY: dict[type, Callable[[_Evaluator, ast.BinOp, Value, Value], Value]] = {
    ast.Add: _Evaluator._add,
    ast.Sub: _Evaluator._add,
    ast.Mult: _Evaluator._multiply,
    ast.Div: _Evaluator._multiply,
    ast.Pow: _Evaluator._power,
}


def _adapts(v: Value) -> bool:
    """A value written without a unit that takes the dimension of where it stands (a key's
    value, an element of a vector), read in SI: a bare number, or a number known when the
    file is read whose dimension is no length or angle (``0.05*cos(pi/6)``)."""
    return v.dim is None or (v.dim == NUMBER and bool(v.sx.is_constant()))


def adapts(v: Value) -> bool:
    """Whether a whole value takes the dimension its key declares (see `_adapts`)."""
    return _adapts(v) or (v.dim == NUMBER and all(v.sx[i].is_constant() for i in range(v.size)))


def _number(v: Value) -> float | None:
    """The value of a known scalar, else None."""
    return float(ca.DM(v.sx)) if v.size == 1 and v.sx.is_constant() else None


def _text(e: ca.SX) -> str:
    x = float(ca.DM(e))
    return "NaN" if math.isnan(x) else "-inf" if x < 0 else "inf"


def _why(what: str, args: list[Value]) -> str:
    """Which operation made a number that is not finite, and why."""
    x = [_number(a) for a in args]
    reason = _REASONS.get(what)
    if reason is not None:
        return reason(x)
    if what in ("+", "-", "*"):
        return f"'{what}' overflows"
    return f"{what}() gives a number that is not finite"


def si_text(dim: Dim) -> str:
    """The SI unit of a dimension: ``m``, ``rad``, ``m^2``, ``m*rad`` ("" for a plain number)."""
    if dim is None:
        return ""
    parts = [unit + ("" if power == 1 else f"^{power:g}") for unit, power in (("m", dim[0]), ("rad", dim[1])) if power]
    return "*".join(parts)


def _source(node: ast.AST) -> str:
    """An argument as written (near enough: ``l2^2 - cx^2``)."""
    return ast.unparse(node).replace(" ** ", "^").replace("**", "^")


def _power_reason(x: list[float | None]) -> str:
    if x[0] == 0 and x[1] is not None and x[1] < 0:
        return "zero to a negative power"
    if x[0] is not None and x[0] < 0 and x[1] is not None and not float(x[1]).is_integer():
        return "a negative number to a fractional power"
    return "the power overflows"


#: why an operation's value is not finite, from its arguments' values (None: not known)
_REASONS: dict[str, Callable[[list[float | None]], str]] = {
    "/": lambda x: "division by zero" if x[1] == 0 else "the quotient overflows",
    "^": _power_reason,
    "sqrt": lambda _x: "sqrt of a negative number",
    "log": lambda x: "log of zero" if x[0] == 0 else "log of a negative number",
    "asin": lambda _x: "asin of a number outside [-1, 1]",
    "acos": lambda _x: "acos of a number outside [-1, 1]",
    "exp": lambda _x: "exp overflows (its argument is above about 709)",
    "unit": lambda _x: "unit() of a zero vector",
}


def _is_negated_constant(node: ast.AST) -> bool:
    return isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub) and isinstance(node.operand, ast.Constant)


def _construct(node: ast.AST) -> str:
    names = {
        "Attribute": "an attribute (a.b)",
        "Compare": "a comparison",
        "BoolOp": "'and'/'or'",
        "Lambda": "a lambda",
        "IfExp": "'if ... else'",
        "Dict": "a mapping",
        "Set": "a set",
        "ListComp": "a comprehension",
        "GeneratorExp": "a comprehension",
        "NamedExpr": "':='",
        "Starred": "'*'",
        "JoinedStr": "a string",
        "BitXor": "'^'",
        "FloorDiv": "'//'",
        "Mod": "'%'",
        "MatMult": "'@'",
        "Not": "'not'",
        "Invert": "'~'",
    }
    return names.get(type(node).__name__, f"'{type(node).__name__}'")


def _plain_number(number: float) -> Value:
    """A number given as a number (YAML reads ``1e999`` and ``.nan`` as floats)."""
    if isinstance(number, int) and abs(number) > LARGEST:
        raise ExpressionError(too_large(number), 1)
    if not math.isfinite(number):
        read = f" (a number beyond about {LARGEST:.3g} is read as inf)" if math.isinf(number) else ""
        raise ExpressionError(f"expected a finite number, got {number!r}{read}", 1)
    return Value(ca.SX(float(number)), None)


def parse(text: object, symbols: Mapping[str, Value]) -> Value:
    """The CasADi value of an expression (a string, or a plain number)."""
    if isinstance(text, bool):
        raise ExpressionError(f"expected an expression or a number, got {text!r}", 1)
    if isinstance(text, (int, float)):
        return _plain_number(text)
    if isinstance(text, list):
        text = "[" + ", ".join(str(t) for t in text) + "]"
    if not isinstance(text, str) or not text.strip():
        raise ExpressionError(f"expected an expression (a string such as 'b + L*cos(alpha0)'), got {text!r}", 1)
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"an expression of {len(text)} characters; at most {MAX_LENGTH}", 1)
    _check_nesting(text)
    source, cols = _translate(text)
    source, cols, units = _units(source, cols)
    try:
        tree = ast.parse(source.strip(), mode="eval")
    except SyntaxError as exc:
        lead = len(source) - len(source.lstrip())
        off = max((exc.offset or 1) - 1 + lead, 0)
        raise ExpressionError(f"syntax error ({exc.msg})", cols[min(off, len(cols) - 1)] + 1) from None
    except (ValueError, RecursionError, MemoryError) as exc:
        raise ExpressionError(f"cannot parse the expression ({type(exc).__name__})", 1) from None
    lead = len(source) - len(source.lstrip())
    try:
        return _Evaluator(symbols, cols[lead:], units, text).eval(tree)
    except RecursionError:
        raise ExpressionError("the expression is nested too deeply", 1) from None


#: a number followed by a word (``3 mm``, ``1deg``, ``-22.22 mm``: the sign is an operator): a
#: number with its unit; not after a name or a number's own characters (``x1 mm`` is no number)
_UNIT_LITERAL = re.compile(
    r"(?<![\w.])((?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)(?![eE][+-]?\d)[ \t]*([A-Za-zµ]+)(?![\w(])(?![ \t]*\*\*)"
)
#: a number then a word then a power or a call: ``3 mm^2``, ``2 sin(a)`` (refused with a message)
_UNIT_AMBIGUOUS = re.compile(
    r"(?<![\w.])((?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)(?![eE][+-]?\d)[ \t]*([A-Za-zµ]+)(?=[ \t]*(\*\*|\())"
)
#: the units an expression takes: of length and of angle (others through pint, then checked)
EXPRESSION_DIMENSIONS = ("length", "angle")
_EXPRESSION_UNITS = [u for u, (_f, d) in FAST_UNITS.items() if d in EXPRESSION_DIMENSIONS]


def _unit_value(number: str, unit: str, column: int) -> Value:
    """The SI value and dimension of ``<number> <unit>``, a length or an angle."""
    text = f"{number} {unit}"
    if not math.isfinite(float(number)):
        raise ExpressionError(f"'{text}': a number beyond the largest float (about {LARGEST:.3g})", column)
    fast = FAST_UNITS.get(unit)
    if fast is not None and fast[1] not in EXPRESSION_DIMENSIONS:
        raise ExpressionError(
            f"'{text}' is {_article(fast[1])}; an expression of a mechanism file takes lengths "
            f"({', '.join(UNIT_DIMENSIONS['length'].common_units)}) and angles "
            f"({', '.join(UNIT_DIMENSIONS['angle'].common_units)})",
            column,
        )
    dims = [fast[1]] if fast is not None else list(EXPRESSION_DIMENSIONS)
    for dim in dims:
        try:
            si = parse_quantity(text, dim)
        except InputError:
            continue
        if not math.isfinite(si) or abs(si) > LARGEST:
            raise ExpressionError(f"'{text}' is not a finite number", column)
        return Value(ca.SX(si), DIMENSION_OF[dim])
    hint = suggest(unit, _EXPRESSION_UNITS)
    more = f"; did you mean {' or '.join(repr(f'{number} {h}') for h in hint)}?" if hint else ""
    raise ExpressionError(
        f"{unit!r} after the number {number} is not a unit of length or angle (a product is written "
        f"{number}*{unit}){more}",
        column,
    )


def _article(dim: str) -> str:
    noun = dim.replace("_", " ")
    return ("an " if noun[:1] in "aeiou" else "a ") + noun


def _units(source: str, cols: list[int]) -> tuple[str, list[int], dict[str, Value]]:
    """Each number with its unit (``3 mm``) replaced by a placeholder name (bound to its SI
    value and dimension), and the column map kept: the placeholder maps to the number's column."""
    ambiguous = _UNIT_AMBIGUOUS.search(source)
    if ambiguous is not None:
        number, unit = ambiguous.group(1), ambiguous.group(2)
        if ambiguous.group(3) == "**":
            why = f"'{number} {unit}^...' is ambiguous: write the quantity in brackets, ({number} {unit})^2"
        else:
            why = f"a number before a call: a product is written {number}*{unit}(...)"
        raise ExpressionError(why, cols[ambiguous.start()] + 1)
    matches = list(_UNIT_LITERAL.finditer(source))
    if not matches:
        return source, cols, {}
    prefix = "_unit"
    while prefix in source:
        prefix += "_"
    out, new_cols, units, last = [], [], {}, 0
    for k, m in enumerate(matches):
        name = f"{prefix}{k}"
        column = cols[m.start()] + 1
        units[name] = _unit_value(m.group(1), m.group(2), column)
        out.append(source[last : m.start()])
        new_cols += cols[last : m.start()]
        out.append(name)
        new_cols += [cols[m.start()]] * len(name)
        last = m.end()
    out.append(source[last:])
    new_cols += cols[last:]
    return "".join(out), new_cols, units


def _check_nesting(text: str) -> None:
    """Brackets nested at most `MAX_NESTING` deep (before Python's parser sees the text)."""
    depth = 0
    for col, ch in enumerate(text, 1):
        if ch in "([{":
            depth += 1
            if depth > MAX_NESTING:
                raise ExpressionError(f"brackets nested more than {MAX_NESTING} deep", col)
        elif ch in ")]}":
            depth -= 1


def names_in(text: object) -> set[str]:
    """The symbol names an expression uses (for dependency order); empty when it does not parse."""
    if not isinstance(text, str):
        return set()
    try:
        source, cols = _translate(text)
        source, _cols, units = _units(source, cols)
        tree = ast.parse(source.strip(), mode="eval")
    except (SyntaxError, ValueError, RecursionError, ExpressionError):
        return set()
    return {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)} - RESERVED - set(units)


def diagnose(text: object, values: Mapping[str, tuple[float | list[float], Dim]]) -> ExpressionError | None:
    """Why an expression is not finite for these values of its symbols (name -> (value,
    dimension)): the error naming the first operation that made a number that is not
    finite (``sqrt of a negative number``, column 6), or None if none did."""
    symbols = {n: Value(ca.SX(ca.DM(v)), dim) for n, (v, dim) in values.items()}
    try:
        parse(text, symbols)
    except ExpressionError as exc:
        return exc
    return None
