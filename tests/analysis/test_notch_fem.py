"""The 3-D finite-element reference itself (tests/reference/notch_fem.py, scikit-fem, the ``fem``
extra): a coarse notch against the stored table, the 3-PRS leg against Timoshenko's cantilever,
a thin strip's torsion against Vlasov's restrained warping.  Skipped without scikit-fem."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("skfem", reason="the 3-D reference needs scikit-fem (pip install -e '.[fem]')")

from cpm_nlp.analysis.flexure_compliance import rectangle_torsion_constant  # noqa: E402
from tests.reference import notch_fem as nf  # noqa: E402

REFERENCE = json.loads((Path(__file__).resolve().parents[1] / "data" / "notch_fem_reference.json").read_text())
E = REFERENCE["material"]["E"]
NU = REFERENCE["material"]["nu"]
G = E / (2.0 * (1.0 + NU))


def test_coarse_notch_reproduces_the_stored_table_within_its_convergence_error():
    """t/R = 0.2, w/t = 10 on the coarsest mesh of the study (rotation and axial between elastic
    blocks, the other bending and torsion with the end faces as clamp and rigid body): the stored
    coarse values (the same model, to solver round-off), and within the coarse mesh's own distance
    to the extrapolated value (+ the extrapolation's error estimate) of the stored reference."""

    def stored(key):
        return next(p for p in REFERENCE[key] if round(p["t"] / p["R"], 3) == 0.2 and round(p["w"] / p["t"]) == 10)

    for key, cases, names in (("grid", (0, 1), ("bend", "axial")), ("end_faces_grid", (2, 3), ("bend2", "torsion"))):
        point = stored(key)
        t, r, w = point["t"], point["R"], point["w"]
        run = nf.solve(nf.notch_body(t, r, w, block=point["block"]), REFERENCE["scales"][0], E, NU, cases=cases)
        blocks = nf.block_compliances(t, r, w, point["block"], E, NU)
        for name in names:
            i = {"bend": 5, "bend2": 4, "torsion": 3, "axial": 0}[name]
            k = 1.0 / (run["C"][i, i] - blocks[name])
            ref = point["fem"][name]
            assert k == pytest.approx(ref["values"][0], rel=1e-6), name
            bound = abs(ref["values"][0] - ref["extrapolated"]) + ref["error"]
            assert abs(k - ref["extrapolated"]) <= 1.01 * bound, name
            assert bound / ref["extrapolated"] < 0.03, name


def test_leg_tip_compliance_against_timoshenko():
    """The 3-PRS leg (10 x 10 x 109 mm, Al 7075) clamped at its base, a rigid cap at its tip: the
    6 x 6 tip compliance on a coarse mesh against the Timoshenko cantilever (Cowper's shear
    coefficient, Roark's torsion constant) within 1.5 %: the clamp's restrained Poisson contraction
    and warping make the 3-D body slightly stiffer (0.1-0.7 % on the stored fine meshes)."""
    a = b = 10e-3
    L = 109e-3
    C = nf.solve(nf.beam_body(a, b, L), 2, E, NU)["C"]
    Ct = nf.timoshenko_tip_compliance(a, b, L, E, NU)
    nonzero = Ct != 0.0
    np.testing.assert_allclose(C[nonzero], Ct[nonzero], rtol=0.015)
    assert np.abs(C[~nonzero]).max() < 1e-9 * np.abs(Ct).max()
    stored = np.array(REFERENCE["leg"]["C"])
    np.testing.assert_allclose(stored[nonzero], Ct[nonzero], rtol=0.01)


def test_thin_strip_torsion_follows_restrained_warping():
    """A strip 0.2 x 3 mm, 2 mm long between the clamp and the rigid cap (both stop its warping):
    3-D torsion is 2.8 times Saint-Venant's G J/L and within 6 % of Vlasov's restrained torsion of a
    uniform bar, k = (G J/L) / (1 - tanh(λL/2)/(λL/2)), λ² = G J/(E I_w), I_w = b³ t³/144 (the warping
    model behind the default notch torsion; 3-D is 4-5 % stiffer on this coarse mesh)."""
    a, b, L = 0.2e-3, 3e-3, 2e-3
    C = nf.solve(nf.beam_body(a, b, L, base=(16, 1, 4)), 1, E, NU, cases=(3,))["C"]  # torsion only
    J = rectangle_torsion_constant(b, a)
    Iw = b**3 * a**3 / 144.0
    x = math.sqrt(G * J / (E * Iw)) * L / 2.0
    k_vlasov = G * J / L / (1.0 - math.tanh(x) / x)
    k = 1.0 / C[3, 3]
    assert k > 2.5 * G * J / L
    assert k == pytest.approx(k_vlasov, rel=0.06)
