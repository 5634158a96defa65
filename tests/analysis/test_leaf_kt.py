"""The stress-concentration factor of a leaf spring with corner fillets (issue 25, item 2):
Roark's Table 17.1 square shoulder with fillet in a member of rectangular section, in-plane
bending (:func:`~cpm_nlp.analysis.hinge_types.leaf_fillet_kt`), and the peak stress K_t x
nominal a problem file reports for a `leaf_spring` hinge given its fillet radius r."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from cpm_nlp.analysis import hinge_types as ht
from cpm_nlp.core.errors import InputError
from cpm_nlp.problems.file import load_problem, solve

ROOT = Path(__file__).resolve().parents[2]
TABLE2 = ROOT / "problems" / "prs3_table2_forces.yaml"


def _roark_coefficients(h_over_r: float) -> np.ndarray:
    """C1..C4 of Roark's Formulas for Stress and Strain, 7th ed. (Young & Budynas 2002), Table
    17.1, square shoulder with fillet in a member of rectangular section, in-plane bending, typed
    here from the eng-calculations.com transcription of that table (not the book), independently
    of the code: one row set for 0.1 <= h/r <= 2.0, one for 2.0 < h/r <= 20."""
    s, hr = math.sqrt(h_over_r), h_over_r
    if h_over_r <= 2.0:
        rows = [(1.007, 1.000, -0.031), (-0.270, -2.404, 0.749), (0.677, 1.133, -0.904), (-0.414, 0.271, 0.186)]
    else:
        rows = [(1.042, 0.982, -0.036), (-3.599, 1.619, -0.431), (6.084, -5.607, 1.158), (-2.527, 3.006, -0.691)]
    return np.array([a + b * s + c * hr for a, b, c in rows])


def _roark_kt(t: float, r: float, h: float) -> float:
    """K_t = C1 + C2 x + C3 x^2 + C4 x^3, x = 2h/D with D = t + 2h (the leaf t between blocks)."""
    x = 2 * h / (t + 2 * h)
    return float(np.polyval(_roark_coefficients(h / r)[::-1], x))


@pytest.mark.parametrize("h_over_r", [0.1, 0.5, 1.0, 2.0, 2.0001, 5.0, 20.0])
@pytest.mark.parametrize("t_over_r", [0.05, 0.25, 1.0, 4.0])
def test_the_fit_is_roarks_polynomial(t_over_r, h_over_r):
    r = 2e-3
    t, h = t_over_r * r, h_over_r * r
    assert ht.leaf_fillet_kt(t, r, h) == pytest.approx(_roark_kt(t, r, h), rel=1e-12)
    if h_over_r == 1.0:  # h defaults to r, as the filleted rod's fit assumes
        assert ht.leaf_fillet_kt(t, r) == ht.leaf_fillet_kt(t, r, h)


@pytest.mark.parametrize("h_over_r", [0.1, 0.5, 1.0, 2.0, 2.0001, 5.0, 10.0, 20.0])
def test_the_coefficients_sum_to_one_so_kt_tends_to_one_for_a_thin_leaf(h_over_r):
    """The table's limit: as the leaf thins against the block (2h/D -> 1), K_t -> 1; the four
    coefficients of each row set sum to 1 within the transcription's rounding (3 decimals)."""
    assert sum(_roark_coefficients(h_over_r)) == pytest.approx(1.0, abs=2e-3)
    assert ht.leaf_fillet_kt(1e-12, 1e-3, h_over_r * 1e-3) == pytest.approx(1.0, abs=2e-3)


def test_the_two_row_sets_meet_at_h_over_r_2():
    """Continuity where the fit changes rows (h/r = 2): within 1e-3 at every thickness."""
    for t_over_r in np.linspace(0.01, 5.0, 30):
        low = ht.leaf_fillet_kt(t_over_r, 1.0, 2.0)
        high = ht.leaf_fillet_kt(t_over_r, 1.0, 2.0 + 1e-9)
        assert high == pytest.approx(low, abs=1e-3)


def test_kt_falls_as_the_fillet_grows():
    """A larger fillet, a milder corner: K_t falls monotonically in r, with the block's shoulder
    h = r (the default) and with a fixed block (h = 2 mm, over r = 0.1 ... 2 mm: h/r 1 ... 20),
    from well above 1 toward 1."""
    t = 0.5e-3
    radii = np.linspace(0.05e-3, 20e-3, 80)
    kts = [ht.leaf_fillet_kt(t, r) for r in radii]
    assert all(b < a for a, b in zip(kts, kts[1:]))
    # the fit's own rounding: at t/r = 0.025 it gives 0.99996, not a peak below the nominal
    assert kts[-1] == pytest.approx(1.0, abs=1e-3) and kts[0] > 1.5
    fixed = [ht.leaf_fillet_kt(t, r, 2e-3) for r in np.linspace(0.1e-3, 2e-3, 80)]
    assert all(b < a for a, b in zip(fixed, fixed[1:]))


