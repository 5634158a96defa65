"""The sweep section: points, validation (exit 2, key path, did you mean), each
point solved exactly as ``cpm-nlp solve --set`` solves it.  No Dask here."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest

import cpm_nlp as cn
from cpm_nlp.core.extras import require
from cpm_nlp.sweep.run import ERROR, INVALID_INPUT, fingerprint, job_of, override, solve_point
from tests.conftest import PROBLEMS, ROOT

SWEEP_FILE = PROBLEMS / "sweep_prs3_requirements.yaml"

BASE = """\
problem: joint_requirements
mechanism:
  type: prs3
  parameters: {b: 47.91 mm, L: 109.215 mm, alpha0: 45 deg}
inputs: {dz: [-2 mm, 2 mm], psi: [-0.2 deg, 0.2 deg], theta: 0 deg}
outputs: {values: [s_min, s_max]}
"""


def write(tmp_path, sweep, base=BASE):
    path = tmp_path / "sweep.yaml"
    path.write_text(base + sweep)
    return path


def test_grid_points_first_parameter_slowest(tmp_path):
    path = write(
        tmp_path,
        "sweep:\n  parameters:\n    mechanism.parameters.L: {from: 100 mm, to: 120 mm, count: 3}\n"
        "    mechanism.parameters.alpha0: [40 deg, 50 deg]\n",
    )
    spec = cn.load_problem(path).sweep
    assert spec.size == 6 and spec.samples is None
    points = [p for _, p in spec.points()]
    assert [p["mechanism.parameters.L"] for p in points] == pytest.approx([0.1, 0.1, 0.11, 0.11, 0.12, 0.12])
    assert [p["mechanism.parameters.alpha0"] for p in points] == pytest.approx([math.radians(a) for a in [40, 50] * 3])
    assert [a.dimension for a in spec.axes] == ["length", "angle"]


def test_random_sample_is_seeded_and_grows_without_changing_points(tmp_path):
    text = (
        "sweep:\n  parameters:\n    mechanism.parameters.b: {random: uniform, from: 40 mm, to: 60 mm}\n"
        "    mechanism.parameters.L: {random: loguniform, from: 90 mm, to: 130 mm}\n"
        "    mechanism.parameters.alpha0: [40 deg, 50 deg]\n  samples: {n}\n  seed: 7\n"
    )
    small = cn.load_problem(write(tmp_path, text.replace("{n}", "5"))).sweep
    large = cn.load_problem(write(tmp_path, text.replace("{n}", "50"))).sweep
    assert small.size == 10 and large.size == 100
    assert [small.point(k) for k in range(10)] == [large.point(k) for k in range(10)]  # same seed, same points
    bs = [large.point(k)["mechanism.parameters.b"] for k in range(100)]
    Ls = [large.point(k)["mechanism.parameters.L"] for k in range(100)]
    assert 0.04 <= min(bs) and max(bs) <= 0.06 and max(bs) - min(bs) > 0.01  # spread over the range
    assert 0.09 <= min(Ls) and max(Ls) <= 0.13
    # the grid parameter varies fastest, the sample slowest: each draw is crossed with every grid value
    assert large.point(0)["mechanism.parameters.b"] == large.point(1)["mechanism.parameters.b"]
    other = cn.load_problem(write(tmp_path, text.replace("{n}", "5").replace("seed: 7", "seed: 8"))).sweep
    assert other.point(0) != small.point(0)


def test_fingerprint_ignores_samples_not_the_problem(tmp_path):
    text = (
        "sweep:\n  parameters:\n    mechanism.parameters.b: {random: uniform, from: 40 mm, to: 60 mm}\n  samples: {n}\n"
    )
    a = job_of(cn.load_problem(write(tmp_path, text.replace("{n}", "5"))))
    b = job_of(cn.load_problem(write(tmp_path, text.replace("{n}", "9"))))
    c = job_of(cn.load_problem(write(tmp_path, text.replace("{n}", "5")), ["inputs.theta=0.1 deg"]))
    assert fingerprint(a) == fingerprint(b) != fingerprint(c)


def test_each_point_is_solved_exactly_as_solve_with_set(tmp_path):
    path = write(
        tmp_path,
        "sweep:\n  parameters:\n    mechanism.parameters.L: {from: 100 mm, to: 120 mm, count: 3}\n"
        "    solver.method: [ipopt, newton]\n",
    )
    job = job_of(cn.load_problem(path))
    for k in (0, 5):
        record, units, dims = solve_point(job, k)
        overrides = [override(key, v) for key, v in job.spec.point(k).items()]
        expected = cn.solve(cn.load_problem(path, overrides))
        assert record["status"] == "solved"
        assert {n: record[n] for n in ("s_min", "s_max")} == expected.values  # bit for bit
        assert units == {"s_min": "m", "s_max": "m"} and dims == {"s_min": "length", "s_max": "length"}
    assert solve_point(job, 5)[0]["solver.method"] == "newton"


def test_a_point_that_fails_is_recorded_with_status_and_message(tmp_path):
    base = """\
