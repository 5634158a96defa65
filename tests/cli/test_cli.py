"""The cpm-nlp command line: solve, --json, -o, --set, check, describe."""

import json
import math
import subprocess
import sys

import pytest

from tests.conftest import PROBLEMS, ROOT

FK = str(PROBLEMS / "prs3_forward_kinematics.yaml")


def test_solve_prints_a_table(cli):
    run = cli("solve", FK)
    assert run.code == 0, run.err
    assert "status  : solved" in run.out
    for name in ("px", "py", "pz", "psi", "theta", "phi", "s1", "alpha1", "beta_m1", "beta_l3"):
        assert f"\n{name} " in run.out
    assert run.err == ""


def test_solve_json_shape(cli):
    run = cli("solve", FK, "--json")
    assert run.code == 0
    data = json.loads(run.out)
    assert data["problem"] == "forward_kinematics"
    assert data["status"] == "solved"
    assert set(data["solver"]) == {"name", "iterations", "seconds", "build_seconds", "path"}
    assert data["solver"]["name"] == "ipopt" and data["solver"]["iterations"] > 0
    values = data["values"]
    assert values["s1"] == pytest.approx(1.0e-3) and values["s3"] == pytest.approx(-0.3e-3)  # SI
    assert values["pz"] == pytest.approx(0.0776, abs=1e-3)
    assert data["units"]["pz"] == "m" and data["units"]["psi"] == "rad"


def test_output_file_is_written_whole(cli, tmp_path):
    out = tmp_path / "fk.json"
    run = cli("solve", FK, "-o", str(out), "-q")
    assert run.code == 0 and run.out == ""
    data = json.loads(out.read_text())
    assert data["status"] == "solved"
    assert [p.name for p in tmp_path.iterdir()] == ["fk.json"]  # no temporary left behind


def test_set_overrides_any_value(cli):
    base = json.loads(cli("solve", FK, "--json").out)["values"]
    run = cli(
        "solve",
        FK,
        "--json",
        "--set",
        "inputs.s1=2 mm",
        "--set",
        "mechanism.parameters.b=50 mm",
        "--set",
        "solver=newton",
        "--set",
        "solver.options.abstol=1e-13",
    )
    assert run.code == 0, run.err
    data = json.loads(run.out)
    assert data["values"]["s1"] == pytest.approx(2e-3)
    assert data["model"]["b"] == pytest.approx(0.05)
    assert data["solver"]["name"] == "newton"
    assert data["values"]["pz"] != pytest.approx(base["pz"])


def test_set_list_makes_a_batch(cli):
    run = cli(
        "solve",
        FK,
        "--json",
        "--set",
        "inputs.s1=[0 mm, 1 mm]",
        "--set",
        "inputs.s2=[0 mm, 1 mm]",
        "--set",
        "inputs.s3=[0 mm, 1 mm]",
    )
    data = json.loads(run.out)
    assert run.code == 0
    assert data["statuses"] == ["solved", "solved"]
    assert data["values"]["dz"][0] == pytest.approx(0.0, abs=1e-12)
    assert data["values"]["psi"][1] == pytest.approx(0.0, abs=1e-12)


def test_failed_solve_exit_1_and_no_numbers(cli, tmp_path):
    out = tmp_path / "r.json"
    run = cli(
        "solve", str(PROBLEMS / "prs3_inverse_kinematics.yaml"), "--json", "-o", str(out), "--set", "inputs.dz=150 mm"
    )
    assert run.code == 1
    data = json.loads(run.out)
    assert data["status"] == "unreachable"
    assert data["values"]["s1"] is None and data["values"]["pz"] is None
    assert json.loads(out.read_text())["status"] == "unreachable"  # the honest result is still written


def test_outside_limits_status(cli):
    run = cli("solve", str(PROBLEMS / "prs3_inverse_kinematics.yaml"), "--set", "mechanism.limits.s=[-1 mm, 1 mm]")
    assert run.code == 1
    assert "outside_joint_limits" in run.out and "s1 = " in run.out


def test_outputs_selection(cli):
    run = cli("solve", FK, "--json", "--set", "outputs.values=[pz, psi]")
    assert set(json.loads(run.out)["values"]) == {"pz", "psi"}


def test_jacobian_problem(cli):
    data = json.loads(cli("solve", str(PROBLEMS / "prs3_jacobian.yaml"), "--json").out)
    assert data["status"] == "solved"
    J = data["values"]["J"]
    assert len(J) == 6 and len(J[0]) == 3
    assert data["values"]["psi"] == pytest.approx(math.radians(0.1))
    assert data["values"]["cond"] >= 1.0


def test_check_and_describe(cli):
    run = cli("check", FK)
    assert run.code == 0 and "ok (forward_kinematics on prs3" in run.out
    run = cli("describe")
    assert "prs3" in run.out and "joint_requirements" in run.out
    run = cli("describe", "prs3")
    assert "alpha0" in run.out and "eq 22" in run.out


