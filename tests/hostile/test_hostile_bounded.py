"""Hostile input, bounded: files that are huge, endless or never written, a reader
that goes away, a mechanism that repeats a leg 20 000 times, Ctrl-C in a long
search, and the smaller refusals of issue 19 (YAML key paths, ``--type``,
sidecar data files, standard input and pipes).

Each refusal asserts: the exit status, one message line, no traceback,
nothing written and no file changed, and that it did not hang (``HANG_S``,
in-process; the subprocess cases allow for the interpreter's start-up).  The
1 s target itself is measured by benchmarks/bench_hostile.py.
"""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.conftest import PROBLEMS, run_cli
from tests.hostile.test_hostile import HANG_S, assert_refused, dump

FK = PROBLEMS / "prs3_forward_kinematics.yaml"
MECHANISM = PROBLEMS / "mechanisms" / "delta.yaml"
CLI = [sys.executable, "-m", "cpm_nlp.cli"]
#: a subprocess's own start-up (Python, NumPy, CasADi) on a loaded machine, on top of the 1 s
STARTUP = 30.0


def snapshot(folder: Path) -> dict[str, str]:
    """As :func:`tests.hostile.test_hostile.snapshot`, but a file over 1 MiB (a sparse file of
    these tests) is known by its size and modification time: hashing it would read it."""
    out = {}
    for p in sorted(folder.rglob("*")):
        if p.is_symlink():
            out[str(p)] = "-> " + os.readlink(p)
        elif p.is_fifo():
            out[str(p)] = "fifo"
        elif p.is_file():
            st = p.stat()
            big = st.st_size > 1 << 20
            out[str(p)] = f"{st.st_size} bytes, {st.st_mtime_ns}" if big else hashlib.sha256(p.read_bytes()).hexdigest()
        elif p.is_dir():
            out[str(p)] = "dir"
    return out


def timed(*argv: str):
    t0 = time.perf_counter()
    run = run_cli(*argv)
    return run, time.perf_counter() - t0


def refused_fast(tmp_path: Path, *argv: str, names, key: str | None = None, code: int = 2) -> str:
    before = snapshot(tmp_path)
    run, seconds = timed(*argv)
    line = assert_refused(run, names, key, code)
    assert seconds < HANG_S, seconds
    assert snapshot(tmp_path) == before
    return line


