"""Certified bounds of the conditioning of a closure at a pose, as symbolic (SX) expressions
the kernels evaluate without an inverse of Φ_x or a singular value decomposition:

* `cond1_bound`: κ₁(Φ_x) from an approximate inverse (Φ_x⁻¹ at the home pose);
* `cond1_block_bound`: κ₁(Φ_x) from the inverses of the diagonal blocks of its block
  triangular (Dulmage-Mendelsohn) form at the pose;
* `cond2_left_inverse_bound`: κ₂ of the tall Jacobian e_x of every closure equation of a
  closure solved through normal equations, from a block left inverse
  (`LeftInverseBlocks`).

Each is +inf where nothing is certified (a non-finite value, a structurally singular matrix).
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from .model import LoopClosure
from .solver import solvers_of


def all_finite(v: ca.SX) -> ca.SX:
    # |v| < inf is false for inf and NaN (not v * 0 == 0: CasADi simplifies v * 0 to 0)
    return ca.sum1(ca.fabs(ca.vec(v)) < ca.inf) == v.numel()


def robust_max_abs(v: ca.SX) -> ca.SX:
    """max |v|, inf if any entry is NaN (C's fmax would skip NaN)."""
    return ca.if_else(all_finite(v), ca.mmax(ca.fabs(v)), ca.inf)


#: Condition number of Φ_x (or of the homogenised J) above which a pose is reported
#: as near a singularity: 1e4 below the 1e10 at which it is refused as singular
#: (status ``singular``); at 1e6 an error of 1e-10 in the closures (the solver's
#: tolerance) can move the pose by 1e-4 of its scale, and an actuator error is
#: amplified a million times in the worst direction (`cpm_nlp.analysis.validity` words
#: the warning; the kinds read the threshold here without importing it).
NEAR_SINGULAR_CONDITION = 1e6

#: the preconditioned residual ‖I - Φ_x B‖₁ must stay below this for `cond1_bound` to certify
CERTIFY_DELTA = 0.9


def _induced_norm_1(m: ca.SX) -> ca.SX:
    """‖M‖₁ = largest column sum of |M| (the induced 1-norm)."""
    return ca.mmax(ca.sum1(ca.fabs(m)))


def _robust_norm_1(m: ca.SX) -> ca.SX:
    """‖M‖₁, inf if any entry is not finite (C's fmax would skip NaN): the column sums of |M|
    carry a NaN or inf into their total (a total that overflows also gives inf: conservative)."""
    sums = ca.sum1(ca.fabs(m))
    return ca.if_else(ca.sum2(sums) < ca.inf, ca.mmax(sums), ca.inf)


def cond1_bound(phi_x: ca.SX, b: ca.SX) -> ca.SX:
    """A certified upper bound of the 1-norm condition number of Φ_x, from an
    approximate inverse B (Φ_x⁻¹ at the home pose, numbers) and no inverse
    at the pose itself.

    With δ = ‖I - Φ_x B‖₁ < 1, Φ_x B is invertible (Neumann series) and
    ‖Φ_x⁻¹‖₁ = ‖B (Φ_x B)⁻¹‖₁ ≤ ‖B‖₁ / (1 - δ), so
    κ₁(Φ_x) ≤ ‖Φ_x‖₁ ‖B‖₁ / (1 - δ) (induced 1-norms).  Where δ >
    `CERTIFY_DELTA` (far from home) or Φ_x is not finite the bound is
    +inf: nothing is certified.  Costs one nx x nx product instead of a
    symbolic inverse.
    """
    n = phi_x.size1()
    delta = _induced_norm_1(ca.DM.eye(n) - ca.mtimes(phi_x, b))
    bound = _induced_norm_1(phi_x) * _induced_norm_1(b) / (1 - delta)
    return ca.if_else(ca.logic_and(all_finite(ca.vec(phi_x)), delta <= CERTIFY_DELTA), bound, ca.inf)


def _block_upper(u: ca.SX, rows: list[list[int]], cols: list[list[int]]) -> bool:
    """Whether u has no structural nonzero below its diagonal blocks."""
    return all(u[rows[i], cols[j]].nnz() == 0 for i in range(len(rows)) for j in range(i))


def cond1_block_bound(phi_x: ca.SX) -> ca.SX:
    """An upper bound of the 1-norm condition number of Φ_x at the pose itself, from its block
    triangular form: no approximate inverse from elsewhere, so it holds as far from home as
    Φ_x stays regular.

    The sparsity's Dulmage-Mendelsohn form (fixed when the kernel is built) permutes Φ_x to a
    block upper triangular U with square diagonal blocks D_i.  The inverse X = U⁻¹ is block
    upper triangular too: X_jj = D_j⁻¹ and X_ij = -D_i⁻¹ Σ_{i<k≤j} U_ik X_kj, so with
    α_i = ‖D_i⁻¹‖₁ (each block inverted at the pose; a 1 x 1 block is 1/d) the norms obey
    ‖X_ij‖₁ ≤ β_ij = α_i Σ_k ‖U_ik‖₁ β_kj, and ‖Φ_x⁻¹‖₁ = ‖X‖₁ ≤ max_j Σ_i β_ij (a column of
    block column j sums at most the blocks' 1-norms).  Permutations keep the 1-norm, so
    κ₁(Φ_x) ≤ ‖Φ_x‖₁ max_j Σ_i β_ij (induced 1-norms).  A structurally singular Φ_x, a
    singular block (its inverse not finite) or a Φ_x that is not finite gives +inf (NaN is
    read as singular too: `is_singular`).  Costs the inverses of the diagonal blocks only
    (for a linkage's normal equations: the block of the loops' passive coordinates).
    """
    n = phi_x.size1()
    sp = phi_x.sparsity()
    if ca.sprank(sp) < n:
        return ca.SX(ca.inf)
    nb, rowperm, colperm, rowblock, colblock, *_ = sp.btf()
    rows = [list(range(rowblock[k], rowblock[k + 1])) for k in range(nb)]
    cols = [list(range(colblock[k], colblock[k + 1])) for k in range(nb)]
    u = phi_x[rowperm, colperm]
    if not _block_upper(u, rows, cols):  # the lower form (CasADi 3.6 gives it): reversing both orders makes it upper
        rowperm, colperm = rowperm[::-1], colperm[::-1]
        rows = [[n - 1 - r for r in rows[k][::-1]] for k in reversed(range(nb))]
        cols = [[n - 1 - r for r in cols[k][::-1]] for k in reversed(range(nb))]
        u = phi_x[rowperm, colperm]
        if not _block_upper(u, rows, cols):  # pragma: no cover - the Dulmage-Mendelsohn form is triangular
            return ca.SX(ca.inf)
    alpha = []
    for i in range(nb):
        d = u[rows[i], cols[i]]
        alpha.append(1 / ca.fabs(d) if d.numel() == 1 else _robust_norm_1(ca.inv(ca.densify(d))))
    beta: dict[tuple[int, int], ca.SX] = {}
    sums = []
    for j in range(nb):
        column = []
        for i in range(j, -1, -1):
            if i == j:
                b = alpha[j]
            else:
                terms = [
                    _induced_norm_1(u[rows[i], cols[k]]) * beta[k, j]
                    for k in range(i + 1, j + 1)
                    if u[rows[i], cols[k]].nnz() and (k, j) in beta
                ]
                if not terms:
                    continue
                b = alpha[i] * ca.sum1(ca.vertcat(*terms))
            beta[i, j] = b
            column.append(b)
        sums.append(ca.sum1(ca.vertcat(*column)))
    return _robust_norm_1(phi_x) * robust_max_abs(ca.vertcat(*sums))  # inf where a sum is NaN


@dataclass(frozen=True)
class LeftInverseBlocks:
    """A block upper triangular form of e_x (m x n, m >= n: the Jacobian of every closure
    equation of a closure solved through normal equations) with tall diagonal blocks: ``rows[i]``
    (the rows of group i) and ``cols[i]`` (column block i), in order.  A row of group i has
    nonzeros in column blocks i, i+1, ... only; each diagonal block has at least as many rows as
    columns and full structural column rank.  Rows of e_x with no structural nonzero are left
    out (they add nothing to e_xᵀ e_x)."""

    rows: tuple[tuple[int, ...], ...]
    cols: tuple[tuple[int, ...], ...]


def left_inverse_blocks(e_sp: ca.Sparsity, phi_sp: ca.Sparsity) -> LeftInverseBlocks | None:
    """The column blocks of Φ_x's block triangular (Dulmage-Mendelsohn) form, in upper order, and
    each row of e_x in the group of the first column block it touches: e_x is then block upper
    triangular by construction.  Where a diagonal block would be wide or structurally singular, one
    block (the whole of e_x); None if e_x is structurally rank deficient."""
    m, n = e_sp.shape
    touched = [[] for _ in range(m)]
    for r, c in zip(*e_sp.get_triplet()):
        touched[r].append(c)
    live = [r for r in range(m) if touched[r]]
    whole = LeftInverseBlocks((tuple(live),), (tuple(range(n)),))
    if ca.sprank(e_sp) < n:
        return None
    if ca.sprank(phi_sp) < n:
        return whole
    nb, rowperm, colperm, rowblock, colblock, *_ = phi_sp.btf()
    rows = [list(range(rowblock[k], rowblock[k + 1])) for k in range(nb)]
    cols = [list(range(colblock[k], colblock[k + 1])) for k in range(nb)]
    u = ca.DM(phi_sp, 1)[rowperm, colperm]
    if not _block_upper(u, rows, cols):  # the lower form: reverse the blocks' order
        colperm = colperm[::-1]
        cols = [[n - 1 - c for c in cols[k][::-1]] for k in reversed(range(nb))]
    blocks = [tuple(colperm[c] for c in block) for block in cols]
    block_of = {c: k for k, block in enumerate(blocks) for c in block}
    groups: list[list[int]] = [[] for _ in blocks]
    for r in live:
        groups[min(block_of[c] for c in touched[r])].append(r)
    for g, b in zip(groups, blocks):
        if len(g) < len(b) or ca.sprank(ca.DM(e_sp, 1)[g, list(b)].sparsity()) < len(b):
            return whole
    return LeftInverseBlocks(tuple(tuple(g) for g in groups), tuple(blocks))


def _left_inverse_norm(d: ca.SX) -> ca.SX:
    """An upper bound of ‖D⁺‖₂ = 1/σ_min(D) for a tall block D (full column rank): 1/‖d‖₂ for a
    single column (exact), else ‖T⁻¹‖_F with D = QT its QR factorization (CasADi's modified
    Gram-Schmidt; σ_min(T) = σ_min(D), and ‖T⁻¹‖₂ <= ‖T⁻¹‖_F).  No DᵀD is formed: the bound is
    as accurate as D's smallest singular value is in floating point (κ(D) u), never κ(D)² u."""
    d = ca.densify(d)
    if d.size2() == 1:
        return 1 / ca.norm_2(d)
    _q, t = ca.qr(d)
    return ca.norm_fro(ca.solve(t, ca.SX.eye(t.size1())))


def closure_blocks(closure: LoopClosure) -> LeftInverseBlocks | None:
    """`left_inverse_blocks` of a closure's e_x (built once per closure)."""
    c = closure
    return solvers_of(c).memo(
        ("left_inverse_blocks",),
        lambda: left_inverse_blocks(c.cond_matrix.sparsity_out(0), c.phi_x.sparsity_out(0)),
    )


def cond2_left_inverse_bound(e_x: ca.SX, blocks: LeftInverseBlocks | None) -> ca.SX:
    """An upper bound of the 2-norm condition number κ₂(e_x) = σ_max/σ_min of the (tall) Jacobian
    of every closure equation, from a block left inverse at the pose: no SVD, no e_xᵀ e_x.

    Any left inverse X (X e_x = I) bounds the smallest singular value: |v| = |X e_x v| <=
    ‖X‖₂ |e_x v|, so σ_min(e_x) >= 1/‖X‖₂.  In the form of `left_inverse_blocks` (block
    upper triangular U, tall diagonal blocks D_i) one left inverse is block upper triangular:
    X_ii = D_i⁺ (the pseudo-inverse) and X_ij = -D_i⁺ Σ_{i<k<=j} U_ik X_kj, so with
    α_i >= ‖D_i⁺‖₂ (`_left_inverse_norm`) the norms obey ‖X_ij‖₂ <= β_ij = α_i Σ_k ‖U_ik‖_F
    β_kj (‖·‖₂ <= ‖·‖_F), and ‖X‖₂ <= ‖(β_ij)‖₂ <= ‖(β_ij)‖_F (a block matrix's 2-norm is at most
    that of its blocks' norms).  So κ₂(e_x) <= ‖e_x‖_F ‖(β_ij)‖_F.  For a square closure e_x is Φ_x
    itself: this is the same measure the 2-norm check decides on.  +inf where e_x is structurally
    rank deficient (``blocks`` None), a block is singular or a value is not finite (NaN too).
    """
    if blocks is None:
        return ca.SX(ca.inf)
    rows, cols = blocks.rows, blocks.cols
    nb = len(rows)
    alpha = [_left_inverse_norm(e_x[list(rows[i]), list(cols[i])]) for i in range(nb)]
    beta: dict[tuple[int, int], ca.SX] = {}
    squares = []
    for j in range(nb):
        for i in range(j, -1, -1):
            if i == j:
                b = alpha[j]
            else:
                terms = [
                    ca.norm_fro(e_x[list(rows[i]), list(cols[k])]) * beta[k, j]
                    for k in range(i + 1, j + 1)
                    if (k, j) in beta and e_x[list(rows[i]), list(cols[k])].nnz()
                ]
                if not terms:
                    continue
                b = alpha[i] * ca.sum1(ca.vertcat(*terms))
            beta[i, j] = b
            squares.append(b**2)
    bound = ca.norm_fro(e_x) * ca.sqrt(ca.sum1(ca.vertcat(*squares)))
    return ca.if_else(bound < ca.inf, bound, ca.inf)  # NaN and inf: +inf
