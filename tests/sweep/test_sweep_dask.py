"""Sweeps on a real Dask LocalCluster (two worker processes): results match
in-process solves, failed points are recorded, an interrupted sweep resumes
without solving anything twice, a worker that dies is retried, the CLI runs
on a local default cluster and on an existing scheduler."""

from __future__ import annotations

import os
import signal

import pytest

import cpm_nlp as cn
from cpm_nlp.io.results import read_results
from cpm_nlp.sweep.run import job_of, run_sweep, solve_points
from tests.conftest import PROBLEMS
from tests.figure_checks import assert_png_drawn

distributed = pytest.importorskip("distributed")

MAP = """\
problem: joint_requirements
mechanism:
  type: prs3
  parameters: {b: 47.91 mm, L: 109.215 mm, alpha0: 45 deg}
inputs: {dz: [-2 mm, 0 mm, 2 mm], psi: [-0.2 deg, 0.2 deg], theta: [-0.2 deg, 0.2 deg]}
outputs: {values: [s_min, s_max, dalpha_max]}
sweep:
  parameters:
    mechanism.parameters.b: {from: 30 mm, to: 60 mm, count: 4}
    mechanism.parameters.L: {from: 90 mm, to: 130 mm, count: 5}
"""

STATUSES = """\
problem: inverse_kinematics
mechanism:
  type: prs3
  parameters: {b: 47.91 mm, L: 109.215 mm}
  limits: {s: [-1.5 mm, 1.5 mm]}
inputs: {dz: 0 mm, psi: 0 deg, theta: 0 deg}
outputs: {values: [s1, s2, s3]}
sweep:
  parameters:
    inputs.dz: [0 mm, 1 mm, 2 mm, 150 mm]
    inputs.psi: [0 deg, 0.1 deg]
"""


@pytest.fixture(scope="module")
def cluster():
    with (
        distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cl,
        distributed.Client(cl) as client,
    ):
        yield cl, client