def cli_process(*argv: str, cwd: Path, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run([*CLI, *argv], cwd=cwd, capture_output=True, text=True, timeout=STARTUP + 30, **kwargs)


@pytest.fixture
def problem(tmp_path):
    target = tmp_path / "p.yaml"
    target.write_text(FK.read_text())
    return target


# -- files that are not what they seem --------------------------------------------------------


@pytest.mark.parametrize("command", ["describe", "solve", "check"])
def test_a_16_gb_sparse_file_is_refused_before_it_is_read(tmp_path, command):
    big = tmp_path / "big.yaml"
    subprocess.run(["truncate", "-s", "16G", str(big)], check=True)
    line = refused_fast(tmp_path, command, str(big), names=big)
    assert "16 GiB" in line and "1 MiB" in line


@pytest.mark.parametrize("command", ["describe", "solve"])
def test_a_symbolic_link_to_dev_zero_is_refused(tmp_path, command):
    link = tmp_path / "zero.yaml"
    link.symlink_to("/dev/zero")
    line = refused_fast(tmp_path, command, str(link), names=link)
    assert "character device" in line


@pytest.mark.parametrize("command", ["describe", "solve"])
def test_a_fifo_nobody_writes_to_is_refused_at_once(tmp_path, command):
    """The FIFO is opened without blocking; with no writer there is nothing to read.
    Run in a subprocess so that a hang fails the test (timeout) instead of blocking it."""
    fifo = tmp_path / "f.yaml"
    os.mkfifo(fifo)
    before = snapshot(tmp_path)
    t0 = time.perf_counter()
    run = cli_process(command, str(fifo), cwd=tmp_path)
    assert time.perf_counter() - t0 < STARTUP
    assert run.returncode == 2, run.stderr
    assert run.stderr.splitlines() == [f"error: {fifo}: a named pipe that no program writes to; nothing to read"]
    assert snapshot(tmp_path) == before


def test_a_fifo_with_a_writer_is_read_as_the_problem_file(tmp_path):
    fifo = tmp_path / "f.yaml"
    os.mkfifo(fifo)
    proc = subprocess.Popen([*CLI, "solve", str(fifo), "--json"], cwd=tmp_path, stdout=subprocess.PIPE, text=True)
    with open(fifo, "w") as fh:  # blocks until the CLI opens the FIFO; then the CLI reads to the end
        fh.write(FK.read_text().replace("solver: ipopt", "solver: newton"))
    out, _ = proc.communicate(timeout=STARTUP + 30)
    assert proc.returncode == 0 and '"status": "solved"' in out


def test_a_pipe_larger_than_the_limit_is_refused_without_reading_it_all(tmp_path):
    """/dev/zero through a pipe (cat): at most the limit + 1 bytes are read."""
    run = subprocess.run(
        ["bash", "-c", f"cat /dev/zero | {' '.join(CLI)} solve -"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=STARTUP + 30,
    )
    assert run.returncode == 2
    assert run.stderr.splitlines() == ["error: <stdin>: more than the limit of 1 MiB was written to the pipe"]


# -- standard input and process substitution --------------------------------------------------


def test_solve_dash_reads_the_problem_from_standard_input(tmp_path):
    text = FK.read_text().replace("solver: ipopt", "solver: newton")
    run = cli_process("solve", "-", "--json", cwd=tmp_path, input=text)
    assert run.returncode == 0, run.stderr
    assert '"status": "solved"' in run.stdout and run.stderr == ""


def test_a_terminal_or_a_device_on_standard_input_is_refused(tmp_path):
    with open(os.devnull) as null:
        run = subprocess.run(
            [*CLI, "solve", "-"], cwd=tmp_path, stdin=null, capture_output=True, text=True, timeout=STARTUP + 30
        )
    assert run.returncode == 2
    assert run.stderr.splitlines() == [
        "error: <stdin>: expected a pipe or a file on standard input, got a character device"
    ]


def test_stdin_problem_errors_name_stdin_and_relative_paths_resolve_in_the_cwd(tmp_path):
    data = yaml.safe_load(FK.read_text())
    data["mechanism"] = {"file": "m.yaml"}  # not in the cwd: an error naming the cwd's file
    run = cli_process("check", "-", cwd=tmp_path, input=dump(data))
    assert run.returncode == 2
    assert run.stderr.splitlines() == [
        f"error: <stdin>: mechanism.file: mechanism file not found: {tmp_path.resolve() / 'm.yaml'}"
    ]


def test_process_substitution_is_read_like_a_file(tmp_path):
    problem = tmp_path / "p.yaml"
    problem.write_text(FK.read_text().replace("solver: ipopt", "solver: newton"))
    run = subprocess.run(
        ["bash", "-c", f"{' '.join(CLI)} solve <(cat p.yaml) --json"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=STARTUP + 30,
    )
    assert run.returncode == 0, run.stderr
    assert '"status": "solved"' in run.stdout
    mech = subprocess.run(
        ["bash", "-c", f"{' '.join(CLI)} describe <(cat {MECHANISM})"],
        capture_output=True,
        text=True,
        timeout=STARTUP + 30,
    )
    assert mech.returncode == 0 and mech.stdout.startswith("delta:"), mech.stderr


def test_the_output_checks_hold_for_a_problem_on_standard_input(tmp_path, problem):
    refused_fast(tmp_path, "solve", str(problem), "-o", str(problem), names=problem, key="-o")
    run = cli_process("solve", "-", "-o", "r.json", cwd=tmp_path, input=problem.read_text())
    assert run.returncode == 0, run.stderr
    assert '"status": "solved"' in (tmp_path / "r.json").read_text()


# -- a reader that goes away ------------------------------------------------------------------


def test_describe_into_head_exits_quietly(tmp_path):
    """``head -n 0`` exits before cpm-nlp writes: the write meets a closed pipe (EPIPE)."""
    run = subprocess.run(
        ["bash", "-c", f"{' '.join(CLI)} describe | head -n 0; echo status=${{PIPESTATUS[0]}}"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=STARTUP + 30,
    )
    assert run.stdout.splitlines() == ["status=141"]
    assert run.stderr == ""


def test_a_closed_stdout_through_a_subprocess_pipe(tmp_path):
    proc = subprocess.Popen([*CLI, "describe", "prs3"], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # before it writes anything
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=STARTUP + 30) == 141
    assert err == ""


# -- limits of mechanism files -----------------------------------------------------------------


def _mechanism(tmp_path: Path, edit) -> Path:
    data = yaml.safe_load(MECHANISM.read_text())
    data.pop("examples", None)
    edit(data)
    target = tmp_path / "m.yaml"
    target.write_text(dump(data))
    return target


def test_a_leg_repeated_20000_times_is_refused_at_once(tmp_path):
    assert run_cli("describe", str(MECHANISM)).code == 0  # the imports of describe, not timed
    target = _mechanism(tmp_path, lambda d: d["legs"][0]["repeat"].update(values=list(range(1, 20_001))))
    line = refused_fast(tmp_path, "describe", str(target), names=target, key="legs[0].repeat.values")
    assert "20000 legs" in line and "at most 64" in line


def test_too_many_joints_in_a_leg_and_in_all(tmp_path):
    def long_leg(d):
        d["legs"][0]["joints"] = d["legs"][0]["joints"] * 20

    target = _mechanism(tmp_path, long_leg)
    line = refused_fast(tmp_path, "describe", str(target), names=target, key="legs[0].joints")
    assert "40 joints in one leg; at most 32" in line

    def many_legs(d):
        leg = d["legs"][0]
        leg["joints"] = leg["joints"] * 15  # 30 joints, 3 legs each
        d["legs"] = [dict(leg, name=f"arm{k}_") for k in range(6)]

    target = _mechanism(tmp_path, many_legs)
    line = refused_fast(tmp_path, "describe", str(target), names=target, key="legs[5].repeat.values")
    assert "540 joints in all legs" in line and "at most 512" in line


def test_an_expression_nested_too_deeply_or_too_long(tmp_path):
    target = _mechanism(tmp_path, lambda d: d["derived"].update(deep="(" * 40 + "1" + ")" * 40))
    line = refused_fast(tmp_path, "describe", str(target), names=target)
    assert "nested more than 32 deep" in line
    target = _mechanism(tmp_path, lambda d: d["derived"].update(long="+".join(["1"] * 1500)))
    line = refused_fast(tmp_path, "describe", str(target), names=target)
    assert "at most 2000" in line


# -- YAML errors name the key path -------------------------------------------------------------


def test_a_duplicate_key_names_its_key_path(tmp_path):
    target = tmp_path / "dup.yaml"
    target.write_text(FK.read_text().replace("  s2: 0.5 mm\n", "  s2: 0.5 mm\n  s2: 0.7 mm\n"))
    line = refused_fast(tmp_path, "check", str(target), names=target, key="inputs.s2")
    assert "duplicate key 's2'" in line and "line" in line and "column" in line


def test_an_alias_bomb_names_its_key_path(tmp_path):
    lines = FK.read_text().splitlines() + ["description:", '  a: &a ["lol","lol","lol","lol","lol","lol","lol","lol"]']
    prev = "a"
    for name in "bcdefghi":
        lines.append(f"  {name}: &{name} [" + ", ".join([f"*{prev}"] * 9) + "]")
        prev = name
    target = tmp_path / "bomb.yaml"
    target.write_text("\n".join(line for line in lines if not line.startswith("description: 3-PRS")) + "\n")
    line = refused_fast(tmp_path, "check", str(target), names=target, key="description.")
    assert "values once aliases are expanded" in line


def test_too_many_aliases_name_the_key_path(tmp_path):
    anchors = [f"    - &a{i} 1" for i in range(101)]
    refs = [f"    - *a{i}" for i in range(101)]
    target = tmp_path / "aliases.yaml"
    text = "problem: forward_kinematics\ninputs:\n  x:\n" + "\n".join(anchors) + "\n  y:\n" + "\n".join(refs)
    target.write_text(text)
    line = refused_fast(tmp_path, "check", str(target), names=target, key="inputs.y[100]")
    assert "more than 100 aliases" in line


# -- --type before the solve -------------------------------------------------------------------


def test_an_unknown_plot_type_is_refused_before_the_solve(tmp_path, problem):
    line = refused_fast(
        tmp_path, "solve", str(problem), "--plot", str(tmp_path / "out.png"), "--type", "pie", names="--type"
    )
    assert "unknown plot type 'pie'" in line and "workspace" in line
    line = refused_fast(
        tmp_path, "solve", str(problem), "--plot", str(tmp_path / "out.png"), "--type", "workspce", names="--type"
    )
    assert "did you mean 'workspace'" in line


# -- sidecar data files ------------------------------------------------------------------------


def _batch(tmp_path: Path, data) -> Path:
    doc = yaml.safe_load(FK.read_text())
    doc["inputs"] = {"data": data}
    doc["solver"] = "newton"
    target = tmp_path / "batch.yaml"
    target.write_text(dump(doc))
    return target


def test_a_100000_pose_batch_comes_from_a_data_file(tmp_path):
    rng = np.random.default_rng(0)
    q = rng.uniform(-2e-3, 2e-3, (100_000, 3))
    with open(tmp_path / "poses.csv", "w") as fh:
        fh.write("s1 [m], s2, s3 [mm]\n")
        np.savetxt(fh, q * [1, 1, 1e3], delimiter=",")
    np.save(tmp_path / "poses.npy", q)
    csv = run_cli("solve", str(_batch(tmp_path, "poses.csv")))
    assert csv.code == 0, csv.err
    assert "all 100000 points solved" in csv.out
    npy = run_cli("check", str(_batch(tmp_path, {"file": "poses.npy", "columns": ["s1", "s2", "s3"]})))
    assert npy.code == 0, npy.err


def test_a_parquet_data_file(tmp_path):
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq

    pq.write_table(pa.table({"s1": [0.0, 1e-3], "s2": [0.0, 5e-4], "s3": [0.0, -3e-4]}), tmp_path / "q.parquet")
    run = run_cli("solve", str(_batch(tmp_path, "q.parquet")), "--json")
    assert run.code == 0, run.err


@pytest.mark.parametrize(
    ("setup", "data", "expected"),
    [
        (lambda t: (t / "q.csv").write_text("s1,s2,s3\n0,0,nan\n"), "q.csv", "row 1, column 's3': expected a finite"),
        (lambda t: (t / "q.csv").write_text("s1,s2,s3\n0,0,root:x\n"), "q.csv", "column 's3': expected a number"),
        (lambda t: (t / "q.csv").write_text("s1,s2,s_3\n0,0,0\n"), "q.csv", "did you mean 's3'"),
        (lambda t: (t / "q.csv").write_text("s1,s2,s1\n0,0,0\n"), "q.csv", "named twice"),
        (lambda t: np.save(t / "q.npy", np.zeros((3, 2))), {"file": "q.npy", "columns": ["s1", "s2", "s3"]}, "(3, 2)"),
        (lambda t: None, "/etc/passwd.csv", "relative to the problem file's folder"),
        (lambda t: None, "../q.csv", "without '..'"),
        (lambda t: (t / "q.csv").symlink_to("/etc/hostname"), "q.csv", "leads out of the problem file's folder"),
        (lambda t: os.mkfifo(t / "q.csv"), "q.csv", "expected a regular file, got a named pipe"),
        (lambda t: (t / "q.csv").symlink_to("/dev/zero"), "q.csv", "leads out of the problem file's folder"),
        (lambda t: None, "q.txt", "expected a data file ending in .csv, .npy, .parquet"),
    ],
)
def test_a_bad_data_file_is_refused_with_row_and_column(tmp_path, setup, data, expected):
    setup(tmp_path)
    target = _batch(tmp_path, data)
    line = refused_fast(tmp_path, "check", str(target), names=target, key="inputs.data")
    assert expected in line
    assert "root:x" not in line  # the file's content is never echoed


def test_a_sparse_data_file_over_the_limit(tmp_path):
    subprocess.run(["truncate", "-s", "300M", str(tmp_path / "q.csv")], check=True)
    line = refused_fast(tmp_path, "check", str(_batch(tmp_path, "q.csv")), names="batch.yaml", key="inputs.data")
    assert "300 MiB" in line and "256 MiB" in line


# -- Ctrl-C in a long search -------------------------------------------------------------------


def _long_search(tmp_path: Path) -> subprocess.Popen:
    problem = tmp_path / "p.yaml"
    problem.write_text(FK.read_text())
    proc = subprocess.Popen(
        [*CLI, "solve", "p.yaml", "--set", "inputs.assembly_modes=all", "--set", "inputs.mode_starts=1000000"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        # Ctrl-C as at a terminal: a test run started as a background job of a script (bash
        # "cmd &", a CI runner) has SIGINT ignored, the child would inherit it, and the CLI
        # rightly keeps an inherited "ignore" (cli.main.main_entry)
        preexec_fn=_sigint_default,
    )
    return proc


def _sigint_default() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _wait_for_the_search(proc: subprocess.Popen) -> None:
    """Until the process runs the search: its threads are busy (a few seconds after start-up)."""
    deadline = time.monotonic() + STARTUP
    while time.monotonic() < deadline:
        threads = len(os.listdir(f"/proc/{proc.pid}/task")) if os.path.exists(f"/proc/{proc.pid}/task") else 0
        if threads > 1 and _cpu_seconds(proc.pid) > 3.0:
            return
        time.sleep(0.2)
    raise AssertionError("the search did not start")


def _cpu_seconds(pid: int) -> float:
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


@pytest.mark.parametrize("presses", [1, 2])
def test_ctrl_c_in_the_mode_search_exits_130_within_a_second(tmp_path, presses):
    proc = _long_search(tmp_path)
    try:
        _wait_for_the_search(proc)
        t0 = time.perf_counter()
        for _ in range(presses):
            os.killpg(proc.pid, signal.SIGINT)
            time.sleep(0.05)
        out, err = proc.communicate(timeout=10)
        seconds = time.perf_counter() - t0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    assert seconds < HANG_S, seconds
    assert err.splitlines() == ["interrupted"], err
    assert "Traceback" not in err and out == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.yaml"]


def test_the_search_in_process_reports_progress_and_stops_between_chunks():
    """The library side: the assembly-mode search reports through cpm_nlp.core.progress,
    and a KeyboardInterrupt raised from that report (as Ctrl-C would) stops it at once."""
    from cpm_nlp.analysis.assembly import assembly_modes
    from cpm_nlp.core import progress
    from cpm_nlp.problems.file import load_problem

    problem = load_problem(FK)
    seen = []

    def report(what, done, total):
        seen.append((what, done, total))
        if what == "assembly-mode search" and done < total:
            raise KeyboardInterrupt

    t0 = time.perf_counter()
    with progress.reporting(report), pytest.raises(KeyboardInterrupt):
        assembly_modes(problem.model, problem.model.q_home, problem.solver, starts=1_000_000)
    assert time.perf_counter() - t0 < 5.0
    assert seen and seen[0][0] == "assembly-mode search" and seen[0][2] == 1_000_000
