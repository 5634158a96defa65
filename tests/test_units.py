"""Quantities: units in, SI out; anything else is one clear error."""

import math

import pytest

from cpm_nlp.core.errors import InputError
from cpm_nlp.core.units import format_quantity, parse_quantity


@pytest.mark.parametrize(
    "text, dim, si",
    [
        ("47.91 mm", "length", 0.04791),
        ("15 um", "length", 15e-6),
        ("15 µm", "length", 15e-6),
        ("15 μm", "length", 15e-6),
        (0.1, "length", 0.1),
        ("0.2 deg", "angle", math.radians(0.2)),
        ("0.2°", "angle", math.radians(0.2)),
        ("5 arcmin", "angle", math.radians(5 / 60)),
        (0.5, "angle", 0.5),
        ("2 GPa", "stress", 2e9),
        ("2.81 g/cm^3", "density", 2810.0),
        ("98.37 N*m/rad", "rotational_stiffness", 98.37),
        ("1e-3", "length", 1e-3),
    ],
)
def test_parse_quantity(text, dim, si):
    assert parse_quantity(text, dim) == pytest.approx(si, rel=1e-12)


@pytest.mark.parametrize(
    "text, dim, fragment",
    [
        ("47.91 mmm", "length", "unknown unit 'mmm'"),
        ("47.91 kg", "length", "'47.91 kg' is not a length"),
        ("0.2 mm/m", "angle", "is not an angle"),
        ("mm", "length", "write a number first"),
        ("1,5 mm", "length", "unknown unit"),
        ("nan mm", "length", "write a number first"),
        (float("nan"), "length", "finite number"),
        (float("inf"), "length", "finite number"),
        (True, "length", "got True"),
        (None, "length", "got None"),
        ([1], "length", "got list"),
    ],
)
def test_parse_quantity_rejects(text, dim, fragment):
    with pytest.raises(InputError) as exc:
        parse_quantity(text, dim, ("mechanism", "parameters", "b"))
    assert fragment in str(exc.value)
    assert str(exc.value).startswith("mechanism.parameters.b: ")


def test_unknown_unit_suggests():
    with pytest.raises(InputError) as exc:
        parse_quantity("3 nmm", "length")
    assert "did you mean" in str(exc.value)


def test_format_quantity():
    assert format_quantity(0.04791, "length") == "47.91 mm"
    assert format_quantity(math.radians(0.2), "angle") == "0.2 deg"
