"""Canonical forms of results that a numerical library leaves to chance.

An eigenvector has no sign of its own, and the eigenvectors of a repeated
eigenvalue are any basis of its subspace: LAPACK returns one that depends on
the BLAS CPU kernel (the 3-PRS has f2 = f3, and its modes 2 and 3 came out
mixed differently on a Haswell and a Sandybridge kernel).  The functions here
return the same answer on every machine, to rounding:

* `eigen_clusters` groups sorted eigenvalues that agree to
  `CLUSTER_RTOL` (relative) into clusters: a repeated eigenvalue and its
  multiplicity.
* `canonical_basis` is the convention for the basis of a subspace (a
  cluster's, or a single eigenvector's sign): the reduced row echelon form of
  the subspace with respect to the coordinates in their order, orthonormalised
  in order (in the metric ``M``), each vector's component on its pivot
  coordinate positive.  It depends on the subspace only, never on the basis it
  is given.  For one vector it reads: the first coordinate that carries a
  significant part of the vector (`PIVOT_FRACTION`) is positive.
* `canonical_eigh` is ``scipy.linalg.eigh`` with both applied.

The general rule of the project (docs/site/design.md): a result that is only
defined up to a sign, a basis or an order is reported in one documented
canonical form, computed here.
"""

from __future__ import annotations

import numpy as np

#: eigenvalues within this relative distance (of the larger of two neighbours,
#: or of the largest eigenvalue near zero) form one cluster: a repeated eigenvalue.
#: Rounding across BLAS kernels moves a double eigenvalue by ~1e-15; two distinct
#: frequencies closer than this are reported as one, and their modes as a subspace.
CLUSTER_RTOL = 1e-6

#: a coordinate becomes a pivot of the echelon form when the subspace has a part
#: along it of at least this fraction (the cosine of the angle between the subspace,
#: beyond the earlier pivots, and the coordinates so far); below it the coordinate
#: is treated as zero in the subspace.  Not a "round" number, so that a symmetric
#: mechanism (cosines 1/2, 1/sqrt(2), 1/sqrt(3) ...) never sits on the threshold.
PIVOT_FRACTION = 0.0731

#: an entry of a canonical vector below this fraction of its largest entry is rounding
#: (a zero by symmetry) and is reported as 0.0
ZERO_RTOL = 1e-12


def eigen_clusters(values: np.ndarray, rtol: float = CLUSTER_RTOL) -> list[list[int]]:
    """Indices of the ascending ``values`` grouped into clusters of equal values:
    neighbours ``a <= b`` are equal when ``b - a <= rtol * max(|a|, |b|, 1e-6 * max|values|)``."""
    values = np.asarray(values, dtype=float)
    if values.size == 0:
        return []
    floor = 1e-6 * float(np.max(np.abs(values)))
    clusters = [[0]]
    for k in range(1, values.size):
        a, b = values[k - 1], values[k]
        if b - a <= rtol * max(abs(a), abs(b), floor):
            clusters[-1].append(k)
        else:
            clusters.append([k])
    return clusters


def _pivots(Q: np.ndarray) -> list[int]:
    """The pivot coordinates of the echelon form of the span of the orthonormal
    columns of ``Q`` (n x m): coordinate j is a pivot when the m-th singular value
    of rows 0..j rises above `PIVOT_FRACTION` for the (d+1)-th time, d the
    pivots so far.  Singular values of an orthonormal basis' rows are invariant
    under a change of basis, so the pivots depend on the subspace only."""
    n, m = Q.shape
    pivots: list[int] = []
    for j in range(n):
        if len(pivots) == m:
            break
        s = np.linalg.svd(Q[: j + 1], compute_uv=False)
        if s.size > len(pivots) and s[len(pivots)] > PIVOT_FRACTION:
            pivots.append(j)
    for j in range(n):  # fewer than m pivots only if rounding ate one: fill in order
        if len(pivots) == m:
            break
        if j not in pivots:
            pivots.append(j)
    return sorted(pivots)


