"""The ``solver`` section (cpm_nlp/problems/solver_section.py): a preset or a method,
never both; the preset's options stay and the file's are merged over them."""

from __future__ import annotations

import pytest

from cpm_nlp.core.errors import InputError
from cpm_nlp.problems.solver_section import parse_solver


@pytest.mark.parametrize("method", ["ipopt", "newton"])
def test_a_preset_and_a_method_together_are_refused(method):
    # {preset: newton, method: ipopt} used to drop the preset's options silently: now it is an error
    with pytest.raises(InputError) as err:
        parse_solver({"preset": "newton", "method": method, "options": {"ipopt.tol": 1e-12}}, None)
    assert err.value.path == ("solver",)
    assert "'preset' and 'method' given together" in err.value.message and "use one" in err.value.message


def test_a_preset_keeps_its_options_and_merges_the_files():
    config = parse_solver({"preset": "newton", "options": {"max_iter": 8}}, None)
    assert config.method == "newton" and config.options == {"abstol": 1e-14, "max_iter": 8}
    config = parse_solver({"preset": "ipopt", "tolerance": 1e-9}, None)
    assert config.method == "ipopt" and config.options["ipopt.tol"] == 1e-12 and config.tolerance == 1e-9


def test_an_option_of_the_other_method_is_reported():
    with pytest.raises(InputError) as err:
        parse_solver({"method": "ipopt", "options": {"abstol": 1e-14}}, None)
    assert "abstol" in str(err.value) and "newton method" in str(err.value) and err.value.path[0] == "solver"


def test_options_nested_under_ipopt_are_checked_like_dotted_ones():
    config = parse_solver({"method": "ipopt", "options": {"ipopt": {"tol": 1e-9}}}, None)
    assert config.options == {"ipopt.tol": 1e-9}
    with pytest.raises(InputError) as err:
        parse_solver({"method": "ipopt", "options": {"ipopt": {"hsllib": "./lib.so"}}}, None)
    assert err.value.path == ("solver", "options", "ipopt.hsllib")
