"""Results files of sweeps (CSV and Parquet): rows written as points finish,
read back exactly, resumed after an interruption or a crash, never mixed
with another sweep's rows.  The records are real solves; no Dask here."""

from __future__ import annotations

import json
import os
import stat

import pytest

import cpm_nlp as cn
from cpm_nlp.io.results import journal_path, open_store, read_results
from cpm_nlp.sweep.run import columns, job_of, metadata, solve_points

TEXT = """\
problem: joint_requirements
mechanism:
  type: prs3
  parameters: {b: 47.91 mm, L: 109.215 mm, alpha0: 45 deg}
inputs: {dz: [-2 mm, 2 mm], psi: [-0.2 deg, 0.2 deg], theta: 0 deg}
outputs: {values: [s_min, s_max, dalpha_max, alpha1]}
sweep:
  parameters:
    mechanism.parameters.L: {from: 100 mm, to: 120 mm, count: 3}
    mechanism.parameters.alpha0: [40 deg, 50 deg]
"""


@pytest.fixture(scope="module")
def problem(tmp_path_factory):
    path = tmp_path_factory.mktemp("sweep") / "s.yaml"
    path.write_text(TEXT)
    return cn.load_problem(path)


@pytest.fixture(scope="module")
def solved(problem):
    """Every point of the sweep, solved in this process."""
    return solve_points(job_of(problem), range(6))


def store_for(problem, path, **kw):
    job = job_of(problem)
    return open_store(path, metadata(problem, job), columns(job), **kw)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_rows_round_trip_exactly(problem, solved, tmp_path, suffix):
    path = tmp_path / f"r{suffix}"
    store = store_for(problem, path)
    store.append(solved["records"][:4], solved["units"], solved["dimensions"])
    store.append(solved["records"][4:], {}, {})
    store.close()
    table = read_results(path)
    assert table.rows == solved["records"]  # floats bit for bit, the alpha1 lists as lists
    assert isinstance(table.rows[0]["alpha1"], list) and len(table.rows[0]["alpha1"]) == 4
    assert table.meta["units"] == {"s_min": "m", "s_max": "m", "dalpha_max": "rad", "alpha1": "rad"}
    assert [p["key"] for p in table.parameters] == ["mechanism.parameters.L", "mechanism.parameters.alpha0"]
    assert table.parameters[0]["base"] == pytest.approx(0.109215) and table.parameters[0]["dimension"] == "length"
    assert list(table.rows[0]) == columns(job_of(problem))
    assert not journal_path(path).exists()
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~umask  # as any new file, not mkstemp's 0600


def test_csv_is_readable_as_plain_csv(problem, solved, tmp_path):
    import csv

    path = tmp_path / "r.csv"
    store = store_for(problem, path)
    store.append(solved["records"], solved["units"], solved["dimensions"])
    store.close()
    lines = path.read_text().splitlines()
    assert lines[0].startswith("# cpm_nlp sweep {") and json.loads(lines[0][16:])["points"] == 6
    rows = list(csv.DictReader(lines[1:]))
    assert len(rows) == 6 and rows[2]["status"] == "solved"
    assert float(rows[2]["s_max"]) == solved["records"][2]["s_max"]


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_resume_keeps_rows_and_knows_what_is_done(problem, solved, tmp_path, suffix):
    path = tmp_path / f"r{suffix}"
    store = store_for(problem, path)
    store.append(solved["records"][:2], solved["units"], solved["dimensions"])
    store.close()  # an interrupted run
    again = store_for(problem, path)
    assert set(again.done) == {0, 1}
    again.append(solved["records"][1:], {}, {})  # point 1 again: ignored, never duplicated
    assert again.added == 4
    again.close()
    table = read_results(path)
    assert [r["point"] for r in table.rows] == list(range(6))
    assert again.status_counts() == {"solved": 6}


