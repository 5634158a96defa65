"""Hostile solver options (issue 19): a problem file, a preset or ``--set`` is data and never
reaches a compiler, a shell, a library loader or a file nobody named on the command line.

The exact inputs of the issue: CasADi's JIT with a shell "compiler"; the same from a
``configs/ipopt.yaml`` preset; ``ipopt.linear_solver: ma57`` with ``ipopt.hsllib`` naming a
library whose constructor writes a marker; ``ipopt.output_file`` naming the problem file;
``ipopt.option_file_name: /etc/passwd``; ``preset`` with ``method``.  Each is refused through
``check``, ``solve`` and ``export``: exit 2, one message naming the key, no traceback, nothing
written or changed, no marker, in under 1 s.  Also: the allow-list against the installed IPOPT and
CasADi, and every shipped preset and problem file against the allow-list.
"""

from __future__ import annotations

import dataclasses
import shutil
import subprocess
import time
from pathlib import Path

import casadi as ca
import pytest

from cpm_nlp import load_problem
from cpm_nlp.core.errors import InputError
from cpm_nlp.core.solver import SolverConfig
from cpm_nlp.core.solver_options import (
    CASADI_REFUSED,
    IPOPT_REFUSED,
    casadi_rules,
    check_options,
    ipopt_rules,
    option_table,
    refused_table,
    table,
)
from cpm_nlp.problems.reader import load_yaml_text
from cpm_nlp.problems.shipped import shipped_configs_dir
from cpm_nlp.problems.solver_section import parse_solver
from cpm_nlp.sweep.run import INVALID_INPUT, job_of, solve_points
from tests.conftest import PROBLEMS, ROOT, run_cli
from tests.hostile.test_hostile import HANG_S, assert_refused, dump, snapshot

BASE = load_yaml_text((PROBLEMS / "rpr_forward_kinematics.yaml").read_text())

#: the issue's JIT input: CasADi would run 'touch X; true' as its compiler and linker
JIT = {
    "method": "ipopt",
    "options": {
        "jit": True,
        "compiler": "shell",
        "jit_options": {"compiler": "touch X; true", "linker": "touch X; true"},
    },
}

#: (label, solver section, text the one message line holds: the key)
CASES = [
    ("jit", JIT, "solver.options.jit:"),
    (
        "hsllib",
        {"method": "ipopt", "options": {"ipopt.linear_solver": "ma57", "ipopt.hsllib": "./lib.so"}},
        "solver.options.ipopt.linear_solver:",
    ),
    ("hsllib_alone", {"method": "ipopt", "options": {"ipopt.hsllib": "./lib.so"}}, "solver.options.ipopt.hsllib:"),
    (
        "output_file",
        {"method": "ipopt", "options": {"ipopt.output_file": "p.yaml"}},
        "solver.options.ipopt.output_file:",
    ),
    (
        "option_file_name",
        {"method": "ipopt", "options": {"ipopt.option_file_name": "/etc/passwd"}},
        "solver.options.ipopt.option_file_name:",
    ),
    ("preset_and_method", {"preset": "newton", "method": "ipopt"}, "solver: 'preset' and 'method' given together"),
    ("nested_ipopt", {"method": "ipopt", "options": {"ipopt": {"hsllib": "./lib.so"}}}, "solver.options.ipopt.hsllib:"),
    ("jit_on_newton", {"method": "newton", "options": dict(JIT["options"])}, "solver.options.jit:"),
]

COMMANDS = {"check": ("check",), "solve": ("solve",), "export": ("export", "--out", "out")}

MARKER = "MARKER_from_lib_so"


@pytest.fixture
def lib_so(tmp_path):
    """``tmp_path/lib.so``: a library whose constructor writes ``tmp_path/MARKER`` when loaded."""
    cc = shutil.which("gcc") or shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler to build the marker library")
    src = tmp_path / "lib.c"
    src.write_text(
        "#include <stdio.h>\n"
        "__attribute__((constructor)) static void mark(void) {\n"
        f'  FILE* f = fopen("{tmp_path / MARKER}", "w"); if (f) {{ fputs("loaded", f); fclose(f); }}\n'
        "}\n"
    )
    subprocess.run([cc, "-shared", "-fPIC", str(src), "-o", str(tmp_path / "lib.so")], check=True)
    src.unlink()
    return tmp_path / "lib.so"


def _no_marker(folder: Path) -> None:
    assert not (folder / "X").exists(), "the JIT 'compiler' command ran"
    assert not (folder / MARKER).exists(), "the library named by the file was loaded"


