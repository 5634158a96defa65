"""Published figures and formulas of the 3-PRC paper (../shared/papers/prc3-li-2018.md),
each pinned with its source and tolerance: the amplifier (eq 1-2), the stiffness and
mass of the Lagrange model (eq 28-38), the natural frequency (eq 40-41)."""

import math

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.result import Status
from cpm_nlp.mechanisms.prc3 import dynamics as P
from tests.conftest import PROBLEMS

# Table 1 (SI) and the material of section 'Modal analysis'
L1, L2, L3, L4, L5, L6, L7, L8 = 9.5e-3, 25e-3, 9e-3, 30e-3, 26e-3, 33e-3, 73.5e-3, 59.5e-3
R, T, B = 3e-3, 0.5e-3, 6.5e-3
E, RHO, G = 71.7e9, 2810.0, 9.81


@pytest.fixture(scope="module")
def amplifier():
    res = cn.solve(cn.load_problem(PROBLEMS / "prc3_amplifier.yaml"))
    assert res.status is Status.SOLVED
    return res.values


@pytest.fixture(scope="module")
def dyn():
    res = cn.solve(cn.load_problem(PROBLEMS / "prc3_dynamics.yaml"))
    assert res.status is Status.SOLVED, res.message
    return res.values


# -- amplifier (eq 1-3) ------------------------------------------------------------------------------


def test_amplification_ratios_eq1(amplifier):
    # eq 1, printed to four significant figures (half a unit of the last digit: 0.02 %)
    assert amplifier["A1"] == pytest.approx(2.632, rel=2e-4)
    assert amplifier["A2"] == pytest.approx(8.772, rel=2e-4)
    # exact: A1 = 25/9.5, A2 = 750/85.5
    assert amplifier["A1"] == pytest.approx(25 / 9.5, rel=1e-15)
    assert amplifier["A2"] == pytest.approx(750 / 85.5, rel=1e-15)


def test_amplifier_output_eq2(amplifier):
    # d = A2 q (eq 2) over the stroke of eq 27
    np.testing.assert_allclose(amplifier["d1"], [0.0, 750 / 85.5 * 7.5e-6, 750 / 85.5 * 15e-6], rtol=1e-12, atol=0)


def test_fea_ratio_is_not_claimed():
    # eq 3: A_act = 8.245 by FEA; the paper's 6.01 % is (A2 - A_act)/A2 -- the rigid model lists it as
    # "not reproducible" rather than computing it
    rows = {r.quantity: r for r in cn.reproduce([PROBLEMS / "prc3_amplifier.yaml"])}
    fea = rows["amplification ratio A_act by FEA (ANSYS)"]
    assert fea.verdict == "not reproducible" and fea.computed is None
    assert (8.772 - 8.245) / 8.772 == pytest.approx(0.0601, abs=5e-5)


# -- the Lagrange model (eq 28-38) ------------------------------------------------------------------


def file_masses():
    """The masses prc3_dynamics.yaml assumes: Al 7075-T6 blocks (see the file)."""
    bar = RHO * B * 6.5e-3
    return {
        "m0": RHO * 40e-3 * 40e-3 * 6.5e-3,
        "m1": RHO * 6.5e-3**3,
        "m2": bar * L2,
        "m3": bar * L5,
        "m4": bar * L4,
        "m5": bar * L6,
        "m6": RHO * 6.5e-3**3,
        "m7": bar * L7,
    }


def test_hinge_stiffness_after_eq28(dyn):
    # k = 2 E b t^2.5 / (9 pi r^0.5); by hand (tests/analysis/test_flexure.py) 3.36458 N m/rad
    assert dyn["k"] == pytest.approx(3.36458, rel=2e-5)
    # the full notch integral (Paros-Weisbord) is 2.1 % stiffer for t/r = 1/6
    assert dyn["k_exact"] == pytest.approx(3.43804, rel=1e-5)


def test_stiffness_K_e(dyn):
    A1, A2 = L2 / L1, L2 * L4 / (L1 * L3)
    k = 2 * E * B * T**2.5 / (9 * math.pi * R**0.5)
    # eq 38 as printed: 4k [2 A1^2/L2^2 + 3 A2^2/(2 L4^2) + (1/L7^2 + 1/L8^2)]
    printed = 4 * k * (2 * A1**2 / L2**2 + 3 * A2**2 / (2 * L4**2) + (1 / L7**2 + 1 / L8**2))
    assert dyn["K_e_printed"] == pytest.approx(printed, rel=1e-12)
    # by hand: 13.45843 * (22160.66 + 128244.6 + 467.57) = 13.45843 * 150872.8 = 2.03051e6 N/m
    assert dyn["K_e_printed"] == pytest.approx(2.03051e6, rel=1e-5)
    # from the energies (eq 28, 31): the leg term carries A2^2, since beta = z/L8 = -A2 q3/L8
    model = 4 * k * (2 * A1**2 / L2**2 + 3 * A2**2 / (2 * L4**2) + A2**2 * (1 / L7**2 + 1 / L8**2))
    assert dyn["K_e"] == pytest.approx(model, rel=1e-12)
    assert dyn["K_e"] == pytest.approx(2.50843e6, rel=1e-5)  # 13.45843 * (150405.3 + 76.94675 * 467.57)
    np.testing.assert_allclose(dyn["K"], dyn["K_e"] * np.eye(3), rtol=1e-12, atol=1e-6)


