"""The small dense linear algebra of the compiled solve (`drake_dock.core.kernels.small_linalg`)
against numpy's LAPACK on seeded random systems: LU solve and determinant, the singular
values, the condition number, and the least-squares solution of least norm with a cut-off on
rank-deficient matrices; and the SVD's factors reproduce the matrix with orthonormal U and
V."""
import numpy as np
import pytest

from drake_dock.core.kernels import small_linalg as L

RNG = np.random.default_rng(5)


@pytest.mark.parametrize("n", [1, 2, 3, 5, 9, 14])
def test_lu_solves_and_gives_the_determinant(n):
    for _ in range(5):
        A = RNG.normal(size=(n, n))
        b = RNG.normal(size=n)
        LU, piv, sign = L.lu(A)
        np.testing.assert_allclose(L.lu_solve(LU, piv, b), np.linalg.solve(A, b), rtol=1e-9,
                                   atol=1e-12)
        assert abs(L.lu_det(LU, sign) - np.linalg.det(A)) <= 1e-10 * max(1.0, abs(np.linalg.det(A)))


@pytest.mark.parametrize("n", [1, 2, 3, 6, 12])
def test_svd_and_condition_number(n):
    for _ in range(5):
        A = RNG.normal(size=(n, n)) @ np.diag(10.0 ** RNG.uniform(-3, 3, n))
        U, s, V = L.svd(A)
        ref = np.linalg.svd(A, compute_uv=False)
        # Both accurate to round-off of the largest: an absolute error of a few eps s_max.
        np.testing.assert_allclose(s, ref, rtol=1e-10, atol=1e-13 * ref[0])
        np.testing.assert_allclose(U @ np.diag(s) @ V.T, A, atol=1e-12 * np.abs(A).max())
        np.testing.assert_allclose(V.T @ V, np.eye(n), atol=1e-12)
        np.testing.assert_allclose(U.T @ U, np.eye(n), atol=1e-10)
        assert abs(L.cond(A) / np.linalg.cond(A) - 1) < 1e-13 * np.linalg.cond(A) + 1e-8


@pytest.mark.parametrize("rank", [1, 2, 4])
def test_least_squares_of_a_rank_deficient_matrix(rank):
    n = 6
    for _ in range(5):
        A = RNG.normal(size=(n, rank)) @ RNG.normal(size=(rank, n))
        b = RNG.normal(size=n)
        x = L.lstsq(A, b, 1e-10)
        ref = np.linalg.lstsq(A, b, rcond=1e-10)[0]
        np.testing.assert_allclose(x, ref, rtol=1e-8, atol=1e-10 * np.abs(ref).max())


def test_products_and_norm():
    A, B, x = RNG.normal(size=(4, 3)), RNG.normal(size=(3, 5)), RNG.normal(size=3)
    np.testing.assert_allclose(L.matmul(A, B), A @ B, rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(L.matvec(A, x), A @ x, rtol=1e-14, atol=1e-14)
    assert abs(L.norm(x) - np.linalg.norm(x)) < 1e-15