def _refused_in_time(folder: Path, argv: list[str], names, key: str) -> str:
    before = snapshot(folder)
    t0 = time.perf_counter()
    run = run_cli(*argv)
    seconds = time.perf_counter() - t0
    line = assert_refused(run, names, key)
    assert run.out == "" or run.code == 2
    assert "root:" not in run.out + run.err  # /etc/passwd was not echoed
    assert snapshot(folder) == before  # nothing written, nothing changed (the problem file included)
    _no_marker(folder)
    assert seconds < HANG_S, f"refused after {seconds:.2f} s"
    return line


@pytest.mark.parametrize("command", list(COMMANDS))
@pytest.mark.parametrize(("label", "solver", "key"), CASES, ids=[c[0] for c in CASES])
def test_a_hostile_solver_section_is_refused(tmp_path, monkeypatch, lib_so, command, label, solver, key):
    monkeypatch.chdir(tmp_path)
    problem = tmp_path / "p.yaml"
    problem.write_text(dump({**BASE, "solver": solver}))
    run_cli("check", str(problem))  # warm: imports and tables loaded once, as in a real run
    line = _refused_in_time(tmp_path, [*COMMANDS[command], str(problem)], problem, key)
    if label != "preset_and_method":
        assert "is refused: it" in line and "a problem file is data" in line


@pytest.mark.parametrize(
    ("override", "key"),
    [
        ("solver.options.jit=true", "solver.options.jit:"),
        ("solver.options.compiler=shell", "solver.options.compiler:"),
        ("solver.options.jit_options={compiler: 'touch X; true', linker: 'touch X; true'}", "jit_options"),
        ("solver.options.jit_options.compiler=touch X; true", "solver.options.jit_options.compiler:"),
        ("solver.options.ipopt.hsllib=./lib.so", "solver.options.ipopt.hsllib:"),
        ("solver.options.ipopt.linear_solver=ma57", "solver.options.ipopt.linear_solver:"),
        ("solver.options.ipopt.output_file=p.yaml", "solver.options.ipopt.output_file:"),
        ("solver.options.ipopt.option_file_name=/etc/passwd", "solver.options.ipopt.option_file_name:"),
        ("solver.options.dump=true", "solver.options.dump:"),
        ("solver.options.common_options={jit: true}", "solver.options.common_options:"),
        ("solver.method=ipopt", "'preset' and 'method' given together"),
    ],
)
def test_the_same_through_set_is_refused(tmp_path, monkeypatch, lib_so, override, key):
    monkeypatch.chdir(tmp_path)
    problem = tmp_path / "p.yaml"
    problem.write_text(dump({**BASE, "solver": "newton"}))
    run_cli("check", str(problem))
    _refused_in_time(tmp_path, ["solve", str(problem), "--set", override], problem, key)


def test_a_hostile_preset_beside_the_problem_file_is_refused_naming_the_preset(tmp_path, monkeypatch):
    # the issue's second case: the file says only 'solver: ipopt', configs/ipopt.yaml holds the JIT options
    monkeypatch.chdir(tmp_path)
    (tmp_path / "configs").mkdir()
    preset = tmp_path / "configs" / "ipopt.yaml"
    preset.write_text(dump(JIT))
    problem = tmp_path / "p.yaml"
    problem.write_text(dump({**BASE, "solver": "ipopt"}))
    for command in COMMANDS.values():
        line = _refused_in_time(tmp_path, [*command, str(problem)], preset, "options.jit:")
        assert "is refused" in line


def test_a_preset_in_the_working_directory_alone_is_not_read(tmp_path, monkeypatch):
    # a configs/ that happens to be in the working directory does not change what 'solver: ipopt' means
    (tmp_path / "configs").mkdir()
    (tmp_path / "configs" / "ipopt.yaml").write_text(dump(JIT))
    work = tmp_path / "elsewhere" / "deeper"
    work.mkdir(parents=True)
    problem = work / "p.yaml"
    problem.write_text(dump({**BASE, "solver": "ipopt"}))
    monkeypatch.chdir(tmp_path)
    before = snapshot(tmp_path)
    run = run_cli("check", str(problem))
    assert run.code == 0, run.err
    assert snapshot(tmp_path) == before
    _no_marker(tmp_path)


def test_a_preset_named_by_cpm_nlp_configs_passes_the_same_allow_list(tmp_path, monkeypatch):
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "fast.yaml").write_text(dump({"method": "ipopt", "options": {"ipopt.output_file": "p.yaml"}}))
    monkeypatch.setenv("CPM_NLP_CONFIGS", str(mine))
    monkeypatch.chdir(tmp_path)
    problem = tmp_path / "p.yaml"
    problem.write_text(dump({**BASE, "solver": "fast"}))
    _refused_in_time(tmp_path, ["solve", str(problem)], mine / "fast.yaml", "options.ipopt.output_file:")


