"""``cpm-nlp reproduce``: solve the problem files that carry a ``reproduce``
section and compare each published figure with the computed value (the
section's format and the comparison are in `cpm_nlp.problems.published`)."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from ..core.errors import InputError
from ..core.progress import track
from ..io.inputs import unique_paths
from ..mechanisms.registry import mechanism_names, mechanism_type
from .file import load_problem, solve
from .published import Comparison, compare
from .shipped import shipped_problems_dir


def problem_files(paths: Iterable[str | Path]) -> list[Path]:
    """Problem files under the given files/directories (and their subdirectories),
    sorted; a directory's ``mechanisms/`` subfolders hold mechanism descriptions, not
    problems, and are left out."""
    out: list[Path] = []
    for p in paths:
        p = Path(p)
        if p.is_dir():
            out += sorted(f for f in p.rglob("*.yaml") if "mechanisms" not in f.relative_to(p).parts[:-1])
        else:
            out.append(p)
    return out


def default_problem_dirs() -> list[Path]:
    """``./problems`` if present, else the shipped ``problems/``."""
    here = Path.cwd() / "problems"
    if here.is_dir():
        return [here]
    shipped = shipped_problems_dir()
    return [shipped] if shipped.is_dir() else []


def plugin_problem_files() -> list[Path]:
    """The problem files that mechanisms from plugins ship (``Mechanism.problem_files``, absolute paths).

    Only plugins' (an entry point): a mechanism described in a file is registered when a
    problem loads it, from wherever that file was, and its examples are problem files of
    their own folder; the shipped ones are in ``problems/`` already (they were listed
    twice), and a file loaded earlier in the same process is no plugin."""
    out: list[Path] = []
    for name in mechanism_names():
        mech = mechanism_type(name)
        if mech.origin.kind == "plugin":
            out += [Path(f) for f in mech.problem_files if Path(f).is_absolute()]
    return out


def _unique(files: Iterable[Path]) -> list[Path]:
    """``files`` without repeats (a path and a symbolic link to it, a directory and a
    file in it): each file is compared once, so every published figure is one row."""
    return unique_paths(files)


def reproduce(paths: Iterable[str | Path] | None = None) -> list[Comparison]:
    """Solve every problem file with a ``reproduce`` section; all rows.  Without
    paths: the shipped problem files, and those of mechanism plugins.  Comparing
    nothing is bad input ([`InputError`][cpm_nlp.core.errors.InputError], naming what was given): no
    problem files, or none with a ``reproduce`` section."""
    given = [str(p) for p in paths] if paths is not None else None
    if given is not None:
        files = problem_files(given)
        what = ", ".join(given) if given else "no paths"
    else:
        dirs = default_problem_dirs()
        files = problem_files(dirs) + plugin_problem_files()
        what = ", ".join(str(d) for d in dirs) if dirs else "the shipped problems/ (not found)"
    files = _unique(files)
    if not files:
        raise InputError(f"no problem files (*.yaml) to compare in {what}")
    rows: list[Comparison] = []
    for f in track(files, "reproducing the published figures"):
        problem = load_problem(f)
        if problem.reproduce is None:
            continue
        result = solve(problem)
        rows += compare(problem.reproduce, result, str(f))
    if not rows:
        names = ", ".join(str(f) for f in files[:3]) + (f" and {len(files) - 3} more" if len(files) > 3 else "")
        raise InputError(
            f"nothing compared: {names} {'has' if len(files) == 1 else 'have'} no 'reproduce' section",
            hint="a problem file that reproduces published figures carries 'reproduce: {paper, rows}'",
        )
    return rows
