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


# -- the fast path (issue 15): the same answers and messages as pint ---------------------------------


def test_fast_units_are_pints_factors():
    """Every factor of the fast path is the float pint computes for that unit, and of the
    dimension pint gives it (same root units as the dimension's SI unit)."""
    from cpm_nlp.core import units as U

    for unit, (factor, dim) in U.FAST_UNITS.items():
        got, root = U._root(U._ureg().parse_units(unit))
        assert got == factor, unit
        si = U.DIMENSIONS[dim].si
        assert root == (U._root(U._ureg().parse_units(si))[1] if si else U._root("")[1]), unit


def _outcome(text, dim):
    try:
        return ("ok", parse_quantity(text, dim))
    except InputError as exc:
        return ("error", str(exc), tuple(exc.suggestions))


def _remembered(fn):
    """fn of one argument, its result or its exception remembered per argument."""
    seen: dict = {}

    def call(arg):
        if arg not in seen:
            try:
                seen[arg] = (True, fn(arg))
            except Exception as exc:  # noqa: BLE001 - pint raises several types; re-raised below
                seen[arg] = (False, exc)
        ok, value = seen[arg]
        if not ok:
            raise value.with_traceback(None)
        return value

    return call


def test_fast_path_agrees_with_pint_over_many_strings(monkeypatch):
    """Numbers in every form the parser admits (and some it does not) times the fast
    units, near misses, other spellings and units of other dimensions, for every
    dimension: the fast path and pint alone accept the same strings with the same
    value (bit for bit) and reject the same strings with the same message."""
    from cpm_nlp.core import units as U

    numbers = ["47.91", "-2.5E-3", ".5", "+3.", "1e308", "1,5", "nan", "", "0x10"]
    units = list(U.FAST_UNITS) + [
        "MM", "Mm", "millimeter", "μm", "degree", "°", "kgs", "m^2", "1/s", "N m", "N*m", "mm/m",
        "foo", "m m", "m/", "%%", "percent", "deg/s", "rad/s", "kN/mm", "g/mm^3", "nm^3", "ks", "GHz",
    ]  # fmt: skip
    strings = []
    for n in numbers:
        for u in units:
            strings += [f"{n} {u}", f"  {n}{u} "]
    assert len(strings) > 1000
    # pint's parsing of a unit text and its factor to root units are pure functions of their
    # argument: remembered here (results and refusals alike) so that the ~50 000 comparisons do
    # not parse the same few dozen units again each time (the test's time, issue 23); every
    # string still goes through parse_quantity on both paths
    reg = U._ureg()
    monkeypatch.setattr(reg, "parse_units", _remembered(reg.parse_units))
    monkeypatch.setattr(U, "_root", _remembered(U._root))
    fast = {(s, d): _outcome(s, d) for s in strings for d in U.DIMENSIONS}
    monkeypatch.setattr(U, "FAST_UNITS", {})  # pint alone
    slow = {(s, d): _outcome(s, d) for s in strings for d in U.DIMENSIONS}
    differ = [k for k in fast if fast[k] != slow[k]]
    assert not differ, differ[:5]
    accepted = sum(1 for v in fast.values() if v[0] == "ok")
    assert accepted > 300 and accepted < len(fast)  # both kinds covered


def test_fast_display_is_pints(monkeypatch):
    from cpm_nlp.core import units as U

    fast = {d: format_quantity(0.0123456789, d) for d in U.DIMENSIONS}
    monkeypatch.setattr(U, "FAST_UNITS", {})
    assert fast == {d: format_quantity(0.0123456789, d) for d in U.DIMENSIONS}


def test_plain_units_do_not_build_the_registry():
    """A fresh process parses the usual units without importing pint."""
    import subprocess
    import sys

    code = (
        "import sys; from cpm_nlp.core.units import parse_quantity, format_quantity; "
        "parse_quantity('47.91 mm', 'length'); parse_quantity('0.2 deg', 'angle'); "
        "parse_quantity('2 GPa', 'stress'); format_quantity(0.04791, 'length'); "
        "print('pint' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


def test_published_quantities_find_the_same_dimension_either_way(monkeypatch):
    """reproduce's parse_any_quantity tries the fast unit's dimension first: the same
    value and dimension as trying every dimension in order through pint, for every
    `published` figure of the shipped problem files and some bad ones."""
    import yaml

    from cpm_nlp.core import units as U
    from cpm_nlp.problems.published import parse_any_quantity
    from tests.conftest import PROBLEMS

    published = ["1.78e-6 m^3", "2 N/um", "5 %", "93.8 Hz", "3 rad", "1,5 mm", "2 furlong", "mm", 0.5]
    for f in sorted(PROBLEMS.glob("*.yaml")):
        rows = (yaml.safe_load(f.read_text()).get("reproduce") or {}).get("rows") or []
        published += [r["published"] for r in rows if "published" in r]
    assert len(published) > 100

    def outcome(v):
        try:
            return parse_any_quantity(v, ("published",))
        except InputError as exc:
            return str(exc)

    fast = [outcome(v) for v in published]
    monkeypatch.setattr(U, "FAST_UNITS", {})
    assert fast == [outcome(v) for v in published]


def test_one_place_gives_the_si_unit_of_a_dimension():
    """core.units.si_unit says the SI unit of a dimension (issue 22, item 2): its one fallback
    is "" for a dimension that is no physical one, and no other module reads DIMENSIONS[...].si."""
    import re
    from pathlib import Path

    from cpm_nlp.core.units import DIMENSIONS, result_unit, si_unit

    assert si_unit("length") == "m" and si_unit("angle") == "rad" and si_unit("stiffness") == "N/m"
    assert si_unit("dimensionless") == "" and si_unit("matrix") == "" and si_unit("text") == ""
    assert all(si_unit(name) == d.si for name, d in DIMENSIONS.items())
    assert result_unit("length") == "m" and result_unit("matrix") == "matrix"
    root = Path(__file__).resolve().parents[2] / "cpm_nlp"
    pattern = re.compile(r"DIMENSIONS\[[^\]]+\]\.si\b|\.si if \w+ in DIMENSIONS")
    offenders = [
        str(p.relative_to(root))
        for p in root.rglob("*.py")
        if p.name != "units.py" and pattern.search(p.read_text(encoding="utf-8"))
    ]
    assert offenders == []
