"""Dense linear algebra for the small systems of the contact solve (a few to a few dozen rows),
compiled, in plain loops: LU with partial pivoting (solve, determinant) and the singular value
decomposition by one-sided Jacobi rotations (condition number, least squares with a cut-off).

numpy's ``np.linalg`` functions in compiled code call LAPACK through wrappers that cost
seconds to compile in every kernel that reaches them and microseconds to call; at these sizes
the loops are as accurate (backward stable: partial pivoting; Jacobi's SVD is accurate to
round-off in the singular values) and cheaper. The tests compare them with numpy's LAPACK.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def lu(A):
    """(LU, piv, sign) of the square A by Gaussian elimination with partial pivoting: L (unit
    lower, below the diagonal) and U in one array, the row order piv (A[piv] = L U) and the
    permutation's sign. A is not written."""
    n = A.shape[0]
    M = A.copy()
    piv = np.arange(n)
    sign = 1.0
    for k in range(n):
        p = k
        big = abs(M[k, k])
        for i in range(k + 1, n):
            if abs(M[i, k]) > big:
                big, p = abs(M[i, k]), i
        if p != k:
            for j in range(n):
                M[k, j], M[p, j] = M[p, j], M[k, j]
            piv[k], piv[p] = piv[p], piv[k]
            sign = -sign
        d = M[k, k]
        if d == 0.0:
            continue
        for i in range(k + 1, n):
            f = M[i, k] / d
            M[i, k] = f
            for j in range(k + 1, n):
                M[i, j] -= f * M[k, j]
    return M, piv, sign


@njit(cache=True)
def lu_det(LU, sign):
    """The determinant from `lu`: the sign times the product of U's diagonal."""
    d = sign
    for k in range(LU.shape[0]):
        d *= LU[k, k]
    return d


@njit(cache=True)
def lu_solve(LU, piv, b):
    """x with A x = b from `lu` (U's diagonal nonzero)."""
    n = LU.shape[0]
    x = np.empty(n)
    for i in range(n):
        s = b[piv[i]]
        for j in range(i):
            s -= LU[i, j] * x[j]
        x[i] = s
    for i in range(n - 1, -1, -1):
        s = x[i]
        for j in range(i + 1, n):
            s -= LU[i, j] * x[j]
        x[i] = s / LU[i, i]
    return x


@njit(cache=True)
def svd(A, sweeps=60):
    """(U, s, V) with A = U diag(s) V^T of the square A, s descending and non-negative, by
    one-sided Jacobi rotations on A's columns until every pair is orthogonal to round-off (or
    ``sweeps`` sweeps)."""
    n = A.shape[0]
    U = A.copy()
    V = np.eye(n)
    for _ in range(sweeps):
        rotated = False
        for p in range(n - 1):
            for q in range(p + 1, n):
                a = b = c = 0.0
                for i in range(n):
                    a += U[i, p] * U[i, p]
                    b += U[i, q] * U[i, q]
                    c += U[i, p] * U[i, q]
                if abs(c) <= 1e-15 * math.sqrt(a * b) or c == 0.0:
                    continue
                rotated = True
                zeta = (b - a) / (2.0 * c)
                t = math.copysign(1.0, zeta) / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                cs = 1.0 / math.sqrt(1.0 + t * t)
                sn = cs * t
                for i in range(n):
                    up, uq = U[i, p], U[i, q]
                    U[i, p], U[i, q] = cs * up - sn * uq, sn * up + cs * uq
                    vp, vq = V[i, p], V[i, q]
                    V[i, p], V[i, q] = cs * vp - sn * vq, sn * vp + cs * vq
        if not rotated:
            break
    s = np.empty(n)
    for j in range(n):
        t = 0.0
        for i in range(n):
            t += U[i, j] * U[i, j]
        s[j] = math.sqrt(t)
    order = np.argsort(-s)
    s = s[order]
    U, V = U[:, order].copy(), V[:, order].copy()
    for j in range(n):
        if s[j] > 0.0:
            for i in range(n):
                U[i, j] /= s[j]
    return U, s, V


@njit(cache=True)
def cond(A):
    """The 2-norm condition number s_max / s_min (inf when singular)."""
    _, s, _ = svd(A)
    return s[0] / s[-1] if s[-1] > 0.0 else math.inf


@njit(cache=True)
def lstsq(A, b, rcond):
    """The least-squares solution of A x = b of least norm, the singular values below rcond
    times the largest cut off (numpy's ``lstsq``)."""
    U, s, V = svd(A)
    return svd_solve(U, s, V, b, rcond)


@njit(cache=True)
def svd_solve(U, s, V, b, rcond):
    """`lstsq` from A's `svd` (U, s, V)."""
    n = U.shape[0]
    cut = rcond * s[0]
    x = np.zeros(n)
    for j in range(n):
        if s[j] > cut and s[j] > 0.0:
            c = 0.0
            for i in range(n):
                c += U[i, j] * b[i]
            c /= s[j]
            for i in range(n):
                x[i] += c * V[i, j]
    return x


@njit(cache=True)
def matmul(A, B):
    """A B of dense matrices."""
    n, m, p = A.shape[0], A.shape[1], B.shape[1]
    C = np.zeros((n, p))
    for i in range(n):
        for k in range(m):
            a = A[i, k]
            if a != 0.0:
                for j in range(p):
                    C[i, j] += a * B[k, j]
    return C


@njit(cache=True)
def matvec(A, x):
    """A x."""
    y = np.zeros(A.shape[0])
    for i in range(A.shape[0]):
        s = 0.0
        for k in range(A.shape[1]):
            s += A[i, k] * x[k]
        y[i] = s
    return y


@njit(cache=True)
def norm(x):
    s = 0.0
    for i in range(x.shape[0]):
        s += x[i] * x[i]
    return math.sqrt(s)


def warm():
    """Compiles or loads the routines on a 3x3 system."""
    A = np.array([[4.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 2.0]])
    b = np.ones(3)
    LU, piv, sign = lu(A)
    lu_det(LU, sign)
    lu_solve(LU, piv, b)
    cond(A)
    lstsq(A, b, 1e-10)
    matvec(matmul(A, A), b)
    norm(b)