def test_csv_line_cut_short_by_a_crash_is_solved_again(problem, solved, tmp_path):
    path = tmp_path / "r.csv"
    store = store_for(problem, path)
    store.append(solved["records"][:3], solved["units"], solved["dimensions"])
    store.close()
    text = path.read_text()
    path.write_text(text[: text.rstrip("\n").rfind("\n") + 40])  # the last record half written
    assert [r["point"] for r in read_results(path).rows] == [0, 1]  # a reader skips the torn line
    again = store_for(problem, path)
    assert set(again.done) == {0, 1}
    again.append(solved["records"][2:], {}, {})
    again.close()
    assert read_results(path).rows == solved["records"]


def test_parquet_journal_survives_a_crash(problem, solved, tmp_path):
    path = tmp_path / "r.parquet"
    store = store_for(problem, path)
    store.append(solved["records"][:3], solved["units"], solved["dimensions"])
    store._fh.close()  # the process dies: no final Parquet file, the journal stays
    journal = journal_path(path)
    assert journal.exists() and not path.exists()
    with open(journal, "a") as fh:
        fh.write('{"point": 3, "mechanism.par')  # torn last line
    table = read_results(path)  # a reader sees what the journal holds
    assert [r["point"] for r in table.rows] == [0, 1, 2]
    again = store_for(problem, path)
    assert set(again.done) == {0, 1, 2}
    again.append(solved["records"][3:], {}, {})
    again.close()
    assert read_results(path).rows == solved["records"]
    assert not journal.exists()


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_results_of_another_sweep_are_never_mixed(problem, solved, tmp_path, suffix):
    path = tmp_path / f"r{suffix}"
    store = store_for(problem, path)
    store.append(solved["records"][:2], solved["units"], solved["dimensions"])
    store.close()
    other = cn.load_problem(_other_file(tmp_path))
    with pytest.raises(cn.InputError) as err:
        store_for(other, path)
    assert str(err.value) == (
        f"-o: {path} holds the results of another sweep (the problem or its sweep section changed since it "
        "was written); give another output file, or --overwrite to start again"
    )
    fresh = store_for(other, path, overwrite=True)
    assert fresh.done == {}
    fresh.close()
    assert len(read_results(path).rows) == 2  # nothing new written: the old file stays
    fresh = store_for(other, path, overwrite=True)
    fresh.append(solved["records"][4:5], {}, {})
    fresh.close()
    assert [r["point"] for r in read_results(path).rows] == [4]  # replaced by the first new record


def _other_file(tmp_path):
    path = tmp_path / "other.yaml"
    path.write_text(TEXT.replace("theta: 0 deg", "theta: 0.1 deg"))
    return path


def test_a_file_that_is_not_a_results_file_is_left_alone(problem, tmp_path):
    path = tmp_path / "r.csv"
    path.write_text("a,b\n1,2")
    with pytest.raises(cn.InputError) as err:
        store_for(problem, path)
    assert "is not a cpm_nlp sweep results file" in str(err.value)
    assert path.read_text() == "a,b\n1,2"  # not truncated, not touched
    bad = tmp_path / "r.parquet"
    bad.write_text("not parquet")
    with pytest.raises(cn.InputError) as err:
        read_results(bad)
    assert "is not a readable Parquet file" in str(err.value)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_more_samples_resume_and_the_metadata_follows(tmp_path, suffix):
    text = TEXT.split("sweep:")[0] + (
        "sweep:\n  parameters:\n    mechanism.parameters.L: {random: uniform, from: 100 mm, to: 120 mm}\n"
        "  samples: {n}\n"
    )
    path = tmp_path / "s.yaml"
    out = tmp_path / f"r{suffix}"
    for n in (3, 5):
        path.write_text(text.replace("{n}", str(n)))
        problem = cn.load_problem(path)
        store = store_for(problem, out)
        todo = [k for k in range(n) if k not in store.done]
        solved = solve_points(job_of(problem), todo)
        store.append(solved["records"], solved["units"], solved["dimensions"])
        store.close()
        assert store.added == (3 if n == 3 else 2)  # the first three are kept, not solved again
    table = read_results(out)
    assert [r["point"] for r in table.rows] == [0, 1, 2, 3, 4] and table.meta["points"] == 5
