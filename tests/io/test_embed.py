"""Embedding API: the model's CasADi Functions in the user's own CasADi code,
and the compiled batch backend."""

import importlib.util
import math
import threading
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.compiled import compiler_available
from cpm_nlp.core.result import Status
from tests.conftest import PAPER_PRS3, PROBLEMS, ROOT
from tests.mechanisms.prs3.test_prs3_kinematics import central_difference

NEWTON = cn.SolverConfig(method="newton")


@pytest.fixture(scope="module")
def fns(prs3):
    return cn.functions(prs3)


def test_functions_are_named_with_parameters_built_in(fns, prs3):
    assert fns.phi.name() == "prs3_phi" and fns.phi.name_in() == ["x", "q"] and fns.phi.name_out() == ["phi"]
    assert fns.fk.name_in() == ["q", "x0"] and fns.fk.name_out()[0] == "x" and fns.fk.name_out()[-1] == "status"
    assert fns.ik.name_in() == ["t"] and fns.ik.name_out()[:3] == ["x", "q", "passive"]
    assert fns.jacobian.name_out() == ["J", "J_inv", "Phi_x", "Phi_q"]
    np.testing.assert_array_equal(
        np.asarray(fns.phi(prs3.x_home, prs3.q_home)).ravel(), cn.residual(prs3, prs3.x_home, prs3.q_home)
    )


def test_functions_from_a_problem_file():
    fns = cn.functions(PROBLEMS / "prs3_forward_kinematics.yaml")
    assert fns.model.limits["s"] == pytest.approx((-3e-3, 3e-3))
    out = fns.fk(q=[4e-3, 0, 0], x0=fns.x_home)  # beyond the file's stroke
    assert cn.status_of(out["status"]) is Status.OUTSIDE_JOINT_LIMITS
    with pytest.raises(cn.InputError, match="expected a Model or the path of a problem file"):
        cn.functions(42)


def test_fk_derivatives_are_exact(fns, prs3):
    """AD through the embedded FK (implicit function theorem) equals the model
    Jacobian J = -Φ_x⁻¹Φ_q and central differences."""
    q = ca.MX.sym("q", 3)
    x = fns.fk(q=q, x0=fns.x_home)["x"]
    dxdq = ca.Function("dxdq", [q], [ca.jacobian(x, q)])
    q0 = np.array([1e-3, -0.5e-3, 0.8e-3])
    ad = np.asarray(dxdq(q0))
    sol = cn.forward_kinematics(prs3, q0, NEWTON)
    np.testing.assert_allclose(ad, cn.jacobians(prs3, sol.x, sol.q).J, rtol=1e-10, atol=1e-14)
    fd = central_difference(lambda qq: np.asarray(fns.fk(q=qq, x0=fns.x_home)["x"]).ravel(), q0, 1e-7)
    np.testing.assert_allclose(ad, fd, atol=1e-6 * np.max(np.abs(ad)))


def test_functions_from_several_threads(fns):
    rng = np.random.default_rng(31)
    qs = rng.uniform(-2e-3, 2e-3, (40, 3))
    serial = [np.asarray(fns.fk(q=q, x0=fns.x_home)["x"]).ravel() for q in qs]
    results = [None] * len(qs)

    def work(lo):
        for k in range(lo, len(qs), 4):
            results[k] = np.asarray(fns.fk(q=qs[k], x0=fns.x_home)["x"]).ravel()

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for a, b in zip(results, serial):
        np.testing.assert_array_equal(a, b)


def test_library_prints_nothing(capfd, prs3):
    cn.forward_kinematics(prs3, [1e-3, 0, 0])
    cn.forward_kinematics(prs3, [1e-3, 0, 0], NEWTON)
    cn.batch_forward_kinematics(prs3, [[1e-3, 0, 0]] * 10)
    cn.functions(prs3).fk(q=[0, 0, 0], x0=prs3.x_home)
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_example_uses_the_fk_in_its_own_optimization():
    """examples/prs3_fk_in_nlp.py: the largest tilt psi at dz = +2 mm within the
    Fig. 6-7 joint ranges; the optimum is a pose the toolkit confirms."""
    spec = importlib.util.spec_from_file_location("prs3_fk_in_nlp", ROOT / "examples" / "prs3_fk_in_nlp.py")
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    r = example.solve()
    assert r["success"] and r["status"] is Status.SOLVED
    assert max(abs(r["beta_m"])) == pytest.approx(math.radians(1.9), rel=1e-6)  # the active constraint
    assert r["psi"] > math.radians(0.2)  # more than the paper's requirement (section 4)
    np.testing.assert_allclose(r["ik_q"], r["q"], atol=1e-12)


# -- compiled backend ----------------------------------------------------------------------