def test_a_shallow_step_in_a_thick_leaf_tends_to_c1():
    """The other end of the table: 2h/D -> 0 (a step small against the section) gives C1."""
    assert ht.leaf_fillet_kt(1e3, 1e-3) == pytest.approx(_roark_coefficients(1.0)[0], rel=1e-5)


def _solve_with(tmp_path, revolute: str):
    """prs3_table2_forces.yaml with its revolute hinges as leaf springs (the mechanism's k kept:
    only the stress changes with the type)."""
    text = TABLE2.read_text().replace(
        "  stress_limit: true", f"  stress_limit: true\n  hinges:\n    revolute: {revolute}"
    )
    f = tmp_path / "leaf.yaml"
    f.write_text(text)
    return load_problem(f)


LEAF = "type: leaf_spring, t: 1 mm, l: 5 mm, w: 10 mm"


def test_a_problem_file_reports_the_peak_of_a_filleted_leaf(tmp_path):
    """Round trip: a leaf spring given r (t 1, r 2 mm, h = r) reports Kt_revolute = Roark's fit
    (1.0379) and stress_peak_revolute = K_t x stress_revolute; without r (a sharp corner: r null
    clears the notch's r of the mechanism) K_t is 1 and the nominal stress is the same."""
    res = solve(_solve_with(tmp_path, "{" + LEAF + ", r: 2 mm}"))
    assert res.ok, res.message
    v = res.values
    kt = _roark_kt(1e-3, 2e-3, 2e-3)
    assert kt == pytest.approx(1.0379, abs=1e-4)
    assert v["Kt_revolute"] == pytest.approx(kt, rel=1e-12)
    assert v["stress_peak_revolute"] == pytest.approx(kt * v["stress_revolute"], rel=1e-12)
    sharp = solve(_solve_with(tmp_path, "{" + LEAF + ", r: null}")).values
    assert sharp["Kt_revolute"] == 1.0
    assert sharp["stress_peak_revolute"] == sharp["stress_revolute"] == pytest.approx(v["stress_revolute"])
    given = solve(_solve_with(tmp_path, "{" + LEAF + ", r: 2 mm, h: 6 mm}")).values
    assert given["Kt_revolute"] == pytest.approx(_roark_kt(1e-3, 2e-3, 6e-3), rel=1e-12)


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (", r: 2 mm, h: 50 mm", r"h/r = 25 is outside the range of Roark's fit.*0\.1 <= h/r <= 20"),
        (", r: 2 mm, h: 0.1 mm", r"h/r = 0\.05 is outside"),
        (", r: null, h: 1 mm", "give the fillet radius r too"),
        (", r: 2 mm, d: 1 mm", r"hinge type leaf_spring has no dimension d \(it takes t, l, w \(optionally r, h\)\)"),
    ],
)
def test_outside_the_fit_is_refused_with_its_key_path(tmp_path, extra, message):
    with pytest.raises(InputError, match=message) as err:
        _solve_with(tmp_path, "{" + LEAF + extra + "}")
    assert "inputs" in str(err.value) and "revolute" in str(err.value)


def test_a_designed_fillet_radius_gives_the_same_kt_symbolically():
    """compliance_synthesis may vary r: the fit on a CasADi symbol (both row sets, by if_else)
    equals the float fit."""
    import casadi as ca

    r = ca.SX.sym("r")
    f = ca.Function("kt", [r], [ht.leaf_fillet_kt(0.5e-3, r, 3e-3)], ["r"], ["kt"])
    for value in (0.5e-3, 1e-3, 2e-3):  # h/r = 6, 3, 1.5
        assert float(f(value)) == pytest.approx(ht.leaf_fillet_kt(0.5e-3, value, 3e-3), rel=1e-14)


@pytest.mark.parametrize(("r_bounds", "refused"), [("[0.5 mm, 12 mm]", False), ("[0.2 mm, 12 mm]", True)])
def test_a_designed_fillet_stays_within_the_fit(tmp_path, r_bounds, refused):
    """compliance_synthesis varying a leaf's r with its block h fixed (6 mm): the bounds must keep
    h/r within 0.1-20 (r = 0.2 mm gives 30: refused, naming inputs.design.revolute)."""
    text = (ROOT / "problems" / "prs3_compliance_synthesis.yaml").read_text()
    text = text.replace("revolute: {t: [0.5 mm, 4 mm], r: [2 mm, 12 mm]}", f"revolute: {{r: {r_bounds}}}")
    text = text.replace(
        "  k_actuator: 0 N/m", "  k_actuator: 0 N/m\n  hinges:\n    revolute: {" + LEAF + ", r: 2 mm, h: 6 mm}"
    )
    f = tmp_path / "design.yaml"
    f.write_text(text)
    if refused:
        with pytest.raises(InputError, match=r"h/r = 30 is outside") as err:
            load_problem(f)
        assert "design" in str(err.value) and "revolute" in str(err.value)
    else:
        assert load_problem(f).kind.name == "compliance_synthesis"
