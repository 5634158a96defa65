"""Published figures, side by side with what the model computes.

A problem file that reproduces published figures carries a ``reproduce``
section::

    reproduce:
      paper: Ruiz et al. (year not printed), 3-PRS compliant stage
      rows:
        - quantity: lowest actuator displacement
          source: section 4, Fig. 6
          published: -2.15 mm
          value: s_min            # a key of the result values; "dz[2]" indexes a list
          tolerance: 5 %          # relative, or an absolute quantity ("0.02 mm")
          reason: why it may differ (printed with the verdict)
        - quantity: actuator force for s = 0.935 mm
          source: Table 2
          published: 20 N
          value: null             # the model cannot compute it ...
          reason: ...and this is why

``expect: differ`` marks a row whose disagreement is understood and
explained by ``reason``; a row that disagrees without it is a regression.

Published values are typed in (they are the paper's); computed values are
always obtained by solving the file.  What the "published" value is, and how
independent an agreement with it is, each row says:

* ``category`` (default ``published``): where the value comes from --
  ``published`` a number printed in the paper; ``derived`` not printed, but
  evaluated by hand from printed formulas and numbers; ``read_off_matrix`` a
  geometry read off the printed matrix the row is compared with;
  ``consistency`` a check whose inputs were read from (or fitted to) the figure
  it is compared with; ``claim`` a statement of the paper written as a
  number (an approximation taken as exact: 0, "lies inside": 0 points
  outside); ``not_printed`` the paper prints no such number (a plot, an
  assumed input).  Only a ``published`` row that agrees and does not
  echo an input is an independent agreement (`summarize`).
* ``echoes``: the computed value is an input given back (an active bound, a
  parameter held fixed), named by this text.
* ``tolerance_reason``: required when the tolerance is wider than half a unit
  of the last digit of the published text (`printed_half_unit`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from ..core.errors import InputError, suggest, unknown_key_error
from ..core.units import DIMENSIONS, article, fast_dimension, format_quantity, parse_quantity, si_unit

ROW_KEYS = (
    "quantity",
    "source",
    "published",
    "category",
    "value",
    "tolerance",
    "tolerance_reason",
    "echoes",
    "reason",
    "expect",
)
VERDICTS = ("agrees", "differs", "not reproducible", "solve failed")
#: what a row comes to (`Comparison.outcome`), each row exactly one of these
OUTCOMES = ("agrees", "differs", "not reproducible", "unexpected")

#: what a row's "published" value is (its ``category``), as shown beside it
CATEGORIES = {
    "published": "printed in the paper",
    "derived": "not printed: evaluated from the paper's printed formulas and numbers",
    "read_off_matrix": "not printed: a geometry read off the printed matrix it is compared with",
    "consistency": "a consistency check: its inputs were read from, or fitted to, the figure it is compared with",
    "claim": "not printed: a statement of the paper (an approximation, 'lies inside') written as a number",
    "not_printed": "the paper prints no such number",
}


@dataclass(frozen=True)
class PublishedFigure:
    """One published figure and how to compare with it."""

    quantity: str
    source: str
    published_text: str
    published: float | None
    dimension: str
    value: str | None
    tolerance_kind: str | None  # "rel" | "abs"
    tolerance: float | None
    reason: str
    expect: str  # "agree" | "differ"
    category: str = "published"
    echoes: str = ""  # the input the computed value gives back, if it does
    tolerance_reason: str = ""


@dataclass(frozen=True)
class ReproduceSpec:
    paper: str
    rows: tuple[PublishedFigure, ...]


@dataclass
class Comparison:
    """One row of the reproduction table."""

    file: str
    paper: str
    quantity: str
    source: str
    published_text: str
    published: float | None
    computed: float | None
    dimension: str
    rel_error: float | None
    verdict: str
    reason: str
    expected: bool  # the verdict is the one the file expects
    category: str = "published"
    echoes: str = ""
    tolerance_reason: str = ""

    @property
    def agrees(self) -> bool:
        return self.verdict.startswith("agrees")

    @property
    def outcome(self) -> str:
        """The row in one word of `OUTCOMES`: ``agrees`` and ``differs`` as the file
        expects (a figure that differs says why), ``not reproducible`` (the model does not
        compute it, and says why), else ``unexpected`` (a regression, or a failed solve)."""
        if not self.expected:
            return "unexpected"
        if self.verdict == "not reproducible":
            return "not reproducible"
        return "agrees" if self.agrees else "differs"

    @property
    def independent(self) -> bool:
        """An agreement with a printed number that is not an input given back."""
        return self.agrees and self.category == "published" and not self.echoes

    def to_dict(self) -> dict[str, Any]:
        def num(x: Any) -> float | None:
            return None if x is None else float(x)

        return {
            "file": self.file,
            "paper": self.paper,
            "quantity": self.quantity,
            "source": self.source,
            "category": self.category,
            "published": num(self.published),
            "published_text": self.published_text,
            "computed": num(self.computed),
            "unit": si_unit(self.dimension),
            "rel_error": num(self.rel_error),
            "verdict": self.verdict,
            "echoes_input": self.echoes or None,
            "independent": bool(self.independent),
            "reason": self.reason,
            "tolerance_reason": self.tolerance_reason or None,
            "expected": bool(self.expected),
        }


def summarize(rows: Iterable[Comparison]) -> dict[str, Any]:
    """Counts of a reproduction table: independent agreements apart from the
    agreements that are not (by category, and inputs echoed back)."""
    rows = list(rows)
    agree = [r for r in rows if r.agrees]
    dependent = [r for r in agree if not r.independent]
    by_category = {c: sum(1 for r in dependent if r.category == c and not r.echoes) for c in CATEGORIES}
    return {
        "figures": len(rows),
        "unexpected": sum(1 for r in rows if not r.expected),
        "agree_independent": sum(1 for r in agree if r.independent),
        "agree_not_independent": len(dependent),
        "agree_not_independent_by_category": {c: n for c, n in by_category.items() if n},
        "agree_echoing_an_input": sum(1 for r in dependent if r.echoes),
        "differ": sum(1 for r in rows if r.verdict.startswith("differs")),
        "unexpected_differ": sum(1 for r in rows if r.verdict.startswith("differs") and not r.expected),
        "not_reproducible": sum(1 for r in rows if r.verdict == "not reproducible"),
        "solve_failed": sum(1 for r in rows if r.verdict == "solve failed"),
        "categories": {c: sum(1 for r in rows if r.category == c) for c in CATEGORIES},
        "papers": by_paper(rows),
    }


def by_paper(rows: Iterable[Comparison]) -> dict[str, dict[str, int]]:
    """Per paper (in the order they first come), the rows of each outcome
    (`OUTCOMES`), and how many of those that agree are independent."""
    out: dict[str, dict[str, int]] = {}
    for r in rows:
        counts = out.setdefault(r.paper, {**{o: 0 for o in OUTCOMES}, "independent": 0})
        counts[r.outcome] += 1
        counts["independent"] += int(r.outcome == "agrees" and r.independent)
    return out


_NUMBER = re.compile(r"\s*[-+]?(\d*)(?:\.(\d*))?(?:[eE]([-+]?\d+))?")


def printed_half_unit(text: str, dimension: str, path: tuple = ()) -> float | None:
    """Half a unit of the last printed digit of ``text`` ("1.78e-6 m^3",
    "0.0795 rad", "21.875"), in SI units; None if ``text`` starts with no number."""
    m = _NUMBER.match(text)
    if m is None or not (m.group(1) or m.group(2)):
        return None
    decimals = len(m.group(2) or "")
    exponent = m.group(3) or "0"
    if len(exponent.lstrip("+-")) > 4 or int(exponent) - decimals > 300:  # 0e400: no float holds the digit
        raise InputError(
            f"{text!r}: a printed digit of 10^{int(exponent) - decimals} is beyond any float (about 1e308)", path=path
        )
    half = 0.5 * 10.0 ** (int(exponent) - decimals)
    rest = text[m.end() :].strip()
    if not rest:
        return half
    return parse_quantity(f"{half!r} {rest}", dimension, path)


def parse_any_quantity(value: Any, path: tuple) -> tuple[float, str]:
    """SI value and dimension of a quantity whose dimension is not declared."""
    if isinstance(value, bool):
        raise InputError(f"expected a number or a quantity, got {value!r}", path=path)
    if isinstance(value, (int, float)):
        return parse_quantity(value, "dimensionless", path), "dimensionless"
    first = fast_dimension(value)  # the unit's own dimension first: no pint registry for the usual units
    # (each dimension has its own root units, so the dimension found is the same in any order)
    for name in ([first] if first else []) + [n for n in DIMENSIONS if n != first]:
        try:
            return parse_quantity(value, name, path), name
        except InputError:
            continue
    raise InputError(f"expected a quantity with a unit such as '2.30 mm' or '1.7 deg', got {value!r}", path=path)


def parse_reproduce(raw: Any, path: tuple) -> ReproduceSpec:
    if not isinstance(raw, Mapping):
        raise InputError("expected a mapping {paper, rows}", path=path)
    for key in raw:
        if key not in ("paper", "rows"):
            raise unknown_key_error(str(key), ("paper", "rows"), path, "reproduce key")
    paper = raw.get("paper")
    if not isinstance(paper, str) or not paper:
        raise InputError(
            "expected the paper's short reference (authors, year, short title), "
            "e.g. 'Li, Li, Ding, Xu 2018, 3-PRC micromanipulator'",
            path=path + ("paper",),
        )
    rows = raw.get("rows")
    if not isinstance(rows, list) or not rows:
        raise InputError("expected a non-empty list of published figures", path=path + ("rows",))
    return ReproduceSpec(paper, tuple(_parse_row(r, path + ("rows", i)) for i, r in enumerate(rows)))


def _text(row: Mapping, key: str, path: tuple, required: bool = True) -> str:
    v = row.get(key)
    if v is None and not required:
        return ""
    if not isinstance(v, str) or not v.strip():
        raise InputError(f"expected text, got {v!r}", path=path + (key,))
    return v.strip()


def _category(row: Mapping, path: tuple) -> str:
    category = row.get("category", "published")
    if not isinstance(category, str) or category not in CATEGORIES:
        raise InputError(
            f"expected one of {', '.join(CATEGORIES)}, got {category!r}",
            path=path + ("category",),
            suggestions=suggest(str(category), CATEGORIES),
        )
    return category


def _tolerance(row: Mapping, dim: str, path: tuple) -> tuple[str, float]:
    tol_raw = row.get("tolerance")
    if tol_raw is None:
        raise InputError("missing required key 'tolerance' ('5 %' relative, or an absolute quantity)", path=path)
    if isinstance(tol_raw, str) and tol_raw.strip().endswith("%"):
        tol = parse_quantity(tol_raw.strip()[:-1], "dimensionless", path + ("tolerance",)) / 100.0
        kind = "rel"
    elif isinstance(tol_raw, str):
        tol = parse_quantity(tol_raw, dim, path + ("tolerance",))
        kind = "abs"
    else:
        raise InputError(
            f"expected '5 %' (relative) or a quantity with a unit (absolute), got {tol_raw!r}",
            path=path + ("tolerance",),
        )
    if not tol > 0:
        raise InputError(f"expected a positive tolerance, got {tol_raw!r}", path=path + ("tolerance",))
    return kind, tol


def _check_tolerance_reason(row: Mapping, fig: PublishedFigure, path: tuple) -> None:
    """A tolerance wider than the printed rounding needs a ``tolerance_reason``."""
    half = printed_half_unit(fig.published_text, fig.dimension, path + ("published",))
    if half is None or fig.published is None or fig.tolerance is None:
        return
    width = fig.tolerance * abs(fig.published) if fig.tolerance_kind == "rel" else fig.tolerance
    if width > half * (1 + 1e-9) and not fig.tolerance_reason:
        raise InputError(
            f"tolerance {row.get('tolerance')} is wider than the printed rounding of "
            f"{fig.published_text!r} (half a unit of its last digit: "
            f"{format_quantity(half, fig.dimension, 3)}); say why in 'tolerance_reason'",
            path=path + ("tolerance",),
        )


def _check_row_keys(row: Any, path: tuple) -> None:
    if not isinstance(row, Mapping):
        raise InputError(f"expected a mapping with keys {', '.join(ROW_KEYS)}", path=path)
    for key in row:
        if key not in ROW_KEYS:
            raise unknown_key_error(str(key), ROW_KEYS, path, "row key")


def _check_not_computed(row: Mapping, reason: str, path: tuple) -> None:
    """A figure the model does not compute (``value: null``): a reason, and nothing to compare."""
    if not reason:
        raise InputError("a figure the model does not compute (value: null) needs a 'reason'", path=path)
    for key in ("tolerance", "tolerance_reason", "echoes"):
        if key in row:
            raise InputError(f"a figure the model does not compute (value: null) has no {key!r}", path=path)


def _check_value_name(value: Any, path: tuple) -> None:
    """The name of a result value, with list indices: ``s_min``, ``dz[0]``."""
    if not isinstance(value, str) or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*(\[\d+\])*", value):
        raise InputError(
            f"expected the name of a result value, e.g. s_min or dz[0], got {value!r}", path=path + ("value",)
        )


def _parse_row(row: Any, path: tuple) -> PublishedFigure:
    _check_row_keys(row, path)
    quantity = _text(row, "quantity", path)
    source = _text(row, "source", path)
    reason = _text(row, "reason", path, required=False)
    category = _category(row, path)
    echoes = _text(row, "echoes", path, required=False)
    tolerance_reason = _text(row, "tolerance_reason", path, required=False)
    expect = row.get("expect", "agree")
    if expect not in ("agree", "differ"):
        raise InputError(f"expected 'agree' or 'differ', got {expect!r}", path=path + ("expect",))
    if "published" not in row:
        raise InputError("missing required key 'published' (the paper's figure)", path=path)
    value = row.get("value")
    published_raw = row["published"]
    if value is None:
        _check_not_computed(row, reason, path)
        return PublishedFigure(
            quantity, source, str(published_raw), None, "dimensionless", None, None, None, reason, "differ", category
        )
    _check_value_name(value, path)
    published, dim = parse_any_quantity(published_raw, path + ("published",))
    kind, tol = _tolerance(row, dim, path)
    if expect == "differ" and not reason:
        raise InputError("a row expected to differ needs a 'reason'", path=path)
    fig = PublishedFigure(
        quantity,
        source,
        str(published_raw),
        published,
        dim,
        value,
        kind,
        tol,
        reason,
        expect,
        category,
        echoes,
        tolerance_reason,
    )
    _check_tolerance_reason(row, fig, path)
    return fig


def _lookup(values: Mapping[str, Any], ref: str) -> Any:
    name, *idx = re.split(r"\[", ref)
    out = values.get(name)
    for i in idx:
        if not isinstance(out, list):
            return None
        k = int(i.rstrip("]"))
        out = out[k] if k < len(out) else None
    return out


def compare(spec: ReproduceSpec, result: Any, file: str) -> list[Comparison]:
    """Compare every row of ``spec`` with a solved ``result``."""
    rows = []
    for fig in spec.rows:

        def row(computed, dim, rel, verdict, reason, expected, fig=fig):
            return Comparison(
                file=file,
                paper=spec.paper,
                quantity=fig.quantity,
                source=fig.source,
                published_text=fig.published_text,
                published=fig.published,
                computed=computed,
                dimension=dim,
                rel_error=None if rel is None else float(rel),
                verdict=verdict,
                reason=reason,
                expected=bool(expected),
                category=fig.category,
                echoes=fig.echoes,
                tolerance_reason=fig.tolerance_reason,
            )

        if fig.value is None:
            rows.append(row(None, fig.dimension, None, "not reproducible", fig.reason, True))
            continue
        computed = _lookup(result.values, fig.value) if result.ok else None
        if not isinstance(computed, (int, float)) or not math.isfinite(computed):
            why = f"{result.status.value}: {result.message}" if not result.ok else f"no value '{fig.value}'"
            rows.append(row(None, fig.dimension, None, "solve failed", why, False))
            continue
        dim = result.dimensions.get(fig.value.split("[")[0], fig.dimension)
        if dim in DIMENSIONS and dim != fig.dimension:
            why = f"published value is {article(fig.dimension)}, computed is {article(dim)}"
            rows.append(row(float(computed), dim, None, "differs", why, False))
            continue
        diff = abs(computed - fig.published)
        rel = diff / abs(fig.published) if fig.published != 0 else None
        if fig.tolerance_kind == "rel":
            ok = rel is not None and rel <= fig.tolerance
            tol_text = f"{fig.tolerance * 100:g} %"
        else:
            ok = diff <= fig.tolerance
            tol_text = format_quantity(fig.tolerance, fig.dimension)
        verdict = f"agrees within {tol_text}" if ok else f"differs (tolerance {tol_text})"
        rows.append(row(float(computed), fig.dimension, rel, verdict, fig.reason, ok == (fig.expect == "agree")))
    return rows
