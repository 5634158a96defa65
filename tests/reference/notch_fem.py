"""An independent 3-D finite-element reference for flexure hinges and beams, in scikit-fem
(https://scikit-fem.readthedocs.io; the optional ``fem`` extra): a right-circular notch hinge
and a prismatic beam (the 3-PRS leg).  Test and benchmark code, not part of the package.

Model (both bodies)
-------------------
Frame: x along the body, y across the thickness (the notch's thinnest section t is along y),
z across the width w (the notch's compliant axis).  The body runs from x0 to x1:

* the face x = x0 is clamped (u = 0): the fixed block;
* the face x = x1 is tied to a rigid block, u = a + θ × (X - X1) with X1 = (x1, 0, 0), whose six
  rigid-body coordinates (a, θ) carry the load (a force and a moment at X1, their work
  conjugates).  The rotation θ is the block's rigid rotation itself (for a rigid block it is
  the least-squares fit of its face's displacement, exactly).

Only a quarter is meshed, y >= 0 and z >= 0, and the six load cases split over four
symmetry cases of the two planes y = 0 and z = 0 (S: symmetric, u normal to the plane = 0;
A: antisymmetric, the two in-plane components = 0):

====== ====== ====== =============================
z = 0  y = 0  block  loads
====== ====== ====== =============================
S      A      a_y θ_z  force along y, moment about z
S      S      a_x      axial force
A      S      a_z θ_y  force along z, moment about y
A      A      θ_x      torsion
====== ====== ====== =============================

so the 6 x 6 compliance at X1 is four small solves (its (a_y, θ_z) and (a_z, θ_y) blocks
are the only couplings the symmetry allows).  The quarter carries a quarter of the load:
the full body's compliance is the quarter's divided by four.

Elements: triquadratic 27-node hexahedra (``ElementHex2``) on an isoparametric quadratic mesh
(``MeshHex2``): the mapped structured mesh is built on the unit cube and every node, the
mid-edge, mid-face and centre nodes too, is mapped onto the exact geometry, so the notch's
circular flanks are interpolated quadratically.  Linear elasticity, small strains, an
isotropic material (E, ν).

Notch mesh: x = R sin φ with tan(φ/2) = k tan ψ, k = sqrt(t/(t + 4R)), ψ uniform (the
substitution `cpm_nlp.analysis.flexure_compliance` integrates in: it puts the elements where
the section is thin), blended 50/50 with a uniform spacing; y = η h(x)/2 with the notch
profile h(x) = t + 2 (R - sqrt(R² - x²)); z graded geometrically towards the free edge
z = w/2 (the anticlastic boundary layer, about t wide).  The notch is modelled over
-R <= x <= R, the length the closed forms integrate over (blocks beyond it rigid).

Convergence: `converged` solves on three meshes, each halving every element size of the
previous one in the mapped coordinates, and Richardson-extrapolates every quantity
(observed order p from the three, the extrapolated value, and the error estimate
|extrapolated - finest|).

Stress: the stress at the root, at mid-width (x = 0, y = t/2, z = 0) and at the edge
(z = w/2), from the displacement gradient in the elements sharing that vertex (averaged),
under the moment about z; σ_xx and von Mises, each as a ratio to the nominal 6M/(w t²).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import Basis, BilinearForm, ElementHex2, ElementVector, MeshHex, MeshHex2, asm
from skfem.helpers import ddot, sym_grad, trace

#: the four symmetry cases: (symmetric about z = 0, symmetric about y = 0, rigid coordinates)
#: rigid coordinates indexed 0..5 = (a_x, a_y, a_z, θ_x, θ_y, θ_z)
#: the mesh scales of the convergence study (element counts = scale x the body's base counts)
SCALES = (2, 3, 4)

SYMMETRY_CASES = (
    (True, False, (1, 5)),
    (True, True, (0,)),
    (False, True, (2, 4)),
    (False, False, (3,)),
)


@dataclasses.dataclass(frozen=True)
class Body:
    """A body meshed from the unit cube: x(ξ), half-height y_top(x) and z(ζ)."""

    x0: float
    x1: float
    x_of: object  # ξ in [0, 1] -> x
    half_height: object  # x -> h(x)/2
    z_of: object  # ζ in [0, 1] -> z in [0, w/2]
    base: tuple  # elements (nx, ny, nz) of the coarsest mesh


UNIFORM_SHARE = 0.2  # of the notch mesh in x, the rest follows the ψ substitution


def notch_body(t: float, R: float, w: float, block: float | None = None, base=(8, 1, 2)) -> Body:
    """A right-circular notch hinge: thinnest section t, notch radius R, width w, between two
    elastic blocks of height t + 2R, width w and length ``block`` (default t + 2R; 0: the
    notch's end faces x = ±R are themselves the clamp and the rigid block)."""
    k = math.sqrt(t / (t + 4.0 * R))
    psi_end = math.atan(1.0 / k)
    H = t + 2.0 * R
    Lb = H if block is None else block
    nb = 1 if Lb > 0 else 0  # elements along each block, per unit scale
    f = nb / (2 * nb + base[0])  # the fraction of ξ in each block
    gamma = 3.0  # block elements graded towards the notch

    def notch_x(xi):
        psi = (2.0 * xi - 1.0) * psi_end
        phi = 2.0 * np.arctan(k * np.tan(psi))
        return R * (UNIFORM_SHARE * (2.0 * xi - 1.0) + (1.0 - UNIFORM_SHARE) * np.sin(phi))

    def x_of(xi):
        xi = np.asarray(xi, float)
        if nb == 0:
            return notch_x(xi)
        inner = notch_x(np.clip((xi - f) / (1.0 - 2.0 * f), 0.0, 1.0))
        left = -R - Lb * np.expm1(gamma * (f - xi) / f) / math.expm1(gamma)
        right = R + Lb * np.expm1(gamma * (xi - 1.0 + f) / f) / math.expm1(gamma)
        return np.where(xi < f, left, np.where(xi > 1.0 - f, right, inner))

    def half_height(x):
        return 0.5 * (t + 2.0 * (R - np.sqrt(np.maximum(R**2 - x**2, 0.0))))

    beta = math.log1p(w / (4.0 * t))  # grading towards the free edge

    def z_of(zeta):
        return 0.5 * w * (1.0 - np.expm1(beta * (1.0 - zeta)) / math.expm1(beta))

    return Body(-R - Lb, R + Lb, x_of, half_height, z_of, (base[0] + 2 * nb, base[1], base[2]))


def block_compliances(t, R, w, block, E, nu) -> dict:
    """The beam compliances of the two prismatic blocks (height H = t + 2R, width w, length
    ``block`` each), subtracted from the body's to leave the notch's: 2 L/(E A), 2 L/(E I),
    2 L/(G J) (Euler-Bernoulli, Saint-Venant with Roark's J)."""
    from cpm_nlp.analysis.flexure_compliance import rectangle_torsion_constant

    H, G = t + 2.0 * R, E / (2.0 * (1.0 + nu))
    L2 = 2.0 * block
    return {
        "axial": L2 / (E * H * w),
        "bend": L2 / (E * w * H**3 / 12.0),
        "bend2": L2 / (E * H * w**3 / 12.0),
        "torsion": L2 / (G * rectangle_torsion_constant(max(H, w), min(H, w))),
    }


def beam_body(a: float, b: float, L: float, base=(8, 1, 1)) -> Body:
    """A prismatic beam of length L along x, section a (along y) x b (along z)."""
    return Body(0.0, L, lambda xi: L * xi, lambda x: 0.5 * a + 0.0 * x, lambda zeta: 0.5 * b * zeta, base)


def mesh(body: Body, scale: int) -> MeshHex2:
    """The quadratic hexahedral mesh of a quarter of ``body`` (y >= 0, z >= 0), ``scale`` times
    the elements of ``body.base`` along each direction (every element size divided by scale)."""
    nx, ny, nz = (n * scale for n in body.base)
    cube = MeshHex.init_tensor(np.linspace(0, 1, nx + 1), np.linspace(0, 1, ny + 1), np.linspace(0, 1, nz + 1))
    quad = MeshHex2.from_mesh(cube)
    xi, eta, zeta = quad.doflocs
    x = body.x_of(xi)
    y = eta * body.half_height(x)
    z = body.z_of(zeta)
    # the cube's end faces map exactly onto x0, x1 (no round-off in the boundary tests)
    x = np.where(xi == 0.0, body.x0, np.where(xi == 1.0, body.x1, x))
    return dataclasses.replace(quad, doflocs=np.vstack([x, y, z]))


def _stiffness(basis, E, nu):
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))

    @BilinearForm
    def form(u, v, w):
        eu, ev = sym_grad(u), sym_grad(v)
        return 2.0 * mu * ddot(eu, ev) + lam * trace(eu) * trace(ev)

    return asm(form, basis)


