# Copyright 2026 newton_euler_ros developers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""Cholesky solve of a symmetric positive definite system (no inverse)."""
import math

from ._jit import njit


@njit(cache=True)
def cholesky_solve(A, b, L, x):
    """
    Solve A x = b for symmetric positive definite A by Cholesky.

    Returns -1 on success, or the index of the first pivot that is not
    positive (A is not positive definite there).  A is left unchanged
    unless L is A: ``cholesky_solve(A, b, A, b)`` factorises and solves
    in place (each entry of A is read before its L entry overwrites it,
    and b[i] before x[i]); the observer's damped solve uses that.
    """
    n = A.shape[0]
    bad = cholesky_factor(A, L, 0, n)
    if bad >= 0:
        return bad
    cholesky_solve_factored(L, b, x, 0, n)
    return -1


@njit(cache=True, inline='always')
def cholesky_factor(A, L, lo, hi):
    """
    Write the lower Cholesky factor of A into L (A = L L^T).

    Of the block A[lo:hi, lo:hi] alone (the whole matrix: 0, n), into the
    same block of L.  Returns -1, or the first pivot that is not positive
    (its index in A).  L may be A.
    """
    for i in range(lo, hi):
        for k in range(lo, i + 1):
            acc = A[i, k]
            for m in range(lo, k):
                acc -= L[i, m] * L[k, m]
            if i == k:
                if not acc > 0:     # an int literal: exact in any dtype
                    return i
                L[i, i] = math.sqrt(acc)
            else:
                L[i, k] = acc / L[k, k]
    return -1


@njit(cache=True, inline='always')
def cholesky_solve_factored(L, b, x, lo, hi):
    """Solve L L^T x = b (x may be b) on the block lo..hi-1 (0, n: all)."""
    for i in range(lo, hi):
        acc = b[i]
        for m in range(lo, i):
            acc -= L[i, m] * x[m]
        x[i] = acc / L[i, i]
    for i in range(hi - 1, lo - 1, -1):
        acc = x[i]
        for m in range(i + 1, hi):
            acc -= L[m, i] * x[m]
        x[i] = acc / L[i, i]


@njit(cache=True, inline='always')
def cholesky_inverse(L, X, rd, one, lo, hi):
    """
    Write (L L^T)^-1 into X (not L), L from :func:`cholesky_factor`.

    Of the block lo..hi-1 alone (0, n: all), into the same block of X.

    L^-1 goes into X's lower triangle, then row i of L^-T L^-1 (entry
    (i, j), j <= i: the sum over m >= i of L^-1[m, i] L^-1[m, j]) into
    its upper triangle (the diagonal last, once row i no longer reads
    it), which is then mirrored: about n^3 / 3 multiply-adds and n
    divisions (``rd``, n scratch: the reciprocal pivots), against n^3
    and n^2 for n solves of unit vectors.  ``one``: 1 in L's type.
    """
    for i in range(lo, hi):
        rd[i] = one / L[i, i]
    for j in range(lo, hi):         # L^-1, column by column
        X[j, j] = rd[j]
        for i in range(j + 1, hi):
            acc = -L[i, j] * X[j, j]
            for m in range(j + 1, i):
                acc -= L[i, m] * X[m, j]
            X[i, j] = acc * rd[i]
    for i in range(lo, hi):         # L^-T L^-1, row i into column i
        for j in range(lo, i + 1):
            acc = X[i, i] * X[i, j]
            for m in range(i + 1, hi):
                acc += X[m, i] * X[m, j]
            if j < i:
                X[j, i] = acc
            else:
                X[i, i] = acc
    for i in range(lo, hi):
        for j in range(lo, i):
            X[i, j] = X[j, i]
