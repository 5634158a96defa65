"""Design sweeps: the ``sweep`` section of a problem file.

A sweep solves the base problem of the file once per point, each point being
the base problem with some values overridden, exactly as
``cpm-nlp solve FILE --set KEY=VALUE ...`` would solve it::

    sweep:
      parameters:                      # dotted keys of the problem file
        mechanism.parameters.L: {from: 90 mm, to: 130 mm, count: 9}     # a grid
        mechanism.parameters.alpha0: [35 deg, 45 deg, 55 deg]            # a list
        mechanism.parameters.b: {random: uniform, from: 40 mm, to: 60 mm}  # a seeded sample
      samples: 200                     # draws of the random parameters
      seed: 1                          # default 0

The grid and list parameters form a full factorial (the first parameter
varies slowest); the random parameters are drawn together ``samples`` times
and crossed with it.  Point ``k`` is ``(sample k // n_grid, grid point
k % n_grid)`` and sample ``s`` is drawn from its own stream ``(seed, s)``, so
raising ``samples`` adds points at the end and keeps the ones already
solved (a sweep resumed with more samples solves only the new ones).

Keys name a value of the file: ``mechanism.parameters.<name>``,
``mechanism.limits.<name>`` (a list of [low, high] pairs), ``inputs.<name>``
(a point's value may itself be a list, a batch), ``solver`` or
``solver.<key>`` and ``solver.options.<CasADi option>``.  Every value is
validated here, against the declaration of what it overrides, so a typo is
reported before anything is solved.  Rules that involve several values (a
mechanism's ``check_parameters``) are checked per point: a point that breaks
one is recorded with status ``invalid_input`` and the message, like a
point that does not solve.

Running a sweep (`run_sweep`, Dask) and its results files
(`cpm_nlp.io.results`) build on this module; parsing needs neither
Dask nor pyarrow.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import math
import os
import signal
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..core import blas
from ..core.errors import InputError
from ..core.extras import require
from ..problems.file import problem_from_dict, solve
from ..problems.overrides import apply_overrides
from ..problems.sweep_section import SweepSpec, override

log = logging.getLogger(__name__)

#: statuses a sweep records besides those of `Status`
INVALID_INPUT = "invalid_input"  # the point's values break a rule of the problem (message says which)
ERROR = "error"  # the point raised an internal error or killed its worker repeatedly (message says what)


# -- the work of one point -------------------------------------------------------------------


@dataclass(frozen=True)
class Job:
    """What a worker needs to solve points of a sweep (small; pickled per task).

    Attributes
    ----------
    data
        the problem file without its ``sweep`` and ``reproduce`` sections (solving them is what
        ``cpm-nlp solve`` does with the file);
    values
        the result values recorded for each point.
    """

    data: dict
    file: str | None
    base_dir: str | None
    spec: SweepSpec
    values: tuple[str, ...]


def solve_point(job: Job, k: int) -> tuple[dict[str, Any], dict[str, str], dict[str, str]]:
    """Solve point ``k`` as ``cpm-nlp solve`` would; never raises for a point.

    Returns (record, units, dimensions): the record holds ``point``, the swept
    values, ``status``, ``message``, ``seconds`` and every recorded value
    (None where the point did not solve).
    """
    params = job.spec.point(k)
    t0 = time.perf_counter()
    units: dict[str, str] = {}
    dims: dict[str, str] = {}
    values: dict[str, Any] = {}
    warnings: list[dict[str, Any]] = []
    try:
        data = apply_overrides(job.data, [override(key, v) for key, v in params.items()])
        problem = problem_from_dict(data, file=job.file, base_dir=Path(job.base_dir) if job.base_dir else None)
        result = solve(problem)
        status, message = result.status.value, result.message
        values = result.to_dict()["values"]
        warnings = [w.to_dict() for w in result.warnings]
        units, dims = dict(result.units), dict(result.dimensions)
    except InputError as exc:
        status, message = INVALID_INPUT, exc.render()
    except Exception as exc:  # a bug in one point must not lose the sweep: recorded, with status "error"
        log.exception("point %d of the sweep raised", k)
        status, message = ERROR, f"internal error: {exc.__class__.__name__}: {exc}"
    record: dict[str, Any] = {"point": k, **params}
    record.update(status=status, message=" ".join(str(message).split()), seconds=round(time.perf_counter() - t0, 6))
    record["warnings"] = warnings
    for name in job.values:
        record[name] = values.get(name)
    return record, {n: units[n] for n in job.values if n in units}, {n: dims[n] for n in job.values if n in dims}


def solve_points(job: Job, ids: Sequence[int]) -> dict[str, Any]:
    """A worker task: solve some points; records plus the units learned."""
    blas.cap_process()  # one BLAS thread in the worker process (core/blas.py): Dask's processes run in parallel
    records, units, dims = [], {}, {}
    for k in ids:
        rec, u, d = solve_point(job, k)
        records.append(rec)
        units.update(u)
        dims.update(d)
    return {"records": records, "units": units, "dimensions": dims}


# -- planning ---------------------------------------------------------------------------------


def job_of(problem: Any) -> Job:
    """The `Job` of a validated problem that has a sweep section."""
    if problem.sweep is None:
        raise InputError(
            "the file has no 'sweep' section; add one naming the values to sweep, e.g. "
            "sweep: {parameters: {mechanism.parameters.L: {from: 90 mm, to: 130 mm, count: 5}}}",
            file=problem.file,
        )
    data = {k: v for k, v in problem.data.items() if k not in ("sweep", "reproduce")}
    values = tuple(problem.outputs or problem.kind.output_names(problem.model))
    base_dir = str(Path(problem.file).resolve().parent) if problem.file else None
    return Job(data, problem.file, base_dir, problem.sweep, values)


def fingerprint(job: Job) -> str:
    """Identity of a sweep's points: the problem solved at each point and the
    swept values (not ``samples``, so a sample can grow)."""
    data = {k: v for k, v in job.data.items() if k != "description"}
    raw = job.spec.raw if isinstance(job.spec.raw, Mapping) else {}
    ident = {
        "data": data,
        "parameters": raw.get("parameters"),
        "seed": job.spec.seed,
        "values": list(job.values),
    }
    text = json.dumps(ident, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def metadata(problem: Any, job: Job) -> dict[str, Any]:
    """What a results file says about itself (besides its rows); a parameter's
    ``base`` is its value in the base problem (the design of the file)."""
    return {
        "format": "cpm_nlp.sweep.run/1",
        "problem": job.data.get("problem"),
        "mechanism": problem.model.name,
        "file": job.file,
        "fingerprint": fingerprint(job),
        "points": job.spec.size,
        "parameters": [a.describe() for a in job.spec.axes],
        "values": list(job.values),
        "units": {},
        "dimensions": {},
    }


def columns(job: Job) -> list[str]:
    """Columns of a results file, in order."""
    return ["point", *(a.key for a in job.spec.axes), "status", "message", "seconds", "warnings", *job.values]


# -- running on Dask --------------------------------------------------------------------------


@dataclass
class SweepSummary:
    """Outcome of `run_sweep`.

    Attributes
    ----------
    total
        points of the sweep;
    statuses
        status -> number of points in the results file;
    solved_now
        points solved in this run;
    seconds
        wall time of this run;
    workers
        worker threads used (0 if nothing was left to do).
    """

    output: str
    total: int
    statuses: dict[str, int]
    solved_now: int
    seconds: float
    workers: int

    @property
    def ok(self) -> bool:
        return set(self.statuses) <= {"solved"} and sum(self.statuses.values()) == self.total


def default_workers() -> int:
    """Worker processes of the local default: one per core this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


