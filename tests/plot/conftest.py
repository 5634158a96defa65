"""Shared by the plot tests: the shipped problem files solved once per session."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def solved_file(shipped_solve):
    """``solved_file(name)``: the result of problems/<name>.yaml with its problem at hand,
    as ``cpm-nlp solve FILE --plot`` plots it (solved once per session, the solve shared with
    the other tests of shipped files: tests/conftest.py ``shipped_solve``)."""
    from cpm_nlp.plot.results import from_solved

    cache = {}

    def get(name):
        if name not in cache:
            # as solve --plot: solved whole (an outputs selection limits what is recorded, not drawn)
            problem, result = shipped_solve(name, whole=True)
            cache[name] = from_solved(result, problem)
        return cache[name]

    return get
