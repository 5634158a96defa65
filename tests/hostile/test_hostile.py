"""Hostile input, generated: every shipped problem file mutated (type swaps,
unit swaps, absurd magnitudes, NaN/inf, unknown keys, duplicate keys, deleted
required keys, bad solver options, YAML bombs, bad sweep axes), and every
command given bad arguments, special files and unsafe outputs.

Every case asserts: the exit status; no traceback; exactly one message line
naming the file (and the key path where there is one); no output file left
behind; no input file modified.  Cases that exit 0 or 1 with ``--json`` print
exactly one JSON document on stdout.  Input validation runs through
``cpm-nlp check`` in-process (fast); only a few cases need a subprocess (file
descriptor 1 itself, a real terminal signal).
"""

from __future__ import annotations

import hashlib
import itertools
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from cpm_nlp.mechanisms.registry import mechanism_type
from cpm_nlp.problems.reader import MAX_ALIASES, MAX_DEPTH, load_yaml_text
from tests.conftest import PROBLEMS, run_cli

# problem files of built-in mechanisms (mechanism: {type: ...}); files that describe their
# mechanism in a file (mechanism: {file: ...}) have their own error tests (test_described*.py)
SHIPPED = sorted(f for f in PROBLEMS.glob("*.yaml") if "type" in load_yaml_text(f.read_text())["mechanism"])
SWEEPS = [f for f in SHIPPED if "sweep" in load_yaml_text(f.read_text())]


