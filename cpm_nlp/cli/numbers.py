"""Numbers as the command line prints them; the JSON of a result keeps every digit.

Two rules, the same everywhere the CLI prints a quantity:

* **Engineering prefixes, chosen per value.**  A quantity whose SI unit takes a
  prefix is shown with the prefix that puts its number between 1 and 1000, to
  `DIGITS` significant digits: 0.00348767 mm is ``3.488 µm``, 0.02 N is
  ``20 mN``, 1.7e8 Pa is ``170 MPa``.  An angle is shown in degrees, the papers' unit
  (``0.5579 deg``), and below 1 mrad in µrad or nrad (``-60.13 µrad``).  A compound unit
  (N/m, m^2, N*m/rad ...) keeps its display unit (`cpm_nlp.core.units.format_quantity`).
* **Noise below the solve's tolerance is zero.**  A solve stops when the largest
  loop-closure residual max |Φ| is at most its tolerance ``tol`` (``solver.tolerance``,
  in metres: Φ is a length).  A length is therefore known to about ``tol``, and any
  other quantity to about the same fraction of its scale: ``tol / L`` times the
  largest magnitude of that dimension among the values of the result (``L``: the
  mechanism's scale, its largest length parameter; 1 m if it has none).  A
  value below that is rounding noise of the solve and is printed as ``0`` (never
  ``-0``): ``psi 1.71766e-15 deg`` is ``0 deg``.  See `Noise`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import Any

#: significant digits of a printed quantity
DIGITS = 4

#: a dimension whose SI unit takes a prefix: the unit and the prefixes used (largest first)
_PREFIXED: dict[str, tuple[str, tuple[tuple[float, str], ...]]] = {
    "length": ("m", ((1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"), (1e-12, "p"))),
    "angle": ("rad", ((1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"))),
    "force": ("N", ((1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"))),
    "stress": ("Pa", ((1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""))),
    "mass": ("g", ((1.0, "k"), (1e-3, ""), (1e-6, "m"), (1e-9, "µ"))),  # SI value in kg
    "time": ("s", ((1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"))),
    "frequency": ("Hz", ((1e6, "M"), (1e3, "k"), (1.0, ""))),
    "energy": ("J", ((1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"))),
}


def _number(x: float, digits: int = DIGITS) -> str:
    text = f"{x:.{digits}g}"
    return "0" if float(text) == 0 else text  # never "-0"


def engineering(value: float, dimension: str | None, digits: int = DIGITS) -> str:
    """``value`` (SI) for people: a prefixed unit chosen for this value (module docstring)."""
    from ..core.units import DIMENSIONS, format_quantity, si_unit

    if not math.isfinite(value):
        return str(value)
    if dimension in _PREFIXED:
        unit, prefixes = _PREFIXED[dimension]
        if value == 0:  # an angle in the papers' unit, as its neighbours in a table
            return "0 deg" if dimension == "angle" else f"0 {unit}"
        rounded = abs(float(f"{value:.{digits}g}"))  # 999.96 µm is 1 mm, not 1000 µm
        size, prefix = next(((f, p) for f, p in prefixes if rounded >= f), prefixes[-1])
        if dimension == "angle" and size >= 1e-3:  # down to 1 mrad: degrees, the papers' unit
            return f"{_number(math.degrees(value), digits)} deg"
        return f"{_number(value / size, digits)} {prefix}{unit}"
    if dimension in DIMENSIONS and si_unit(dimension):
        if value == 0:
            return f"0 {DIMENSIONS[dimension].display}"
        text = format_quantity(value, dimension, digits)
        return text[1:] if text.startswith("-0 ") else text
    return _number(value, digits + 2)


def _magnitudes(value: Any) -> Iterable[float]:
    if isinstance(value, bool):
        return
    if isinstance(value, (int, float)):
        if math.isfinite(value):
            yield abs(float(value))
    elif isinstance(value, list):
        for v in value:
            yield from _magnitudes(v)


class Noise:
    """Which printed values are rounding noise of the solve (the module docstring's rule):
    a value of dimension D below ``tolerance / L * scale[D]`` is noise, ``scale[D]`` the
    largest magnitude of D among the result's values and ``L`` (``length``) the mechanism's
    largest length parameter (1 m if it has none)."""

    def __init__(
        self,
        tolerance: float | None,
        values: Mapping[str, Any],
        dimensions: Mapping[str, str | None],
        length: float | None = None,
    ) -> None:
        self.tolerance = tolerance
        scale: dict[str | None, float] = {}
        for name, value in values.items():
            dim = dimensions.get(name)
            scale[dim] = max([scale.get(dim, 0.0), *_magnitudes(value)])
        self.scale = scale
        self.length = length if length and math.isfinite(length) and length > 0 else 1.0

    def threshold(self, dimension: str | None) -> float:
        """The magnitude below which a value of ``dimension`` is noise (0: none is)."""
        if self.tolerance is None:
            return 0.0
        if dimension == "length":
            return self.tolerance
        return self.tolerance / self.length * self.scale.get(dimension, 0.0)

    def clean(self, value: float, dimension: str | None) -> float:
        """``value``, or 0.0 where it is noise (and for -0.0)."""
        return 0.0 if abs(value) <= self.threshold(dimension) else value


#: a Noise that changes nothing (no tolerance known)
NO_NOISE = Noise(None, {}, {})
