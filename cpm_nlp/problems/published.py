"""Published figures, side by side with what the model computes.

A problem file that reproduces published figures carries a ``reproduce``
section::

    reproduce:
      paper: prs3-ruiz.md
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
always obtained by solving the file.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ..core.errors import InputError, unknown_key_error
from ..core.units import DIMENSIONS, article, fast_dimension, format_quantity, parse_quantity

ROW_KEYS = ("quantity", "source", "published", "value", "tolerance", "reason", "expect")
VERDICTS = ("agrees", "differs", "not reproducible", "solve failed")


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

    def to_dict(self) -> dict[str, Any]:
        return {
            "file": self.file,
            "paper": self.paper,
            "quantity": self.quantity,
            "source": self.source,
            "published": self.published,
            "published_text": self.published_text,
            "computed": self.computed,
            "unit": DIMENSIONS[self.dimension].si if self.dimension in DIMENSIONS else "",
            "rel_error": self.rel_error,
            "verdict": self.verdict,
            "reason": self.reason,
            "expected": self.expected,
        }


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
        raise InputError("expected the paper's file name, e.g. prs3-ruiz.md", path=path + ("paper",))
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


def _parse_row(row: Any, path: tuple) -> PublishedFigure:  # noqa: C901 - one rule per key of a row
    if not isinstance(row, Mapping):
        raise InputError(f"expected a mapping with keys {', '.join(ROW_KEYS)}", path=path)
    for key in row:
        if key not in ROW_KEYS:
            raise unknown_key_error(str(key), ROW_KEYS, path, "row key")
    quantity = _text(row, "quantity", path)
    source = _text(row, "source", path)
    reason = _text(row, "reason", path, required=False)
    expect = row.get("expect", "agree")
    if expect not in ("agree", "differ"):
        raise InputError(f"expected 'agree' or 'differ', got {expect!r}", path=path + ("expect",))
    if "published" not in row:
        raise InputError("missing required key 'published' (the paper's figure)", path=path)
    value = row.get("value")
    published_raw = row["published"]
    if value is None:
        if not reason:
            raise InputError("a figure the model does not compute (value: null) needs a 'reason'", path=path)
        return PublishedFigure(
            quantity, source, str(published_raw), None, "dimensionless", None, None, None, reason, "differ"
        )
    if not isinstance(value, str) or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*(\[\d+\])*", value):
        raise InputError(
            f"expected the name of a result value, e.g. s_min or dz[0], got {value!r}", path=path + ("value",)
        )
    published, dim = parse_any_quantity(published_raw, path + ("published",))
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
    if expect == "differ" and not reason:
        raise InputError("a row expected to differ needs a 'reason'", path=path)
    return PublishedFigure(quantity, source, str(published_raw), published, dim, value, kind, tol, reason, expect)


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
                file,
                spec.paper,
                fig.quantity,
                fig.source,
                fig.published_text,
                fig.published,
                computed,
                dim,
                rel,
                verdict,
                reason,
                expected,
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