problem: forward_kinematics
mechanism:
  type: prs3
  parameters: {b: 47.91 mm, L: 109.215 mm}
  limits: {s: [-3 mm, 3 mm]}
inputs: {s1: 0 mm, s2: 0 mm, s3: 0 mm}
outputs: {values: [dz]}
"""
    path = write(tmp_path, "sweep:\n  parameters:\n    inputs.s1: [1 mm, 4 mm]\n", base)
    job = job_of(cn.load_problem(path))
    ok, _, _ = solve_point(job, 0)
    bad, _, _ = solve_point(job, 1)
    assert ok["status"] == "solved" and ok["dz"] > 0
    assert bad["status"] == INVALID_INPUT and bad["dz"] is None
    assert bad["message"] == (
        f"{path}: inputs.s1: actuator displacement 4 mm is out of reach: expected a value within the stroke "
        "[-3 mm, 3 mm] declared at mechanism.limits.s"
    )
    assert ERROR == "error"


def test_solve_on_a_sweep_file_solves_the_base_problem(cli):
    run = cli("solve", str(SWEEP_FILE), "--json")
    assert run.code == 0, run.err
    data = json.loads(run.out)
    assert data["values"]["s_max"] == pytest.approx(2.295e-3, abs=1e-6)  # the paper's design, Fig. 6
    assert cli("check", str(SWEEP_FILE)).code == 0


def test_shipped_sweep_files_are_small_enough_to_run_in_a_minute(cli):
    sizes = {p.name: cn.load_problem(p).sweep.size for p in sorted(PROBLEMS.glob("sweep_*.yaml"))}
    assert sizes == {
        "sweep_pantograph_cuboid.yaml": 54,  # about 0.4 s a point (IPOPT, 4 starts): 11 s on 2 cores
        "sweep_prs3_requirements.yaml": 169,  # about 3 ms a point, 27 IK each
        "sweep_rpr_transmission.yaml": 1500,  # about 3 ms a point
    }
    for name in sizes:
        assert cli("check", str(PROBLEMS / name)).code == 0


def test_pantograph_cuboid_sweep_points_are_solves_of_the_file():
    problem = cn.load_problem(PROBLEMS / "sweep_pantograph_cuboid.yaml")
    job = job_of(problem)
    point = job.spec.point(21)
    assert point == {"mechanism.parameters.b": pytest.approx(0.05), "mechanism.limits.t": pytest.approx(2e-4)}
    record = solve_point(job, 21)[0]
    expected = cn.solve(
        cn.load_problem(PROBLEMS / "sweep_pantograph_cuboid.yaml", [override(k, v) for k, v in point.items()])
    )
    assert record["status"] == "solved" and record["volume"] == expected.values["volume"]
    # a thicker hinge turns less (eq 30-31): a smaller cuboid than the paper's t = 0.1 mm
    assert record["volume"] < cn.solve(problem).values["volume"]
    assert [a.base for a in job.spec.axes] == pytest.approx([0.05, 1e-4])  # the paper's design


def test_rpr_sweep_points_inside_and_outside_the_design_triangle():
    problem = cn.load_problem(PROBLEMS / "sweep_rpr_transmission.yaml")
    base = cn.solve(problem)
    assert base.values["eta_best"] == pytest.approx(0.913, abs=5e-4)  # eta(1.5, 0), rpr_transmission_map.yaml
    job = job_of(problem)
    records = [solve_point(job, k)[0] for k in range(20)]
    statuses = {r["status"] for r in records}
    assert statuses == {"solved", "infeasible"}
    for r in records:
        s, t = r["inputs.s"], r["inputs.t"]
        l1, l2, l3 = (3 - s - math.sqrt(3) * t) / 2, s, (3 - s + math.sqrt(3) * t) / 2  # eq 23
        inside = min(l1, l3) > 0 and l1 / 2 <= l2 <= 2 * l1  # eq 22
        assert (r["status"] == "solved") == inside, r
        assert (r["eta_best"] is not None) == inside


@pytest.mark.parametrize(
    ("sweep", "message"),
    [
        (
            "sweep:\n  parameters:\n    mechanism.parameters.Lx: [1 mm]\n",
            "sweep.parameters.mechanism.parameters.Lx: unknown parameter 'Lx'; expected one of: L, alpha0, b; "
            "did you mean 'L'?",
        ),
        (
            "sweep:\n  parameters:\n    mechanism.parameter.L: [1 mm]\n",
            "sweep.parameters.mechanism.parameter.L: expected mechanism.parameters.<name> or "
            "mechanism.limits.<name>, got 'mechanism.parameter.L'; did you mean 'mechanism.parameters.L'?",
        ),
        (
            "sweep:\n  parameters:\n    inputs.dzz: [1 mm]\n",
            "sweep.parameters.inputs.dzz: unknown input of joint_requirements 'dzz'; expected one of: dz, psi, pz, "
            "theta; did you mean 'dz'?",
        ),
        (
            "sweep:\n  parameters:\n    outputs.values: [1]\n",
            "sweep.parameters.outputs.values: cannot sweep 'outputs'; expected a key under mechanism, inputs, solver "
            "(e.g. mechanism.parameters.L, inputs.dz, solver.method); did you mean 'inputs'?",
        ),
        (
            "sweep:\n  parameters:\n    mechanism.parameters.L: [100 mm, 10]\n",
            "sweep.parameters.mechanism.parameters.L[1]: expected a length such as '47.91 mm' in (0 mm, 1000 mm), "
            "got 10 (a bare number is read in SI (m); did you mean '10 mm'?)",
        ),
        (
            "sweep:\n  parameters:\n    mechanism.parameters.alpha0: {from: 0 deg, to: 20 deg, count: 3}\n",
            "sweep.parameters.mechanism.parameters.alpha0.from: expected an angle such as '0.2 deg' in "
            "(0 deg, 90 deg), got '0 deg'",
        ),
        (
            "sweep:\n  parameters:\n    mechanism.parameters.L: {from: 90 mm, to: 100 mm, cnt: 3}\n",
            "sweep.parameters.mechanism.parameters.L: unknown grid key 'cnt'; expected one of: count, from, to; "
            "did you mean 'count'?",
        ),
        (
            "sweep:\n  parameters:\n    mechanism.parameters.L: {random: uniform, from: 90 mm, to: 100 mm}\n",
            "sweep: missing 'samples' (how many draws of the random parameter(s) mechanism.parameters.L)",
        ),
        (
            "sweep:\n  parameters:\n    mechanism.parameters.L: {random: gauss, from: 90 mm, to: 100 mm}\n"
            "  samples: 3\n",
            "sweep.parameters.mechanism.parameters.L.random: expected one of 'uniform', 'loguniform', got 'gauss'",
        ),
        (
            "sweep:\n  parameters:\n    mechanism.parameters.L: {random: uniform, from: 100 mm, to: 90 mm}\n"
            "  samples: 3\n",
            "sweep.parameters.mechanism.parameters.L: expected from < to, got from '100 mm', to '90 mm'",
        ),
        (
            "sweep:\n  parameters:\n    mechanism.parameters.L: [100 mm]\n  samples: 3\n",
            "sweep.samples: 'samples' applies to random parameters ({random: uniform, from: ..., to: ...}), "
            "and none is given",
        ),
        (
            "sweep:\n  parameters:\n    mechanism.parameters.L: [100 mm]\n  sampels: 3\n",
            "sweep: unknown sweep key 'sampels'; expected one of: parameters, samples, seed; did you mean 'samples'?",
        ),
        (
            "sweep:\n  parameters:\n    solver.options.ipopt.tolx: [1e-8]\n",
            "sweep.parameters.solver.options.ipopt.tolx[0]: value 1e-08: IPOPT has no option 'tolx'; did you mean "
            "'ipopt.tol'? (see https://coin-or.github.io/Ipopt/OPTIONS.html)",
        ),
        (
            "sweep:\n  parameters:\n    solver.method: [ipopt, newtn]\n",
            "sweep.parameters.solver.method[1]: value 'newtn': expected one of 'ipopt', 'newton', got 'newtn'; "
            "did you mean 'newton'?",
        ),
        (
            "sweep:\n  parameters:\n    mechanism.limits.s: {from: 1 mm, to: 2 mm, count: 2}\n",
            "sweep.parameters.mechanism.limits.s: expected a list of values for mechanism.limits.s "
            "(a grid needs a numeric value)",
        ),
        (
            "sweep:\n  parameters:\n    mechanism.limits.s: [[-1 mm, 1 mm], [2 mm, 1 mm]]\n",
            "sweep.parameters.mechanism.limits.s[1]: expected low < high, got [2 mm, 1 mm]",
        ),
        (
            "sweep:\n  parameters: {}\n",
            "sweep.parameters: expected a non-empty mapping of dotted keys (e.g. mechanism.parameters.L) to a grid "
            "{from, to, count}, a list, or {random: uniform, from, to}",
        ),
        ("sweep: 3\n", "sweep: expected a mapping with keys parameters, samples, seed; got int 3"),
        (
            "sweep:\n  parameters:\n    mechanism.parameters.L: {from: 90 mm, to: 100 mm, count: 2000}\n"
            "    mechanism.parameters.b: {from: 40 mm, to: 50 mm, count: 2000}\n",
            "sweep: the sweep has 4000000 points; expected at most 1000000",
        ),
    ],
)
def test_bad_sweep_section(cli, tmp_path, sweep, message):
    path = write(tmp_path, sweep)
    for command in ("check", "sweep", "solve"):
        out = tmp_path / "results.csv"
        run = cli(command, str(path), *(["-o", str(out)] if command == "sweep" else []))
        assert run.code == 2, (command, run.err)
        assert run.out == "" and not out.exists()
        assert run.err == f"error: {path}: {message}\n"


def test_sweep_without_sweep_section_or_with_a_bad_output(cli, tmp_path):
    fk = str(PROBLEMS / "prs3_forward_kinematics.yaml")
    run = cli("sweep", fk, "-o", str(tmp_path / "r.csv"))
    assert run.code == 2
    assert run.err.startswith(f"error: {fk}: the file has no 'sweep' section; add one naming the values to sweep")
    run = cli("sweep", str(SWEEP_FILE), "-o", str(tmp_path / "r.txt"))
    assert run.err == f"error: -o: expected a results file ending in .parquet or .csv, got '{tmp_path / 'r.txt'}'\n"
    run = cli("sweep", str(SWEEP_FILE), "-o", str(tmp_path / "nowhere" / "r.csv"))
    assert run.code == 2 and "output directory" in run.err and "does not exist" in run.err
    run = cli("sweep", str(SWEEP_FILE), "-o", str(tmp_path / "r.csv"), "--workers", "0")
    assert run.err == "error: --workers: expected a positive number of workers, got 0\n"
    assert list(tmp_path.iterdir()) == []


def test_missing_optional_dependency_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(cn.InputError) as err:
        require("distributed", "sweep", "running a sweep")
    assert str(err.value) == (
        "running a sweep needs the Python package 'distributed', which is not installed (pip install 'cpm_nlp[sweep]')"
    )


def test_solve_imports_neither_dask_nor_matplotlib_nor_pyarrow():
    # (pint imports the light `dask` core when it is installed; the cluster is `distributed`)
    code = (
        "import sys, io; from cpm_nlp.cli.main import main; "
        f"assert main(['solve', {str(PROBLEMS / 'prs3_forward_kinematics.yaml')!r}, '-q']) == 0; "
        "heavy = [m for m in ('distributed', 'matplotlib', 'pyarrow') if m in sys.modules]; "
        "print(heavy)"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"


def test_without_the_extras_solve_check_reproduce_work_and_sweep_says_what_to_install(tmp_path):
    """As after `pip install -e .` alone: the optional packages cannot be imported."""
    code = f"""
