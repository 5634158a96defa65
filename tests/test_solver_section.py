"""The ``solver`` section (cpm_nlp/problems/solver_section.py): a preset's options belong
to its method and do not survive a method override; otherwise the preset's options stay
and the file's are merged over them."""

from __future__ import annotations

import pytest

from cpm_nlp.core.errors import InputError
from cpm_nlp.problems.solver_section import parse_solver


def test_method_override_drops_the_presets_method_options():
    # configs/newton.yaml sets abstol and max_iter, which IPOPT does not know: before the fix
    # this failed with an option error about 'abstol', which the user never wrote
    config = parse_solver({"preset": "newton", "method": "ipopt", "options": {"ipopt.tol": 1e-12}}, None)
    assert config.method == "ipopt"
    assert config.options == {"ipopt.tol": 1e-12}
    assert config.tolerance == 1e-10  # the preset's tolerance is not method-specific: it stays


def test_same_method_keeps_and_merges_the_presets_options():
    config = parse_solver({"preset": "newton", "method": "newton", "options": {"max_iter": 8}}, None)
    assert config.options == {"abstol": 1e-14, "max_iter": 8}
    config = parse_solver({"preset": "ipopt", "tolerance": 1e-9}, None)
    assert config.method == "ipopt" and config.options["ipopt.tol"] == 1e-12 and config.tolerance == 1e-9


def test_an_option_of_the_other_method_written_by_the_user_is_still_reported():
    with pytest.raises(InputError) as err:
        parse_solver({"preset": "newton", "method": "ipopt", "options": {"abstol": 1e-14}}, None)
    assert "abstol" in str(err.value) and err.value.path[0] == "solver"