def test_a_sweep_refuses_a_hostile_swept_option_before_anything_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    problem = tmp_path / "p.yaml"
    sweep = {"parameters": {"solver.options.ipopt.output_file": ["p.yaml"]}}
    problem.write_text(dump({**BASE, "solver": {"method": "ipopt"}, "sweep": sweep}))
    _refused_in_time(tmp_path, ["check", str(problem)], problem, "solver.options.ipopt.output_file")


def test_a_worker_validates_the_problem_it_is_sent(tmp_path, monkeypatch):
    # a worker rebuilds each point from the data it receives, through the same parser: a job
    # carrying the JIT options (never planned by cpm-nlp, sent by hand) runs nothing
    monkeypatch.chdir(tmp_path)
    problem = tmp_path / "p.yaml"
    problem.write_text(dump({**BASE, "sweep": {"parameters": {"inputs.l1": ["40.01 mm"]}}}))
    planned = job_of(load_problem(str(problem)))
    job = dataclasses.replace(planned, data={**planned.data, "solver": JIT})
    before = snapshot(tmp_path)
    out = solve_points(job, [0])
    record = out["records"][0]
    assert record["status"] == INVALID_INPUT and "solver.options.jit" in record["message"], record
    assert snapshot(tmp_path) == before
    _no_marker(tmp_path)


def test_the_python_api_applies_the_same_allow_list():
    with pytest.raises(InputError) as err:
        SolverConfig("ipopt", {"jit": True, "compiler": "shell"})
    assert err.value.path == ("solver", "options", "jit")
    with pytest.raises(InputError):
        SolverConfig("ipopt", {"ipopt.hsllib": "./lib.so"})
    assert SolverConfig("ipopt", {"ipopt.max_iter": 50.0}).options == {"ipopt.max_iter": 50}


@pytest.mark.parametrize(
    ("options", "text"),
    [
        ({"ipopt.tolerance": 1e-8}, "did you mean 'ipopt.tol'"),
        ({"ipopt.mu_stratgy": "adaptive"}, "did you mean 'ipopt.mu_strategy'"),
        ({"ipopt.sb": True}, None),  # YAML's unquoted yes: IPOPT's "yes"
        ({"ipopt.bound_frac": 0.5}, None),  # IPOPT's range 0 < bound_frac <= 0.5
        ({"ipopt.bound_frac": 0.0}, "expected a number in (0, 0.5]"),
        ({"ipopt.linear_solver": "spral"}, None),
        ({"ipopt.linear_solver": "pardiso"}, "library at run time"),
        ({"ipopt.linear_system_scaling": "mc19"}, "library"),
        ({"ipopt.derivative_test": "first-order"}, "derivative checker"),
        ({"ipopt.ma27_pivtol": 1e-8}, "linear solver ma27"),
        ({"monitor": ["nlp_f"]}, "is refused"),
        ({"iteration_callback": "f"}, "is refused"),
        ({"specific_options": {"nlp_f": {"jit": True}}}, "is refused"),
    ],
)
def test_ipopt_options_are_typed_ranged_and_named(options, text):
    if text is None:
        check_options("ipopt", options)
        return
    with pytest.raises(InputError) as err:
        check_options("ipopt", options)
    assert text in err.value.render()


# -- the allow-list against the installed solvers, and the shipped files against the list -----------------


def test_the_table_agrees_with_the_installed_ipopt_and_casadi():
    """Every allowed IPOPT option exists in the installed IPOPT and takes its documented default (one
    solve of a tiny problem with all of them set), every allowed CasADi option exists in CasADi, and
    every refused name the policy lists is documented by IPOPT or CasADi (no stale entries)."""
    allowed, refused, _ = ipopt_rules()
    defaults = {o["name"]: o["default"] for o in table()["ipopt"]}
    opts = {f"ipopt.{n}": defaults[n] for n in allowed if n in defaults}
    opts.update({"ipopt.sb": "yes", "ipopt.print_level": 0, "print_time": False})
    y = ca.SX.sym("y")
    solver = ca.nlpsol("table_check", "ipopt", {"x": y, "f": (y - 1) ** 2}, opts)
    solver(x0=3)
    assert solver.stats()["return_status"] == "Solve_Succeeded"
    for method, build in (
        ("ipopt", lambda o: ca.nlpsol("c", "ipopt", {"x": y, "f": y**2}, {**o, "ipopt.print_level": 0})),
        ("newton", lambda o: ca.rootfinder("c", "newton", ca.Function("g", [y], [y]), o)),
    ):
        for name, rule in casadi_rules(method).items():
            value = False if rule.kind == "bool" else 10 if rule.kind == "int" else 1e-10
            build({name: value, "print_time": False} if name != "print_time" else {name: False})
    documented = {o["name"] for key in ("casadi_nlpsol_ipopt", "casadi_rootfinder_newton") for o in table()[key]}
    assert set(CASADI_REFUSED) <= documented
    assert set(IPOPT_REFUSED) <= set(defaults) and set(IPOPT_REFUSED) <= set(refused)
    assert table()["ipopt_builtin_linear_solvers"] and "mumps" in table()["ipopt_builtin_linear_solvers"]
    assert option_table("ipopt") and refused_table()