#: Dask settings of the local cluster a sweep starts (benchmarks/bench_sweep.py):
#: * the worker's statistical profiler samples every thread's stack every
#:   10 ms; on points that are short CasADi calls wrapped in Python it cost
#:   about half the solve time: off;
#: * the nanny starts workers with MALLOC_TRIM_THRESHOLD_=65536 (for large
#:   dataframes); on many small CasADi allocations it costs about 13 % more
#:   CPU: left to glibc's default;
#: * the event-loop, system and memory monitors wake every 20-500 ms (about
#:   3 % of a core while idle); every 0.5-2 s is plenty for tasks of half a
#:   second.
LOCAL_CLUSTER_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
    "distributed.admin.tick.interval": "500ms",
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.memory.monitor-interval": "1s",
}


#: Environment of the local cluster's worker processes: Dask's own log at
#: level error (cancelling the tasks of an interrupted sweep logs a warning
#: per task; a point that fails is recorded in the results file, not logged).
WORKER_ENVIRON = {"DASK_LOGGING__DISTRIBUTED": "error"}

#: How long a sweep tries to reach a scheduler given by --scheduler (Dask's default is 30 s).
CONNECT_SECONDS = 5.0


def dask_config() -> Any:
    """The settings under which a sweep starts its local cluster (a context)."""
    import dask

    return dask.config.set(LOCAL_CLUSTER_CONFIG)