# -- what every case asserts ------------------------------------------------------------------


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def snapshot(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` (symbolic links by their target) and its content hash."""
    out = {}
    for p in sorted(folder.rglob("*")):
        if p.is_symlink():
            out[str(p)] = "-> " + os.readlink(p)
        elif p.is_file():
            out[str(p)] = _digest(p)
        elif p.is_dir():
            out[str(p)] = "dir"
    return out


def assert_refused(run, names: str | Path, key: str | None = None, code: int = 2) -> str:
    """Exit ``code``, no traceback, one line ``error: ...`` naming ``names`` (and ``key``)."""
    assert run.code == code, run.err
    assert "Traceback" not in run.err and "internal error" not in run.err, run.err
    lines = run.err.splitlines()
    assert len(lines) == 1, run.err
    line = lines[0]
    assert line.startswith("error: "), line
    assert str(names) in line, line
    if key is not None:
        assert key in line, line
    assert len(line) < 2000, len(line)
    return line


#: A refusal that takes longer than this hung, or read what it should not have (a sparse 16 GB file,
#: /dev/zero, a FIFO, 20 000 legs took from 8 s to forever before the limits).  Not a speed target:
#: speed targets are never timed assertions in tests (a loaded machine, or xdist's second worker,
#: makes a 0.3 s refusal take 1 s); the 1 s target of issue 19 is measured, as a ratio to reading a
#: valid file with the load beside it, by benchmarks/bench_hostile.py.
HANG_S = 10.0


def dump(data) -> str:
    return yaml.safe_dump(data, sort_keys=False, allow_unicode=True, width=10_000)


# -- generated mutations of the shipped problem files ------------------------------------------

_QUANTITY = re.compile(r"^\s*[-+]?(\d+(\.\d*)?|\.\d+)([eE][-+]?\d+)?\s*([^\s\d].*)?$")
_ANGLE_UNITS = ("deg", "rad", "mrad", "urad", "arcmin", "arcsec")


def _unit_of(value) -> str | None:
    """The unit a value is written with ("mm", "deg"; "" for a bare number), None if not a quantity."""
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float)):
        return ""
    if isinstance(value, str):
        m = _QUANTITY.match(value)
        if m:
            return (m.group(4) or "").strip()
    return None


def _bad_values(original):
    """Values that no declared option accepts in place of ``original``: (label, value)."""
    out = [
        ("nested_list", [[[1]]]),
        ("mapping", {"zzz_bogus": 1}),
        ("nan", float("nan")),
        ("inf", float("inf")),
        ("minus_inf", float("-inf")),
    ]
    if not isinstance(original, bool):
        out.append(("bool", True))
    unit = _unit_of(original)
    if unit is not None:
        swapped = "mm" if unit in _ANGLE_UNITS else "deg" if unit else "kg/s"
        out.append(("unit_swap", f"1.5 {swapped}"))
        out.append(("wrong_dimension", "3 kg/s"))
        out.append(("absurd", f"1e30 {unit}".strip() if unit else 1e30))
        out.append(("absurd_negative", f"-1e300 {unit}".strip() if unit else -1e300))
    return out


def _leaf(value):
    """(path suffix, value) of the value to mutate: a list's first entry, or the value."""
    if isinstance(value, list) and value and not isinstance(value[0], (list, dict)):
        return (0,), value[0]
    return (), value


def _set(data, path, value):
    node = data
    for part in path[:-1]:
        node = node[part]
    node[path[-1]] = value


def _key_text(path) -> str:
    text = ""
    for p in path:
        text += f"[{p}]" if isinstance(p, int) else ("." if text else "") + str(p)
    return text


SOLVER_CASES = (
    ({"options": {"ipopt.tol": float("nan")}}, "solver.options.ipopt.tol"),
    ({"options": {"ipopt.tol": 0}}, "solver.options.ipopt.tol"),
    ({"options": {"ipopt.max_iter": -1}}, "solver.options.ipopt.max_iter"),
    ({"options": {"ipopt.max_iter": 2.5}}, "solver.options.ipopt.max_iter"),
    ({"options": {"ipopt.max_iter": 10**40}}, "solver.options.ipopt.max_iter"),
    ({"options": {"ipopt.print_level": 99}}, "solver.options.ipopt.print_level"),
    ({"options": {"ipopt.mu_strategy": "fastest"}}, "solver.options.ipopt.mu_strategy"),
    ({"options": {"ipopt.tolerance": 1e-8}}, "did you mean 'ipopt.tol'"),
    ({"method": "newton", "options": {"ipopt.tol": 1e-8}}, "did you mean 'abstol'"),
    ({"method": "newton", "options": {"abstol": -1e-12}}, "solver.options.abstol"),
    ({"method": "newton", "options": {"max_iter": 0}}, "solver.options.max_iter"),
    ({"method": "newton", "options": {"max_itr": 5}}, "did you mean 'max_iter'"),
    ({"tolerance": 0}, "solver.tolerance"),
    ({"tolerance": float("nan")}, "solver.tolerance"),
    ({"tolerance": -1e-9}, "solver.tolerance"),
    ({"preset": "ipoptt"}, "did you mean 'ipopt'"),
    ({"method": "newtn"}, "did you mean 'newton'"),
    ({"options": [1, 2]}, "solver.options"),
)


def _bombs():
    laughs = "lol: &a [x, x, x, x, x, x, x, x, x, x]\n"
    prev = "a"
    for i in range(1, 8):
        laughs += f"l{i}: &l{i} [" + ", ".join([f"*{prev}"] * 10) + "]\n"
        prev = f"l{i}"
    many = "anchor: &x 1\nuse: [" + ", ".join(["*x"] * (MAX_ALIASES + 1)) + "]\n"
    return (
        ("billion_laughs", laughs, "values once aliases are expanded"),
        ("recursive_alias", "loop: &r [1, *r]\n", "refers to a value that contains it"),
        ("recursive_mapping", "loop: &m {a: *m}\n", "refers to a value that contains it"),
        ("deep_nesting", "deep: " + "[" * 10_000 + "]" * 10_000 + "\n", f"nested more than {MAX_DEPTH} levels"),
        ("too_many_aliases", many, f"more than {MAX_ALIASES} aliases"),
    )


def _cases_of(path: Path, counter):  # noqa: C901 - one block per class of mutation
    text = path.read_text()
    data = load_yaml_text(text)
    stem = path.stem
    mech = data["mechanism"]
    mtype = mechanism_type(mech["type"])
    # values of parameters and inputs: one bad value each, rotating over the classes
    targets = [("mechanism", "parameters", k) for k in (mech.get("parameters") or {})]
    targets += [("inputs", k) for k in (data.get("inputs") or {}) if k != "guess"]
    for target in targets:
        node = data
        for p in target:
            node = node[p]
        suffix, original = _leaf(node)
        bad = _bad_values(original)
        label, value = bad[next(counter) % len(bad)]
        mutated = json.loads(json.dumps(data, default=str))
        _set(mutated, target + suffix, value)
        yield f"{stem}-{_key_text(target)}-{label}", dump(mutated), _key_text(target)
    # a required mechanism parameter deleted
    required = [o.name for o in mtype.parameters if o.required and o.name in (mech.get("parameters") or {})]
    if required:
        name = required[next(counter) % len(required)]
        mutated = json.loads(json.dumps(data, default=str))
        del mutated["mechanism"]["parameters"][name]
        yield f"{stem}-delete-{name}", dump(mutated), f"'{name}'"
    for key, where in (("problem", "problem"), ("mechanism", "mechanism")):
        mutated = {k: v for k, v in data.items() if k != key}
        yield f"{stem}-delete-{key}", dump(mutated), where
    # an unknown key, at a rotating place
    # (mechanism.parameters only where the file has it: a file mechanism may take none)
    places = [(), ("mechanism",)] + ([("mechanism", "parameters")] if mech.get("parameters") else [])
    places += [("inputs",)] if data.get("inputs") else []
    place = places[next(counter) % len(places)]
    mutated = json.loads(json.dumps(data, default=str))
    node = mutated
    for p in place:
        node = node.setdefault(p, {})
    node["zzz_unknown"] = 1
    yield f"{stem}-unknown-{_key_text(place) or 'top'}", dump(mutated), "zzz_unknown"
    # a duplicate key (YAML keeps the last silently): the message names both lines
    yield f"{stem}-duplicate-problem", text + "\nproblem: forward_kinematics\n", "duplicate key 'problem'"
    if next(counter) % 3 == 0:
        yield f"{stem}-duplicate-mechanism", text + "\nmechanism: {type: prs3}\n", "duplicate key 'mechanism'"
    # a YAML bomb appended
    bombs = _bombs()
    name, bomb, message = bombs[next(counter) % len(bombs)]
    yield f"{stem}-{name}", text + "\n" + bomb, message
    # a bad solver section
    for _ in range(1):
        section, key = SOLVER_CASES[next(counter) % len(SOLVER_CASES)]
        mutated = json.loads(json.dumps(data, default=str))
        mutated["solver"] = section
        body = dump(mutated).replace("nan", ".nan")
        yield f"{stem}-solver-{key.split()[-1].strip(chr(39))}-{next(counter)}", body, key


def _sweep_cases(path: Path):
    data = load_yaml_text(path.read_text())
    stem = path.stem
    cases = (
        (
            "random_method",
            {"solver.method": {"random": "uniform", "from": 0, "to": 1}},
            "sweep.parameters.solver.method",
        ),
        (
            "random_integer_option",
            {"solver.options.ipopt.max_iter": {"random": "uniform", "from": 10, "to": 100}},
            "sweep.parameters.solver.options.ipopt.max_iter",
        ),
        ("unknown_axis", {"mechanism.parameters.zzz": [1, 2]}, "zzz"),
        ("absurd_grid", {"inputs.zzz": {"from": 0, "to": 1, "count": 10**12}}, "sweep.parameters"),
    )
    for name, axis, key in cases:
        mutated = json.loads(json.dumps(data, default=str))
        mutated["sweep"]["parameters"].update(axis)
        if "random" in json.dumps(axis):
            mutated["sweep"]["samples"] = 3
        yield f"{stem}-sweep-{name}", dump(mutated), key
    mutated = json.loads(json.dumps(data, default=str))
    mutated["sweep"]["samples"] = -1
    yield f"{stem}-sweep-negative-samples", dump(mutated), "sweep"


def _all_cases():
    counter = itertools.count()
    cases = []
    for f in SHIPPED:
        cases += list(_cases_of(f, counter))
    for f in SWEEPS:
        cases += list(_sweep_cases(f))
    return cases


CASES = _all_cases()


def test_the_generated_suite_is_large():
    assert len(CASES) >= 400
    assert {f.stem for f in SHIPPED} <= {c[0].split("-")[0] for c in CASES}


@pytest.mark.parametrize(("name", "text", "key"), CASES, ids=[c[0] for c in CASES])
def test_mutated_problem_file_is_refused(tmp_path, name, text, key):
    f = tmp_path / "problem.yaml"
    f.write_text(text)
    before = snapshot(tmp_path)
    run = run_cli("check", str(f))
    line = assert_refused(run, f, key)
    if "duplicate" in name:
        assert len(re.findall(r"line \d+", line)) == 2, line
    assert snapshot(tmp_path) == before


# -- files that are not files -------------------------------------------------------------------


@pytest.fixture
def specials(tmp_path):
    fifo = tmp_path / "pipe.yaml"
    os.mkfifo(fifo)
    dev = tmp_path / "zero.yaml"
    dev.symlink_to("/dev/zero")
    big = tmp_path / "big.yaml"
    with open(big, "w") as fh:  # 10 MB, sparse: the size is refused before a byte is read
        fh.write("problem: forward_kinematics\n")
        fh.truncate(10 << 20)
    folder = tmp_path / "dir.yaml"
    folder.mkdir()
    latin = tmp_path / "latin.yaml"
    latin.write_bytes(b"problem: forward_kinematics\ndescription: caf\xe9\n")
    return {
        "fifo": (fifo, "named pipe"),
        "device": (dev, "character device"),
        "dev_zero": (Path("/dev/zero"), "character device"),
        "big": (big, "the limit is 1 MiB"),
        "directory": (folder, "directory"),
        "missing": (tmp_path / "missing.yaml", "file not found"),
        "not_utf8": (latin, "expected UTF-8"),
        "dangling": (tmp_path / "nothing.yaml", "file not found"),
    }


COMMANDS = (
    ("check",),
    ("solve",),
    ("solve", "--json"),
    ("sweep",),
    ("export", "--out", "{tmp}/exported"),
)


@pytest.mark.parametrize("special", ["fifo", "device", "dev_zero", "big", "directory", "missing", "not_utf8"])
@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: "-".join(c).replace("{tmp}/", ""))
def test_special_input_files_are_refused_at_once(tmp_path, specials, special, command):
    path, message = specials[special]
    before = snapshot(tmp_path)
    args = [a.replace("{tmp}", str(tmp_path)) for a in command]
    extra = ["-o", str(tmp_path / "r.csv")] if command[0] == "sweep" else []
    run = run_cli(args[0], str(path), *args[1:], *extra)
    assert_refused(run, path, message)
    assert run.out == ""
    assert snapshot(tmp_path) == before


def test_refusing_a_bomb_takes_milliseconds(tmp_path):
    """Not a timing assertion: the limits hold the work to a few thousand values."""
    import time

    f = tmp_path / "bomb.yaml"
    f.write_text(_bombs()[0][1])
    t0 = time.process_time()
    run = run_cli("check", str(f))
    assert_refused(run, f, "values once aliases are expanded")
    assert time.process_time() - t0 < 30  # seconds; the unbounded file takes minutes and gigabytes


def test_long_values_are_cut_in_messages(tmp_path):
    f = tmp_path / "long.yaml"
    f.write_text("problem: " + "x" * 200_000 + "\n")
    line = assert_refused(run_cli("check", str(f)), f, "problem")
    assert "more characters" in line


# -- outputs: never an input, never a special file, never half a file -------------------------

FK = PROBLEMS / "prs3_forward_kinematics.yaml"
SWEEP = PROBLEMS / "sweep_rpr_transmission.yaml"


@pytest.fixture
def problem(tmp_path):
    f = tmp_path / "p.yaml"
    f.write_text(FK.read_text())
    return f


def _targets(tmp_path, problem):
    link_dev = tmp_path / "link_dev.json"
    link_dev.symlink_to("/dev/null")
    link_input = tmp_path / "link_input.json"
    link_input.symlink_to(problem)
    as_dir = tmp_path / "r.json"
    as_dir.mkdir()
    fifo = tmp_path / "fifo.json"
    os.mkfifo(fifo)
    return {
        "the_input": (problem, "input of this command"),
        "link_to_input": (link_input, "input of this command"),
        "link_to_device": (link_dev, "character device"),
        "directory": (as_dir, "is a directory"),
        "fifo": (fifo, "named pipe"),
        "proc": (Path("/proc/r.json"), "cannot write in /proc"),
        "missing_dir": (tmp_path / "no" / "r.json", "does not exist"),
    }


@pytest.mark.parametrize(
    "target", ["the_input", "link_to_input", "link_to_device", "directory", "fifo", "proc", "missing_dir"]
)
@pytest.mark.parametrize("flag", ["-o", "--plot"])
def test_solve_output_is_checked_before_solving(tmp_path, problem, target, flag):
    path, message = _targets(tmp_path, problem)[target]
    if flag == "--plot":
        path = path.with_suffix(".png") if target not in ("the_input", "link_to_input") else path
        if target in ("link_to_device", "directory", "fifo"):
            return  # the same checks; their .png twins do not exist
    before = snapshot(tmp_path)
    run = run_cli("solve", str(problem), flag, str(path))
    if flag == "--plot" and target in ("the_input", "link_to_input"):
        message = "expected a figure file"
    assert_refused(run, path if target not in ("the_input", "link_to_input") or flag == "-o" else flag, message)
    assert snapshot(tmp_path) == before


def test_a_symlink_to_a_regular_file_is_followed(tmp_path, problem):
    real = tmp_path / "real.json"
    real.write_text("old")
    link = tmp_path / "link.json"
    link.symlink_to(real)
    run = run_cli("solve", str(problem), "-o", str(link), "-q")
    assert run.code == 0, run.err
    assert link.is_symlink() and json.loads(real.read_text())["status"] == "solved"


@pytest.mark.parametrize("target", ["the_input", "link_to_device", "directory", "fifo", "proc", "missing_dir"])
def test_reproduce_output_is_checked(tmp_path, problem, target):
    path, message = _targets(tmp_path, problem)[target]
    before = snapshot(tmp_path)
    assert_refused(run_cli("reproduce", str(problem), "-o", str(path)), path, message)
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize(
    ("out", "message"),
    [
        ("/proc/exported", "cannot write in /proc"),
        ("{problem}", "is a file; expected a directory"),
        ("{tmp}/no/such/dir", "does not exist"),
    ],
)
def test_export_out_is_checked(tmp_path, problem, out, message):
    out = out.format(tmp=tmp_path, problem=problem)
    before = snapshot(tmp_path)
    run = run_cli("export", str(problem), "--out", out)
    assert_refused(run, "--out", message)
    assert snapshot(tmp_path) == before


def test_export_never_replaces_its_input(tmp_path):
    folder = tmp_path / "exp"
    folder.mkdir()
    f = folder / "manifest.json"
    f.write_text(FK.read_text())  # a problem file that happens to be named like the manifest
    before = snapshot(tmp_path)
    run = run_cli("export", str(f), "--out", str(folder))
    assert_refused(run, f, "input of this command")
    assert snapshot(tmp_path) == before


def test_export_bad_arguments(tmp_path, problem):
    before = snapshot(tmp_path)
    assert_refused(run_cli("export", str(problem), "--out", str(tmp_path / "e"), "--what", "fk,jacobean"), "--what")
    assert_refused(run_cli("export", str(problem), "--out", str(tmp_path / "e"), "--format", "fortran"), "--format")
    assert snapshot(tmp_path) == before


# -- sweeps -------------------------------------------------------------------------------------


@pytest.fixture
def sweep_file(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text(SWEEP.read_text())
    return f


def test_sweep_onto_another_sweeps_csv_leaves_it_alone(tmp_path, sweep_file):
    other = tmp_path / "other.csv"
    other.write_text('# cpm_nlp sweep {"fingerprint": "0123"}\npoint,status\n0,solved\n1,sol')  # last line cut
    before = snapshot(tmp_path)
    run = run_cli("sweep", str(sweep_file), "-o", str(other))
    assert_refused(run, other, "another sweep")
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize(
    ("args", "key"),
    [
        (["--workers", "0"], "--workers"),
        (["--chunk", "-3"], "--chunk"),
        (["-o", "{tmp}/r.txt"], "-o"),
        (["-o", "/proc/r.csv"], "/proc/r.csv"),
        (["-o", "{tmp}/no/r.csv"], "does not exist"),
        (["--plot", "{tmp}/f.gif"], "--plot"),
        (["--set", "sweep.samples=-1"], "sweep"),
        (["--set", "mechanism.parameters.zzz=1"], "zzz"),
    ],
)
def test_sweep_bad_arguments(tmp_path, sweep_file, args, key):
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    if "-o" not in args:
        args += ["-o", str(tmp_path / "r.csv")]
    before = snapshot(tmp_path)
    assert_refused(run_cli("sweep", str(sweep_file), *args), key)
    assert snapshot(tmp_path) == before


def test_sweep_of_a_file_without_sweep_section(tmp_path, problem):
    before = snapshot(tmp_path)
    assert_refused(run_cli("sweep", str(problem), "-o", str(tmp_path / "r.csv")), problem, "no 'sweep' section")
    assert snapshot(tmp_path) == before


def test_a_journal_cut_in_its_first_line_is_resumed(tmp_path):
    """A crash while writing the journal's first line leaves nothing solved:
    the sweep starts again (it was exit 70)."""
    pytest.importorskip("pyarrow")
    from cpm_nlp.io.results import journal_path, open_store, read_results
    from cpm_nlp.problems.file import load_problem
    from cpm_nlp.sweep.run import columns, job_of, metadata

    problem = load_problem(SWEEP)
    job = job_of(problem)
    out = tmp_path / "r.parquet"
    journal_path(out).write_text('{"fingerprint": "ab')  # cut by the crash
    store = open_store(out, metadata(problem, job), columns(job))
    assert store.done == {}
    record = {c: None for c in columns(job)} | {"point": 0, "status": "solved", "message": "", "seconds": 0.1}
    store.append([record], {}, {})
    store.close()
    table = read_results(out)
    assert [r["point"] for r in table.rows] == [0]


def test_a_journal_damaged_in_the_middle_is_named(tmp_path):
    pytest.importorskip("pyarrow")
    from cpm_nlp.io.results import journal_path

    out = tmp_path / "r.parquet"
    journal_path(out).write_text('{"fingerprint": "ab"}\n{"point": 0, "status": "solved"}\nnot json\n{"point": 1}\n')
    before = snapshot(tmp_path)
    run = run_cli("plot", str(out), "-o", str(tmp_path / "f.png"))
    assert_refused(run, journal_path(out), "line 3")
    assert snapshot(tmp_path) == before


# -- plot ---------------------------------------------------------------------------------------

_META = '# cpm_nlp sweep {"problem": "rpr_transmission_map", "mechanism": "rpr", "parameters": [], "values": []}\n'

PLOT_INPUTS = {
    "json_list": ("r.json", "[1, 2, 3]", "expected a cpm-nlp result"),
    "json_number": ("r.json", "42", "expected a cpm-nlp result"),
    "json_values_not_mapping": ("r.json", '{"problem": "x", "values": 1}', "expected a cpm-nlp result"),
    "json_garbage": ("r.json", "{not json", "expected a JSON result"),
    "json_empty": ("r.json", "", "expected a JSON result"),
    "json_unknown_kind": ("r.json", '{"problem": "zzz", "status": "solved", "values": {}}', "no plot is known"),
    "csv_no_meta": ("r.csv", "point,status\n0,solved\n", "not a cpm_nlp sweep results file"),
    "csv_bad_meta": ("r.csv", "# cpm_nlp sweep {oops\npoint,status\n", "metadata line"),
    "csv_meta_not_mapping": ("r.csv", "# cpm_nlp sweep [1]\npoint,status\n", "metadata line"),
    "csv_bad_point": ("r.csv", _META + "point,status,message,seconds\nzero,solved,,1\n", "line 3"),
    "csv_short_row": ("r.csv", _META + "point,status,message,seconds\n0,solved\n", "line 3"),
    "csv_long_row": ("r.csv", _META + "point,status,message,seconds\n0,solved,,1,7,8\n", "line 3"),
    "parquet_garbage": ("r.parquet", "PAR1 not really", "not a readable Parquet file"),
}


@pytest.mark.parametrize("case", sorted(PLOT_INPUTS))
def test_plot_of_a_bad_results_file(tmp_path, case):
    if case.startswith("parquet"):
        pytest.importorskip("pyarrow")
    pytest.importorskip("matplotlib")
    name, text, message = PLOT_INPUTS[case]
    f = tmp_path / name
    f.write_text(text)
    before = snapshot(tmp_path)
    run = run_cli("plot", str(f), "-o", str(tmp_path / "fig.png"))
    assert_refused(run, f, message)
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("special", ["fifo", "device", "dev_zero", "directory", "missing"])
def test_plot_of_a_special_file(tmp_path, specials, special):
    pytest.importorskip("matplotlib")
    path, message = specials[special]
    if special in ("fifo", "device", "directory", "missing"):
        renamed = path.with_name(path.stem + ".json")
        path.rename(renamed) if path.exists() or path.is_symlink() else None
        path = renamed
    before = snapshot(tmp_path)
    assert_refused(run_cli("plot", str(path), "-o", str(tmp_path / "f.png")), path, message)
    assert snapshot(tmp_path) == before


def test_plot_onto_its_input_or_a_bad_figure_name(tmp_path):
    pytest.importorskip("matplotlib")
    f = tmp_path / "r.json"
    f.write_text('{"problem": "forward_kinematics", "status": "solved", "values": {}}')
    before = snapshot(tmp_path)
    assert_refused(run_cli("plot", str(f), "-o", str(f)), "-o", "expected a figure file")
    assert_refused(run_cli("plot", str(f), "-o", "/proc/f.png"), "/proc/f.png", "cannot write")
    assert_refused(run_cli("plot", str(f), "-o", str(tmp_path / "f.png"), "--type", "mapp"), "--type", "did you mean")
    assert snapshot(tmp_path) == before


# -- reproduce, describe, the command line ------------------------------------------------------


def test_reproduce_value_typo_is_bad_input(tmp_path):
    f = tmp_path / "r.yaml"
    f.write_text(
        FK.read_text()
        + "reproduce:\n  paper: test\n  rows:\n    - {quantity: pz, source: none, published: 109 mm, value: pzz,"
        " tolerance: 0.5 mm}\n"
    )
    before = snapshot(tmp_path)
    line = assert_refused(run_cli("reproduce", str(f)), f, "reproduce.rows[0].value")
    assert "did you mean 'pz'" in line
    assert_refused(run_cli("check", str(f)), f, "did you mean 'pz'")
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize(
    ("argv", "key"),
    [
        (["describe", "prs4"], "did you mean 'prs3'"),
        (["solve", "{p}", "--set", "inputs.s1"], "--set"),
        (["solve", "{p}", "--set", "inputs.s1=1e30 mm"], "inputs.s1"),
        (["solve", "{p}", "--set", "inputs.s1=.nan"], "inputs.s1"),
        (["solve", "{p}", "--set", "mechanism.parameters.alpha0=1e30 rad"], "mechanism.parameters.alpha0"),
        (["solve", "{p}", "--set", "solver=newton", "--set", "solver.options.ipopt.max_iter=5"], "did you mean"),
        (["check", "{p}", "--set", "solver.options.ipopt.tol=0"], "solver.options.ipopt.tol"),
        (["check", "{p}", "--set", "zzz=1"], "zzz"),
    ],
)
def test_command_line_mistakes(tmp_path, problem, argv, key):
    argv = [a.replace("{p}", str(problem)) for a in argv]
    before = snapshot(tmp_path)
    assert_refused(run_cli(*argv), key)
    assert snapshot(tmp_path) == before


def test_an_absurd_angle_is_not_solved(tmp_path):
    f = tmp_path / "ik.yaml"
    f.write_text((PROBLEMS / "prs3_inverse_kinematics.yaml").read_text())
    for value in ("1e30 rad", "1e30 deg", "13 rad", "-800 deg"):  # beyond two turns
        assert_refused(run_cli("check", str(f), "--set", f"inputs.psi={value}"), f, "inputs.psi")


# -- a few cases in a subprocess: file descriptor 1, a real terminal signal --------------------


def _cpm(*args, **kwargs):
    return subprocess.run(
        [sys.executable, "-m", "cpm_nlp", *args], capture_output=True, text=True, timeout=300, **kwargs
    )


def test_json_stdout_is_one_document_whatever_ipopt_prints(tmp_path, problem):
    """The verbose preset prints IPOPT's log, and a bad enum value its option
    documentation, through the C library's stdout; --json stdout stays JSON."""
    run = _cpm("solve", str(problem), "--json", "--set", "solver=ipopt_verbose")
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout)["status"] == "solved"
    assert "Ipopt" in run.stderr  # the log went to stderr
    run = _cpm("solve", str(problem), "--json", "--set", "solver.options.ipopt.mu_oracle=bogus")
    assert run.returncode == 2 and run.stdout == ""
    assert run.stderr.splitlines()[-1].startswith(f"error: {problem}: solver.options.ipopt.mu_oracle")


def test_json_of_a_failed_solve_is_json(tmp_path, problem):
    run = run_cli("solve", str(problem), "--json", "--set", "solver.options.ipopt.max_iter=0")
    assert run.code == 1
    assert json.loads(run.out)["status"] != "solved"


# -- slow failures, Ctrl-C -------------------------------------------------------------------------


def test_a_closed_scheduler_port_fails_fast_with_a_message(tmp_path, sweep_file, monkeypatch):
    pytest.importorskip("distributed")
    import cpm_nlp.sweep.run

    monkeypatch.setattr(cpm_nlp.sweep.run, "CONNECT_SECONDS", 0.5)
    before = snapshot(tmp_path)
    run = run_cli("sweep", str(sweep_file), "-o", str(tmp_path / "r.csv"), "-q", "--scheduler", "tcp://127.0.0.1:1")
    line = assert_refused(run, "--scheduler", "cannot connect to the Dask scheduler tcp://127.0.0.1:1 within 0.5 s")
    assert "is it running" in line
    assert snapshot(tmp_path) == before


def test_worker_processes_ignore_ctrl_c():
    """Processes started while the local cluster starts inherit 'ignore SIGINT'
    (Python then installs no KeyboardInterrupt handler): a Ctrl-C to the
    process group reaches the sweep, not the workers' tracebacks."""
    from cpm_nlp.sweep.run import _ctrl_c_ignored

    probe = (
        "import os, signal; "
        "print(signal.getsignal(signal.SIGINT) == signal.SIG_IGN, os.environ.get('DASK_LOGGING__DISTRIBUTED'))"
    )
    with _ctrl_c_ignored():
        inside = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout
    outside = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout
    assert inside.split() == ["True", "error"]
    import signal

    ignored_here = signal.getsignal(signal.SIGINT) == signal.SIG_IGN  # e.g. a background job of a script
    assert outside.split() == [str(ignored_here), "None"]


def test_batch_progress_is_reported_to_whoever_asks():
    import time

    from cpm_nlp.core import progress

    seen = []
    with progress.reporting(lambda what, done, total: seen.append((what, done, total))):
        for _ in progress.track(range(3), "forward kinematics"):
            time.sleep(progress.INTERVAL)
    assert seen[-1] == ("forward kinematics", 3, 3) and len(seen) >= 2
    assert list(progress.track(range(3), "nobody asks")) == [0, 1, 2]


def test_batch_progress_on_a_terminal_only(problem):
    import argparse
    import io

    from cpm_nlp.cli.bars import progress_bars as _progress_bars

    class Tty(io.StringIO):
        def isatty(self):
            return True

    assert _progress_bars(argparse.Namespace(quiet=False, err=io.StringIO())) is None
    assert _progress_bars(argparse.Namespace(quiet=True, err=Tty())) is None
    err = Tty()
    show = _progress_bars(argparse.Namespace(quiet=False, err=err))
    show("forward kinematics", 50_000, 100_000)
    assert "forward kinematics:  50%" in err.getvalue() and "50000/100000" in err.getvalue()
    assert " poses" in err.getvalue()


def test_a_sweep_that_ran_but_cannot_plot_exits_1(tmp_path, sweep_file, monkeypatch):
    """The solve succeeded: a plot that cannot be drawn afterwards is a failure
    (exit 1, one message), not bad input (it was exit 2)."""
    pytest.importorskip("matplotlib")
    import cpm_nlp.sweep.run
    from cpm_nlp.sweep.run import SweepSummary

    out = tmp_path / "r.csv"
    out.write_text("# cpm_nlp sweep {}\n")  # a results file the plot cannot use
    monkeypatch.setattr(
        cpm_nlp.sweep.run,
        "run_sweep",
        lambda problem, output, **kw: SweepSummary(str(output), 1, {"solved": 1}, 1, 0.1, 1),
    )
    fig = tmp_path / "f.png"
    run = run_cli("sweep", str(sweep_file), "-o", str(out), "-q", "--plot", str(fig))
    assert run.code == 1
    lines = run.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: no plot written: ") and str(out) in lines[0], run.err
    assert not fig.exists()
