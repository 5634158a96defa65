"""The same answer on every machine (issue 19, item 5): a result that a numerical
library leaves to chance (an eigenvector's sign, the basis of a repeated
eigenvalue's subspace, a null space, the order of a ring of points) is reported
in one canonical form (cpm_nlp/core/canonical.py), so that it does not change
with the BLAS CPU kernel."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core import blas
from cpm_nlp.core.canonical import (
    CLUSTER_RTOL,
    canonical_basis,
    canonical_eigh,
    degenerate_note,
    eigen_clusters,
    multiplicities,
)
from cpm_nlp.core.screws import reciprocal_basis
from cpm_nlp.mechanisms.described.drawing import _polygon
from cpm_nlp.plot.draw import principal_axes
from tests.conftest import PROBLEMS, ROOT


def _random_orthogonal(rng, n):
    q, r = np.linalg.qr(rng.normal(size=(n, n)))
    return q * np.sign(np.diag(r))


def _synthetic(rng, values):
    """K, M (M positive definite, not diagonal) with the generalized eigenvalues ``values``
    and V, an M-orthonormal eigenbasis (K V = M V diag(values))."""
    n = len(values)
    A = rng.normal(size=(n, n))
    M = A @ A.T + n * np.eye(n)
    L = np.linalg.cholesky(M)
    Q = _random_orthogonal(rng, n)
    K = L @ Q @ np.diag(values) @ Q.T @ L.T
    V = np.linalg.solve(L.T, Q)
    return 0.5 * (K + K.T), M, V


# -- the canonical basis ------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(5))
def test_canonical_basis_depends_on_the_subspace_only(seed):
    """Any M-orthonormal basis of a degenerate subspace (rotated within it, signs flipped)
    gives the same canonical basis, to rounding."""
    rng = np.random.default_rng(seed)
    K, M, V = _synthetic(rng, [1.0, 2.0, 2.0, 2.0, 5.0, 7.0])
    reference = canonical_basis(V[:, 1:4], M)
    for _ in range(10):
        R = _random_orthogonal(rng, 3) * rng.choice([-1.0, 1.0], size=3)
        got = canonical_basis(V[:, 1:4] @ R, M)
        np.testing.assert_allclose(got, reference, rtol=0, atol=1e-12 * np.abs(reference).max())
    # the basis is M-orthonormal and spans the same subspace
    np.testing.assert_allclose(reference.T @ M @ reference, np.eye(3), atol=1e-12)
    P = V[:, 1:4] @ V[:, 1:4].T @ M  # the M-orthogonal projector on the subspace
    np.testing.assert_allclose(P @ reference, reference, atol=1e-12)


def test_canonical_basis_is_the_echelon_form_with_positive_pivots():
    """Echelon form w.r.t. the coordinates, orthonormalised in order, each vector's pivot
    component positive; with M = I on the plane x + y + z = 0
    (the 3-PRS's two equal modes): (1, 0, -1)/sqrt 2 and (-1, 2, -1)/sqrt 6."""
    rng = np.random.default_rng(7)
    plane = np.array([[1.0, -1.0, 0.0], [0.0, 1.0, -1.0]]).T @ _random_orthogonal(rng, 2)
    W = canonical_basis(plane)
    np.testing.assert_allclose(W[:, 0], np.array([1.0, 0.0, -1.0]) / np.sqrt(2), atol=1e-15)
    np.testing.assert_allclose(W[:, 1], np.array([-1.0, 2.0, -1.0]) / np.sqrt(6), atol=1e-15)
    assert W[1, 0] == 0.0  # a zero by symmetry is reported as 0, not +-1e-17


def test_a_simple_mode_has_a_sign():
    """One vector: its first significant component is positive, whichever sign it came with;
    a component that is rounding (1e-14) does not count."""
    v = np.array([[1e-14], [-0.6], [0.8]])
    for s in (1.0, -1.0):
        np.testing.assert_allclose(canonical_basis(s * v)[:, 0], [0.0, 0.6, -0.8], atol=1e-15)
    np.testing.assert_allclose(canonical_basis(np.array([[-3.0], [4.0]]))[:, 0], [0.6, -0.8], atol=1e-15)


@pytest.mark.parametrize("seed", range(3))
def test_canonical_eigh_is_the_same_after_a_change_of_rounding(seed):
    """K perturbed by 1e-13 relative (what another BLAS kernel does to it) and the
    coordinates' basis unchanged: the same frequencies, multiplicities and modes to 1e-9."""
    rng = np.random.default_rng(seed)
    K, M, _ = _synthetic(rng, [0.5, 3.0, 3.0, 4.0, 4.0, 4.0, 9.0])
    lam, V, clusters = canonical_eigh(K, M)
    assert clusters == [[0], [1, 2], [3, 4, 5], [6]]
    assert multiplicities(clusters) == [1, 2, 2, 3, 3, 3, 1]
    assert lam[1] == lam[2] and lam[3] == lam[4] == lam[5]  # a repeated value is repeated exactly
    E = rng.normal(size=K.shape)
    lam2, V2, clusters2 = canonical_eigh(K + 1e-13 * np.abs(K).max() * (E + E.T), M)
    assert clusters2 == clusters
    np.testing.assert_allclose(lam2, lam, rtol=1e-9)
    np.testing.assert_allclose(V2, V, rtol=0, atol=1e-9 * np.abs(V).max())
    np.testing.assert_allclose(V.T @ M @ V, np.eye(7), atol=1e-12)
    np.testing.assert_allclose(K @ V, M @ V * lam, atol=1e-10 * np.abs(K).max())


def test_clusters_follow_the_documented_tolerance():
    assert eigen_clusters([1.0, 1.0 + 0.5 * CLUSTER_RTOL, 2.0]) == [[0, 1], [2]]
    assert eigen_clusters([1.0, 1.0 + 2 * CLUSTER_RTOL, 2.0]) == [[0], [1], [2]]
    assert eigen_clusters([1e-17, -1e-17 + 2e-17, 5.0]) == [[0, 1], [2]]  # two zeros
    assert degenerate_note([1, 2]) == "f2 = f3: any combination of modes 2 and 3 is a mode"
    assert degenerate_note([0, 1, 2]) == "f1 = f2 = f3: any combination of modes 1, 2 and 3 is a mode"


# -- the 3-PRS: f2 = f3 --------------------------------------------------------------------------


def test_prs3_frequencies_report_the_double_frequency_and_its_canonical_modes():
    result = cn.solve(cn.load_problem(PROBLEMS / "prs3_natural_frequencies.yaml"))
    v = result.values
    assert result.ok and v["multiplicity"] == [1, 2, 2]
    assert v["f2"] == v["f3"] and v["f1"] < v["f2"]
    assert "f2 = f3: any combination of modes 2 and 3 is a mode" in result.message
    Q, M, K = (np.array(v[k]) for k in ("modes_q", "M", "K"))
    # mode 1 moves the three sliders together (+); modes 2 and 3 are the echelon basis of the rest read
    # in the pose coordinates (px, py, pz, psi, theta, phi): a tilt in psi alone, then one in theta alone
    np.testing.assert_allclose(Q[0] / Q[0, 0], [1.0, 1.0, 1.0], atol=1e-12)
    assert Q[0, 0] > 0
    np.testing.assert_allclose(Q[1] / Q[1, 1], [0.0, 1.0, -1.0], atol=1e-12)
    np.testing.assert_allclose(Q[2] / -Q[2, 0], [-1.0, 0.5, 0.5], atol=1e-12)
    assert Q[1, 0] == 0.0 and Q[1, 1] > 0 and Q[2, 1] > 0
    X = np.array(v["modes_x"])
    scale = np.abs(X[1:, 3:5]).max()
    assert X[1, 3] > 0 and abs(X[1, 4]) < 1e-12 * scale  # psi alone, positive
    assert X[2, 4] > 0 and abs(X[2, 3]) < 1e-12 * scale  # theta alone, positive
    np.testing.assert_allclose(Q @ M @ Q.T, np.eye(3), atol=1e-12)
    lam = (2 * np.pi * np.array([v["f1"], v["f2"], v["f3"]])) ** 2
    np.testing.assert_allclose(K @ Q.T, M @ Q.T * lam, rtol=0, atol=1e-9 * np.abs(K).max())
    assert "multiplicity" in problem_outputs()


def problem_outputs():
    problem = cn.load_problem(PROBLEMS / "prs3_natural_frequencies.yaml")
    return problem.kind.output_names(problem.model)


def test_the_modes_plot_says_the_modes_are_degenerate():
    pytest.importorskip("matplotlib")
    from cpm_nlp.plot import figures

    problem = cn.load_problem(PROBLEMS / "prs3_natural_frequencies.yaml")
    data = figures.from_result(cn.solve(problem))
    data.live = problem.model
    fig, kind = figures.figure(data)
    assert kind == "modes"
    assert "f2 = f3: any combination of modes 2 and 3 is a mode" in fig.get_suptitle()


# -- two BLAS kernels ---------------------------------------------------------------------------------

_MODES = """
import json, sys
import numpy as np, scipy.linalg
from threadpoolctl import threadpool_info
import cpm_nlp as cn
r = cn.solve(cn.load_problem(sys.argv[1]))
np.ones(2) @ np.ones(2)
kernels = sorted({str(i.get("architecture")) for i in threadpool_info() if i.get("user_api") == "blas"})
print(json.dumps({"kernel": "+".join(kernels), "modes_q": r.values["modes_q"],
                  "multiplicity": r.values["multiplicity"], "f": [r.values[f"f{k}"] for k in (1, 2, 3)]}))
"""


def _modes_under(coretype: str | None) -> dict:
    env = dict(os.environ)
    if coretype is not None:
        env["OPENBLAS_CORETYPE"] = coretype
    path = str(PROBLEMS / "prs3_natural_frequencies.yaml")
    run = subprocess.run(
        [sys.executable, "-c", _MODES, path], capture_output=True, text=True, env=env, cwd=ROOT, timeout=120
    )
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout.splitlines()[-1])