class _Connection:
    """A Dask client: to an existing scheduler, or to a local cluster it starts
    (and stops) itself, one single-threaded worker process per core (CasADi
    holds the GIL, so processes, not threads, run points in parallel)."""

    def __init__(self, scheduler: str | None, workers: int | None, client: Any) -> None:
        self.scheduler, self.workers, self.given = scheduler, workers, client
        self.client: Any = client
        self.cluster: Any = None

    def __enter__(self) -> Any:
        if self.client is not None:
            return self.client
        distributed = require("distributed", "sweep", "running a sweep")
        if self.scheduler:
            try:
                self.client = distributed.Client(self.scheduler, timeout=CONNECT_SECONDS)
            except (OSError, TimeoutError, ValueError) as exc:
                detail = " ".join(str(exc).split())[:200] or exc.__class__.__name__
                raise InputError(
                    f"cannot connect to the Dask scheduler {self.scheduler} within {CONNECT_SECONDS:g} s ({detail}); "
                    "is it running, and is the address tcp://HOST:PORT?",
                    path=("--scheduler",),
                ) from None
            return self.client
        with dask_config(), _ctrl_c_ignored():  # the worker processes inherit "ignore SIGINT"
            self.cluster = distributed.LocalCluster(
                n_workers=self.workers or default_workers(),
                threads_per_worker=1,
                processes=True,
                dashboard_address=":0",  # a free port: never "8787 is in use" when two sweeps run
            )
        self.client = distributed.Client(self.cluster)
        log.info("local Dask cluster, dashboard at %s", self.client.dashboard_link)
        return self.client

    def __exit__(self, *exc: Any) -> None:
        interrupted = exc[0] is not None and issubclass(exc[0], KeyboardInterrupt)
        with _quiet_dask() if interrupted else contextlib.nullcontext():  # closing after Ctrl-C: no log of it
            if self.given is None and self.client is not None:
                self.client.close()
            if self.cluster is not None:
                self.cluster.close()


@contextlib.contextmanager
def _ctrl_c_ignored() -> Iterator[None]:
    """Ignore SIGINT while the local cluster starts its processes: a process
    started with SIGINT ignored keeps ignoring it (and Python then installs no
    KeyboardInterrupt handler), so a Ctrl-C reaches the sweep's own process
    only, which stops the cluster; no worker prints a traceback."""
    env = {k: os.environ.get(k) for k in WORKER_ENVIRON}
    os.environ.update(WORKER_ENVIRON)
    try:
        previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    except ValueError:  # not the main thread: signals are not ours to change
        previous = None
    try:
        yield
    finally:
        if previous is not None:
            signal.signal(signal.SIGINT, previous)
        for k, v in env.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


@contextlib.contextmanager
def _quiet_dask() -> Iterator[None]:
    """Dask's loggers silenced (closing a cluster after Ctrl-C logs lost workers and cancelled tasks)."""
    loggers = [logging.getLogger(n) for n in ("distributed", "tornado", "asyncio")]
    levels = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for lg, level in zip(loggers, levels):
            lg.setLevel(level)