def test_mass_M_e(dyn):
    A1, A2 = L2 / L1, L2 * L4 / (L1 * L3)
    m = file_masses()
    for name, value in m.items():
        assert dyn[name] == pytest.approx(value, rel=1e-12), name
    # eq 38 as printed
    printed = (
        2 * (m["m1"] + m["m2"] / 3 + (1 + L5**2 / (12 * L2**2)) * m["m3"]) * A1**2
        + (2 * m["m4"] / 3 + 2 * (1 + L6**2 / (12 * L4**2)) * m["m5"] + 2 * m["m6"] + 10 * m["m7"] / 3 + m["m0"])
        * A2**2
    )
    assert dyn["M_e_printed"] == pytest.approx(printed, rel=1e-12)
    # from the first lines of eq 29, 32, 34: m1 moves with q (not A1 q), I_G5 = m5 L6^2/12
    model = (
        2 * m["m1"]
        + 2 * (m["m2"] / 3 + (1 + L5**2 / (12 * L2**2)) * m["m3"]) * A1**2
        + 2 * (m["m4"] / 3 + (1 + L6**2 / (12 * L4**2)) * m["m5"] + m["m6"]) * A2**2
        + (10 * m["m7"] / 3 + m["m0"]) * A2**2
    )
    assert dyn["M_e"] == pytest.approx(model, rel=1e-12)
    np.testing.assert_allclose(dyn["M"], dyn["M_e"] * np.eye(3), rtol=1e-12, atol=1e-15)


def test_gravity_G_e(dyn):
    # eq 35/38 as printed: G = [0, G_e, 0]
    A1, A2 = L2 / L1, L2 * L4 / (L1 * L3)
    m = file_masses()
    Ge = (m["m0"] * A2 + 6 * (m["m1"] + m["m2"] + m["m3"]) * A1 + 6 * (m["m4"] + m["m5"] + m["m6"] + m["m7"]) * A2) * G
    np.testing.assert_allclose(dyn["G"], [0.0, Ge, 0.0], rtol=1e-12, atol=0)
    assert dyn["G_e"] == dyn["G_e_printed"] == pytest.approx(Ge, rel=1e-12)
    np.testing.assert_allclose(dyn["q_static"], [0.0, -Ge / dyn["K_e"], 0.0], rtol=1e-12, atol=0)


def test_natural_frequency_eq40_eq41(dyn):
    # M and K are diagonal and equal on the diagonal: the three roots of eq 40 coincide with eq 41
    f = math.sqrt(dyn["K_e"] / dyn["M_e"]) / (2 * math.pi)
    assert dyn["f"] == pytest.approx(f, rel=1e-14)
    for name in ("f1", "f2", "f3"):
        assert dyn[name] == pytest.approx(f, rel=1e-10)
    assert dyn["f_printed"] == pytest.approx(math.sqrt(dyn["K_e_printed"] / dyn["M_e_printed"]) / (2 * math.pi))


def test_published_frequency_not_reproduced_with_assumed_masses(dyn):
    """eq 41: f = 93.83 Hz.  The masses are not printed; with the file's assumed masses (not fitted)
    the printed formulas give 96.50 Hz and the energies 107.35 Hz (regression pins, 1e-5)."""
    assert dyn["f_printed"] == pytest.approx(96.5015, rel=1e-5)
    assert dyn["f1"] == pytest.approx(107.3476, rel=1e-5)
    # what the printed data allows: the effective mass that 93.83 Hz implies with the printed K_e,
    # K_e / (2 pi 93.83)^2 = 2.03051e6 / 347569 = 5.842 kg, the same size as the 5.52 kg of the
    # assumed masses: the published figure is consistent with link masses of this order
    implied = dyn["K_e_printed"] / (2 * math.pi * 93.83) ** 2
    assert implied == pytest.approx(5.842, rel=1e-3)


def test_lagrangian_energies_against_matrices(dyn):
    """T = 1/2 qd^T M qd and U = 1/2 q^T K q + G^T q (exact: the energies are quadratic)."""
    model = cn.load_problem(PROBLEMS / "prc3_dynamics.yaml").model
    w = np.array(
        [
            {"E": E, "g": G, "b": B, "t": T, "r": R, "L5": L5, "L6": L6, "L8": L8, **file_masses()}[n]
            for n in P.DYNAMIC_PARAMETERS
        ]
    )
    rng = np.random.default_rng(40)
    M, K, Gv = np.array(dyn["M"]), np.array(dyn["K"]), np.array(dyn["G"])
    for _ in range(5):
        q, qd = rng.uniform(0, 15e-6, 3), rng.uniform(-1e-3, 1e-3, 3)
        out = model.mechanism.part(cn.DynamicsModel).lagrangian()(q=q, qd=qd, p=model.p, w=w)
        assert float(out["T"]) == pytest.approx(0.5 * qd @ M @ qd, rel=1e-12)
        assert float(out["U"]) == pytest.approx(0.5 * q @ K @ q + Gv @ q, rel=1e-12)


def test_reproduce_rows_of_the_prc3_files_are_as_expected():
    rows = cn.reproduce(sorted(PROBLEMS.glob("prc3_*.yaml")))
    assert rows and all(r.expected for r in rows), [(r.quantity, r.verdict) for r in rows if not r.expected]
    verdicts = {r.quantity: r.verdict for r in rows}
    assert verdicts["amplification ratio A2 = L2 L4/(L1 L3)"].startswith("agrees")
    assert verdicts["natural frequency f from eq 38 as printed, with the assumed masses"].startswith("differs")
    assert verdicts["platform mass m0"] == "not reproducible"
