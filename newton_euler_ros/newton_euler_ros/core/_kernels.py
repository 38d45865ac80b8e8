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
Compiled kernels: the one Newton-Euler recursion and the kinematics it needs.

Everything here is scalar code over 3-tuples so that numba compiles it to
tight machine code, and so that the very same source can run in plain
Python on other number types (the high-precision reference evaluates this
file with ``njit`` replaced by the identity).  Nothing here allocates in
the hot path: callers pass a workspace array.

Number types.  The kernels are generic in the dtype of the arrays they
are given: they contain no float literal (numba types one as float64, and
float32 op float64 is float64), taking 0, 1/2 and 1 from the constants
row ``frames[F_CONST]`` instead, and comparing with integer literals only.
So float64 arrays give float64 arithmetic, float32 arrays give float32
arithmetic throughout (``core.float32``; the tests check numba's type
maps), and mpf object arrays give mpmath arithmetic (``core.highprec``).

Notation (all vectors of link j are expressed in kernel frame j, whose z
axis is the axis of joint j through its origin O_j; see
``model.compile_arrays``):

- ``R``, ``p``: rotation and origin of kernel frame j in frame j-1.
- ``w``: angular velocity (from qd); ``r``: the *reference* angular velocity
  (from the second velocity argument ``v``); ``al``: angular acceleration;
  ``ae``: acceleration of the point O_j; ``ac``: acceleration of the centre
  of mass.  With ``v == qd`` these are the physical quantities of the
  seed text and the recursion is its eqs. (19)-(21).

Two velocity streams.  The recursion evaluates
``Y(q, qd, v, qdd) = D(q) qdd + C(q, qd) v (+ g + J^T F_e)`` where C is the
Christoffel-symbol Coriolis matrix.  Expanding the Lagrangian with body
Jacobians J_i gives ``C v = sum_i J_i^T (M_i Jdot_i(qd) v + B_i(V_i) J_i v)``
with ``B(V) = (M ad_V - ad_V^T M - K(M V)) / 2``, which is skew-symmetric
(so Ddot - 2C is skew) and satisfies ``B(V) V = -ad_V^T M V`` (so C qd is
the true velocity-product torque).  Written at the centre of mass in
3-vectors this becomes the classical recursion with
``w x (w x c)`` -> ``w x (r x c)``,
``w_{j-1} x z qd_j`` -> ``r_{j-1} x z qd_j`` (revolute),
``2 w x z qd_j`` -> ``(r x z) qd_j + (w x z) v_j`` (prismatic) and
``w x I w`` -> ``(w x I r + r x I w + I (w x r)) / 2``.
Every replacement reduces to the physical term exactly when ``v == qd``.

