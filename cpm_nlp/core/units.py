"""Physical quantities in problem files.

A quantity is written with a unit (``"47.91 mm"``, ``"0.2 deg"``, ``"2 GPa"``)
or as a bare number, which is read in SI (m, rad, Pa, N, kg, s ...).  Every
value inside cpm_nlp is SI; units only exist at the edges (files, printing).

Unit parsing is done by `pint <https://pint.readthedocs.io>`_: it knows SI
prefixes (``µm``, ``um``, ``GPa``), compound units (``g/cm^3``, ``N*m/rad``)
and their dimensions, which a hand-written table would only approximate.  The
number itself is parsed here, strictly, so that ``"1,5 mm"``, ``"mm"``,
``"nan mm"`` and ``"inf"`` are rejected rather than guessed.
"""

from __future__ import annotations

import math
import re
import threading
from dataclasses import dataclass
from typing import Any

from .errors import InputError, suggest

_NUMBER = re.compile(r"^\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)\s*(.*?)\s*$")


@dataclass(frozen=True)
class Dimension:
    """A physical dimension a declared quantity must have.

    ``si`` is the unit of the SI value, ``display`` the unit used when printing
    for people, ``example`` appears in error messages.
    """

    name: str
    si: str
    display: str
    example: str
    common_units: tuple[str, ...]
    #: largest magnitude (SI) a declared option of this dimension accepts
    #: unless it declares its own bounds: far beyond any mechanism of this
    #: toolkit, it only stops absurd values (1e30 rad) from being "solved"
    limit: float = math.inf


DIMENSIONS: dict[str, Dimension] = {
    d.name: d
    for d in (
        Dimension("length", "m", "mm", "47.91 mm", ("m", "mm", "um", "µm", "nm", "cm"), 1e3),
        Dimension("angle", "rad", "deg", "0.2 deg", ("rad", "deg", "mrad", "urad", "arcmin", "arcsec"), 2 * math.pi),
        Dimension("stress", "Pa", "MPa", "400 MPa", ("Pa", "kPa", "MPa", "GPa"), 1e13),
        Dimension("force", "N", "N", "20 N", ("N", "mN", "kN"), 1e7),
        Dimension("mass", "kg", "g", "12 g", ("kg", "g", "mg"), 1e4),
        Dimension("volume", "m^3", "mm^3", "1.78e-6 m^3", ("m^3", "mm^3", "cm^3", "um^3"), 1e3),
        Dimension("density", "kg/m^3", "kg/m^3", "2810 kg/m^3", ("kg/m^3", "g/cm^3"), 1e5),
        Dimension("time", "s", "s", "5 ms", ("s", "ms", "us"), 1e7),
        Dimension("frequency", "Hz", "Hz", "93.8 Hz", ("Hz", "kHz"), 1e12),
        Dimension("stiffness", "N/m", "N/um", "2 N/um", ("N/m", "N/mm", "N/um"), 1e12),
        Dimension("rotational_stiffness", "N*m/rad", "N*m/rad", "98.37 N*m/rad", ("N*m/rad", "N*mm/rad"), 1e9),
        Dimension("volume", "m^3", "mm^3", "1.78e-6 m^3", ("m^3", "mm^3", "um^3", "cm^3"), 1e3),
        Dimension("acceleration", "m/s^2", "m/s^2", "9.81 m/s^2", ("m/s^2", "mm/s^2"), 1e6),
        Dimension("dimensionless", "", "", "0.5", ("", "%"), 1e15),
    )
}


_registry_lock = threading.Lock()
_registry: Any = None


def _ureg() -> Any:
    """The pint registry, created once on first use (about 0.3 s)."""
    global _registry
    with _registry_lock:
        if _registry is None:
            import pint

            _registry = pint.UnitRegistry()
        return _registry


def _root(unit: Any) -> tuple[float, str]:
    """Factor to root (SI base) units and the root unit's canonical text."""
    q = _ureg().Quantity(1.0, unit).to_root_units()
    return float(q.magnitude), str(q.units)


def article(noun: str) -> str:
    """``"angle"`` -> ``"an angle"``."""
    return ("an " if noun[:1] in "aeiou" else "a ") + noun


def _describe(dim: Dimension) -> str:
    return "a dimensionless number" if dim.name == "dimensionless" else article(dim.name.replace("_", " "))


def parse_quantity(value: Any, dimension: str, path: tuple = ()) -> float:  # noqa: C901 - one branch per accepted form of a quantity
    """Return the SI value of ``value``, a quantity of the given ``dimension``.

    ``value`` is a bare number (already SI) or a string ``"<number> <unit>"``.
    Raises :class:`InputError` for anything else, naming ``path``.
    """
    dim = DIMENSIONS[dimension]
    expected = f"{_describe(dim)} such as '{dim.example}' or a bare SI number"
    if isinstance(value, bool) or value is None:
        raise InputError(f"expected {expected}, got {value!r}", path=path)
    if isinstance(value, (int, float)):
        number = float(value)
        if not math.isfinite(number):
            raise InputError(f"expected a finite number ({expected}), got {value!r}", path=path)
        return number
    if not isinstance(value, str):
        raise InputError(f"expected {expected}, got {type(value).__name__} {value!r}", path=path)
    match = _NUMBER.match(value)
    if match is None:
        raise InputError(
            f"expected {expected}, got {value!r} (write a number first, then the unit)",
            path=path,
        )
    number = float(match.group(1))
    unit_text = match.group(2)
    if not math.isfinite(number):  # pragma: no cover - the regex admits no nan/inf
        raise InputError(f"expected a finite number, got '{value}'", path=path)
    if not unit_text:
        return number
    try:
        unit = _ureg().parse_units(unit_text)
        factor, root = _root(unit)
        ref_factor, ref_root = _root(_ureg().parse_units(dim.si)) if dim.si else (1.0, _root("")[1])
    except Exception as exc:  # pint raises several types for unparsable units
        raise InputError(
            f"unknown unit {unit_text!r} in {value!r}; expected {expected}",
            path=path,
            suggestions=suggest(unit_text, dim.common_units),
        ) from exc
    if root != ref_root:
        raise InputError(
            f"{value!r} is not {_describe(dim)}; expected a unit like "
            + ", ".join(f"'{u}'" for u in dim.common_units if u),
            path=path,
            suggestions=suggest(unit_text, [u for u in dim.common_units if u]),
        )
    si = number * factor / ref_factor
    if not math.isfinite(si):
        raise InputError(f"{value!r} overflows", path=path)
    return si


def to_display(value: float, dimension: str) -> tuple[float, str]:
    """Convert an SI value to the display unit of its dimension."""
    dim = DIMENSIONS[dimension]
    if dim.display == dim.si:
        return value, dim.si
    f_disp, _ = _root(_ureg().parse_units(dim.display))
    f_si, _ = _root(_ureg().parse_units(dim.si))
    return value * f_si / f_disp, dim.display


def format_quantity(value: float, dimension: str, digits: int = 6) -> str:
    """``0.04791, "length"`` -> ``"47.91 mm"`` (for people, never for files)."""
    shown, unit = to_display(value, dimension)
    text = f"{shown:.{digits}g}"
    return f"{text} {unit}".strip()
