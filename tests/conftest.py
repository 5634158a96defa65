"""Shared fixtures: the paper's 3-PRS model and an in-process CLI runner."""

from __future__ import annotations

import io
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.cli.main import main

ROOT = Path(__file__).resolve().parent.parent
PROBLEMS = ROOT / "problems"

#: prs3-ruiz.md, section 4: L = 109.215 mm, b = 47.91 mm, alpha = 45 deg at home.
PAPER_PRS3 = {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"}


@pytest.fixture(scope="session", autouse=True)
def compiled_cache_dir(tmp_path_factory):
    """Libraries compiled by the tests go to a throwaway cache, never the user's.  Under
    pytest-xdist the workers share one (the run's base directory): a kernel is compiled once
    per run, not once per worker (the cache renames each library into place, so a worker never
    loads another's half-written file: cpm_nlp.core.compiled)."""
    old = os.environ.get("CPM_NLP_CACHE")
    if os.environ.get("PYTEST_XDIST_WORKER"):
        shared = tmp_path_factory.getbasetemp().parent / "cpm_nlp_cache"
        shared.mkdir(exist_ok=True)
        os.environ["CPM_NLP_CACHE"] = str(shared)
    else:
        os.environ["CPM_NLP_CACHE"] = str(tmp_path_factory.mktemp("cpm_nlp_cache"))
    yield Path(os.environ["CPM_NLP_CACHE"])
    if old is None:
        os.environ.pop("CPM_NLP_CACHE", None)
    else:
        os.environ["CPM_NLP_CACHE"] = old


@pytest.fixture(scope="session")
def shipped_solve():
    """``shipped_solve(name, whole=False)``: ``(problem, result)`` of problems/<name>.yaml,
    solved once per session (per xdist worker) for every test that solves a shipped file (the
    declared outputs, the plots).  ``whole``: with its outputs selection lifted, as ``cpm-nlp
    solve FILE --plot`` draws it (the same solve for a file without a selection); the problem
    returned is the file's own."""
    from dataclasses import replace

    problems: dict[str, cn.Problem] = {}
    results: dict[tuple[str, bool], cn.Result] = {}

    def get(name: str, whole: bool = False):
        if name not in problems:
            problems[name] = cn.load_problem(PROBLEMS / f"{name}.yaml")
        problem = problems[name]
        key = (name, whole and problem.outputs is not None)
        if key not in results:
            results[key] = cn.solve(replace(problem, outputs=None) if key[1] else problem)
        return problem, results[key]

    return get


@pytest.fixture(scope="session")
def prs3():
    return cn.build_model("prs3", PAPER_PRS3)


@dataclass
class Run:
    code: int
    out: str
    err: str


def run_cli(*argv: str) -> Run:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return Run(code, out.getvalue(), err.getvalue())


@pytest.fixture
def cli():
    return run_cli


def central_difference(f, x, h):
    """Central differences of f at x, one column per entry of x (for checking AD Jacobians)."""
    x = np.asarray(x, dtype=float)
    cols = []
    for k in range(x.size):
        e = np.zeros_like(x)
        e[k] = h
        cols.append((np.asarray(f(x + e)) - np.asarray(f(x - e))) / (2 * h))
    return np.column_stack(cols)
