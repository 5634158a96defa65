"""The benchmark harness runs (a smoke run with small sizes; no timing is asserted)."""

import importlib.util
import json
import sys

import pytest

from tests.conftest import ROOT


def test_benchmark_harness_smoke(tmp_path, capsys):
    spec = importlib.util.spec_from_file_location("bench_run", ROOT / "benchmarks" / "run.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    out = tmp_path / "results.json"
    assert bench.main(["--quick", "--repeats", "1", "--skip", "reproduce,memory", "-o", str(out)]) == 0
    data = json.loads(out.read_text())
    assert {"batch_fk_map", "fsolve_casadi", "fsolve_buffer", "ratio_map_vs_fsolve_casadi"} <= set(data["batch"])
    assert {"single_fk_newton", "single_fk_ipopt", "single_fk_function"} <= set(data["single"])
    cases = {c["file"]: c for c in data["cases"]}
    assert cases["problems/prs3_joint_requirements.yaml"]["status"] == "solved"
    for missing in ("problems/pantograph_cuboid.yaml", "problems/pantograph_synthesis.yaml"):
        if not (ROOT / missing).exists():
            assert cases[missing]["note"].startswith("skipped:")
    printed = capsys.readouterr().out
    assert "batch_fk_map" in printed and "written:" in printed


def test_sweep_benchmark_smoke(tmp_path, capsys):
    """benchmarks/bench_sweep.py runs end to end (a few points; no timing is asserted)."""
    spec = importlib.util.spec_from_file_location("bench_sweep", ROOT / "benchmarks" / "bench_sweep.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    out = tmp_path / "bench_sweep.json"
    assert bench.main(["--scale", "0.02", "--repeats", "1", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert [c["case"] for c in data["cases"]] == ["fk", "requirements"]
    assert all(c["ratio_wall"] > 0 and c["ratio_cpu"] > 0 and c["speed_up"] > 0 for c in data["cases"])
    assert "sweep on 1 worker process / plain loop" in capsys.readouterr().out


def test_modes_benchmark_smoke(tmp_path, capsys):
    """benchmarks/bench_modes.py runs end to end (few starts; no timing is asserted)."""
    spec = importlib.util.spec_from_file_location("bench_modes", ROOT / "benchmarks" / "bench_modes.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    out = tmp_path / "bench_modes.json"
    assert bench.main(["--starts", "64", "--repeats", "1", "--baseline", "4", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["modes"] >= 1 and data["seconds"] > 0 and len(data["load_avg_1min"]) == 1
    assert "all assembly modes, 6-UPS" in capsys.readouterr().out


def test_assembly_modes_benchmark_smoke(tmp_path, capsys):
    """benchmarks/bench_assembly_modes.py runs end to end (few starts and boxes; nothing asserted on rates)."""
    spec = importlib.util.spec_from_file_location(
        "bench_assembly_modes", ROOT / "benchmarks" / "bench_assembly_modes.py"
    )
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    out = tmp_path / "bench_assembly_modes.json"
    argv = ["--seeds", "1", "--platforms", "1", "--reference", "300", "--starts", "1000", "--certify-boxes", "100"]
    assert bench.main(argv + ["--before", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["dietmaier"]["searches"] == 1 and data["random_66"]["platforms"] == 1
    assert [c["certified"] for c in data["certificate"]] == [True, True, True, False]
    assert "before" in data and "written:" in capsys.readouterr().out


def _peers_bench():
    spec = importlib.util.spec_from_file_location("bench_peers", ROOT / "benchmarks" / "bench_peers.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    return bench


_TINY = ["--n", "24", "--single", "4", "--repeat", "1", "--jansen-n", "36"]


def _assert_agrees(entry: dict, n: int, tol: float) -> None:
    """Every pose solved by both and the positions equal within tol (m); no timing asserted."""
    a = entry["agreement"]
    assert a["compared_poses"] == a["solved_by_peer"] == a["solved_by_cpm_nlp"] == n
    assert a["max_abs_diff_m_all"] <= tol, a


def test_peer_benchmark_pinocchio(tmp_path, capsys):
    """benchmarks/bench_peers.py: Pinocchio's loop closure (Newton on the constraint, its
    kinematics) gives cpm_nlp's five-bar and Delta positions within 1e-9 m on the same poses."""
    pytest.importorskip("pinocchio")
    out = tmp_path / "bench_peers.json"
    assert _peers_bench().main([*_TINY, "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    for mech in ("five_bar", "delta"):
        entry = data["mechanisms"][mech]["peers"]["pinocchio"]
        _assert_agrees(entry, 24, 1e-9)
        assert entry["single"]["load_1min"] and entry["batch"]["cpu_us_per_pose"] > 0
    assert "pinocchio" in data["versions"] and "written:" in capsys.readouterr().out


def test_peer_benchmark_pylinkage(tmp_path):
    """pylinkage's RRR dyad (objects and its solver kernels in one loop) gives cpm_nlp's five-bar
    end effector within 1e-12 m, and its simulation of Jansen's leg the foot over a turn (36 crank
    angles) within 1e-12 m; the Delta is skipped (pylinkage is planar)."""
    pytest.importorskip("pylinkage")
    out = tmp_path / "bench_peers.json"
    assert _peers_bench().main([*_TINY, "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    entry = data["mechanisms"]["five_bar"]["peers"]["pylinkage"]
    _assert_agrees(entry, 24, 1e-12)
    _assert_agrees({"agreement": entry["agreement_batch"]}, 24, 1e-12)
    _assert_agrees(data["mechanisms"]["jansen"]["peers"]["pylinkage"], 36, 1e-12)
    assert "planar" in data["mechanisms"]["delta"]["peers"]["pylinkage"]["skipped"]


def test_peer_benchmark_without_peers(tmp_path, capsys, monkeypatch):
    """Without the [bench] extra the script says each peer is not installed, skips it, exits 0."""
    monkeypatch.setitem(sys.modules, "pinocchio", None)  # import raises ImportError
    monkeypatch.setitem(sys.modules, "pylinkage", None)
    out = tmp_path / "bench_peers.json"
    assert _peers_bench().main([*_TINY, "--mechanisms", "five_bar", "--json", str(out)]) == 0
    peers = json.loads(out.read_text())["mechanisms"]["five_bar"]["peers"]
    assert peers["pinocchio"] == {"skipped": "pin (Pinocchio) is not installed"}
    assert peers["pylinkage"] == {"skipped": "pylinkage is not installed"}
    printed = capsys.readouterr().out
    assert "pin (Pinocchio) is not installed" in printed and "pylinkage is not installed" in printed


def test_batch_speed_benchmark_smoke(tmp_path, capsys):
    """benchmarks/bench_batch_speed.py runs end to end (small sizes; no timing is asserted, only
    the same bits before and after the flags and the first pass, and the five-bar fallback share,
    a count)."""
    spec = importlib.util.spec_from_file_location("bench_batch_speed", ROOT / "benchmarks" / "bench_batch_speed.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    out = tmp_path / "bench_batch_speed.json"
    assert bench.main(["--quick", "--rounds", "1", "-o", str(out)]) == 0
    data = json.loads(out.read_text())
    if "kernel" in data:  # a C compiler is there
        assert data["kernel"]["kernel_before_same_bits_as_vm"] and data["kernel"]["kernel_now_same_bits_as_vm"]
        assert data["kernel"]["kernel_whole_same_bits_as_vm"]  # the loop before the first pass
        assert data["batch"]["statuses"] == {"solved": 2000}
        same = {k: v for part in ("fivebar", "jansen") for k, v in data[part].items() if k.endswith("same_bits_as_vm")}
        assert len(same) == 7 and all(same.values()), same
    assert data["fivebar"]["fallback_share_now"] < 0.05 < data["fivebar"]["fallback_share_3_steps"]
    assert data["fivebar"]["closed_share"] == 1.0  # every five-bar pose by the closed-form dyad (a count)
    assert data["single"]["single_fk_function_us"] > 0 and "load" in data["single"]
    assert "written:" in capsys.readouterr().out


def test_spherical_benchmark_smoke(tmp_path, capsys):
    """benchmarks/bench_spherical.py runs end to end (small sizes; no timing is asserted, only that
    every pose of the turn is solved, a count)."""
    spec = importlib.util.spec_from_file_location("bench_spherical", ROOT / "benchmarks" / "bench_spherical.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    out = tmp_path / "bench_spherical.json"
    assert bench.main(["--quick", "--rounds", "1", "-o", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["four_bar"]["statuses"] == {"solved": 360}
    assert "written:" in capsys.readouterr().out
