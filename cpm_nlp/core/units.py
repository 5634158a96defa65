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
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

from .errors import InputError, suggest
from .finite import LARGEST as _LARGEST
from .finite import too_large

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


DIMENSIONS: Mapping[str, Dimension] = MappingProxyType(
    {
        d.name: d
        for d in (
            Dimension("length", "m", "mm", "47.91 mm", ("m", "mm", "um", "µm", "nm", "cm"), 1e3),
            Dimension(
                "angle", "rad", "deg", "0.2 deg", ("rad", "deg", "mrad", "urad", "arcmin", "arcsec"), 4 * math.pi
            ),  # two turns: crank angles of a 3-RRR reach 380 deg
            Dimension("stress", "Pa", "MPa", "400 MPa", ("Pa", "kPa", "MPa", "GPa"), 1e13),
            Dimension("force", "N", "N", "20 N", ("N", "mN", "kN"), 1e7),
            Dimension("mass", "kg", "g", "12 g", ("kg", "g", "mg"), 1e4),
            Dimension("area", "m^2", "mm^2", "12 mm^2", ("m^2", "mm^2", "cm^2", "um^2"), 1e6),
            Dimension("area_moment", "m^4", "mm^4", "833.3 mm^4", ("m^4", "mm^4"), 1.0),  # I, J of a section
            Dimension("volume", "m^3", "mm^3", "1.78e-6 m^3", ("m^3", "mm^3", "cm^3", "um^3"), 1e3),
            # sizes of boxes of task coordinates with angles among them (size_dimension)
            Dimension("length_angle", "m*rad", "mm*deg", "2 mm*deg", ("m*rad", "mm*deg"), 1e4),
            Dimension("area_angle", "m^2*rad", "mm^2*deg", "12 mm^2*deg", ("m^2*rad", "mm^2*deg"), 1e7),
            Dimension("length_angle2", "m*rad^2", "mm*deg^2", "2 mm*deg^2", ("m*rad^2", "mm*deg^2"), 1e5),
            Dimension("density", "kg/m^3", "kg/m^3", "2810 kg/m^3", ("kg/m^3", "g/cm^3"), 1e5),
            Dimension("time", "s", "s", "5 ms", ("s", "ms", "us"), 1e7),
            Dimension("frequency", "Hz", "Hz", "93.8 Hz", ("Hz", "kHz"), 1e12),
            Dimension("stiffness", "N/m", "N/um", "2 N/um", ("N/m", "N/mm", "N/um"), 1e12),
            Dimension("rotational_stiffness", "N*m/rad", "N*m/rad", "98.37 N*m/rad", ("N*m/rad", "N*mm/rad"), 1e9),
            Dimension("moment", "N*m", "N*m", "0.1 N*m", ("N*m", "N*mm"), 1e7),
            Dimension("inertia", "kg*m^2", "kg*m^2", "1e-4 kg*m^2", ("kg*m^2", "g*mm^2"), 1e6),
            Dimension("compliance", "m/N", "um/N", "15 um/N", ("m/N", "um/N"), 1e6),
            Dimension("rotational_compliance", "rad/(N*m)", "rad/(N*m)", "0.01 rad/(N*m)", ("rad/(N*m)",), 1e9),
            Dimension("energy", "J", "J", "1 mJ", ("J", "mJ"), 1e9),
            Dimension("acceleration", "m/s^2", "m/s^2", "9.81 m/s^2", ("m/s^2", "mm/s^2"), 1e6),
            Dimension("dimensionless", "", "", "0.5", ("", "%"), 1e15),
        )
    }
)