def canonical_basis(V: np.ndarray, M: np.ndarray | None = None, T: np.ndarray | None = None) -> np.ndarray:
    """The canonical basis of the span of the columns of ``V`` (n x m, full column rank).

    The echelon form is taken in the coordinates the user reads: those of ``T V``
    when ``T`` (p x n, e.g. the task Jacobian that maps actuator motions to pose
    coordinates) is given and ``T V`` has rank m, else those of ``V``, weighted by
    sqrt(diag M) (so their units do not matter).  The pivots are chosen in
    coordinate order (`_pivots`); the basis W with W[pivots] = I (the
    reduced row echelon form) is orthonormalised in order in the metric M
    (identity if None) by Gram-Schmidt, which keeps each vector's pivot
    component positive.  The result is M-orthonormal, and the same for any basis
    V of the same subspace: with T, the 3-PRS's two equal tilt modes come out as
    a tilt about x and a tilt about y."""
    V = np.asarray(V, dtype=float)
    n, m = V.shape
    M = np.eye(n) if M is None else np.asarray(M, dtype=float)
    d = np.sqrt(np.clip(np.diag(M), 0.0, None))
    d = np.where(d > 0, d, 1.0)
    view = _coordinates(V, d, T)  # the reading coordinates: maps a vector of R^n to them
    X = view(V)
    Q, R = np.linalg.qr(X)  # orthonormal basis of the subspace in the reading coordinates
    piv = _pivots(Q)
    W = V @ np.linalg.solve(R, np.linalg.inv(Q[piv]))  # echelon form: view(W)[piv] = I
    out = np.zeros((n, m))
    for k in range(m):
        w = W[:, k].copy()
        for i in range(k):  # twice: classical Gram-Schmidt, re-orthogonalised
            w -= (out[:, i] @ M @ w) * out[:, i]
        for i in range(k):
            w -= (out[:, i] @ M @ w) * out[:, i]
        w /= np.sqrt(w @ M @ w)
        w[np.abs(w) <= ZERO_RTOL * np.abs(w).max()] = 0.0  # a zero by symmetry is 0, not +-1e-17
        out[:, k] = w if view(w[:, None])[piv[k], 0] >= 0 else -w
    return out


def _coordinates(V: np.ndarray, d: np.ndarray, T: np.ndarray | None):
    """The map from R^n to the coordinates a canonical basis is read in: ``T x``
    when T keeps the span of V at full rank, else ``d * x`` (the weighted own coordinates)."""
    if T is not None:
        T = np.asarray(T, dtype=float)
        X = T @ V
        s = np.linalg.svd(X, compute_uv=False)
        if s.size == V.shape[1] and s[-1] > 1e-9 * max(s[0], 1e-300):
            return lambda x: T @ x
    return lambda x: d[:, None] * x


def canonical_eigh(K: np.ndarray, M: np.ndarray | None = None, rtol: float = CLUSTER_RTOL, T: np.ndarray | None = None):
    """``scipy.linalg.eigh(K, M)`` in canonical form: (eigenvalues, eigenvectors as
    columns, clusters).  The eigenvalues of a cluster are replaced by their mean
    (a repeated eigenvalue is reported once, exactly repeated); the eigenvectors of
    each cluster are its `canonical_basis` (M-orthonormal, sign fixed), read
    in the coordinates of ``T`` (e.g. the task Jacobian) when it is given."""
    import scipy.linalg  # here: a solve that needs no eigenvalues loads no scipy (start-up time)

    K = np.asarray(K, dtype=float)
    lam, V = scipy.linalg.eigh(K, M) if M is not None else scipy.linalg.eigh(K)
    clusters = eigen_clusters(lam, rtol)
    lam = lam.copy()
    for idx in clusters:
        lam[idx] = float(np.mean(lam[idx]))
        V[:, idx] = canonical_basis(V[:, idx], M, T)
    return lam, V, clusters


def multiplicities(clusters: list[list[int]]) -> list[int]:
    """The multiplicity of each eigenvalue, in order (1 for a simple one)."""
    out = [0] * sum(len(c) for c in clusters)
    for idx in clusters:
        for k in idx:
            out[k] = len(idx)
    return out


def degenerate_note(cluster: list[int]) -> str:
    """The sentence that says a frequency is repeated, e.g. "f2 = f3: any combination
    of modes 2 and 3 is a mode" (``cluster``: 0-based indices of the modes)."""
    k = [i + 1 for i in cluster]
    fs = " = ".join(f"f{i}" for i in k)
    modes = ", ".join(str(i) for i in k[:-1]) + f" and {k[-1]}"
    return f"{fs}: any combination of modes {modes} is a mode"