The prismatic Coriolis term is ``2 w x z qd``: the seed's eqs. (15)-(18)
keep only the ``zdot qd`` half and miss the half that comes from
differentiating ``w x r`` while r grows at the rate ``z qd``.
"""
import math

try:  # the high-precision reference injects its own (identity) decorator
    njit = __njit_override__  # noqa: F821
except NameError:
    from numba import njit

# Columns of the per-link parameter array ``links`` (one row per joint), in
# kernel frames (see ``model.compile_arrays``): kernel frame j is kernel
# frame j-1 moved by the constant placement (R, p), then by Rz(q_j)
# (revolute) or Tz(q_j) (prismatic).  The joint axis is z of kernel frame
# j and passes through its origin.
L_TYPE = 0       # 0.0 revolute, 1.0 prismatic
L_R = 1          # 9, row-major: placement rotation in kernel frame j-1
L_P = 10         # 3: placement origin in kernel frame j-1
L_MASS = 13
L_COM = 14       # 3 columns, kernel frame j
L_INERTIA = 17   # 9 columns, row-major, about the com in kernel-frame axes
L_BODY = 26      # 12: R (9) then p (3) of link frame j in kernel frame j
L_WIDTH = 38

# Rows of the fixed-frame array ``frames`` (shape (F_ROWS, 12)).
F_BASE = 0       # R (9, row-major) then p (3): DH frame 0 in the base frame
F_TOOL = 1       # end-effector frame in the last link frame
F_GRAV = 2       # first 3 entries: gravity in frame-0 axes
F_CONST = 3      # the constants below, in the arrays' own number type
F_ROWS = 4

# Columns of the constants row ``frames[F_CONST]``.  A float literal in
# numba code is a float64, and float32 op float64 is float64: the kernels
# take every constant from this row so that they compute purely in the
# dtype of the arrays they are given (float64, float32, or mpmath's mpf).
C_ZERO = 0       # 0.0
C_HALF = 1       # 0.5
C_ONE = 2        # 1.0
CONSTANTS = (0.0, 0.5, 1.0)

# Columns of the workspace ``ws`` (one row per joint).
W_R = 0          # 9: rotation of kernel frame j in kernel frame j-1
W_P = 9          # 3: origin of kernel frame j in kernel frame j-1
W_F = 12         # 3 net force on link j (m * a_c)
W_N = 15         # 3 net moment about the com
W_CT = 18        # cos(q_j) (1 for a prismatic joint)
W_ST = 19        # sin(q_j) (0 for a prismatic joint)
W_DD = 20        # q_j for a prismatic joint (0 for a revolute one)
W_WIDTH = 21

# Returned when finite inputs overflow float64 in the result.
OVERFLOW = 9000

# Wrench modes.
WRENCH_NONE = 0
WRENCH_BASE = 1
WRENCH_EE = 2


@njit(cache=True)
def _cross(a0, a1, a2, b0, b1, b2):
    return (a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0)


@njit(cache=True)
def _revolute(links, frames, j):
    """Return True when joint j is revolute (its type code is zero)."""
    return links[j, L_TYPE] == frames[F_CONST, C_ZERO]


@njit(cache=True)
def joint_trig(links, frames, q, ws):
    """
    Fill cos(q_j), sin(q_j) and the slide of every joint into ``ws``.

    A revolute joint's constant offset is part of its placement, so its
    angle is q itself: a large q is never rounded by adding an offset.
    A prismatic joint needs no trigonometry per call.
    """
    n = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    one = frames[F_CONST, C_ONE]
    for j in range(n):
        if _revolute(links, frames, j):
            ws[j, W_CT] = math.cos(q[j])
            ws[j, W_ST] = math.sin(q[j])
            ws[j, W_DD] = zero
        else:
            ws[j, W_CT] = one
            ws[j, W_ST] = zero
            ws[j, W_DD] = q[j]


@njit(cache=True)
def _link_geometry(links, frames, j, ws):
    """
    R, p of kernel frame j in kernel frame j-1 at the trig values in ``ws``.

    R = R_place Rz(q) and p = p_place + R_place z * slide: a revolute joint
    mixes the first two columns of its placement, a prismatic one moves
    the origin along the third.
    """
    c = ws[j, W_CT]
    s = ws[j, W_ST]
    d = ws[j, W_DD]
    k = L_R
    r0 = links[j, k]
    r1 = links[j, k + 1]
    r2 = links[j, k + 2]
    r3 = links[j, k + 3]
    r4 = links[j, k + 4]
    r5 = links[j, k + 5]
    r6 = links[j, k + 6]
    r7 = links[j, k + 7]
    r8 = links[j, k + 8]
    R = (r0 * c + r1 * s, r1 * c - r0 * s, r2,
         r3 * c + r4 * s, r4 * c - r3 * s, r5,
         r6 * c + r7 * s, r7 * c - r6 * s, r8)
    p = (links[j, L_P] + r2 * d, links[j, L_P + 1] + r5 * d,
         links[j, L_P + 2] + r8 * d)
    return R, p


@njit(cache=True)
def _rotT(R, x0, x1, x2):
    """R^T x."""
    return (R[0] * x0 + R[3] * x1 + R[6] * x2,
            R[1] * x0 + R[4] * x1 + R[7] * x2,
            R[2] * x0 + R[5] * x1 + R[8] * x2)


@njit(cache=True)
def _rot(R, x0, x1, x2):
    """R x."""
    return (R[0] * x0 + R[1] * x1 + R[2] * x2,
            R[3] * x0 + R[4] * x1 + R[5] * x2,
            R[6] * x0 + R[7] * x1 + R[8] * x2)


@njit(cache=True)
def _matmul(A, B):
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
def _frame_rot(frames, row):
    f = frames[row]
    return (f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7], f[8])


@njit(cache=True)
def recursion(links, frames, qd, v, qdd, wrench, gravity_on, velocity_on,
              wrench_mode, ws, tau):
    """
    Newton-Euler recursion: tau = D qdd + C(q, qd) v [+ g] [+ J^T F_e].

    ``joint_trig(links, frames, q, ws)`` must have been called for the same q.
    Cost: about 250 flops per joint, O(n).  Every vector of link j is in
    kernel frame j, whose z axis is joint j's axis through its origin.

    Parameters
    ----------
    links : (n, L_WIDTH) array
        Per-joint placement, mass, centre-of-mass and inertia parameters
        (the ``L_*`` columns).
    frames : (F_ROWS, 12) array
        Base frame, tool frame, gravity and constants (the ``F_*`` rows).
    qd, v, qdd : (n,) arrays
        Joint velocity, reference velocity, acceleration.
    wrench : (6,) array
        [f; n] exerted by the end effector on its environment, moment about
        the end-effector origin; base-frame axes when
        ``wrench_mode == WRENCH_BASE``, end-effector axes when
        ``WRENCH_EE``; ignored when ``WRENCH_NONE``.
    gravity_on, velocity_on : bool
        Skip the gravity or velocity-product terms altogether when False.
    wrench_mode : int
        ``WRENCH_NONE``, ``WRENCH_BASE`` or ``WRENCH_EE``.
    ws : (n, W_WIDTH) array
        Workspace: reads the trig columns ``joint_trig`` filled, overwrites
        the other ``W_*`` columns.
    tau : (n,) array
        Output.

    """
    n = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    half = frames[F_CONST, C_HALF]
    # Gravity enters as an upward acceleration of the base: a_0 = -g.
    if gravity_on:
        ae = (-frames[F_GRAV, 0], -frames[F_GRAV, 1], -frames[F_GRAV, 2])
    else:
        ae = (zero, zero, zero)
    w = (zero, zero, zero)
    r = (zero, zero, zero)
    al = (zero, zero, zero)
    Racc = _frame_rot(frames, F_BASE)

    # ---- forward recursion: base to tip ----
    for j in range(n):
        R, p = _link_geometry(links, frames, j, ws)
        # acceleration of the new origin O_j, still in frame j-1 axes
        t = _cross(al[0], al[1], al[2], p[0], p[1], p[2])
        ae = (ae[0] + t[0], ae[1] + t[1], ae[2] + t[2])
        if velocity_on:
            t = _cross(r[0], r[1], r[2], p[0], p[1], p[2])
            t = _cross(w[0], w[1], w[2], t[0], t[1], t[2])
            ae = (ae[0] + t[0], ae[1] + t[1], ae[2] + t[2])
        # rotate everything into frame j
        ae = _rotT(R, ae[0], ae[1], ae[2])
        al = _rotT(R, al[0], al[1], al[2])
        revolute = _revolute(links, frames, j)
        if velocity_on:
            w = _rotT(R, w[0], w[1], w[2])
            r = _rotT(R, r[0], r[1], r[2])
            if revolute:
                # alpha_j = R^T alpha_{j-1} + z qdd + (r_{j-1} x z) qd_j
                al = (al[0] + r[1] * qd[j], al[1] - r[0] * qd[j],
                      al[2] + qdd[j])
                w = (w[0], w[1], w[2] + qd[j])
                r = (r[0], r[1], r[2] + v[j])
            else:
                # the sliding joint: z qdd + Coriolis 2 w x z qd (v == qd)
                ae = (ae[0] + r[1] * qd[j] + w[1] * v[j],
                      ae[1] - r[0] * qd[j] - w[0] * v[j],
                      ae[2] + qdd[j])
        elif revolute:
            al = (al[0], al[1], al[2] + qdd[j])
        else:
            ae = (ae[0], ae[1], ae[2] + qdd[j])
        # acceleration of the centre of mass
        c0 = links[j, L_COM]
        c1 = links[j, L_COM + 1]
        c2 = links[j, L_COM + 2]
        t = _cross(al[0], al[1], al[2], c0, c1, c2)
        ac = (ae[0] + t[0], ae[1] + t[1], ae[2] + t[2])
        if velocity_on:
            t = _cross(r[0], r[1], r[2], c0, c1, c2)
            t = _cross(w[0], w[1], w[2], t[0], t[1], t[2])
            ac = (ac[0] + t[0], ac[1] + t[1], ac[2] + t[2])
        m = links[j, L_MASS]
        ws[j, W_F] = m * ac[0]
        ws[j, W_F + 1] = m * ac[1]
        ws[j, W_F + 2] = m * ac[2]
        # Euler's equation about the com
        k = L_INERTIA
        Ic = (links[j, k], links[j, k + 1], links[j, k + 2],
              links[j, k + 3], links[j, k + 4], links[j, k + 5],
              links[j, k + 6], links[j, k + 7], links[j, k + 8])
        Ia = _rot(Ic, al[0], al[1], al[2])
        Nn = Ia
        if velocity_on:
            Ir = _rot(Ic, r[0], r[1], r[2])
            Iw = _rot(Ic, w[0], w[1], w[2])
            t = _cross(w[0], w[1], w[2], Ir[0], Ir[1], Ir[2])
            t2 = _cross(r[0], r[1], r[2], Iw[0], Iw[1], Iw[2])
            wr = _cross(w[0], w[1], w[2], r[0], r[1], r[2])
            t3 = _rot(Ic, wr[0], wr[1], wr[2])
            Nn = (Ia[0] + half * ((t[0] + t2[0]) + t3[0]),
                  Ia[1] + half * ((t[1] + t2[1]) + t3[1]),
                  Ia[2] + half * ((t[2] + t2[2]) + t3[2]))
        ws[j, W_N] = Nn[0]
        ws[j, W_N + 1] = Nn[1]
        ws[j, W_N + 2] = Nn[2]
        for k in range(9):
            ws[j, W_R + k] = R[k]
        for k in range(3):
            ws[j, W_P + k] = p[k]
        if wrench_mode == WRENCH_BASE:
            Racc = _matmul(Racc, R)

    # ---- the wrench the tip exerts, as "f_{n+1}, tau_{n+1}" in frame n ----
    f = (zero, zero, zero)
    nm = (zero, zero, zero)
    if wrench_mode != WRENCH_NONE:
        Rt = _frame_rot(frames, F_TOOL)
        fe = (wrench[0], wrench[1], wrench[2])
        ne = (wrench[3], wrench[4], wrench[5])
        if wrench_mode == WRENCH_BASE:
            Ree = _matmul(Racc, Rt)
            fe = _rotT(Ree, fe[0], fe[1], fe[2])
            ne = _rotT(Ree, ne[0], ne[1], ne[2])
        f = _rot(Rt, fe[0], fe[1], fe[2])
        nm = _rot(Rt, ne[0], ne[1], ne[2])
        t = _cross(frames[F_TOOL, 9], frames[F_TOOL, 10], frames[F_TOOL, 11],
                   f[0], f[1], f[2])
        nm = (nm[0] + t[0], nm[1] + t[1], nm[2] + t[2])

    # ---- backward recursion: tip to base ----
    # f, nm hold the force and the moment (about O_j) that link j exerts on
    # its child, in frame j axes.
    for j in range(n - 1, -1, -1):
        F0 = ws[j, W_F]
        F1 = ws[j, W_F + 1]
        F2 = ws[j, W_F + 2]
        t = _cross(links[j, L_COM], links[j, L_COM + 1], links[j, L_COM + 2],
                   F0, F1, F2)
        nm = (nm[0] + t[0] + ws[j, W_N], nm[1] + t[1] + ws[j, W_N + 1],
              nm[2] + t[2] + ws[j, W_N + 2])
        f = (f[0] + F0, f[1] + F1, f[2] + F2)
        # the joint takes the moment about (revolute) or the force along
        # (prismatic) its axis z
        if _revolute(links, frames, j):
            tau[j] = nm[2]
        else:
            tau[j] = f[2]
        if j > 0:
            R = (ws[j, W_R], ws[j, W_R + 1], ws[j, W_R + 2],
                 ws[j, W_R + 3], ws[j, W_R + 4], ws[j, W_R + 5],
                 ws[j, W_R + 6], ws[j, W_R + 7], ws[j, W_R + 8])
            f = _rot(R, f[0], f[1], f[2])
            nm = _rot(R, nm[0], nm[1], nm[2])
            t = _cross(ws[j, W_P], ws[j, W_P + 1], ws[j, W_P + 2],
                       f[0], f[1], f[2])
            nm = (nm[0] + t[0], nm[1] + t[1], nm[2] + t[2])


@njit(cache=True)
def first_nonfinite(x):
    """Index of the first non-finite entry of x, or -1."""
    for i in range(x.shape[0]):
        if not math.isfinite(x[i]):
            return i
    return -1


@njit(cache=True)
def round_into(x, out):
    """
    Copy x into out, converting to out's dtype.

    float64 -> float32 rounds to nearest and gives +-inf past the float32
    range, without the warning numpy's cast would print.
    """
    for i in range(x.shape[0]):
        out[i] = x[i]


@njit(cache=True)
def check_finite(q, qd, qdd, wrench):
    """-1 when all entries are finite, else 1000 * argument + index."""
    i = first_nonfinite(q)
    if i >= 0:
        return i
    i = first_nonfinite(qd)
    if i >= 0:
        return 1000 + i
    i = first_nonfinite(qdd)
    if i >= 0:
        return 2000 + i
    i = first_nonfinite(wrench)
    if i >= 0:
        return 3000 + i
    return -1


@njit(cache=True)
def inverse_dynamics(links, frames, q, qd, qdd, wrench, gravity_on,
                     velocity_on, wrench_mode, ws, tau):
    """
    tau(q, qd, qdd, F_e) after checking the inputs are finite.

    Returns -1, or the code of the first non-finite input (see
    ``check_finite``); tau is untouched then.
    """
    bad = check_finite(q, qd, qdd, wrench)
    if bad >= 0:
        return bad
    joint_trig(links, frames, q, ws)
    recursion(links, frames, qd, qd, qdd, wrench, gravity_on, velocity_on,
              wrench_mode, ws, tau)
    if first_nonfinite(tau) >= 0:
        return OVERFLOW
    return -1


@njit(cache=True)
def inverse_dynamics_batch(links, frames, Q, QD, QDD, W, gravity_on,
                           velocity_on, wrench_mode, ws, TAU):
    """Row-by-row inverse dynamics over a batch of states."""
    for k in range(Q.shape[0]):
        joint_trig(links, frames, Q[k], ws)
        recursion(links, frames, QD[k], QD[k], QDD[k], W[k], gravity_on,
                  velocity_on, wrench_mode, ws, TAU[k])


@njit(cache=True)
def _unit_columns(links, frames, qd, coriolis, ws, scratch, M):
    """
    Columns of D (``coriolis`` False) or C(q, qd) from unit inputs.

    D e_k = Y(q, 0, 0, e_k) and C e_k = Y(q, qd, e_k, 0), where Y is the
    two-stream recursion; ``joint_trig`` must have been called for q.
    ``scratch`` is a (3, n) array.  Cost: n recursions, O(n^2).
    """
    n = links.shape[0]
    zero = scratch[0]
    unit = scratch[1]
    col = scratch[2]
    for i in range(n):
        zero[i] = frames[F_CONST, C_ZERO]
        unit[i] = frames[F_CONST, C_ZERO]
    for k in range(n):
        unit[k] = frames[F_CONST, C_ONE]
        if coriolis:
            recursion(links, frames, qd, unit, zero, zero, False, True,
                      WRENCH_NONE, ws, col)
        else:
            recursion(links, frames, zero, zero, unit, zero, False, False,
                      WRENCH_NONE, ws, col)
        unit[k] = frames[F_CONST, C_ZERO]
        for i in range(n):
            M[i, k] = col[i]


@njit(cache=True)
def mass_matrix(links, frames, q, ws, scratch, D):
    """D(q) column by column: D e_k = recursion(qd = 0, qdd = e_k)."""
    n = links.shape[0]
    half = frames[F_CONST, C_HALF]
    joint_trig(links, frames, q, ws)
    _unit_columns(links, frames, q, False, ws, scratch, D)
    # D is symmetric in exact arithmetic; make it so to the last bit.
    for i in range(n):
        for k in range(i + 1, n):
            avg = half * (D[i, k] + D[k, i])
            D[i, k] = avg
            D[k, i] = avg
    return _matrix_status(D)


@njit(cache=True)
def coriolis_matrix(links, frames, q, qd, ws, scratch, C):
    """Christoffel C(q, qd) column by column: C e_k = Y(q, qd, e_k, 0)."""
    joint_trig(links, frames, q, ws)
    _unit_columns(links, frames, qd, True, ws, scratch, C)
    return _matrix_status(C)


@njit(cache=True)
def _sym_mul(S, x0, x1, x2):
    """S x for a symmetric S stored as (xx, yy, zz, xy, yz, xz)."""
    return (S[0] * x0 + S[3] * x1 + S[5] * x2,
            S[3] * x0 + S[1] * x1 + S[4] * x2,
            S[5] * x0 + S[4] * x1 + S[2] * x2)


@njit(cache=True)
def _sym_rotate(R, S):
    """R S R^T for a symmetric S, both stored as (xx, yy, zz, xy, yz, xz)."""
    # rows of A = R S (S is symmetric, so row k of R times S is S r_k)
    a0 = _sym_mul(S, R[0], R[1], R[2])
    a1 = _sym_mul(S, R[3], R[4], R[5])
    a2 = _sym_mul(S, R[6], R[7], R[8])
    # (A R^T)_ik = a_i . r_k, upper triangle only
    return (a0[0] * R[0] + a0[1] * R[1] + a0[2] * R[2],
            a1[0] * R[3] + a1[1] * R[4] + a1[2] * R[5],
            a2[0] * R[6] + a2[1] * R[7] + a2[2] * R[8],
            a0[0] * R[3] + a0[1] * R[4] + a0[2] * R[5],
            a1[0] * R[6] + a1[1] * R[7] + a1[2] * R[8],
            a0[0] * R[6] + a0[1] * R[7] + a0[2] * R[8])


@njit(cache=True)
def mass_matrix_crba(links, frames, q, ws, D):
    """
    D(q) by the composite-rigid-body algorithm (CRBA); O(n^2), small constant.

    Column i of D is the torque for qdd = e_i at rest without gravity
    (what ``mass_matrix`` computes with one recursion).  Then links 0..i-1
    stand still and need no force, and links i..n-1 move as one rigid
    *composite body i*; so every joint j <= i transmits just the wrench
    composite i needs, and D[j, i] is joint j's component of it.  The
    entries j > i of the column come from symmetry, D[j, i] = D[i, j],
    filled when column j is done.

    Composite i is kept in kernel frame i as its mass M, first moment
    h = sum m_k c_k (c_k: centre of mass of link k seen from O_i) and
    rotational inertia I about O_i, never divided by the mass, so massless
    links and composites need no care.  It is built from the tip: add link
    i (h += m c, I += I_c + m (|c|^2 1 - c c^T), with the symmetric part of
    I_c), use it, then carry it into frame i-1 (R, p of frame i in frame
    i-1): with hr = R h, h' = hr + M p and, since the position of each
    mass element becomes r' = R r + p,
    I' = R I R^T - [p][hr] - [hr][p] - M [p][p] ([x] the cross-product
    matrix), written with g = hr + M p / 2 as
    I' = R I R^T + 2 (g . p) 1 - (g p^T + p g^T) so it stays symmetric.

    Unit rate of joint i (axis z through O_i): revolute, angular
    acceleration z with O_i at rest; prismatic, no rotation and O_i
    accelerating by z.  Newton-Euler about O_i (not the centre of mass)
    at zero velocity: F = M a + al x h, N = I al + h x a, that is
    F = z x h, N = I z (revolute) or F = M z, N = h x z (prismatic).
    D[i, i] is joint i's component (N_z, or F_z); for j = i-1..0 the
    wrench is carried to frame j by the recursion's backward step
    F <- R F, N <- R N + p x F and D[j, i] = D[i, j] is joint j's
    component.  D is symmetric exactly.  Cost: about 170 flops per joint
    plus 50 per pair j < i, against the n recursions of ``mass_matrix``;
    the same D as those up to round-off (the tests check 10 n eps in
    float64 and 1e-40 at 50 digits).

    Returns -1, or OVERFLOW when an entry is not finite (as ``mass_matrix``).
    """
    n = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    half = frames[F_CONST, C_HALF]
    joint_trig(links, frames, q, ws)
    for j in range(n):
        R, p = _link_geometry(links, frames, j, ws)
        for k in range(9):
            ws[j, W_R + k] = R[k]
        for k in range(3):
            ws[j, W_P + k] = p[k]
    M = zero
    h = (zero, zero, zero)
    Io = (zero, zero, zero, zero, zero, zero)
    for i in range(n - 1, -1, -1):
        # ---- add link i to the composite (frame i, about O_i) ----
        m = links[i, L_MASS]
        c0 = links[i, L_COM]
        c1 = links[i, L_COM + 1]
        c2 = links[i, L_COM + 2]
        mc0 = m * c0
        mc1 = m * c1
        mc2 = m * c2
        k = L_INERTIA
        M = M + m
        h = (h[0] + mc0, h[1] + mc1, h[2] + mc2)
        Io = (Io[0] + links[i, k] + (mc1 * c1 + mc2 * c2),
              Io[1] + links[i, k + 4] + (mc0 * c0 + mc2 * c2),
              Io[2] + links[i, k + 8] + (mc0 * c0 + mc1 * c1),
              Io[3] + half * (links[i, k + 1] + links[i, k + 3]) - mc0 * c1,
              Io[4] + half * (links[i, k + 5] + links[i, k + 7]) - mc1 * c2,
              Io[5] + half * (links[i, k + 2] + links[i, k + 6]) - mc0 * c2)
        # ---- wrench on the composite for a unit rate of joint i ----
        revolute = _revolute(links, frames, i)
        if revolute:
            F = (-h[1], h[0], zero)
            N = (Io[5], Io[4], Io[2])
            D[i, i] = N[2]
        else:
            F = (zero, zero, M)
            N = (h[1], -h[0], zero)
            D[i, i] = F[2]
        # ---- carry it to the base, joint by joint ----
        for j in range(i - 1, -1, -1):
            R = (ws[j + 1, W_R], ws[j + 1, W_R + 1], ws[j + 1, W_R + 2],
                 ws[j + 1, W_R + 3], ws[j + 1, W_R + 4], ws[j + 1, W_R + 5],
                 ws[j + 1, W_R + 6], ws[j + 1, W_R + 7], ws[j + 1, W_R + 8])
            F = _rot(R, F[0], F[1], F[2])
            N = _rot(R, N[0], N[1], N[2])
            t = _cross(ws[j + 1, W_P], ws[j + 1, W_P + 1], ws[j + 1, W_P + 2],
                       F[0], F[1], F[2])
            N = (N[0] + t[0], N[1] + t[1], N[2] + t[2])
            if _revolute(links, frames, j):
                x = N[2]
            else:
                x = F[2]
            D[j, i] = x
            D[i, j] = x
        # ---- the composite in frame i-1, about O_{i-1} ----
        if i > 0:
            R = (ws[i, W_R], ws[i, W_R + 1], ws[i, W_R + 2],
                 ws[i, W_R + 3], ws[i, W_R + 4], ws[i, W_R + 5],
                 ws[i, W_R + 6], ws[i, W_R + 7], ws[i, W_R + 8])
            p = (ws[i, W_P], ws[i, W_P + 1], ws[i, W_P + 2])
            hr = _rot(R, h[0], h[1], h[2])
            Ir = _sym_rotate(R, Io)
            hM = half * M
            g = (hr[0] + hM * p[0], hr[1] + hM * p[1], hr[2] + hM * p[2])
            g0p0 = g[0] * p[0]
            g1p1 = g[1] * p[1]
            g2p2 = g[2] * p[2]
            Io = (Ir[0] + ((g1p1 + g2p2) + (g1p1 + g2p2)),
                  Ir[1] + ((g0p0 + g2p2) + (g0p0 + g2p2)),
                  Ir[2] + ((g0p0 + g1p1) + (g0p0 + g1p1)),
                  Ir[3] - (g[0] * p[1] + g[1] * p[0]),
                  Ir[4] - (g[1] * p[2] + g[2] * p[1]),
                  Ir[5] - (g[0] * p[2] + g[2] * p[0]))
            h = (hr[0] + M * p[0], hr[1] + M * p[1], hr[2] + M * p[2])
    return _matrix_status(D)


@njit(cache=True)
def _matrix_status(M):
    """Return -1 when every entry is finite, else OVERFLOW."""
    for i in range(M.shape[0]):
        if first_nonfinite(M[i]) >= 0:
            return OVERFLOW
    return -1


@njit(cache=True)
def _chain_poses(links, frames, q, ws, Ts, link_frames):
    """
    Walk the chain and store the poses of its frames in ``Ts``.

    Rows 1..n get kernel frames 1..n (or, with ``link_frames``, the link
    frames of the model, B_j applied), row 0 frame 0, row n+1 the end
    effector; all in the base frame, each row R (9, row-major) then p (3).
    """
    n = links.shape[0]
    joint_trig(links, frames, q, ws)
    Rw = _frame_rot(frames, F_BASE)
    pw = (frames[F_BASE, 9], frames[F_BASE, 10], frames[F_BASE, 11])
    for k in range(9):
        Ts[0, k] = Rw[k]
    for k in range(3):
        Ts[0, 9 + k] = pw[k]
    for j in range(n + 1):
        if j < n:
            R, p = _link_geometry(links, frames, j, ws)
        else:
            R = _frame_rot(frames, F_TOOL)
            p = (frames[F_TOOL, 9], frames[F_TOOL, 10], frames[F_TOOL, 11])
        t = _rot(Rw, p[0], p[1], p[2])
        pw = (pw[0] + t[0], pw[1] + t[1], pw[2] + t[2])
        Rw = _matmul(Rw, R)
        Ro = Rw
        po = pw
        if link_frames and j < n:
            k = L_BODY
            RB = (links[j, k], links[j, k + 1], links[j, k + 2],
                  links[j, k + 3], links[j, k + 4], links[j, k + 5],
                  links[j, k + 6], links[j, k + 7], links[j, k + 8])
            t = _rot(Rw, links[j, k + 9], links[j, k + 10], links[j, k + 11])
            po = (pw[0] + t[0], pw[1] + t[1], pw[2] + t[2])
            Ro = _matmul(Rw, RB)
        for k in range(9):
            Ts[j + 1, k] = Ro[k]
        for k in range(3):
            Ts[j + 1, 9 + k] = po[k]


@njit(cache=True)
def forward_kinematics(links, frames, q, ws, Ts):
    """
    Poses of frame 0, the link frames 1..n and the end effector.

    ``Ts`` is (n + 2, 12), in the base frame: row 0 frame 0, rows 1..n the
    model's link frames (where its inertial parameters are given), row
    n+1 the end effector; each row R (9, row-major) then p (3).
    """
    _chain_poses(links, frames, q, ws, Ts, True)


@njit(cache=True)
def jacobian(links, frames, q, in_ee_axes, ws, Ts, J):
    """
    Geometric Jacobian of the end-effector origin, rows [v; w].

    Base-frame axes, or end-effector axes when ``in_ee_axes``.  Cost O(n).
    Joint j moves about z of kernel frame j, through its origin.
    """
    n = links.shape[0]
    _chain_poses(links, frames, q, ws, Ts, False)
    pe = (Ts[n + 1, 9], Ts[n + 1, 10], Ts[n + 1, 11])
    zero = frames[F_CONST, C_ZERO]
    for j in range(n):
        row = j + 1
        z = (Ts[row, 2], Ts[row, 5], Ts[row, 8])
        if _revolute(links, frames, j):
            rel = (pe[0] - Ts[row, 9], pe[1] - Ts[row, 10],
                   pe[2] - Ts[row, 11])
            lin = _cross(z[0], z[1], z[2], rel[0], rel[1], rel[2])
            ang = z
        else:
            lin = z
            ang = (zero, zero, zero)
        if in_ee_axes:
            Re = (Ts[n + 1, 0], Ts[n + 1, 1], Ts[n + 1, 2], Ts[n + 1, 3],
                  Ts[n + 1, 4], Ts[n + 1, 5], Ts[n + 1, 6], Ts[n + 1, 7],
                  Ts[n + 1, 8])
            lin = _rotT(Re, lin[0], lin[1], lin[2])
            ang = _rotT(Re, ang[0], ang[1], ang[2])
        for k in range(3):
            J[k, j] = lin[k]
            J[3 + k, j] = ang[k]


@njit(cache=True)
def cholesky_solve(A, b, L, x):
    """
    Solve A x = b for symmetric positive definite A by Cholesky.

    Returns -1 on success, or the index of the first pivot that is not
    positive (A is not positive definite there).  A is left unchanged.
    """
    n = A.shape[0]
    for i in range(n):
        for k in range(i + 1):
            acc = A[i, k]
            for m in range(k):
                acc -= L[i, m] * L[k, m]
            if i == k:
                if not acc > 0:     # an int literal: exact in any dtype
                    return i
                L[i, i] = math.sqrt(acc)
            else:
                L[i, k] = acc / L[k, k]
    for i in range(n):
        acc = b[i]
        for m in range(i):
            acc -= L[i, m] * x[m]
        x[i] = acc / L[i, i]
    for i in range(n - 1, -1, -1):
        acc = x[i]
        for m in range(i + 1, n):
            acc -= L[m, i] * x[m]
        x[i] = acc / L[i, i]
    return -1