def problem_of(tmp_path, text, name="s.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return cn.load_problem(path)


def test_sweep_on_two_worker_processes_matches_in_process_solves(cluster, tmp_path):
    _, client = cluster
    assert len(client.scheduler_info()["workers"]) == 2
    problem = problem_of(tmp_path, MAP)
    out = tmp_path / "map.parquet"
    seen = []
    summary = run_sweep(problem, out, client=client, progress=lambda d, t: seen.append((d, t)))
    assert summary.ok and summary.total == 20 and summary.solved_now == 20 and summary.statuses == {"solved": 20}
    assert seen[0] == (0, 20) and seen[-1] == (20, 20) and [d for d, _ in seen] == sorted(d for d, _ in seen)
    rows = read_results(out).rows
    assert [r["point"] for r in rows] == list(range(20))
    expected = solve_points(job_of(problem), range(20))["records"]
    for got, want in zip(rows, expected):  # every value bit for bit as solved in this process
        assert {k: got[k] for k in ("s_min", "s_max", "dalpha_max", "mechanism.parameters.b")} == {
            k: want[k] for k in ("s_min", "s_max", "dalpha_max", "mechanism.parameters.b")
        }
    pids = set(client.run(os.getpid).values())
    assert len(pids) == 2 and os.getpid() not in pids  # the points were solved in two other processes


def test_failed_points_are_recorded_not_dropped(cluster, tmp_path):
    _, client = cluster
    out = tmp_path / "st.csv"
    summary = run_sweep(problem_of(tmp_path, STATUSES), out, client=client, chunk_size=3)
    assert not summary.ok and summary.total == 8
    rows = {(r["inputs.dz"], r["inputs.psi"]): r for r in read_results(out).rows}
    assert len(rows) == 8
    assert rows[(0.0, 0.0)]["status"] == "solved" and rows[(0.0, 0.0)]["s1"] == pytest.approx(0.0, abs=1e-12)
    assert rows[(0.002, 0.0)]["status"] == "outside_joint_limits"
    assert rows[(0.002, 0.0)]["message"].startswith("the pose needs a joint outside its declared limits: s1 = 0.00")
    assert rows[(0.15, 0.0)]["status"] == "unreachable" and rows[(0.15, 0.0)]["s1"] is None
    assert summary.statuses == {"solved": 4, "outside_joint_limits": 2, "unreachable": 2}


def test_interrupted_sweep_resumes_without_solving_twice(cluster, tmp_path):
    _, client = cluster
    problem = problem_of(tmp_path, MAP)
    out = tmp_path / "map.csv"

    def interrupt(done, total):
        if done >= 5:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_sweep(problem, out, client=client, chunk_size=2, progress=interrupt)
    first = {r["point"]: r for r in read_results(out).rows}
    assert 5 <= len(first) < 20
    summary = run_sweep(problem, out, client=client)
    assert summary.ok and summary.solved_now == 20 - len(first)
    rows = read_results(out).rows
    assert sorted(r["point"] for r in rows) == list(range(20))  # each point once
    for r in rows:
        if r["point"] in first:
            assert r == first[r["point"]]  # kept as written, not solved again (same seconds)
    again = run_sweep(problem, out, client=client)
    assert again.solved_now == 0 and again.ok and again.workers == 0  # nothing left: no task at all


def _kill_a_busy_worker(client, killed):
    """A progress callback: at the first result at which a worker is processing a task,
    SIGKILL that worker."""

    def callback(done, total):
        if done == 0 or killed:
            return
        busy = [w for w, keys in client.processing().items() if keys]
        pids = client.run(os.getpid, workers=busy[:1]) if busy else {}
        if not pids:  # no worker busy at this instant (both just finished): try at the next result
            return
        victim = next(iter(pids.values()))
        os.kill(victim, signal.SIGKILL)
        killed.append(victim)

    return callback


def test_a_worker_that_dies_is_retried_and_the_sweep_completes(tmp_path):
    problem = problem_of(tmp_path, MAP)
    out = tmp_path / "map.parquet"
    with (
        distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cl,
        distributed.Client(cl) as client,
    ):
        killed = []
        summary = run_sweep(problem, out, client=client, chunk_size=2, progress=_kill_a_busy_worker(client, killed))
        client.wait_for_workers(2, timeout=30)
        after = set(client.run(os.getpid).values())
    assert killed and killed[0] not in after  # the worker died (its nanny started a new process)
    assert summary.ok and summary.statuses == {"solved": 20}
    assert sorted(r["point"] for r in read_results(out).rows) == list(range(20))


def _die_once_at_point(point, marker):
    """A function for ``client.run``: in each worker process, solving ``point`` kills
    that process (SIGKILL, while its task runs), the first time in the cluster only
    (``marker``, created atomically, says it happened)."""

    def install():
        import cpm_nlp.sweep.run as run

        solve = run.solve_point

        def solve_point(job, k):
            if k == point:
                try:
                    os.close(os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
                except FileExistsError:
                    return solve(job, k)
                os.kill(os.getpid(), signal.SIGKILL)
            return solve(job, k)

        run.solve_point = solve_point

    return install


def test_a_task_that_fails_beyond_the_retries_is_split_into_points(tmp_path, caplog):
    """With no retry allowed, the task of the killed worker fails (KilledWorker): its
    points are solved one by one, none is lost.

    The worker dies inside the task, while it solves point 5 (of the task of points
    4-7).  Killing a worker from the progress callback instead was a race: the worker
    could finish its last task between "it is busy" and the kill; its result then lived
    on the dead worker, Dask computed it again (a lost result is no failure), and no
    task failed (1 run in 3)."""
    import dask

    problem = problem_of(tmp_path, MAP)
    out = tmp_path / "map.csv"
    marker = str(tmp_path / "killed")
    with (
        dask.config.set({"distributed.scheduler.allowed-failures": 0}),
        distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cl,
        distributed.Client(cl) as client,
    ):
        client.run(_die_once_at_point(5, marker))
        with caplog.at_level("WARNING", logger="cpm_nlp.sweep.run"):
            summary = run_sweep(problem, out, client=client, chunk_size=4)
    assert os.path.exists(marker)  # a worker died in the task
    failed = [r.getMessage() for r in caplog.records if "a task of 4 points failed" in r.getMessage()]
    assert failed and all("died while running it" in m and "one by one" in m for m in failed)
    assert summary.ok and summary.statuses == {"solved": 20}
    assert sorted(r["point"] for r in read_results(out).rows) == list(range(20))


def test_cli_on_an_existing_scheduler(cluster, cli, tmp_path):
    cl, client = cluster
    path = tmp_path / "s.yaml"
    path.write_text(MAP)
    out = tmp_path / "r.csv"
    fig = tmp_path / "map.png"
    run = cli("sweep", str(path), "-o", str(out), "--scheduler", cl.scheduler_address, "--plot", str(fig))
    assert run.code == 0, run.err
    assert "this run: 20 points in" in run.out and f"on {cl.scheduler_address}" in run.out
    assert "points  : 20 (20 solved)" in run.out and f"plot    : {fig} (map)" in run.out
    assert run.err == ""  # no progress bar when stderr is not a terminal (tests/sweep/test_sweep.py draws one)
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(client.scheduler_info()["workers"]) == 2  # the cluster is left running, unchanged
    run = cli("sweep", str(path), "-o", str(out), "--scheduler", cl.scheduler_address, "-q")
    assert run.code == 0 and run.out == "" and run.err == ""


def test_cli_default_starts_a_local_cluster(cli, tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(STATUSES)
    out = tmp_path / "r.parquet"
    run = cli("sweep", str(path), "-o", str(out), "--workers", "2")
    assert run.code == 1, run.err  # some points are not solved: the file says which
    assert "on a local cluster of 2 worker processes" in run.out
    assert "points  : 8 (4 solved, 2 outside_joint_limits, 2 unreachable)" in run.out
    assert len(read_results(out).rows) == 8


def test_scheduler_that_does_not_answer(cli, tmp_path):
    import dask

    path = tmp_path / "s.yaml"
    path.write_text(STATUSES)
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        run = cli("sweep", str(path), "-o", str(tmp_path / "r.csv"), "--scheduler", "tcp://127.0.0.1:9", "-q")
    assert run.code == 2
    assert run.err.startswith("error: --scheduler: cannot connect to the Dask scheduler tcp://127.0.0.1:9")
    assert not (tmp_path / "r.csv").exists()  # bad input writes nothing


def test_shipped_rpr_sweep_maps_the_design_triangle(cluster, cli, tmp_path):
    """problems/sweep_rpr_transmission.yaml with a smaller sample: points outside eq 22 are
    recorded as infeasible, the map is drawn over the triangle the solved points span."""
    cl, _ = cluster
    out, png = tmp_path / "eta.csv", tmp_path / "eta.png"
    run = cli(
        "sweep",
        str(PROBLEMS / "sweep_rpr_transmission.yaml"),
        "--set",
        "sweep.samples=300",
        "-o",
        str(out),
        "--scheduler",
        cl.scheduler_address,
        "-q",
        "--plot",
        str(png),
        "--best",
        "max",
    )
    assert run.code == 1, run.err  # points outside the design space are not solved: the file says so
    rows = read_results(out).rows
    counts = {s: sum(r["status"] == s for r in rows) for s in ("solved", "infeasible")}
    assert counts["solved"] + counts["infeasible"] == 300 and 50 < counts["solved"] < 150  # the triangle: 30 %
    assert all(0 < r["eta_best"] <= 1 for r in rows if r["status"] == "solved")
    assert_png_drawn(png, min_ink=0.15)
