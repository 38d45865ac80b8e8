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

"""
Small vector algebra shared by every pass, and the two frame carries.

3-vectors and 3x3 matrices are tuples, 6x6 matrices blocks of workspace
rows.  The carries between neighbouring frames:

- :func:`motion_to_child`: a motion vector (angular velocity or
  acceleration, with the velocity or acceleration of the origin) of frame
  j-1 expressed in frame j;
- :func:`force_to_parent`: a wrench (force, and moment about O_j) of frame
  j expressed in frame j-1 about O_{j-1}: f' = R f, n' = R n + p x f'.

(R, p) is always the pose of frame j in frame j-1.
"""
from ._jit import njit


@njit(cache=True)
def cross(a0, a1, a2, b0, b1, b2):
    return (a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0)


@njit(cache=True)
def rot_t(R, x0, x1, x2):
    """R^T x."""
    return (R[0] * x0 + R[3] * x1 + R[6] * x2,
            R[1] * x0 + R[4] * x1 + R[7] * x2,
            R[2] * x0 + R[5] * x1 + R[8] * x2)


@njit(cache=True)
def rot(R, x0, x1, x2):
    """R x."""
    return (R[0] * x0 + R[1] * x1 + R[2] * x2,
            R[3] * x0 + R[4] * x1 + R[5] * x2,
            R[6] * x0 + R[7] * x1 + R[8] * x2)


@njit(cache=True)
def matmul(A, B):
    return (A[0] * B[0] + A[1] * B[3] + A[2] * B[6],
            A[0] * B[1] + A[1] * B[4] + A[2] * B[7],
            A[0] * B[2] + A[1] * B[5] + A[2] * B[8],
            A[3] * B[0] + A[4] * B[3] + A[5] * B[6],
            A[3] * B[1] + A[4] * B[4] + A[5] * B[7],
            A[3] * B[2] + A[4] * B[5] + A[5] * B[8],
            A[6] * B[0] + A[7] * B[3] + A[8] * B[6],
            A[6] * B[1] + A[7] * B[4] + A[8] * B[7],
            A[6] * B[2] + A[7] * B[5] + A[8] * B[8])


@njit(cache=True)
def transpose(A):
    return (A[0], A[3], A[6], A[1], A[4], A[7], A[2], A[5], A[8])


@njit(cache=True)
def skew(p):
    """[p], the matrix of p x (.), row-major."""
    zero = p[0] - p[0]
    return (zero, -p[2], p[1], p[2], zero, -p[0], -p[1], p[0], zero)


@njit(cache=True, inline='always')
def load3(a, row, col):
    """Return the 3-vector stored in ``a[row, col:col + 3]``."""
    return (a[row, col], a[row, col + 1], a[row, col + 2])


@njit(cache=True, inline='always')
def load9(a, row, col):
    """Return the 3x3 matrix stored row-major in ``a[row, col:col + 9]``."""
    return (a[row, col], a[row, col + 1], a[row, col + 2],
            a[row, col + 3], a[row, col + 4], a[row, col + 5],
            a[row, col + 6], a[row, col + 7], a[row, col + 8])


@njit(cache=True)
def frame_rot(frames, row):
    """Return the rotation of a fixed frame (an ``F_*`` row)."""
    return load9(frames, row, 0)


@njit(cache=True)
def sym_mul(S, x0, x1, x2):
    """S x for a symmetric S stored as (xx, yy, zz, xy, yz, xz)."""
    return (S[0] * x0 + S[3] * x1 + S[5] * x2,
            S[3] * x0 + S[1] * x1 + S[4] * x2,
            S[5] * x0 + S[4] * x1 + S[2] * x2)


@njit(cache=True)
def sym_rotate(R, S):
    """R S R^T for a symmetric S, both stored as (xx, yy, zz, xy, yz, xz)."""
    # rows of A = R S (S is symmetric, so row k of R times S is S r_k)
    a0 = sym_mul(S, R[0], R[1], R[2])
    a1 = sym_mul(S, R[3], R[4], R[5])
    a2 = sym_mul(S, R[6], R[7], R[8])
    # (A R^T)_ik = a_i . r_k, upper triangle only
    return (a0[0] * R[0] + a0[1] * R[1] + a0[2] * R[2],
            a1[0] * R[3] + a1[1] * R[4] + a1[2] * R[5],
            a2[0] * R[6] + a2[1] * R[7] + a2[2] * R[8],
            a0[0] * R[3] + a0[1] * R[4] + a0[2] * R[5],
            a1[0] * R[6] + a1[1] * R[7] + a1[2] * R[8],
            a0[0] * R[6] + a0[1] * R[7] + a0[2] * R[8])


@njit(cache=True)
def vec6(M, row, col):
    return (M[row, col], M[row, col + 1], M[row, col + 2],
            M[row, col + 3], M[row, col + 4], M[row, col + 5])


@njit(cache=True)
def block(M, row, col, r0, c0):
    """Return the 3x3 block at (r0, c0) of the 6x6 matrix in M[row, col:]."""
    b = col + 6 * r0 + c0
    return (M[row, b], M[row, b + 1], M[row, b + 2],
            M[row, b + 6], M[row, b + 7], M[row, b + 8],
            M[row, b + 12], M[row, b + 13], M[row, b + 14])


@njit(cache=True)
def add_block(M, row, col, r0, c0, B):
    b = col + 6 * r0 + c0
    for r in range(3):
        for s in range(3):
            M[row, b + 6 * r + s] += B[3 * r + s]


@njit(cache=True, inline='always')
def mat6_vec(M, row, col, x, out, orow, ocol):
    """out[orow, ocol:ocol + 6] = (6x6 in M[row, col:]) x (x a 6-tuple)."""
    for r in range(6):
        b = col + 6 * r
        out[orow, ocol + r] = (M[row, b] * x[0] + M[row, b + 1] * x[1]
                               + M[row, b + 2] * x[2] + M[row, b + 3] * x[3]
                               + M[row, b + 4] * x[4] + M[row, b + 5] * x[5])


@njit(cache=True)
def motion_to_child(R, p, x):
    """Express a motion vector of frame j-1 in frame j (R, p: j in j-1)."""
    w = rot_t(R, x[0], x[1], x[2])
    t = cross(x[0], x[1], x[2], p[0], p[1], p[2])
    v = rot_t(R, x[3] + t[0], x[4] + t[1], x[5] + t[2])
    return (w[0], w[1], w[2], v[0], v[1], v[2])


@njit(cache=True, inline='always')
def force_to_parent(R, p, f, n):
    """
    Carry a wrench from frame j to frame j-1: the backward passes' step.

    ``f`` and ``n`` are a force and its moment about O_j in frame-j axes;
    returns them in frame j-1 axes, the moment about O_{j-1}:
    f' = R f, n' = R n + p x f'.
    """
    f = rot(R, f[0], f[1], f[2])
    n = rot(R, n[0], n[1], n[2])
    t = cross(p[0], p[1], p[2], f[0], f[1], f[2])
    return f, (n[0] + t[0], n[1] + t[1], n[2] + t[2])