def run_sweep(
    problem: Any,
    output: str | os.PathLike,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    client: Any = None,
    chunk_size: int | None = None,
    overwrite: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> SweepSummary:
    """Solve every point of ``problem.sweep`` on Dask, streaming records to ``output``.

    Parameters
    ----------
    output
        ``.parquet`` or ``.csv``.  If it already holds points of this sweep, only the missing
        ones are solved (resume); a file of another sweep is an
        [`InputError`][cpm_nlp.core.errors.InputError] unless ``overwrite``.
    scheduler
        address of an existing Dask scheduler (``tcp://host:port``);
    client
        an existing ``distributed.Client``; neither: a local cluster of ``workers`` processes
        (default: one per core).
    chunk_size
        points per Dask task (default: adapted so a task takes about half a second).
    progress
        called with (points done, total) as points finish.
    """
    from ..io.results import open_store

    t0 = time.perf_counter()
    job = job_of(problem)
    store = open_store(output, metadata(problem, job), columns(job), overwrite=overwrite)
    n_workers = 0
    try:
        pending = [k for k in range(job.spec.size) if k not in store.done]
        if progress is not None:
            progress(job.spec.size - len(pending), job.spec.size)
        if pending:
            with _Connection(scheduler, workers, client) as dask_client:
                n_workers = _execute(dask_client, job, pending, store, chunk_size, progress)
    finally:
        store.close()
    return SweepSummary(
        str(output), job.spec.size, store.status_counts(), store.added, time.perf_counter() - t0, n_workers
    )


#: a task aims at this many seconds of work (per-task overhead of Dask is a few ms)
TASK_SECONDS = 0.5
#: tasks kept in flight per worker thread, so that no worker waits for the client
IN_FLIGHT = 2


def _threads(client: Any) -> int:
    return max(1, sum(client.nthreads().values()))


def _execute(
    client: Any,
    job: Job,
    pending: list[int],
    store: Any,
    chunk_size: int | None,
    progress: Callable[[int, int], None] | None,
) -> int:
    """Feed chunks of points to the cluster, write records as they come back.

    A chunk whose task fails (its worker died more often than Dask retries,
    or it raised) is split into single points; a single point that fails is
    recorded with status ``error``.  Returns the number of worker threads."""
    distributed = require("distributed", "sweep", "running a sweep")
    run = _Scheduling(client, job, pending, store, chunk_size)
    seq = distributed.as_completed([])
    try:
        run.submit(seq)
        last_threads = time.monotonic()
        for fut in seq:
            run.collect(fut)
            if progress is not None:
                progress(run.done, run.total)
            if time.monotonic() - last_threads > 2.0:  # clusters grow and shrink
                run.threads, last_threads = _threads(client), time.monotonic()
            run.submit(seq)
    finally:
        if run.futures:
            client.cancel(list(run.futures))
    return run.threads


class _Scheduling:
    """The state of the scheduling loop of `_execute`: the points still to submit, the
    chunks to retry one point at a time, the tasks in flight and the measured time per point."""

    def __init__(self, client: Any, job: Job, pending: list[int], store: Any, chunk_size: int | None) -> None:
        self.client, self.job, self.store, self.chunk_size = client, job, store, chunk_size
        self.queue = list(reversed(pending))  # pop() from the end = lowest point first
        self.threads = _threads(client)
        self.per_point: float | None = None  # seconds, measured
        self.futures: dict[Any, list[int]] = {}
        self.done = len(store.done)
        self.total = job.spec.size
        self.retry: list[list[int]] = []

    def next_chunk(self) -> list[int]:
        if self.retry:
            return self.retry.pop()
        queue = self.queue
        if self.chunk_size:
            n = self.chunk_size
        elif self.per_point is None:
            n = 1  # measure first
        else:
            n = int(TASK_SECONDS / max(self.per_point, 1e-6))
            n = min(n, math.ceil(len(queue) / (2 * self.threads)))  # keep the end balanced
        n = max(1, min(n, len(queue)))
        return [queue.pop() for _ in range(n)]

    def submit(self, seq: Any) -> None:
        while (self.queue or self.retry) and len(self.futures) < IN_FLIGHT * self.threads:
            ids = self.next_chunk()
            fut = self.client.submit(solve_points, self.job, ids, pure=False)
            self.futures[fut] = ids
            seq.add(fut)

    def collect(self, fut: Any) -> None:
        """A task come back: its records written, or its points split for a retry, or (one
        point) an ``error`` record."""
        ids = self.futures.pop(fut)
        if fut.status == "finished":
            out = fut.result()
            self.store.append(out["records"], out["units"], out["dimensions"])
            secs = [r["seconds"] for r in out["records"]]
            mean = sum(secs) / len(secs)
            self.per_point = mean if self.per_point is None else 0.7 * self.per_point + 0.3 * mean
            self.done += len(ids)
            return
        exc = fut.exception() if fut.status == "error" else None
        if len(ids) > 1:
            log.warning("a task of %d points failed (%s); solving them one by one", len(ids), exc)
            self.retry.extend([i] for i in reversed(ids))
        else:
            self.store.append([_error_record(self.job, ids[0], exc)], {}, {})
            self.done += 1


def _error_record(job: Job, k: int, exc: BaseException | None) -> dict[str, Any]:
    record: dict[str, Any] = {"point": k, **job.spec.point(k)}
    text = f"{exc.__class__.__name__}: {exc}" if exc is not None else "the task failed"
    record.update(status=ERROR, message=" ".join(f"the task failed: {text}".split()), seconds=None)
    record.update({name: None for name in job.values})
    return record