#: unit text -> (factor to pint's root units, dimension), for the units of DIMENSIONS: the
#: floats pint gives (Quantity(1.0, unit).to_root_units().magnitude; tests/core/test_units.py
#: checks each against pint)
FAST_UNITS: Mapping[str, tuple[float, str]] = MappingProxyType(
    {
        "m": (1.0, "length"),
        "mm": (0.001, "length"),
        "um": (1e-06, "length"),
        "µm": (1e-06, "length"),
        "nm": (1e-09, "length"),
        "cm": (0.01, "length"),
        "rad": (1.0, "angle"),
        "deg": (0.017453292519943295, "angle"),
        "mrad": (0.001, "angle"),
        "urad": (1e-06, "angle"),
        "arcmin": (0.00029088820866572163, "angle"),
        "arcsec": (4.84813681109536e-06, "angle"),
        "Pa": (1000.0, "stress"),
        "kPa": (1000000.0, "stress"),
        "MPa": (1000000000.0, "stress"),
        "GPa": (1000000000000.0, "stress"),
        "N": (1000.0, "force"),
        "mN": (1.0, "force"),
        "kN": (1000000.0, "force"),
        "kg": (1000.0, "mass"),
        "g": (1.0, "mass"),
        "mg": (0.001, "mass"),
        "m^2": (1.0, "area"),
        "mm^2": (1e-06, "area"),
        "cm^2": (0.0001, "area"),
        "um^2": (1e-12, "area"),
        "m^4": (1.0, "area_moment"),
        "mm^4": (1.0000000000000002e-12, "area_moment"),
        "m^3": (1.0, "volume"),
        "mm^3": (1e-09, "volume"),
        "cm^3": (1.0000000000000002e-06, "volume"),
        "um^3": (9.999999999999999e-19, "volume"),
        "kg/m^3": (1000.0, "density"),
        "g/cm^3": (999999.9999999999, "density"),
        "s": (1.0, "time"),
        "ms": (0.001, "time"),
        "us": (1e-06, "time"),
        "Hz": (1.0, "frequency"),
        "kHz": (1000.0, "frequency"),
        "N/m": (1000.0, "stiffness"),
        "N/mm": (1000000.0, "stiffness"),
        "N/um": (1000000000.0, "stiffness"),
        "N*m/rad": (1000.0, "rotational_stiffness"),
        "N*mm/rad": (1.0, "rotational_stiffness"),
        "m/s^2": (1.0, "acceleration"),
        "mm/s^2": (0.001, "acceleration"),
        "%": (0.01, "dimensionless"),
    }
)


def fast_dimension(value: Any) -> str | None:
    """The dimension of a ``"<number> <unit>"`` string whose unit is in
    `FAST_UNITS` (else None): where a caller tries dimensions in turn, the
    one to try first."""
    if not isinstance(value, str):
        return None
    match = _NUMBER.match(value)
    unit = FAST_UNITS.get(match.group(2)) if match else None
    return unit[1] if unit else None


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


def parse_quantity(value: Any, dimension: str, path: tuple = ()) -> float:
    """Return the SI value of ``value``, a quantity of the given ``dimension``.

    ``value`` is a bare number (already SI) or a string ``"<number> <unit>"``.
    Raises [`InputError`][cpm_nlp.core.errors.InputError] for anything else, naming ``path``.
    """
    dim = DIMENSIONS[dimension]
    expected = f"{_describe(dim)} such as '{dim.example}' or a bare SI number"
    if isinstance(value, bool) or value is None:
        raise InputError(f"expected {expected}, got {value!r}", path=path)
    if isinstance(value, (int, float)):
        return _bare_number(value, expected, path)
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
    fast = FAST_UNITS.get(unit_text)
    ref = FAST_UNITS.get(dim.si) if dim.si else (1.0, dimension)
    if fast is not None and ref is not None and fast[1] == dimension == ref[1]:
        factor, ref_factor = fast[0], ref[0]  # the same operations as the pint path, on the same factors
    else:
        factor, ref_factor = _pint_factors(value, unit_text, dim, expected, path)
    si = number * factor / ref_factor
    if not math.isfinite(si):
        raise InputError(f"{value!r} overflows", path=path)
    return si


def _bare_number(value: int | float, expected: str, path: tuple) -> float:
    """A bare number: already SI, finite, and (an int) within a float's range."""
    if isinstance(value, int) and abs(value) > _LARGEST:
        raise InputError(f"{too_large(value)}; expected {expected}", path=path)
    number = float(value)
    if not math.isfinite(number):
        raise InputError(f"expected a finite number ({expected}), got {value!r}", path=path)
    return number


def _pint_factors(value: str, unit_text: str, dim: Dimension, expected: str, path: tuple) -> tuple[float, float]:
    """Pint's factors to the root units of ``unit_text`` and of the dimension's SI unit; bad input
    where the unit is unknown or of another dimension."""
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
    return factor, ref_factor


