"""Shared by the plot tests: the shipped problem files solved once per session."""

from __future__ import annotations

from dataclasses import replace

import pytest


@pytest.fixture(scope="session")
def solved_file():
    """``solved_file(name)``: the result of problems/<name>.yaml with its problem at hand,
    as ``cpm-nlp solve FILE --plot`` plots it (solved once per session)."""
    import cpm_nlp as cn
    from cpm_nlp.plot.results import from_solved
    from tests.conftest import PROBLEMS

    cache = {}

    def get(name):
        if name not in cache:
            problem = cn.load_problem(PROBLEMS / f"{name}.yaml")
            # as solve --plot: solved whole (an outputs selection limits what is recorded, not drawn)
            cache[name] = from_solved(cn.solve(replace(problem, outputs=None)), problem)
        return cache[name]

    return get