def test_modes_are_the_same_under_two_blas_kernels():
    """The 3-PRS's modes in a subprocess under the machine's kernel and under another
    (OPENBLAS_CORETYPE: Sandybridge, or Nehalem where Sandybridge already runs): equal to
    1e-9 of the largest entry.  Before the canonical basis, Sandybridge mixed modes 2 and 3
    and flipped mode 1."""
    first = _modes_under(None)
    x86 = ("Haswell", "SkylakeX", "Zen", "Cooperlake", "Sapphirerapids", "Sandybridge", "Nehalem")
    if not any(k in first["kernel"] for k in x86):
        pytest.skip(f"no OpenBLAS x86-64 kernel to switch to (this machine runs {first['kernel']})")
    other = "Nehalem" if "Sandybridge" in first["kernel"] else "Sandybridge"
    second = _modes_under(other)
    assert second["kernel"] == other, f"OPENBLAS_CORETYPE={other} was not taken: {second['kernel']}"
    assert first["multiplicity"] == second["multiplicity"] == [1, 2, 2]
    np.testing.assert_allclose(second["f"], first["f"], rtol=1e-12)
    a, b = np.array(first["modes_q"]), np.array(second["modes_q"])
    np.testing.assert_allclose(b, a, rtol=0, atol=1e-9 * np.abs(a).max())