import sys
for m in ("distributed", "matplotlib", "pyarrow"):
    sys.modules[m] = None  # ImportError on import, as when not installed
from cpm_nlp.cli.main import main
assert main(["check", {str(SWEEP_FILE)!r}]) == 0
assert main(["solve", {str(SWEEP_FILE)!r}, "-q"]) == 0
assert main(["reproduce", {str(PROBLEMS / "prs3_joint_requirements.yaml")!r}]) == 0
print("exit", main(["sweep", {str(SWEEP_FILE)!r}, "-q", "-o", {str(tmp_path / "r.csv")!r}]))
print("exit", main(["solve", {str(SWEEP_FILE)!r}, "-q", "--plot", {str(tmp_path / "r.png")!r}]))
"""
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines()[-2:] == ["exit 2", "exit 2"]
    assert proc.stderr.splitlines()[-2:] == [
        "error: running a sweep needs the Python package 'distributed', which is not installed "
        "(pip install 'cpm_nlp[sweep]')",
        "error: plotting needs the Python package 'matplotlib', which is not installed (pip install 'cpm_nlp[plot]')",
    ]
    assert list(tmp_path.iterdir()) == []


def test_interrupted_cli_sweep_says_how_to_resume(cli, tmp_path, monkeypatch):
    import cpm_nlp.sweep.run

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(cpm_nlp.sweep.run, "run_sweep", interrupted)
    out = tmp_path / "r.csv"
    run = cli("sweep", str(SWEEP_FILE), "-o", str(out))
    assert run.code == 130
    assert run.err == f"\ninterrupted before any point was solved; nothing was written ({out} does not exist)\n"
    out.write_text("# cpm_nlp sweep {}\n")  # a file with points of this sweep
    run = cli("sweep", str(SWEEP_FILE), "-o", str(out))
    assert run.code == 130
    assert run.err == f"\ninterrupted: the points solved so far are in {out}; run the same command to resume\n"


def test_progress_bar_redraws_in_place_on_a_terminal():
    """The sweep's progress: a tqdm bar redrawn in place on a terminal, closed
    (a new line) at the end; nothing when stderr is a log, or with -q."""
    import argparse
    import io

    from cpm_nlp.cli.bars import progress_bars as _progress_bars

    class Tty(io.StringIO):
        def isatty(self):
            return True

    stream = Tty()
    show = _progress_bars(argparse.Namespace(quiet=False, err=stream))
    for done in (0, 5, 10):
        show("sweep", done, 10)
    text = stream.getvalue()
    assert text.startswith("\rsweep:   0%") and "0/10" in text
    assert "\rsweep:  50%" in text and "5/10" in text and " points" in text
    assert "\rsweep: 100%" in text and "10/10" in text and text.endswith("\r")  # erased when done
    assert _progress_bars(argparse.Namespace(quiet=False, err=io.StringIO())) is None  # a log: no bar
    assert _progress_bars(argparse.Namespace(quiet=True, err=Tty())) is None
