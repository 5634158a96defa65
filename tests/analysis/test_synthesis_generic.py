"""Generic dimensional synthesis (cpm_nlp.analysis.synthesis; the ``synthesis``
kind's fallback for a mechanism without a paper formulation), on the demo
plugin's biglide (tests/plugin_pkg), checked two independent ways:

* a closed form: with slider strokes |q_i| <= s and the platform above the
  sliders, the biglide's workspace in (x, r = sqrt(L² - y²)) is the diamond
  |x| + |r - d| <= s cut at r <= L.  The largest rectangle reaching y = 0
  spans x in [-h, h] and r in [d - s + h, L] with h <= s + d - L; its area
  2h sqrt(L² - (d - s + h)²) is largest for d = L - s + h, so over d the
  optimum maximises h² (L² - (c + 2h)²), c = L - 2s:
  16 h² + 12 c h - 2 (L² - c²) = 0, d* = L - s + h*, area* = 2 h* sqrt(L² - (c + 2h*)²);
* a brute-force grid over the parameter, the largest cuboid of each design by
  the (separately tested) inscribed_cuboid.
"""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis.synthesis import cuboid_synthesis
from cpm_nlp.analysis.workspace import check_box, inscribed_cuboid
from cpm_nlp.core.errors import InputError
from cpm_nlp.problems.file import problem_from_dict, solve

PLUGIN = Path(__file__).resolve().parents[1] / "plugin_pkg"
L, S = 0.1, 0.02


@pytest.fixture(scope="module")
def biglide():
    sys.path.insert(0, str(PLUGIN))
    try:
        from cpm_nlp_demo_plugin import MECHANISM
    finally:
        sys.path.remove(str(PLUGIN))
    cn.register_mechanism(MECHANISM, replace=True)
    yield MECHANISM
    cn.unregister_mechanism("biglide")


def _model(d=0.05):
    return cn.build_model("biglide", {"d": d, "L": L}, {"q": [-S, S]})


def test_closed_form_optimum(biglide):
    c = L - 2 * S
    h = (-12 * c + math.sqrt(144 * c * c + 128 * (L * L - c * c))) / 32
    d_star, area_star = L - S + h, 2 * h * math.sqrt(L * L - (c + 2 * h) ** 2)
    rep = cuboid_synthesis(_model(), {"d": (0.03, 0.099)}, None, starts=3)
    assert rep.found and rep.shrink == 1.0 and rep.check.passed and rep.agreed == 3
    assert rep.parameters["d"] == pytest.approx(d_star, rel=1e-6)
    assert rep.volume == pytest.approx(area_star, rel=1e-6)
    np.testing.assert_allclose(rep.lower, [-h, 0.0], atol=1e-7)
    # the re-check, independently: the box at the optimal design is inside the workspace
    m = _model(rep.parameters["d"])
    assert check_box(m, rep.lower, rep.upper, 21)[0].passed


def test_footprint_against_brute_force_grid(biglide):
    """Area per unit of d (footprint {d: 1}): the optimum beats every design of
    a grid over d and lies within one grid step of the grid's best."""
    rep = cuboid_synthesis(_model(), {"d": (0.03, 0.099)}, {"d": 1.0}, starts=3)
    assert rep.found and rep.check.passed
    grid = np.linspace(0.03, 0.099, 24)
    ratios = []
    for d in grid:
        box = inscribed_cuboid(_model(d), starts=2)
        ratios.append(box.volume / d if box.found else 0.0)
    best = int(np.argmax(ratios))
    assert rep.objective >= max(ratios) * (1 - 1e-6)
    assert rep.objective <= max(ratios) * 1.05  # the grid's best is close (step 3 mm)
    assert abs(rep.parameters["d"] - grid[best]) <= grid[1] - grid[0]
    assert rep.footprint == pytest.approx(rep.parameters["d"]) and rep.objective == pytest.approx(
        rep.volume / rep.footprint
    )
    assert 0.03 < rep.parameters["d"] < 0.099  # an interior optimum


def test_synthesis_kind_falls_back_to_the_generic_formulation(biglide):
    data = {
        "problem": "synthesis",
        "mechanism": {
            "type": "biglide",
            "parameters": {"d": "50 mm", "L": "100 mm"},
            "limits": {"q": ["-20 mm", "20 mm"]},
        },
        "inputs": {"design": {"d": ["30 mm", "99 mm"]}, "starts": 2},
    }
    res = solve(problem_from_dict(data))
    assert res.ok and res.values["check_outside"] == 0
    assert res.values["d"] == pytest.approx(L - S + 0.0136420818, rel=1e-6)
    assert res.units["volume"] == "m^2" and res.dimensions["volume"] == "area"  # two length task coordinates
    bad = dict(data, inputs={"design": {"dd": ["30 mm", "99 mm"]}})
    with pytest.raises(InputError, match="unknown parameter 'dd'"):
        problem_from_dict(bad)
    no_bounds = dict(data, inputs={"design": ["d"]})  # biglide declares no upper bound of d
    with pytest.raises(InputError, match="declares no finite bounds"):
        problem_from_dict(no_bounds)
    log_zero = dict(data, inputs={"design": {"d": ["0 mm", "99 mm"]}, "footprint": {"d": 1}})
    with pytest.raises(InputError, match="lower bound must be positive"):
        problem_from_dict(log_zero)