# -- other canonical forms ---------------------------------------------------------------------------


def test_ellipsoid_axes_have_a_fixed_sign_and_equal_axes_lie_along_the_coordinates():
    rng = np.random.default_rng(3)
    R = _random_orthogonal(rng, 3)
    S = R @ np.diag([1e-7, 2e-7, 4e-7]) @ R.T
    w, V = principal_axes(S)
    np.testing.assert_allclose(w, [1e-7, 2e-7, 4e-7], rtol=1e-12)
    for k in range(3):
        first = next(i for i in range(3) if abs(V[i, k]) > 0.1)
        assert V[first, k] > 0  # the first significant component is positive
        assert abs(abs(V[:, k] @ R[:, k]) - 1) < 1e-12
    w2, V2 = principal_axes(R @ np.diag([1e-7, 2e-7, 4e-7]) @ R.T + 1e-22 * np.eye(3))
    np.testing.assert_allclose(V2, V, atol=1e-9)
    # a circle in x-y: its axes are x and y (any pair of axes would do; these are canonical)
    w, V = principal_axes(np.diag([3e-8, 3e-8, 1e-8]) + 1e-24 * np.ones((3, 3)))
    assert w[1] == w[2]
    np.testing.assert_allclose(np.abs(V), np.eye(3)[:, [2, 0, 1]], atol=1e-9)
    assert np.all(np.diag(V[[2, 0, 1]]) > 0)


def test_reciprocal_screws_come_in_a_canonical_basis():
    """The null space of an SVD is any basis of it; reciprocal_basis gives one basis for
    the span of the screws, whatever combination of them it is given."""
    rng = np.random.default_rng(4)
    screws = rng.normal(size=(6, 3))
    base = reciprocal_basis(screws)
    assert base.shape == (6, 3)
    for _ in range(5):
        mixed = screws @ rng.normal(size=(3, 3))  # the same span
        np.testing.assert_allclose(reciprocal_basis(mixed), base, atol=1e-10)


def test_a_face_ring_starts_at_its_first_point_whatever_the_rotation():
    """A regular hexagon (equal singular values: any in-plane axes) keeps one ring order
    under rotations and reflections of space."""
    rng = np.random.default_rng(5)
    names = [f"p{k}" for k in range(6)]
    angles = [0, 2, 4, 1, 3, 5]  # given out of order around the ring
    flat = {n: np.array([np.cos(a * np.pi / 3), np.sin(a * np.pi / 3), 0.0]) for n, a in zip(names, angles)}
    reference = _polygon(flat, names, 1e-9)
    assert reference[0] == "p0" and set(reference) == set(names)
    assert reference == ["p0", "p3", "p1", "p4", "p2", "p5"]  # around the ring, towards the lower neighbour
    for _ in range(5):
        R = _random_orthogonal(rng, 3)
        moved = {n: R @ p + 0.1 for n, p in flat.items()}
        assert _polygon(moved, names, 1e-9) == reference


def test_one_blas_thread_within_small_algebra():
    from threadpoolctl import threadpool_info

    with blas.small_algebra():
        assert all(i["num_threads"] == 1 for i in threadpool_info() if i["user_api"] == "blas")
