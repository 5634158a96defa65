"""Twists, wrenches and compliance matrices (screw theory), for every mechanism.

Conventions (those of the papers; e.g. rpr-2rpu-upr-zhang-2022.md, eq 7-19
and the appendix):

* A screw is a 6-vector in Plücker *axis* order ``(s; s0)``, referred to a
  reference point c.
* A **twist** is ``(ω; v)``: angular velocity ω and the velocity v of the body
  point that coincides with c.  A unit rotation about the line through a with
  direction s is ``(s; (a - c) × s)``; a unit translation along s is ``(0; s)``.
* A **wrench** is ``(f; m)``: force f and its moment m about c.  A unit force
  along the line through a is ``(s; (a - c) × s)`` (the same line coordinates
  as the rotation), a couple is ``(0; s)``.
* The **reciprocal product** ``$1 ∘ $2 = s1·s02 + s01·s2 = $1ᵀ Δ $2`` with
  Δ = [[0, I], [I, 0]]; for a twist and a wrench it is their power.  It does not
  depend on the reference point.
* A **compliance matrix** C maps a wrench ``(f; m)`` applied at its reference
  point to the small displacement ``(δ; φ)`` (translation first, rotation
  second) of that point: ``(δ; φ) = C (f; m)``; the work of a wrench w is
  ``wᵀ C w``.

Every function accepts numpy arrays and CasADi symbols (SX/MX) alike, except
`reciprocal_basis` (numerical: an SVD) and `null_screw`'s
numerical branch noted there.
"""

from __future__ import annotations

from typing import Any

import casadi as ca
import numpy as np

from .canonical import canonical_basis

#: Δ of the reciprocal product, $1ᵀ Δ $2 (rpr-2rpu-upr-zhang-2022.md, eq 9).
DELTA = np.block([[np.zeros((3, 3)), np.eye(3)], [np.eye(3), np.zeros((3, 3))]])


def _symbolic(*args: Any) -> bool:
    return any(isinstance(a, (ca.SX, ca.MX, ca.DM)) for a in args)


def _ca(a: Any) -> Any:
    """A CasADi column from a CasADi expression or numbers."""
    if isinstance(a, (ca.SX, ca.MX, ca.DM)):
        return ca.vec(a)
    return ca.DM(np.asarray(a, dtype=float).reshape(-1, 1))


def _cross(a: Any, b: Any) -> Any:
    if _symbolic(a, b):
        return ca.cross(_ca(a), _ca(b))
    return np.cross(np.asarray(a, dtype=float).ravel(), np.asarray(b, dtype=float).ravel())


def _cat(*parts: Any) -> Any:
    if _symbolic(*parts):
        return ca.vertcat(*[_ca(p) for p in parts])
    return np.concatenate([np.asarray(p, dtype=float).ravel() for p in parts])


def _dot(a: Any, b: Any) -> Any:
    if _symbolic(a, b):
        return ca.dot(_ca(a), _ca(b))
    return float(np.dot(np.asarray(a, dtype=float).ravel(), np.asarray(b, dtype=float).ravel()))


def _norm(a: Any) -> Any:
    return ca.norm_2(_ca(a)) if _symbolic(a) else float(np.linalg.norm(np.asarray(a, dtype=float)))


def skew(a: Any) -> Any:
    """[a]×, the matrix with [a]× b = a × b."""
    if _symbolic(a):
        a = _ca(a)
        return ca.vertcat(
            ca.horzcat(0, -a[2], a[1]),
            ca.horzcat(a[2], 0, -a[0]),
            ca.horzcat(-a[1], a[0], 0),
        )
    a = np.asarray(a, dtype=float).ravel()
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def axis_rotation(axis: Any, angle: Any) -> Any:
    """The rotation by ``angle`` about the unit ``axis`` k (Rodrigues' formula),
    R = cos θ I + sin θ [k]× + (1 - cos θ) k kᵀ (= I + sin θ [k]× + (1 - cos θ) [k]×² for a
    unit k): a CasADi matrix if the axis or the angle is CasADi (SX in, SX out), else a numpy
    array.  The k kᵀ form lets the zero entries of an axis along a base axis drop out of a
    symbolic R (the elementary rotation itself: cos, ±sin, 1).  The one rotation of the
    package: the file mechanisms' joints, the hinge chains and the URDF importer use it."""
    if _symbolic(axis, angle):
        k = axis if isinstance(axis, (ca.SX, ca.MX)) else _ca(axis)
        c, s = ca.cos(angle), ca.sin(angle)
        return c * ca.DM.eye(3) + s * ca.skew(k) + (1 - c) * (k @ k.T)
    k = np.asarray(axis, dtype=float).ravel()
    return np.cos(angle) * np.eye(3) + np.sin(angle) * skew(k) + (1.0 - np.cos(angle)) * np.outer(k, k)