def _dofs(basis, where, comps):
    view = basis.get_dofs(where)
    return np.unique(np.concatenate([view.all(f"u^{c + 1}") for c in comps]).astype(int))


def _rigid_rows(locs, comp, X1, coords):
    """The coefficients of the rigid coordinates ``coords`` in u_comp = (a + θ × (X - X1))_comp."""
    d = locs - np.asarray(X1)[:, None]
    rows = np.zeros((locs.shape[1], len(coords)))
    # u = a + θ × d: ux = a_x + θy dz - θz dy, uy = a_y + θz dx - θx dz, uz = a_z + θx dy - θy dx
    table = {
        0: {0: 1.0, 4: d[2], 5: -d[1]},
        1: {1: 1.0, 5: d[0], 3: -d[2]},
        2: {2: 1.0, 3: d[1], 4: -d[0]},
    }[comp]
    for j, c in enumerate(coords):
        if c in table:
            rows[:, j] = table[c]
    return rows


def solve(body: Body, scale: int, E: float, nu: float, stress_at=None, cases=None) -> dict:
    """The 6 x 6 compliance of the full body at X1 = (x1, 0, 0) (order a_x, a_y, a_z, θ_x, θ_y,
    θ_z; SI), from its quarter on the mesh of ``scale``; with ``stress_at`` (a list of points
    (x, y, z)), also the stress tensors there under a unit moment about z on the full body.
    ``cases``: the indices of `SYMMETRY_CASES` to solve (default all; the others' entries stay 0)."""
    m = mesh(body, scale)
    basis = Basis(m, ElementVector(ElementHex2()), intorder=5)
    K = _stiffness(basis, E, nu).tocsr()
    locs = basis.doflocs
    tol = 1e-9 * (body.x1 - body.x0)
    clamp = _dofs(basis, lambda x: np.abs(x[0] - body.x0) < tol, (0, 1, 2))
    X1 = (body.x1, 0.0, 0.0)
    C = np.zeros((6, 6))
    stresses = None
    for sym_z, sym_y, coords in (SYMMETRY_CASES[i] for i in (range(4) if cases is None else cases)):
        fixed = [clamp]
        fixed.append(_dofs(basis, lambda x: np.abs(x[2]) < tol, (2,) if sym_z else (0, 1)))
        fixed.append(_dofs(basis, lambda x: np.abs(x[1]) < tol, (1,) if sym_y else (0, 2)))
        rigid = {c: _dofs(basis, lambda x: np.abs(x[0] - body.x1) < tol, (c,)) for c in range(3)}
        rigid_all = np.concatenate(list(rigid.values()))
        fixed_all = np.unique(np.concatenate(fixed))
        free = np.setdiff1d(np.arange(basis.N), np.union1d(fixed_all, rigid_all))
        # u = P q, q = (u_free, rigid coordinates)
        n_free, n_rig = len(free), len(coords)
        rows, cols, vals = [free], [np.arange(n_free)], [np.ones(n_free)]
        for c, dofs in rigid.items():
            coef = _rigid_rows(locs[:, dofs], c, X1, coords)
            for j in range(n_rig):
                nz = coef[:, j] != 0.0
                rows.append(dofs[nz])
                cols.append(np.full(nz.sum(), n_free + j))
                vals.append(coef[nz, j])
        P = sp.csr_matrix(
            (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(basis.N, n_free + n_rig)
        )
        Kr = (P.T @ K @ P).tocsc()
        F = np.zeros((n_free + n_rig, n_rig))
        F[n_free:, :] = np.eye(n_rig)  # a unit generalised force on each rigid coordinate
        lu = spla.splu(Kr, permc_spec="COLAMD")
        Q = lu.solve(F)
        block = Q[n_free:, :] / 4.0  # quarter -> full body
        C[np.ix_(coords, coords)] = block
        if stress_at is not None and 5 in coords:
            j = coords.index(5)
            u = P @ (Q[:, j] / 4.0)  # the quarter's field under a unit moment about z on the full body
            stresses = [_stress_at(basis, m, u, np.asarray(p, float), E, nu) for p in stress_at]
    C = 0.5 * (C + C.T)
    return {"C": C, "dofs": int(basis.N), "stress": stresses}


def _stress_at(basis, m, u, point, E, nu):
    """The stress tensor at a vertex of the mesh, averaged over the elements sharing it."""
    vertex = int(np.argmin(np.linalg.norm(m.p - point[:, None], axis=0)))
    elements = np.nonzero((m.t == vertex).any(axis=0))[0]
    ref = MeshHex.init_refdom().p  # the reference vertices, in m.t's order
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    out = []
    for el in elements:
        local = int(np.nonzero(m.t[:, el] == vertex)[0][0])
        X = ref[:, local : local + 1]
        b = Basis(m, basis.elem, elements=np.array([el]), quadrature=(X, np.array([1.0])))
        g = b.interpolate(u).grad[:, :, 0, 0]  # du_i/dx_j
        eps = 0.5 * (g + g.T)
        out.append(2 * mu * eps + lam * np.trace(eps) * np.eye(3))
    return np.mean(out, axis=0)


def von_mises(s) -> float:
    dev = s - np.trace(s) / 3.0 * np.eye(3)
    return float(np.sqrt(1.5 * np.sum(dev * dev)))


def richardson(values, scales=SCALES) -> dict:
    """Richardson extrapolation of q on three meshes of element sizes h_i ∝ 1/scales[i]:
    q(h) = q* + c h^p fitted through the three (the observed order p), the extrapolated q*, and
    the error estimate |q* - q_finest|.  When the three do not converge monotonically the
    finest value is kept and the error estimate is the larger of the two differences."""
    q1, q2, q3 = (float(v) for v in values)
    h1, h2, h3 = (1.0 / s for s in scales)
    d1, d2 = q1 - q2, q2 - q3
    ratio = d1 / d2 if d2 != 0.0 else float("inf")

    def excess(p):
        return (h1**p - h2**p) / (h2**p - h3**p) - ratio

    lo, hi = 0.2, 16.0
    if math.isfinite(ratio) and excess(lo) < 0.0 < excess(hi):
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if excess(mid) < 0.0 else (lo, mid)
        p = 0.5 * (lo + hi)
        c = d2 / (h2**p - h3**p)
        ext = q3 - c * h3**p
        err = abs(ext - q3)
    else:  # not in the asymptotic range: no extrapolation
        p, ext, err = float("nan"), q3, max(abs(d1), abs(d2))
    return {"values": [q1, q2, q3], "order": p, "extrapolated": ext, "error": err, "relative_error": err / abs(ext)}


def notch_reference(t, R, w, E, nu, block=None, scales=SCALES, base=(8, 1, 2), cases=None) -> dict:
    """The rotational (about z), other bending (about y), torsional and axial stiffnesses of a
    circular notch hinge [N m/rad, N/m] (the blocks' beam compliances subtracted) and its root
    stress ratios, per mesh scale and Richardson-extrapolated over three scales."""
    body = notch_body(t, R, w, block, base)
    Lb = t + 2.0 * R if block is None else block
    blocks = block_compliances(t, R, w, Lb, E, nu)
    points = [(0.0, t / 2, 0.0), (0.0, t / 2, w / 2)]
    runs = [solve(body, s, E, nu, stress_at=points, cases=cases) for s in scales]
    index = {"bend": 5, "bend2": 4, "torsion": 3, "axial": 0}
    solved = {c for i in (range(4) if cases is None else cases) for c in SYMMETRY_CASES[i][2]}
    quantities = {key: [1.0 / (r["C"][i, i] - blocks[key]) for r in runs] for key, i in index.items() if i in solved}
    nominal = 6.0 / (w * t**2)
    for name, idx in (("mid", 0), ("edge", 1)) if 5 in solved else ():
        quantities[f"sxx_{name}"] = [-r["stress"][idx][0, 0] / nominal for r in runs]
        quantities[f"vm_{name}"] = [von_mises(r["stress"][idx]) / nominal for r in runs]
    out = {k: richardson(v, scales) if len(v) == 3 else {"values": v} for k, v in quantities.items()}
    out["dofs"] = [r["dofs"] for r in runs]
    return out


def beam_reference(a, b, L, E, nu, scales=SCALES, base=(8, 1, 1)) -> dict:
    """The 6 x 6 tip compliance of a cantilever of section a x b and length L (clamped at
    x = 0, a rigid cap at x = L), per mesh scale and extrapolated entry by entry."""
    body = beam_body(a, b, L, base)
    runs = [solve(body, s, E, nu) for s in scales]
    C = np.zeros((6, 6))
    err = np.zeros((6, 6))
    for i in range(6):
        for j in range(6):
            vals = [r["C"][i, j] for r in runs]
            if all(abs(v) > 0 for v in vals):
                rich = richardson(vals, scales) if len(vals) == 3 else {"extrapolated": vals[-1], "error": 0.0}
                C[i, j], err[i, j] = rich["extrapolated"], rich["error"]
    return {"C": C, "error": err, "finest": runs[-1]["C"], "dofs": [r["dofs"] for r in runs]}


def timoshenko_tip_compliance(a, b, L, E, nu, shear_coefficient=None, torsion_constant=None):
    """The closed-form 6 x 6 tip compliance of a Timoshenko cantilever of rectangular section
    a (along y) x b (along z), length L along x, at the tip centre (order a_x, a_y, a_z, θ_x,
    θ_y, θ_z): L/(EA); L³/(3EI) + L/(κGA) with the coupling L²/(2EI) and L/(EI) per bending
    plane; L/(GJ).  κ: Cowper's 10(1+ν)/(12+11ν) for a rectangle (Cowper, J. Appl. Mech. 33,
    1966); J: Roark's rectangle (`cpm_nlp.analysis.flexure_compliance.rectangle_torsion_constant`)."""
    from cpm_nlp.analysis.flexure_compliance import rectangle_torsion_constant

    G = E / (2 * (1 + nu))
    A = a * b
    Iz = b * a**3 / 12.0  # bending in the x-y plane (about z)
    Iy = a * b**3 / 12.0
    kappa = 10 * (1 + nu) / (12 + 11 * nu) if shear_coefficient is None else shear_coefficient
    J = rectangle_torsion_constant(max(a, b), min(a, b)) if torsion_constant is None else torsion_constant
    C = np.zeros((6, 6))
    C[0, 0] = L / (E * A)
    C[1, 1] = L**3 / (3 * E * Iz) + L / (kappa * G * A)
    C[5, 5] = L / (E * Iz)
    C[1, 5] = C[5, 1] = L**2 / (2 * E * Iz)  # a force along y turns the tip about +z
    C[2, 2] = L**3 / (3 * E * Iy) + L / (kappa * G * A)
    C[4, 4] = L / (E * Iy)
    C[2, 4] = C[4, 2] = -(L**2) / (2 * E * Iy)  # a force along z turns the tip about -y
    C[3, 3] = L / (G * J)
    return C