@pytest.fixture
def compiled_cache(tmp_path, monkeypatch):
    """A fresh cache for this test (the session's may hold libraries already)."""
    monkeypatch.setenv("CPM_NLP_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


@pytest.mark.skipif(not compiler_available(), reason="no C compiler")
def test_compiled_backend_equals_map(compiled_cache):
    model = cn.build_model("prs3", PAPER_PRS3, {"s": ["-2 mm", "2 mm"]})
    rng = np.random.default_rng(32)
    q = rng.uniform(-2.2e-3, 2.2e-3, (3000, 3))
    q[::100] = [0.3, -0.3, 0.0]
    a = cn.batch_forward_kinematics(model, q, backend="map")
    b = cn.batch_forward_kinematics(model, q, backend="compiled")
    assert b.backend == "compiled" and a.backend == "map"
    np.testing.assert_array_equal(a.status, b.status)
    # the same bits: the C is built without floating-point contraction (compiled.CFLAGS)
    np.testing.assert_array_equal(b.x, a.x)
    for k in ("residual", "round_trip_error", "cond1", "limit_margin"):
        np.testing.assert_array_equal(b.checks[k], a.checks[k])
    t = np.column_stack([model.derived["pz0"] + q[:, 0], q[:, 1], q[:, 2]])
    ia = cn.batch_inverse_kinematics(model, t, backend="map")
    ib = cn.batch_inverse_kinematics(model, t, backend="compiled")
    np.testing.assert_array_equal(ia.status, ib.status)
    np.testing.assert_allclose(ib.q, ia.q, rtol=1e-12, atol=1e-18)
    ja = cn.batch_jacobians(model, ia.x[ia.ok], ia.q[ia.ok], backend="map")
    jb = cn.batch_jacobians(model, ia.x[ia.ok], ia.q[ia.ok], backend="compiled")
    np.testing.assert_allclose(jb.J, ja.J, rtol=1e-12, atol=1e-18)
    # the library is cached by content hash: a second model of the type reuses it
    libs = sorted(Path(compiled_cache).glob("compiled/*/*.so"))
    assert sorted(p.name for p in libs) == ["prs3_fk.so", "prs3_ik.so", "prs3_jacobian.so"]
    other = cn.build_model("prs3", {"b": "40 mm", "L": "100 mm"})
    assert cn.batch_forward_kinematics(other, q[1:11], backend="compiled").ok.all()
    assert sorted(Path(compiled_cache).glob("compiled/*/*.so")) == libs


def test_a_slow_build_does_not_block_other_entries():
    """A C compilation in one thread must not stall single solves in others."""
    from cpm_nlp.core.solver import SolverCache

    cache = SolverCache()
    started, release = threading.Event(), threading.Event()

    def slow():
        started.set()
        release.wait(5)
        return "slow"

    builder = threading.Thread(target=lambda: cache.memo(("a",), slow))
    builder.start()
    assert started.wait(5)
    assert cache.memo(("b",), lambda: "fast") == "fast"  # returned while "a" is still building
    release.set()
    builder.join()
    assert cache.memo(("a",), lambda: "again") == "slow"


# -- the direct call on numbers (issue 23, item 3) ---------------------------------------------


def _poses(model, n, seed):
    """Actuators inside the stroke, beyond the joint limits and out of reach."""
    q = np.random.default_rng(seed).uniform(-2.5e-3, 2.5e-3, (n, 3))
    q[::17] = [0.3, -0.3, 0.0]  # out of reach
    q[5::23] = [4e-3, 0.0, 0.0]  # beyond the limits of the model below
    return q


def _casadi_call(fn, *args):
    """CasADi's own call (DM in, DM out) as numpy, for comparison."""
    out = fn(*[ca.DM(np.asarray(a, dtype=float)) for a in args])
    return [np.asarray(v) for v in (out if isinstance(out, tuple) else (out,))]


def _as_casadi_shape(value, shape):
    return np.reshape(np.asarray(value, dtype=float), shape, order="F")


@pytest.mark.parametrize("backend", ["auto", "map"])
def test_direct_fk_equals_casadi_call_bit_for_bit(backend):
    """fk, ik and jacobian on numbers give CasADi's own numbers to the bit, every status
    included, positional and by name; the types are numpy."""
    model = cn.build_model("prs3", PAPER_PRS3, {"s": ["-3 mm", "3 mm"]})
    fns = cn.functions(model, backend=backend)
    q = _poses(model, 200, 41)
    statuses = set()
    for qi in q:
        got = fns.fk(qi, model.x_home)
        want = _casadi_call(fns.fk, qi, model.x_home)
        assert len(got) == len(want) == 8
        for k, (g, w) in enumerate(zip(got, want)):
            np.testing.assert_array_equal(_as_casadi_shape(g, w.shape), w, err_msg=fns.fk.name_out()[k])
        named = fns.fk(q=qi.tolist(), x0=model.x_home)
        assert list(named) == fns.fk.name_out()
        np.testing.assert_array_equal(named["x"], got[0])
        statuses.add(cn.status_of(got[-1]))
    assert {Status.SOLVED, Status.NOT_CONVERGED, Status.OUTSIDE_JOINT_LIMITS} <= statuses
    assert isinstance(got[0], np.ndarray) and got[0].shape == (6, 1) and isinstance(got[-1], np.float64)
    expected = ("compiled" if compiler_available() else "map") if backend == "auto" else "map"
    assert fns.fk.backend_used == expected
    # the IK and the Jacobians: a matrix output comes back 2-D, as np.asarray of the DM
    t = np.column_stack([model.derived["pz0"] + q[:, 0], q[:, 1], q[:, 2]])
    t[3, 0] = 0.2  # unreachable
    for ti in t[:60]:
        for g, w in zip(fns.ik(ti), _casadi_call(fns.ik, ti)):
            np.testing.assert_array_equal(_as_casadi_shape(g, w.shape), w)
    sol = cn.forward_kinematics(model, q[1], NEWTON)
    jac = fns.jacobian(x=sol.x, q=sol.q)
    assert jac["J"].shape == (6, 3)
    for g, w in zip(jac.values(), _casadi_call(fns.jacobian, sol.x, sol.q)):
        np.testing.assert_array_equal(g, w)


def test_direct_fk_from_several_threads_equals_one_thread(fns, prs3):
    """One set of buffers per thread: 4 threads calling the same Function give the
    numbers of the serial calls (and of CasADi's call), each result its own copy."""
    q = _poses(prs3, 400, 42)
    serial = [fns.fk(qi, prs3.x_home) for qi in q]
    results: list = [None] * len(q)

    def work(lo):
        for k in range(lo, len(q), 4):
            results[k] = fns.fk(q=q[k], x0=prs3.x_home)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for k, (a, b) in enumerate(zip(results, serial)):
        for name, value in zip(fns.fk.name_out(), b):
            np.testing.assert_array_equal(a[name], value)
        if k % 40 == 0:
            np.testing.assert_array_equal(b[0], _casadi_call(fns.fk, q[k], prs3.x_home)[0])
    assert serial[0][0] is not serial[1][0] and not np.shares_memory(serial[0][0], serial[1][0])


def test_direct_fk_agrees_with_the_ik(fns, prs3):
    """FK against IK: the closed-form IK of every solved FK pose gives back its actuators,
    and the FK of the IK's actuators gives back the pose."""
    q = _poses(prs3, 120, 43)
    solved = 0
    for qi in q:
        out = fns.fk(q=qi, x0=prs3.x_home)
        if cn.status_of(out["status"]) is not Status.SOLVED:
            continue
        solved += 1
        back = fns.ik(t=prs3.task_of(out["x"]))
        assert cn.status_of(back["status"]) is Status.SOLVED
        np.testing.assert_allclose(back["q"].ravel(), qi, rtol=0, atol=1e-13)
        again = fns.fk(back["q"], prs3.x_home)
        np.testing.assert_allclose(again[0], out["x"], rtol=0, atol=1e-12)
    assert solved > 80


def test_direct_fk_keeps_casadi_semantics(fns, prs3):
    """Symbols and DMs stay CasADi's call; a missing name takes CasADi's default 0; a size
    CasADi would interpret goes to CasADi (which raises); unpickled it is a plain Function."""
    import pickle

    q = ca.MX.sym("q", 3)
    assert isinstance(fns.fk(q=q, x0=fns.x_home)["x"], ca.MX)
    assert isinstance(fns.fk(ca.DM([1e-3, 0, 0]), ca.DM(fns.x_home))[0], ca.DM)
    np.testing.assert_array_equal(fns.fk(q=[1e-3, 0, 0])["x"], np.asarray(fns.fk(q=ca.DM([1e-3, 0, 0]))["x"]))
    with pytest.raises(RuntimeError):
        fns.fk(q=[1e-3, 0], x0=fns.x_home)
    plain = pickle.loads(pickle.dumps(fns.fk))
    assert type(plain) is ca.Function and plain.name_out() == fns.fk.name_out()
    with pytest.raises(cn.InputError, match="unknown backend 'compile'"):
        cn.functions(prs3, backend="compile")


def test_direct_fk_without_a_working_compiler_uses_the_virtual_machine(tmp_path, monkeypatch, caplog):
    """backend "auto" and a compiler that fails: the call on numbers still answers, through a
    FunctionBuffer, with the same numbers (a warning says so)."""
    monkeypatch.setenv("CPM_NLP_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("CC", "false")  # a "compiler" that always fails
    model = cn.build_model("prs3", PAPER_PRS3)
    fns = cn.functions(model)
    q = np.array([1e-3, 0.5e-3, -0.3e-3])
    with caplog.at_level("WARNING", logger="cpm_nlp"):
        out = fns.fk(q, model.x_home)
    assert fns.fk.backend_used == "map" and "backend 'auto' uses 'map'" in caplog.text
    for got, want in zip(out, _casadi_call(fns.fk, q, model.x_home)):
        np.testing.assert_array_equal(_as_casadi_shape(got, want.shape), want)