def vee(M: Any) -> Any:
    """The axial vector of a 3 x 3 matrix's skew part, (M - Mᵀ)/2 = [v]× (the inverse of
    `skew`; for a rotation by a small angle about w: the angle times w)."""
    return 0.5 * ca.vertcat(M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1])


# -- elementary screws ----------------------------------------------------------------------------


def line(direction: Any, point: Any, reference: Any = (0.0, 0.0, 0.0)) -> Any:
    """Line coordinates ``(s; (a - c) × s)`` of the line through ``point`` (a)
    with direction ``direction`` (s, not normalised), referred to ``reference`` (c).

    It is the twist of a rotation about that line and the wrench of a force
    along it (unit rate or magnitude when |s| = 1)."""
    s = direction
    arm = _sub(point, reference)
    return _cat(s, _cross(arm, s))


def rotation(axis: Any, point: Any, reference: Any = (0.0, 0.0, 0.0)) -> Any:
    """Twist of a rotation at unit rate about ``axis`` through ``point``."""
    return line(axis, point, reference)


def force(direction: Any, point: Any, reference: Any = (0.0, 0.0, 0.0)) -> Any:
    """Wrench of a force ``direction`` acting along the line through ``point``."""
    return line(direction, point, reference)


def translation(direction: Any) -> Any:
    """Twist of a translation ``direction`` (a free vector): ``(0; s)``."""
    return _cat(_zeros3(direction), direction)


def couple(direction: Any) -> Any:
    """Wrench of a couple (pure moment) ``direction``: ``(0; s)``."""
    return translation(direction)


def _zeros3(like: Any) -> Any:
    return ca.DM.zeros(3, 1) if _symbolic(like) else np.zeros(3)


def _sub(a: Any, b: Any) -> Any:
    if _symbolic(a, b):
        return _ca(a) - _ca(b)
    return np.asarray(a, dtype=float).ravel() - np.asarray(b, dtype=float).ravel()


def _add(a: Any, b: Any) -> Any:
    if _symbolic(a, b):
        return _ca(a) + _ca(b)
    return np.asarray(a, dtype=float).ravel() + np.asarray(b, dtype=float).ravel()


# -- operations -------------------------------------------------------------------------------------


def reciprocal(a: Any, b: Any) -> Any:
    """Reciprocal product ``a ∘ b = a[:3]·b[3:] + a[3:]·b[:3]`` (= aᵀ Δ b):
    the power of a wrench on a twist; zero when they are reciprocal."""
    return _dot(a[0:3], b[3:6]) + _dot(a[3:6], b[0:3])


def transport(screw: Any, reference: Any, new_reference: Any) -> Any:
    """The same screw referred to ``new_reference`` instead of ``reference``:
    ``s0' = s0 + s × (c' - c)``.  For a twist this is the velocity of the body
    point at c'; for a wrench the moment about c'."""
    s = screw[0:3]
    return _cat(s, _add(screw[3:6], _cross(s, _sub(new_reference, reference))))


def velocity_at(twist: Any, reference: Any, point: Any) -> Any:
    """Velocity of the body point at ``point`` for a twist referred to ``reference``."""
    return transport(twist, reference, point)[3:6]


def pitch(screw: Any) -> Any:
    """h = s·s0 / |s|² (0 for a rotation or a force; infinite pitch, |s| = 0,
    is not defined here)."""
    s = screw[0:3]
    return _dot(s, screw[3:6]) / _dot(s, s)