def si_unit(dimension: str) -> str:
    """The SI unit of a dimension of `DIMENSIONS` ("length" -> "m"), the one place
    that says it.  Fallback: a dimension that is no physical one ("matrix", "vector",
    "text", "bool", a kind's own label) has no SI unit, and gives ""."""
    dim = DIMENSIONS.get(dimension) if isinstance(dimension, str) else None
    return dim.si if dim is not None else ""


def result_unit(dimension: str) -> str:
    """The unit a result of the generic kinds writes for a value of ``dimension``:
    `si_unit`, and for a value with no SI unit (a matrix, a text ...) the name of
    what it is, as their results have always written it (kept for byte-identical JSON)."""
    return si_unit(dimension) if dimension in DIMENSIONS else dimension


def to_display(value: float, dimension: str) -> tuple[float, str]:
    """Convert an SI value to the display unit of its dimension."""
    dim = DIMENSIONS[dimension]
    if dim.display == dim.si:
        return value, dim.si
    fast, fast_si = FAST_UNITS.get(dim.display), FAST_UNITS.get(dim.si)
    if fast is not None and fast_si is not None:
        return value * fast_si[0] / fast[0], dim.display
    f_disp, _ = _root(_ureg().parse_units(dim.display))
    f_si, _ = _root(_ureg().parse_units(dim.si))
    return value * f_si / f_disp, dim.display


#: the size of a box of task coordinates by its numbers of lengths and angles
#: (a length, an area or a volume by the number of translational coordinates)
SIZE_DIMENSIONS: Mapping[tuple[int, int], str] = MappingProxyType(
    {
        (1, 0): "length",
        (2, 0): "area",
        (3, 0): "volume",
        (0, 1): "angle",
        (1, 1): "length_angle",
        (2, 1): "area_angle",
        (1, 2): "length_angle2",
    }
)
#: (powers of length, of angle) of the sizes whose printed unit takes an SI prefix
_SIZE_POWERS = MappingProxyType({d: k for k, d in SIZE_DIMENSIONS.items() if k[0] > 1 or (k[0] and k[1])})
_PREFIXES = (("m", 1.0), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9))


def size_dimension(kinds: Any) -> tuple[str, str]:
    """Dimension and SI unit of the size of a box whose sides have the dimensions
    ``kinds`` (task coordinates): ``["length", "length"]`` -> ``("area", "m^2")``,
    ``["length", "length", "angle"]`` -> ``("area_angle", "m^2*rad")``; other
    mixes: ``"task volume"`` and the product of the SI units."""
    kinds = list(kinds)
    key = (kinds.count("length"), kinds.count("angle"))
    if sum(key) == len(kinds) and key in SIZE_DIMENSIONS:
        dim = SIZE_DIMENSIONS[key]
        return dim, DIMENSIONS[dim].si
    return "task volume", "*".join(DIMENSIONS[k].si for k in kinds)


def _size_display(value: float, dimension: str) -> tuple[float, str]:
    """An area, a volume or a length-angle product for people: in mm (mm^2, mm^3, mm*deg)
    unless the number would be below 1e-3 (then µm, else nm) or at or above 1e9 (then m);
    angles in degrees."""
    n_len, n_ang = _SIZE_POWERS[dimension]
    shown = value * (180.0 / math.pi) ** n_ang
    prefix, size = "mm", 1e-3
    if math.isfinite(value) and value != 0.0:
        if abs(shown) >= 1e9 * 1e-3**n_len:
            prefix, size = "m", 1.0
        else:
            prefix, size = next((p for p in _PREFIXES[1:] if abs(shown) >= 1e-3 * p[1] ** n_len), _PREFIXES[-1])
    unit = prefix + (f"^{n_len}" if n_len > 1 else "")
    unit += ("*deg" + (f"^{n_ang}" if n_ang > 1 else "")) if n_ang else ""
    return shown / size**n_len, unit


def format_quantity(value: float, dimension: str, digits: int = 6) -> str:
    """``0.04791, "length"`` -> ``"47.91 mm"`` (for people, never for files); a size
    (area, volume, area times angle) in mm unless tiny or huge: ``2.68e-7 m^2`` ->
    ``"0.268133 mm^2"``, ``2.7e-14 m^3`` -> ``"27000 µm^3"``."""
    shown, unit = _size_display(value, dimension) if dimension in _SIZE_POWERS else to_display(value, dimension)
    text = f"{shown:.{digits}g}"
    return f"{text} {unit}".strip()