def test_the_table_ships_as_package_data():
    assert "solver_options.json" in (ROOT / "setup.py").read_text()


@pytest.mark.parametrize("preset", sorted(shipped_configs_dir().glob("*.yaml")), ids=lambda p: p.stem)
def test_every_shipped_preset_passes_the_allow_list(preset):
    data = load_yaml_text(preset.read_text())
    check_options(data.get("method", "ipopt"), data.get("options") or {})
    assert parse_solver(preset.stem, None).preset == preset.stem


def test_every_shipped_problem_file_passes_the_allow_list():
    files = sorted(PROBLEMS.glob("*.yaml"))
    assert len(files) > 20
    for f in files:
        data = load_yaml_text(f.read_text())
        parse_solver(data.get("solver"), f.parent)
        for key, values in ((data.get("sweep") or {}).get("parameters") or {}).items():
            if key.startswith("solver.options."):
                for v in values if isinstance(values, list) else [values]:
                    parse_solver({"method": "ipopt", "options": {key[len("solver.options.") :]: v}}, f.parent)


# -- mechanism files: names that become C and file names, files a problem file may read ------------------

RPR_FILE = load_yaml_text((PROBLEMS / "rpr_file_forward_kinematics.yaml").read_text())


@pytest.mark.parametrize(
    "name", ["m" + "a" * 299, "_a", "a_", "a__b", "éa"], ids=["300_chars", "lead", "trail", "double", "non_ascii"]
)
@pytest.mark.parametrize("command", list(COMMANDS))
def test_a_mechanism_name_that_cannot_name_c_or_files_is_refused(tmp_path, monkeypatch, name, command):
    # the issue: exporting a mechanism with a 300-character name failed inside CasADi
    monkeypatch.chdir(tmp_path)
    mech = load_yaml_text((PROBLEMS / "mechanisms" / "rpr.yaml").read_text())
    (tmp_path / "m.yaml").write_text(dump({**mech, "name": name}))
    problem = tmp_path / "p.yaml"
    problem.write_text(dump({**RPR_FILE, "mechanism": {**RPR_FILE["mechanism"], "file": "m.yaml"}}))
    line = _refused_in_time(tmp_path, [*COMMANDS[command], str(problem)], problem, "mechanism.file:")
    assert "name: expected a mechanism type name of at most 64" in line


@pytest.mark.parametrize("target", ["/etc/passwd", "../../../../../../etc/passwd", "/etc/hostname"])
def test_a_problem_file_reads_only_yaml_mechanism_files_and_never_echoes_another_file(tmp_path, monkeypatch, target):
    monkeypatch.chdir(tmp_path)
    problem = tmp_path / "p.yaml"
    problem.write_text(dump({**RPR_FILE, "mechanism": {**RPR_FILE["mechanism"], "file": target}}))
    line = _refused_in_time(tmp_path, ["check", str(problem)], problem, "mechanism.file:")
    assert "ending in .yaml or .yml" in line
    (tmp_path / "secret.yaml").write_text("the first line of a file that is not a mechanism\n")
    problem.write_text(dump({**RPR_FILE, "mechanism": {**RPR_FILE["mechanism"], "file": "secret.yaml"}}))
    line = _refused_in_time(tmp_path, ["check", str(problem)], problem, "mechanism.file:")
    assert "first line" not in line and "got str of" in line


def test_one_table_of_newton_options():
    """Issue 22, item 5: the allow-list, cpm_nlp's defaults and the options the kernels'
    fast_newton honours all come from one table; every default passes the option check, and
    every option the kernels honour or ignore is one a file may give."""
    from types import MappingProxyType

    from cpm_nlp.core import kernels, solver, solver_options

    names = [o.name for o in solver_options.NEWTON_TABLE]
    assert len(names) == len(set(names))
    assert list(solver_options.NEWTON_ALLOWED) == names
    assert dict(solver.DEFAULT_OPTIONS["newton"]) == {
        "abstol": 1e-14,
        "max_iter": 50,
        "error_on_fail": False,
        "print_iteration": False,
    }
    assert set(kernels.NEWTON_OPTIONS) | set(kernels._IGNORED_NEWTON) <= set(names)
    assert kernels.NEWTON_OPTIONS == ("abstol", "abstolStep", "max_iter")
    assert isinstance(solver.DEFAULT_OPTIONS, MappingProxyType)
    config = solver.SolverConfig("newton", dict(solver.DEFAULT_OPTIONS["newton"]))
    assert kernels.newton_options(config) == {"abstol": 1e-14, "max_iter": 50}
    assert kernels.batch_newton_supported(config)
