"""The constraint solve of `drake_dock.core.constraints.solve_given_modes` compiled (Eq. 48-52):
the forces and accelerations of a contact set for given modes, over the packed rows of
`drake_dock.core.kernels.constraints`, with the reference's operations in its order (BLAS
products, LAPACK's LU solve) and the squeeze of two sticking couples
(`drake_dock.core.squeeze`)."""
from __future__ import annotations

import math

import numpy as np
from numba import njit, types
from numba.extending import intrinsic

from drake_dock.core import constraints as ref
from drake_dock.core.squeeze import squeezed

STICK, SLIDE, DETACH = 0, 1, 2
CODE = {ref.STICK: STICK, ref.SLIDE: SLIDE, ref.DETACH: DETACH}
NAME = (ref.STICK, ref.SLIDE, ref.DETACH)
OK, SINGULAR, NONFINITE, NONE_CONSISTENT, INDETERMINATE = 0, 1, 2, 3, 4
SLIDE_START_ITER = ref.SLIDE_START_ITER



@intrinsic
def _fma(typingctx, a, b, c):
    """a b + c rounded once (LLVM's fma)."""
    def codegen(context, builder, signature, args):
        return builder.fma(*args)
    return types.float64(types.float64, types.float64, types.float64), codegen


@njit(cache=True)
def stabilised(x, vn, gap, omega):
    """x + 2 omega g' + omega^2 g: the Baumgarte-stabilised normal row (Eq. 52), x = g'' or its
    velocity-product term bn."""
    return x + 2 * omega * vn + omega ** 2 * gap


@njit(cache=True)
def solve_modes(Minv, a0, W, bias, gap, vn, mu, mu_s, modes, dirs, omega, vdot, lam_n, lam_t,
                gf):
    """`constraints.solve_given_modes` into vdot (nv,), lam_n (k,), lam_t (k, 2) and the
    generalized force gf (nv,); returns (status, cond(A)): SINGULAR when the constraint matrix
    is singular and the equations inconsistent, NONFINITE when they hold an inf or a nan."""
    k, nv = W.shape[0], W.shape[1]
    m = 0
    for i in range(k):
        m += 3 if modes[i] == STICK else (1 if modes[i] == SLIDE else 0)
    lam_n[:] = 0.0
    lam_t[:] = 0.0
    if m == 0:
        vdot[:] = a0
        gf[:] = 0.0
        return OK, 0.0
    Ct = np.empty((m, nv))         # C^T and D^T, C-ordered: C = Ct.T as the reference's
    Dt = np.empty((m, nv))
    rhs = np.empty(m)
    soft = 0.0       # the Baumgarte terms' squared norm (see the reference's singular case)
    j = 0
    for i in range(k):
        if modes[i] != DETACH:
            soft += (2 * omega * vn[i] + omega ** 2 * gap[i]) ** 2
        if modes[i] == STICK:
            for c in range(3):
                for a in range(nv):
                    Ct[j + c, a] = W[i, a, c]
                    Dt[j + c, a] = W[i, a, c]
            rhs[j] = stabilised(bias[i, 0], vn[i], gap[i], omega)
            rhs[j + 1] = bias[i, 1]
            rhs[j + 2] = bias[i, 2]
            j += 3
        elif modes[i] == SLIDE:
            s0, s1 = dirs[i, 0], dirs[i, 1]
            for a in range(nv):
                # Wt s as numpy's product of the (nv, 2) by the 2-vector rounds it
                Ct[j, a] = W[i, a, 0] - mu[i] * _fma(W[i, a, 1], s0, W[i, a, 2] * s1)
                Dt[j, a] = W[i, a, 0]
            rhs[j] = stabilised(bias[i, 0], vn[i], gap[i], omega)
            j += 1
    C = Ct.T
    MinvC = np.dot(Minv, C)
    A = np.dot(Dt, MinvC)
    b = -(rhs + np.dot(Dt, a0))
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(b))):
        return NONFINITE, np.nan        # LAPACK is not called on them
    # The reference's singularity test: the Hadamard ratio |det A| / prod of its row norms.
    prod, positive = 1.0, True
    for r in range(m):
        s = 0.0
        for c in range(m):
            s += A[r, c] * A[r, c]
        rn = math.sqrt(s)
        positive = positive and rn > 0
        prod *= rn
    ratio = abs(np.linalg.det(A)) / prod if positive and prod > 0 else 0.0
    cond = 0.0
    if np.isfinite(ratio) and ratio > 1e-12:
        lam = np.linalg.solve(A, b)
    else:
        cond = np.linalg.cond(A)
        lam = np.linalg.lstsq(A, b, rcond=1e-10)[0]
        if np.linalg.norm(np.dot(A, lam) - b) > (1e-8 * (1.0 + np.linalg.norm(b))
                                                   + math.sqrt(soft)):
            return SINGULAR, cond
        ns = 0
        for i in range(k):
            ns += 1 if modes[i] == STICK else 0
        offsets, mus = np.empty(ns, np.int64), np.empty(ns)
        j, n = 0, 0
        for i in range(k):
            if modes[i] == STICK:
                offsets[n], mus[n] = j, mu_s[i]
                n += 1
            j += 3 if modes[i] == STICK else (1 if modes[i] == SLIDE else 0)
        lam = squeezed(lam, A, C, offsets, mus)     # `drake_dock.core.squeeze` (Eq. 51)
    vdot[:] = a0 + np.dot(MinvC, lam)
    gf[:] = np.dot(C, lam)
    j = 0
    for i in range(k):
        if modes[i] == STICK:
            lam_n[i], lam_t[i, 0], lam_t[i, 1] = lam[j], lam[j + 1], lam[j + 2]
            j += 3
        elif modes[i] == SLIDE:
            lam_n[i] = lam[j]
            f = -mu[i] * lam[j]
            lam_t[i, 0], lam_t[i, 1] = f * dirs[i, 0], f * dirs[i, 1]
            j += 1
    return OK, cond


@njit(cache=True)
def accelerations(W, bias, vdot, gdd, at):
    """g'' (k,) and the tangential relative accelerations at (k, 2) at vdot."""
    for i in range(W.shape[0]):
        for c in range(3):
            s = 0.0
            for a in range(W.shape[1]):
                s += W[i, a, c] * vdot[a]
            if c == 0:
                gdd[i] = s + bias[i, 0]
            else:
                at[i, c - 1] = s + bias[i, c]