def axis_point(screw: Any, reference: Any = (0.0, 0.0, 0.0)) -> Any:
    """The point of the screw axis nearest the reference point,
    ``c + s × s0 / |s|²`` (for |s| > 0)."""
    s = screw[0:3]
    offset = _cross(s, screw[3:6]) / _dot(s, s)
    return _add(reference, offset)


def distance_to_axis(screw: Any, point: Any, reference: Any = (0.0, 0.0, 0.0)) -> Any:
    """Distance from ``point`` to the axis of a screw with |s| > 0."""
    s = screw[0:3]
    rel = _sub(point, axis_point(screw, reference))
    return _norm(_cross(rel, s)) / _norm(s)


def normalize(screw: Any) -> Any:
    """The screw scaled to |s| = 1 (rotations, forces, finite-pitch screws)."""
    return screw / _norm(screw[0:3])


def null_screw(rows: Any) -> Any:
    """The screw X with ``rowsᵀ Δ X = 0`` for five independent screws (the
    columns of the 6 x 5 ``rows``): the generalised cross product, component
    k = (-1)^k det(M without column k) of M = rowsᵀ Δ.  Works on CasADi
    symbols (used inside IPOPT) and numbers; its scale is arbitrary."""
    symbolic = _symbolic(rows)
    M = (ca.DM(DELTA) @ rows).T if symbolic else (DELTA @ np.asarray(rows, dtype=float)).T  # 5 x 6
    comps = []
    for k in range(6):
        cols = [j for j in range(6) if j != k]
        minor = M[:, cols]
        det = ca.det(minor) if symbolic else float(np.linalg.det(minor))
        comps.append(det if k % 2 == 0 else -det)
    return ca.vertcat(*comps) if symbolic else np.array(comps)


def reciprocal_basis(screws: Any, tol: float = 1e-9) -> np.ndarray:
    """Columns spanning every screw reciprocal to all columns of ``screws``
    (numerical, by SVD; relative tolerance ``tol``), orthonormal, in the canonical
    basis of `cpm_nlp.core.canonical.canonical_basis` (the SVD's null space
    is any basis of it, which depends on the BLAS kernel)."""
    A = (DELTA @ np.asarray(screws, dtype=float)).T
    _, sv, vt = np.linalg.svd(A)
    rank = int(np.sum(sv > tol * (sv[0] if sv.size else 1.0)))
    null = vt[rank:].T
    return canonical_basis(null) if null.shape[1] else null


# -- compliance matrices -------------------------------------------------------------------------


def wrench_transform(d: Any) -> Any:
    """T with ``w_A = T w_B`` for a wrench given at B and referred to A,
    d = B - A: ``m_A = m_B + d × f``."""
    S = skew(d)
    if _symbolic(d):
        return ca.vertcat(ca.horzcat(ca.DM.eye(3), ca.DM.zeros(3, 3)), ca.horzcat(S, ca.DM.eye(3)))
    return np.block([[np.eye(3), np.zeros((3, 3))], [S, np.eye(3)]])


def transport_compliance(C: Any, point: Any, new_point: Any) -> Any:
    """A compliance matrix defined at ``point`` (A), for wrenches applied and
    displacements measured at ``new_point`` (B): ``C_B = Tᵀ C_A T`` with
    T = `wrench_transform` (B - A)."""
    T = wrench_transform(_sub(new_point, point))
    return T.T @ C @ T


def rotate_compliance(C: Any, R: Any) -> Any:
    """A compliance matrix given in a frame whose axes are the columns of R,
    expressed in the reference frame: ``blkdiag(R, R) C blkdiag(R, R)ᵀ``."""
    if _symbolic(C, R):
        Z = ca.DM.zeros(3, 3)
        B = ca.vertcat(ca.horzcat(R, Z), ca.horzcat(Z, R))
    else:
        R = np.asarray(R, dtype=float)
        B = np.block([[R, np.zeros((3, 3))], [np.zeros((3, 3)), R]])
    return B @ C @ B.T