def test_console_script_runs_out_of_process():
    """The installed entry point, exactly as a user runs it."""
    proc = subprocess.run(
        [sys.executable, "-m", "cpm_nlp.cli.main", "solve", FK, "--json"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["status"] == "solved"


def test_library_does_not_print(capfd):
    import cpm_nlp as cn

    model = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm"})
    cn.forward_kinematics(model, [1e-3, 0, 0])
    cn.forward_kinematics(model, [1e-3, 0, 0], cn.SolverConfig("newton"))
    cn.inverse_kinematics(model, [0.078, 0.001, 0.0], method="solve")
    cn.forward_kinematics(model, [0.3, -0.3, 0])  # a failing solve
    captured = capfd.readouterr()
    assert captured.out == "" and captured.err == ""


def test_start_up_loads_only_what_the_command_needs():
    """`import cpm_nlp` and `cpm-nlp --help` load neither numpy, CasADi, YAML, the mechanisms
    nor a subcommand's module; a solve of a file with plain units loads neither pint, scipy,
    matplotlib, Dask nor pyarrow, and a single FK solve none of what it does not run: the
    assembly-mode search, a graph file's generator and assembly, batches, the compiled
    backend, the plot layer, threadpoolctl (the BLAS cap is set before numpy loads), the entry
    points of plugins, difflib (issues 15 and 23: start-up time; benchmarks/bench_issue15.py
    measures it)."""
    heavy = ("numpy", "casadi", "pint", "scipy", "matplotlib", "dask", "distributed", "pyarrow")
    ours = (
        "yaml",
        "threadpoolctl",
        "importlib.metadata",
        "difflib",
        "cpm_nlp.mechanisms.registry",
        "cpm_nlp.cli.solve",
        "cpm_nlp.cli.describe",
        "cpm_nlp.cli.sweep",
        "cpm_nlp.plot",
        "cpm_nlp.analysis.assembly",
        "cpm_nlp.mechanisms.described.graph",
        "cpm_nlp.mechanisms.described.assembly",
        "cpm_nlp.analysis.mode_certificate",
        "cpm_nlp.analysis.workspace",
        "cpm_nlp.analysis.requirements",
        "cpm_nlp.core.batch",
        "cpm_nlp.core.compiled",
        "cpm_nlp.problems.published",
        "cpm_nlp.problems.sweep_section",
    )

    def loaded(body: str, watched: tuple = heavy + ours) -> set[str]:
        report = f"print('loaded:' + ','.join(m for m in {watched!r} if m in sys.modules))"
        argv = [sys.executable, "-c", f"import sys, io; {body}; {report}"]
        out = subprocess.run(argv, capture_output=True, text=True, check=True, cwd=ROOT).stdout
        line = [ln for ln in out.splitlines() if ln.startswith("loaded:")][-1]
        return {m for m in line[len("loaded:") :].split(",") if m}

    assert loaded("import cpm_nlp", heavy + ours + ("logging",)) == set()
    help_ = "from cpm_nlp.cli.main import main; main(['--help'], out=io.StringIO())"
    assert loaded(help_, heavy + ours + ("logging",)) == set()  # the NullHandler: cpm_nlp.core.errors
    # the plot types listed under `solve --help` import no plot module, nor Matplotlib
    plot_modules = ("matplotlib", "cpm_nlp.plot.workspace_plots", "cpm_nlp.plot.draw_panels", "cpm_nlp.cli.solve")
    listed = loaded("from cpm_nlp.cli.main import main; main(['solve', '--help'], out=io.StringIO())", plot_modules)
    assert listed == set()
    fk = "problems/prs3_forward_kinematics.yaml"
    solve = f"from cpm_nlp.cli.main import main; assert main(['solve', '{fk}'], out=io.StringIO()) == 0"
    assert loaded(solve) == {"numpy", "casadi", "yaml", "cpm_nlp.mechanisms.registry", "cpm_nlp.cli.solve"}
    # the lazy API still answers every public name
    import cpm_nlp

    assert all(getattr(cpm_nlp, name) is not None for name in cpm_nlp.__all__)


def test_describe_a_mechanism_file_loads_and_checks_it(cli, tmp_path):
    run = cli("describe", str(PROBLEMS / "mechanisms" / "five_bar.yaml"))
    assert run.code == 0, run.err
    assert run.out.startswith("five_bar: planar five-bar") and "file " in run.out
    text = (PROBLEMS / "mechanisms" / "five_bar.yaml").read_text()
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace("type: planar_R, at: [-cx, cy]", "type: planar_RR, at: [-cx, cy]"))
    run = cli("describe", str(bad))
    assert run.code == 2 and "legs[0].joints[1].type" in run.err and "did you mean 'planar_R'" in run.err
