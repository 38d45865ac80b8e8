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


@njit(cache=True, inline='always')
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


@njit(cache=True, inline='always')
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


@njit(cache=True, inline='always')
def _placement(links, frames, j, ws):
    """Return R, p of kernel frame j in j-1 (``_link_geometry``), stored."""
    R, p = _link_geometry(links, frames, j, ws)
    for k in range(9):
        ws[j, W_R + k] = R[k]
    for k in range(3):
        ws[j, W_P + k] = p[k]
    return R, p


@njit(cache=True, inline='always')
def _link_inertia(links, j):
    """Return link j's rotational inertia about its com, row-major 3x3."""
    k = L_INERTIA
    return (links[j, k], links[j, k + 1], links[j, k + 2],
            links[j, k + 3], links[j, k + 4], links[j, k + 5],
            links[j, k + 6], links[j, k + 7], links[j, k + 8])


@njit(cache=True, inline='always')
def _stored_placement(ws, j):
    """Return R, p of kernel frame j in j-1 as a pass stored them in ws."""
    R = (ws[j, W_R], ws[j, W_R + 1], ws[j, W_R + 2],
         ws[j, W_R + 3], ws[j, W_R + 4], ws[j, W_R + 5],
         ws[j, W_R + 6], ws[j, W_R + 7], ws[j, W_R + 8])
    return R, (ws[j, W_P], ws[j, W_P + 1], ws[j, W_P + 2])


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


@njit(cache=True, inline='always')
def recursion(links, frames, qd, v, qdd, wrench, gravity_on, velocity_on,
              wrench_mode, ws, tau):
    """
    Newton-Euler recursion: tau = D qdd + C(q, qd) v [+ g] [+ J^T F_e].

    ``joint_trig(links, frames, q, ws)`` must have been called for the same q.
    A forward step per joint, base to tip, then a backward step per joint,
    tip to base, as in the seed text (Pinocchio's RneaForwardStep and
    RneaBackwardStep).  They are written inline, in one function: numba
    passes arrays and tuples between functions at a cost (measured: 35%
    more per call with the steps as functions, inlined or not).
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

    # ---- forward steps, base to tip: the seed's eqs. (19)-(21) ----
    # from link j-1's w, r, al, ae (frame j-1 axes) to link j's (frame j
    # axes); link j's net force m a_c and moment about its com into ws
    for j in range(n):
        R, p = _placement(links, frames, j, ws)
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
        Ic = _link_inertia(links, j)
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
        if wrench_mode == WRENCH_BASE:
            Racc = _matmul(Racc, R)

    # ---- the wrench the tip exerts, as "f_{n+1}, tau_{n+1}" in frame n ----
    f = (zero, zero, zero)
    nm = (zero, zero, zero)
    if wrench_mode != WRENCH_NONE:
        e = _tip_wrench(frames, wrench, wrench_mode, Racc)
        nm = (e[0], e[1], e[2])
        f = (e[3], e[4], e[5])

    # ---- backward steps, tip to base: the force and moment balance ----
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
            R, _ = _stored_placement(ws, j)
            f = _rot(R, f[0], f[1], f[2])
            nm = _rot(R, nm[0], nm[1], nm[2])
            t = _cross(ws[j, W_P], ws[j, W_P + 1], ws[j, W_P + 2],
                       f[0], f[1], f[2])
            nm = (nm[0] + t[0], nm[1] + t[1], nm[2] + t[2])


@njit(cache=True, inline='always')
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


@njit(cache=True, inline='always')
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


@njit(cache=True, inline='always')
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
        R, p = _placement(links, frames, j, ws)
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
            R, _ = _stored_placement(ws, j + 1)
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
            R, p = _stored_placement(ws, i)
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


# ---------------------------------------------------------------------------
# Spatial (6-vector) algorithms: articulated-body forward dynamics and the
# O(n^2) Coriolis matrix.  A spatial motion vector is [angular; linear] and
# a spatial force [moment; force], both at the origin of the frame whose
# axes they are given in (Featherstone's convention).  6x6 matrices are
# stored row-major in 36 consecutive columns of a workspace row.

# Columns of the articulated-body workspace ``aw`` (n + 1 rows; row n is
# scratch).
A_IA = 0         # 36: articulated inertia of link j about O_j, frame j
A_PA = 36        # 6: articulated bias force
A_V = 42         # 6: spatial velocity of link j
A_C = 48         # 6: velocity-product acceleration v_j x (S_j qd_j)
A_U = 54         # 6: U = IA S (the column of IA on the joint axis)
A_D = 60         # D = S^T IA S
A_UU = 61        # u = tau - S^T pA
A_WIDTH = 62

# Columns of the Coriolis workspace ``cw`` (n + 1 rows; row n is scratch:
# the composite inertia IC (36), the composite Coriolis matrix BC (36),
# then I_j V_j (6)).
CW_S = 0         # 6: motion subspace of joint j, frame 0 at its origin
CW_SD = 6        # 6: its rate, V_j x S_j
CW_F1 = 12       # 6: IC_j S_j
CW_F2 = 18       # 6: BC_j^T S_j
CW_G = 24        # 6: IC_j Sdot_j + BC_j S_j
CW_RW = 30       # 9: rotation of kernel frame j in frame 0
CW_OW = 39       # 3: origin of kernel frame j in frame 0
CW_V = 42        # 6: spatial velocity of link j
CW_I = 48        # 36: spatial inertia of link j, frame 0 about its origin
CW_WIDTH = 84


@njit(cache=True)
def _axis_index(links, frames, j):
    """Index of joint j's motion subspace in a spatial vector: 2 or 5."""
    return 2 if _revolute(links, frames, j) else 5


@njit(cache=True, inline='always')
def _body_inertia(links, j, R, o, M, row, col):
    """
    Write link j's spatial inertia into ``M[row, col:col + 36]``.

    About the origin o of the frame whose rotation (to link j's kernel
    frame axes) is R: the link's centre of mass is o + R c and its
    rotational inertia R I_c R^T.  Blocks [[I_o, m [c]], [m [c]^T, m 1]].
    """
    m = links[j, L_MASS]
    c = _rot(R, links[j, L_COM], links[j, L_COM + 1], links[j, L_COM + 2])
    c = (o[0] + c[0], o[1] + c[1], o[2] + c[2])
    Ic = _matmul(_matmul(R, _link_inertia(links, j)), _transpose(R))
    mc = (m * c[0], m * c[1], m * c[2])
    cc = c[0] * mc[0] + c[1] * mc[1] + c[2] * mc[2]
    zero = m - m
    for r in range(3):
        for s in range(3):
            v = Ic[3 * r + s] - mc[r] * c[s]
            if r == s:
                v = v + cc
            M[row, col + 6 * r + s] = v
            M[row, col + 6 * (r + 3) + s + 3] = m if r == s else zero
    # m [c] (top right) and its transpose (bottom left)
    X = (zero, -mc[2], mc[1], mc[2], zero, -mc[0], -mc[1], mc[0], zero)
    for r in range(3):
        for s in range(3):
            M[row, col + 6 * r + s + 3] = X[3 * r + s]
            M[row, col + 6 * (s + 3) + r] = X[3 * r + s]


@njit(cache=True)
def _transpose(A):
    return (A[0], A[3], A[6], A[1], A[4], A[7], A[2], A[5], A[8])


@njit(cache=True)
def _block(M, row, col, r0, c0):
    """Return the 3x3 block at (r0, c0) of the 6x6 matrix in M[row, col:]."""
    b = col + 6 * r0 + c0
    return (M[row, b], M[row, b + 1], M[row, b + 2],
            M[row, b + 6], M[row, b + 7], M[row, b + 8],
            M[row, b + 12], M[row, b + 13], M[row, b + 14])


@njit(cache=True)
def _add_block(M, row, col, r0, c0, B):
    b = col + 6 * r0 + c0
    for r in range(3):
        for s in range(3):
            M[row, b + 6 * r + s] += B[3 * r + s]


@njit(cache=True)
def _skew(p):
    """[p], the matrix of p x (.), row-major."""
    zero = p[0] - p[0]
    return (zero, -p[2], p[1], p[2], zero, -p[0], -p[1], p[0], zero)


@njit(cache=True, inline='always')
def _mat6_vec(M, row, col, x, out, orow, ocol):
    """out[orow, ocol:ocol + 6] = (6x6 in M[row, col:]) x (x a 6-tuple)."""
    for r in range(6):
        b = col + 6 * r
        out[orow, ocol + r] = (M[row, b] * x[0] + M[row, b + 1] * x[1]
                               + M[row, b + 2] * x[2] + M[row, b + 3] * x[3]
                               + M[row, b + 4] * x[4] + M[row, b + 5] * x[5])


@njit(cache=True)
def _vec6(M, row, col):
    return (M[row, col], M[row, col + 1], M[row, col + 2],
            M[row, col + 3], M[row, col + 4], M[row, col + 5])


@njit(cache=True)
def _motion_to_child(R, p, x):
    """Express a motion vector of frame j-1 in frame j (R, p: j in j-1)."""
    w = _rotT(R, x[0], x[1], x[2])
    t = _cross(x[0], x[1], x[2], p[0], p[1], p[2])
    v = _rotT(R, x[3] + t[0], x[4] + t[1], x[5] + t[2])
    return (w[0], w[1], w[2], v[0], v[1], v[2])


@njit(cache=True)
def _tip_wrench(frames, wrench, wrench_mode, Racc):
    """
    Return the wrench the tip exerts, at O_n in frame-n axes: [n; f].

    ``Racc`` is the rotation of frame n in the base frame (used for
    ``WRENCH_BASE``).  As the recursion's "f_{n+1}, tau_{n+1}".
    """
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
    return (nm[0] + t[0], nm[1] + t[1], nm[2] + t[2], f[0], f[1], f[2])


@njit(cache=True, inline='always')
def _aba_forward_velocities(links, frames, qd, wrench, velocity_on,
                            wrench_mode, ws, aw):
    """
    ABA pass 1, base to tip: poses, velocities, bias accelerations.

    Stores R, p (``ws``), v_j, c_j = v_j x S_j qd_j, the link's spatial
    inertia as the starting articulated inertia IA_j and its bias force
    pA_j = v_j x* (I_j v_j), plus the tip's wrench on the last link.
    """
    n = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    one = frames[F_CONST, C_ONE]
    v = (zero, zero, zero, zero, zero, zero)
    Racc = _frame_rot(frames, F_BASE)
    ident = (one, zero, zero, zero, one, zero, zero, zero, one)
    origin = (zero, zero, zero)
    for j in range(n):
        R, p = _placement(links, frames, j, ws)
        if wrench_mode == WRENCH_BASE:
            Racc = _matmul(Racc, R)
        _body_inertia(links, j, ident, origin, aw, j, A_IA)
        c = (zero, zero, zero, zero, zero, zero)
        if velocity_on:
            v = _motion_to_child(R, p, v)
            s = qd[j]
            if _revolute(links, frames, j):
                c = (v[1] * s, -v[0] * s, zero, v[4] * s, -v[3] * s, zero)
                v = (v[0], v[1], v[2] + s, v[3], v[4], v[5])
            else:
                c = (zero, zero, zero, v[1] * s, -v[0] * s, zero)
                v = (v[0], v[1], v[2], v[3], v[4], v[5] + s)
            # pA = v x* (I v): [w x h_n + v_o x h_f; w x h_f]
            _mat6_vec(aw, j, A_IA, v, aw, j, A_PA)
            h = _vec6(aw, j, A_PA)
            t1 = _cross(v[0], v[1], v[2], h[0], h[1], h[2])
            t2 = _cross(v[3], v[4], v[5], h[3], h[4], h[5])
            t3 = _cross(v[0], v[1], v[2], h[3], h[4], h[5])
            pa = (t1[0] + t2[0], t1[1] + t2[1], t1[2] + t2[2],
                  t3[0], t3[1], t3[2])
        else:
            pa = (zero, zero, zero, zero, zero, zero)
        if j == n - 1 and wrench_mode != WRENCH_NONE:
            e = _tip_wrench(frames, wrench, wrench_mode, Racc)
            pa = (pa[0] + e[0], pa[1] + e[1], pa[2] + e[2],
                  pa[3] + e[3], pa[4] + e[4], pa[5] + e[5])
        for k in range(6):
            aw[j, A_V + k] = v[k]
            aw[j, A_C + k] = c[k]
            aw[j, A_PA + k] = pa[k]


@njit(cache=True, inline='always')
def _aba_backward_inertias(links, frames, tau, ws, aw):
    """
    ABA pass 2, tip to base: articulated inertias and bias forces.

    Returns -1, or the index of the joint whose D = S^T IA S is not
    positive (no inertia moves with it: the mass matrix is singular).
    """
    n = links.shape[0]
    for j in range(n - 1, -1, -1):
        k = _axis_index(links, frames, j)
        U = (aw[j, A_IA + k], aw[j, A_IA + 6 + k], aw[j, A_IA + 12 + k],
             aw[j, A_IA + 18 + k], aw[j, A_IA + 24 + k],
             aw[j, A_IA + 30 + k])
        D = U[k]
        if not D > 0:       # an int literal: exact in any dtype
            return j
        u = tau[j] - aw[j, A_PA + k]
        for r in range(6):
            aw[j, A_U + r] = U[r]
        aw[j, A_D] = D
        aw[j, A_UU] = u
        if j == 0:
            break
        # Ia = IA - U U^T / D and pa = pA + Ia c + U u / D, in place
        for r in range(6):
            Ur = U[r] / D
            for s in range(6):
                aw[j, A_IA + 6 * r + s] -= Ur * U[s]
        c = _vec6(aw, j, A_C)
        _mat6_vec(aw, j, A_IA, c, aw, n, 0)
        uD = u / D
        for r in range(6):
            aw[j, A_PA + r] += aw[n, r] + U[r] * uD
        # carry both into frame j-1 about O_{j-1}: X_F = [[R, [p] R], [0, R]]
        R, p = _stored_placement(ws, j)
        Rt = _transpose(R)
        P = _skew(p)
        A = _matmul(_matmul(R, _block(aw, j, A_IA, 0, 0)), Rt)
        B = _matmul(_matmul(R, _block(aw, j, A_IA, 0, 3)), Rt)
        Mr = _matmul(_matmul(R, _block(aw, j, A_IA, 3, 3)), Rt)
        PB = _matmul(P, _transpose(B))           # P B^T
        PM = _matmul(P, Mr)                      # P M
        PMP = _matmul(PM, _transpose(P))         # P M P^T
        TL = (A[0] + PB[0] + PB[0] + PMP[0], A[1] + PB[1] + PB[3] + PMP[1],
              A[2] + PB[2] + PB[6] + PMP[2], A[3] + PB[3] + PB[1] + PMP[3],
              A[4] + PB[4] + PB[4] + PMP[4], A[5] + PB[5] + PB[7] + PMP[5],
              A[6] + PB[6] + PB[2] + PMP[6], A[7] + PB[7] + PB[5] + PMP[7],
              A[8] + PB[8] + PB[8] + PMP[8])
        TR = (B[0] + PM[0], B[1] + PM[1], B[2] + PM[2],
              B[3] + PM[3], B[4] + PM[4], B[5] + PM[5],
              B[6] + PM[6], B[7] + PM[7], B[8] + PM[8])
        _add_block(aw, j - 1, A_IA, 0, 0, TL)
        _add_block(aw, j - 1, A_IA, 0, 3, TR)
        _add_block(aw, j - 1, A_IA, 3, 0, _transpose(TR))
        _add_block(aw, j - 1, A_IA, 3, 3, Mr)
        f = _rot(R, aw[j, A_PA + 3], aw[j, A_PA + 4], aw[j, A_PA + 5])
        m = _rot(R, aw[j, A_PA], aw[j, A_PA + 1], aw[j, A_PA + 2])
        t = _cross(p[0], p[1], p[2], f[0], f[1], f[2])
        aw[j - 1, A_PA] += m[0] + t[0]
        aw[j - 1, A_PA + 1] += m[1] + t[1]
        aw[j - 1, A_PA + 2] += m[2] + t[2]
        aw[j - 1, A_PA + 3] += f[0]
        aw[j - 1, A_PA + 4] += f[1]
        aw[j - 1, A_PA + 5] += f[2]
    return -1


@njit(cache=True, inline='always')
def _aba_forward_accelerations(links, frames, gravity_on, ws, aw, qdd):
    """ABA pass 3, base to tip: a_j = X a_{j-1} + c_j + S qdd_j."""
    n = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    if gravity_on:      # gravity as an upward acceleration of the base
        a = (zero, zero, zero, -frames[F_GRAV, 0], -frames[F_GRAV, 1],
             -frames[F_GRAV, 2])
    else:
        a = (zero, zero, zero, zero, zero, zero)
    for j in range(n):
        R, p = _stored_placement(ws, j)
        a = _motion_to_child(R, p, a)
        a = (a[0] + aw[j, A_C], a[1] + aw[j, A_C + 1], a[2] + aw[j, A_C + 2],
             a[3] + aw[j, A_C + 3], a[4] + aw[j, A_C + 4],
             a[5] + aw[j, A_C + 5])
        Ua = (aw[j, A_U] * a[0] + aw[j, A_U + 1] * a[1]
              + aw[j, A_U + 2] * a[2] + aw[j, A_U + 3] * a[3]
              + aw[j, A_U + 4] * a[4] + aw[j, A_U + 5] * a[5])
        x = (aw[j, A_UU] - Ua) / aw[j, A_D]
        qdd[j] = x
        if _revolute(links, frames, j):
            a = (a[0], a[1], a[2] + x, a[3], a[4], a[5])
        else:
            a = (a[0], a[1], a[2], a[3], a[4], a[5] + x)


@njit(cache=True, inline='always')
def articulated_body(links, frames, q, qd, tau, wrench, gravity_on,
                     velocity_on, wrench_mode, ws, aw, qdd):
    """
    Forward dynamics by the articulated-body algorithm: O(n).

    Solves D(q) qdd = tau - C(q, qd) qd - g(q) - J^T F_e without forming D
    (Featherstone's three passes: velocities base to tip, articulated
    inertias tip to base, accelerations base to tip).  Every spatial
    quantity of link j is in kernel frame j about O_j, where the joint's
    motion subspace S_j is a unit vector (z angular, or z linear).
    ``aw`` is an (n + 1, A_WIDTH) workspace.

    Returns -1; or the index of the first joint (from the tip) with no
    inertia to move (D singular there); or OVERFLOW when finite inputs
    overflow in qdd.
    """
    joint_trig(links, frames, q, ws)
    _aba_forward_velocities(links, frames, qd, wrench, velocity_on,
                            wrench_mode, ws, aw)
    bad = _aba_backward_inertias(links, frames, tau, ws, aw)
    if bad >= 0:
        return bad
    _aba_forward_accelerations(links, frames, gravity_on, ws, aw, qdd)
    if first_nonfinite(qdd) >= 0:
        return OVERFLOW
    return -1


@njit(cache=True, inline='always')
def _coriolis_forward(links, frames, qd, ws, cw):
    """
    Coriolis pass 1, base to tip, everything in frame 0 about its origin.

    Stores each kernel frame's pose, each joint's motion subspace S_j
    ([z; o x z] revolute, [0; z] prismatic), each link's velocity
    V_j = V_{j-1} + S_j qd_j and Sdot_j = V_j x S_j.
    """
    n = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    one = frames[F_CONST, C_ONE]
    Rw = (one, zero, zero, zero, one, zero, zero, zero, one)
    ow = (zero, zero, zero)
    V = (zero, zero, zero, zero, zero, zero)
    for j in range(n):
        R, p = _link_geometry(links, frames, j, ws)
        t = _rot(Rw, p[0], p[1], p[2])
        ow = (ow[0] + t[0], ow[1] + t[1], ow[2] + t[2])
        Rw = _matmul(Rw, R)
        z = (Rw[2], Rw[5], Rw[8])
        if _revolute(links, frames, j):
            v = _cross(ow[0], ow[1], ow[2], z[0], z[1], z[2])
            S = (z[0], z[1], z[2], v[0], v[1], v[2])
        else:
            S = (zero, zero, zero, z[0], z[1], z[2])
        s = qd[j]
        V = (V[0] + S[0] * s, V[1] + S[1] * s, V[2] + S[2] * s,
             V[3] + S[3] * s, V[4] + S[4] * s, V[5] + S[5] * s)
        # motion cross product V x S = [w x s_w; w x s_v + v x s_w]
        a = _cross(V[0], V[1], V[2], S[0], S[1], S[2])
        b = _cross(V[0], V[1], V[2], S[3], S[4], S[5])
        c = _cross(V[3], V[4], V[5], S[0], S[1], S[2])
        Sd = (a[0], a[1], a[2], b[0] + c[0], b[1] + c[1], b[2] + c[2])
        for k in range(6):
            cw[j, CW_S + k] = S[k]
            cw[j, CW_SD + k] = Sd[k]
            cw[j, CW_V + k] = V[k]
        for k in range(9):
            cw[j, CW_RW + k] = Rw[k]
        for k in range(3):
            cw[j, CW_OW + k] = ow[k]


@njit(cache=True, inline='always')
def _coriolis_backward(links, frames, cw):
    """
    Coriolis pass 2, tip to base: composite inertia and Coriolis matrices.

    With I_k the spatial inertia of link k and
    B_k = (Y + Y^T + [I_k V_k]^) / 2, Y = (V_k x*) I_k, where
    [h]^ x = x x* h (Echeandia and Wensing's body Coriolis matrix in a
    fixed frame), the composites IC_j = sum_{k >= j} I_k and
    BC_j = sum_{k >= j} B_k give each joint's three vectors
    F1 = IC S, F2 = BC^T S and G = IC Sdot + BC S.
    """
    n = links.shape[0]
    half = frames[F_CONST, C_HALF]
    zero = frames[F_CONST, C_ZERO]
    IC = 0          # scratch row n: IC, BC, I_j V_j
    BC = 36
    H = 72
    for k in range(72):
        cw[n, k] = zero
    for j in range(n - 1, -1, -1):
        Rw = (cw[j, CW_RW], cw[j, CW_RW + 1], cw[j, CW_RW + 2],
              cw[j, CW_RW + 3], cw[j, CW_RW + 4], cw[j, CW_RW + 5],
              cw[j, CW_RW + 6], cw[j, CW_RW + 7], cw[j, CW_RW + 8])
        ow = (cw[j, CW_OW], cw[j, CW_OW + 1], cw[j, CW_OW + 2])
        _body_inertia(links, j, Rw, ow, cw, j, CW_I)
        V = _vec6(cw, j, CW_V)
        _mat6_vec(cw, j, CW_I, V, cw, n, H)
        h = _vec6(cw, n, H)
        # Y = (V x*) I, with V x* = [[w x, v x], [0, w x]], column by
        # column: Y e = V x* (I e).  B = (Y + Y^T + H) / 2 with
        # H = [h]^ = [[-[h_n], -[h_f]], [-[h_f], 0]].
        Hn = _skew((h[0], h[1], h[2]))
        Hf = _skew((h[3], h[4], h[5]))
        for col in range(6):
            b = CW_I + col
            m0 = cw[j, b]
            m1 = cw[j, b + 6]
            m2 = cw[j, b + 12]
            f0 = cw[j, b + 18]
            f1 = cw[j, b + 24]
            f2 = cw[j, b + 30]
            t1 = _cross(V[0], V[1], V[2], m0, m1, m2)
            t2 = _cross(V[3], V[4], V[5], f0, f1, f2)
            t3 = _cross(V[0], V[1], V[2], f0, f1, f2)
            y = (t1[0] + t2[0], t1[1] + t2[1], t1[2] + t2[2],
                 t3[0], t3[1], t3[2])
            for r in range(6):
                # Y[r, col] goes to B[r, col] and, as Y^T, to B[col, r]
                cw[n, BC + 6 * r + col] += half * y[r]
                cw[n, BC + 6 * col + r] += half * y[r]
        for r in range(3):
            for s in range(3):
                cw[n, BC + 6 * r + s] -= half * Hn[3 * r + s]
                cw[n, BC + 6 * r + s + 3] -= half * Hf[3 * r + s]
                cw[n, BC + 6 * (r + 3) + s] -= half * Hf[3 * r + s]
        for k in range(36):
            cw[n, IC + k] += cw[j, CW_I + k]
        S = _vec6(cw, j, CW_S)
        Sd = _vec6(cw, j, CW_SD)
        for r in range(6):
            f1 = zero
            f2 = zero
            g = zero
            for s in range(6):
                ic = cw[n, IC + 6 * r + s]
                f1 += ic * S[s]
                f2 += cw[n, BC + 6 * s + r] * S[s]
                g += ic * Sd[s] + cw[n, BC + 6 * r + s] * S[s]
            cw[j, CW_F1 + r] = f1
            cw[j, CW_F2 + r] = f2
            cw[j, CW_G + r] = g


@njit(cache=True, inline='always')
def coriolis_matrix_composite(links, frames, q, qd, ws, cw, C):
    """
    Christoffel C(q, qd) in O(n^2) from composite bodies.

    With body Jacobians in a fixed frame, C = sum_k J_k^T (I_k Jdot_k +
    B_k J_k) (see ``_coriolis_backward``).  Column b of J_k is S_b for the
    joints b up to k, so only the links beyond max(a, b) contribute to
    C[a, b]:

    - b <= a: C[a, b] = S_a^T (IC_a Sdot_b + BC_a S_b) = F1_a . Sdot_b
      + F2_a . S_b
    - b > a:  C[a, b] = S_a^T (IC_b Sdot_b + BC_b S_b) = S_a . G_b

    Two O(n) passes and 18 multiply-adds per entry, against the n
    recursions of ``coriolis_matrix``; the same C up to round-off.
    ``cw`` is an (n + 1, CW_WIDTH) workspace.  Returns -1 or OVERFLOW.
    """
    n = links.shape[0]
    joint_trig(links, frames, q, ws)
    _coriolis_forward(links, frames, qd, ws, cw)
    _coriolis_backward(links, frames, cw)
    for a in range(n):
        f10 = cw[a, CW_F1]
        f11 = cw[a, CW_F1 + 1]
        f12 = cw[a, CW_F1 + 2]
        f13 = cw[a, CW_F1 + 3]
        f14 = cw[a, CW_F1 + 4]
        f15 = cw[a, CW_F1 + 5]
        f20 = cw[a, CW_F2]
        f21 = cw[a, CW_F2 + 1]
        f22 = cw[a, CW_F2 + 2]
        f23 = cw[a, CW_F2 + 3]
        f24 = cw[a, CW_F2 + 4]
        f25 = cw[a, CW_F2 + 5]
        for b in range(a + 1):
            C[a, b] = ((f10 * cw[b, CW_SD] + f11 * cw[b, CW_SD + 1]
                        + f12 * cw[b, CW_SD + 2] + f13 * cw[b, CW_SD + 3]
                        + f14 * cw[b, CW_SD + 4] + f15 * cw[b, CW_SD + 5])
                       + (f20 * cw[b, CW_S] + f21 * cw[b, CW_S + 1]
                          + f22 * cw[b, CW_S + 2] + f23 * cw[b, CW_S + 3]
                          + f24 * cw[b, CW_S + 4] + f25 * cw[b, CW_S + 5]))
        s0 = cw[a, CW_S]
        s1 = cw[a, CW_S + 1]
        s2 = cw[a, CW_S + 2]
        s3 = cw[a, CW_S + 3]
        s4 = cw[a, CW_S + 4]
        s5 = cw[a, CW_S + 5]
        for b in range(a + 1, n):
            C[a, b] = (s0 * cw[b, CW_G] + s1 * cw[b, CW_G + 1]
                       + s2 * cw[b, CW_G + 2] + s3 * cw[b, CW_G + 3]
                       + s4 * cw[b, CW_G + 4] + s5 * cw[b, CW_G + 5])
    return _matrix_status(C)


# ---------------------------------------------------------------------------
# Entry points.  Python calls these, never the functions above: each takes
# the model packed into one array (``pack``), the switches as one integer
# (``flags``), checks every size against the model (numba does not check
# bounds) and every input for finiteness, and returns a status code.  Few
# arguments, because numba's dispatcher costs about 40 ns per argument.
#
# They are compiled without numba's reference-counting runtime (NRT,
# option ``_nrt``): they allocate nothing and keep no array past the call,
# so it has nothing to do, yet with it every call wraps each array argument
# in a freshly allocated MemInfo and counts references to the arguments and
# views at every early return, atomically (measured: about 0.25 us of a
# 0.6 us call to ``run_mass_matrix_crba`` or ``run_gravity_torques``).
# Without NRT an allocation in an entry point does not compile.
ENTRY = {'cache': True, '_nrt': False}

# Status codes (besides -1, success):
#   1000 * a + i   input a (0 q, 1 qd, 2 qdd or tau, 3 wrench) is not
#                  finite at index i
SIZE = 8000      # + a: input a has the wrong size (4: an output, 5: the
#                  workspace)
#   OVERFLOW       finite inputs overflowed in the result
SINGULAR = 10000  # + j: no inertia moves with joint j (D is singular)

# Bits of ``flags``.
GRAVITY = 1
VELOCITY = 2
WRENCH_SHIFT = 2     # the wrench mode, shifted


def pack(links, frames):
    """Stack the link rows and the fixed-frame rows into one array."""
    import numpy as np
    n = len(links)
    packed = np.zeros((n + F_ROWS, L_WIDTH), dtype=np.asarray(links).dtype
                      if n else np.float64)
    if n:
        packed[:n] = links
    packed[n:, :12] = frames
    return packed


def flags(gravity=True, velocity=True, wrench_mode=WRENCH_NONE):
    """Return the ``flags`` integer of the entry points."""
    return ((GRAVITY if gravity else 0) | (VELOCITY if velocity else 0)
            | (wrench_mode << WRENCH_SHIFT))


@njit(cache=True)
def _split(P):
    n = P.shape[0] - F_ROWS
    return P[:n], P[n:]


@njit(cache=True)
def _sizes(n, q, qd, qdd, wrench, ws, ws_width):
    """SIZE + a for the first argument of the wrong size, else -1."""
    if q.shape[0] != n:
        return SIZE
    if qd.shape[0] != n:
        return SIZE + 1
    if qdd.shape[0] != n:
        return SIZE + 2
    if wrench.shape[0] != 6:
        return SIZE + 3
    if ws.shape[0] < n or ws.shape[1] != ws_width:
        return SIZE + 5
    return -1


@njit(**ENTRY)
def run_inverse_dynamics(P, q, qd, qdd, wrench, flags, ws, tau):
    """tau(q, qd, qdd, F_e); ``flags`` selects gravity, velocity, wrench."""
    links, frames = _split(P)
    n = links.shape[0]
    bad = _sizes(n, q, qd, qdd, wrench, ws, W_WIDTH)
    if bad >= 0:
        return bad
    if tau.shape[0] != n:
        return SIZE + 4
    bad = check_finite(q, qd, qdd, wrench)
    if bad >= 0:
        return bad
    joint_trig(links, frames, q, ws)
    recursion(links, frames, qd, qd, qdd, wrench, (flags & GRAVITY) != 0,
              (flags & VELOCITY) != 0, flags >> WRENCH_SHIFT, ws, tau)
    if first_nonfinite(tau) >= 0:
        return OVERFLOW
    return -1


@njit(cache=True, inline='always')
def _split_checked(P, q, ws):
    """
    Return (links, frames, status) for an entry point taking q only.

    status is -1, or the code of q's size, the workspace's size or q's
    first non-finite entry.  (frames[0, :6] stands for a wrench: a
    6-vector, always finite.)
    """
    links, frames = _split(P)
    bad = _sizes(links.shape[0], q, q, q, frames[0, :6], ws, W_WIDTH)
    if bad < 0:
        bad = first_nonfinite(q)
    return links, frames, bad


@njit(cache=True, inline='always')
def _gravity(links, frames, q, ws, tau):
    """g(q) into tau: the recursion at rest with gravity only."""
    unused = frames[0, :6]      # velocities and wrench: not read here
    joint_trig(links, frames, q, ws)
    # tau, zeroed, serves as qdd: the forward pass reads it before the
    # backward pass writes the torques into it
    for j in range(tau.shape[0]):
        tau[j] = frames[F_CONST, C_ZERO]
    recursion(links, frames, unused, unused, tau, unused, True, False,
              WRENCH_NONE, ws, tau)


@njit(cache=True, inline='always')
def _first_bad_row(M, status):
    """Index of the first row of M with a non-finite entry (status set)."""
    for k in range(M.shape[0]):
        if first_nonfinite(M[k]) >= 0:
            status[0] = OVERFLOW
            return k
    return -1


@njit(**ENTRY)
def run_gravity_torques(P, q, ws, tau):
    """g(q): ``run_inverse_dynamics`` at rest with gravity, fewer arguments."""
    links, frames, bad = _split_checked(P, q, ws)
    if bad >= 0:
        return bad
    n = links.shape[0]
    if tau.shape[0] != n:
        return SIZE + 4
    _gravity(links, frames, q, ws, tau)
    if first_nonfinite(tau) >= 0:
        return OVERFLOW
    return -1


@njit(cache=True)
def _square(M, n):
    return M.shape[0] == n and M.shape[1] == n


@njit(**ENTRY)
def run_mass_matrix_crba(P, q, ws, D):
    """D(q) by CRBA: ``run_mass_matrix`` with fewer arguments."""
    links, frames, bad = _split_checked(P, q, ws)
    if bad >= 0:
        return bad
    n = links.shape[0]
    if not _square(D, n):
        return SIZE + 4
    return mass_matrix_crba(links, frames, q, ws, D)


@njit(**ENTRY)
def run_mass_matrix(P, q, crba, ws, scratch, D):
    """D(q) by CRBA (``crba``) or by n recursions."""
    links, frames, bad = _split_checked(P, q, ws)
    if bad >= 0:
        return bad
    n = links.shape[0]
    if not _square(D, n):
        return SIZE + 4
    if scratch.shape[0] != 3 or scratch.shape[1] < n:
        return SIZE + 5
    if crba:
        return mass_matrix_crba(links, frames, q, ws, D)
    return mass_matrix(links, frames, q, ws, scratch, D)


@njit(**ENTRY)
def run_coriolis_matrix(P, q, qd, composite, ws, cw, scratch, C):
    """C(q, qd) by composite bodies (``composite``) or n recursions."""
    links, frames = _split(P)
    n = links.shape[0]
    bad = _sizes(n, q, qd, q, frames[0, :6], ws, W_WIDTH)
    if bad >= 0:
        return bad
    if not _square(C, n):
        return SIZE + 4
    if (cw.shape[0] < n + 1 or cw.shape[1] != CW_WIDTH
            or scratch.shape[0] != 3 or scratch.shape[1] < n):
        return SIZE + 5
    bad = check_finite(q, qd, q, frames[0, :6])
    if bad >= 0:
        return bad
    if composite:
        return coriolis_matrix_composite(links, frames, q, qd, ws, cw, C)
    return coriolis_matrix(links, frames, q, qd, ws, scratch, C)


@njit(**ENTRY)
def run_forward_dynamics(P, q, qd, tau, wrench, flags, ws, aw, qdd):
    """Compute qdd by the articulated-body algorithm (``articulated_body``)."""
    links, frames = _split(P)
    n = links.shape[0]
    bad = _sizes(n, q, qd, tau, wrench, ws, W_WIDTH)
    if bad >= 0:
        return bad
    if qdd.shape[0] != n:
        return SIZE + 4
    if aw.shape[0] < n + 1 or aw.shape[1] != A_WIDTH:
        return SIZE + 5
    bad = check_finite(q, qd, tau, wrench)
    if bad >= 0:
        return bad
    bad = articulated_body(links, frames, q, qd, tau, wrench,
                           (flags & GRAVITY) != 0, (flags & VELOCITY) != 0,
                           flags >> WRENCH_SHIFT, ws, aw, qdd)
    if 0 <= bad < n:
        return SINGULAR + bad
    return bad


@njit(**ENTRY)
def run_jacobian(P, q, in_ee_axes, ws, Ts, J):
    """J(q), 6 x n (see ``jacobian``)."""
    links, frames, bad = _split_checked(P, q, ws)
    if bad >= 0:
        return bad
    n = links.shape[0]
    if J.shape[0] != 6 or J.shape[1] != n:
        return SIZE + 4
    if Ts.shape[0] != n + 2 or Ts.shape[1] != 12:
        return SIZE + 5
    jacobian(links, frames, q, in_ee_axes, ws, Ts, J)
    return _matrix_status(J)


@njit(**ENTRY)
def run_link_poses(P, q, ws, Ts):
    """Poses of frame 0, the link frames and the end effector (``Ts``)."""
    links, frames, bad = _split_checked(P, q, ws)
    if bad >= 0:
        return bad
    n = links.shape[0]
    if Ts.shape[0] != n + 2 or Ts.shape[1] != 12:
        return SIZE + 5
    forward_kinematics(links, frames, q, ws, Ts)
    return _matrix_status(Ts)


# Batches: one compiled loop over the rows of (m, n) arrays of states.  The
# caller checks shapes and finiteness (numpy, once per batch); each returns
# -1, or the first row that failed (its code in ``status[0]``).

@njit(**ENTRY)
def run_inverse_dynamics_batch(P, Q, QD, QDD, W, flags, ws, TAU, status):
    """Compute tau for each row (the inputs are finite: checked in numpy)."""
    links, frames = _split(P)
    gravity_on = (flags & GRAVITY) != 0
    velocity_on = (flags & VELOCITY) != 0
    mode = flags >> WRENCH_SHIFT
    for k in range(Q.shape[0]):
        joint_trig(links, frames, Q[k], ws)
        recursion(links, frames, QD[k], QD[k], QDD[k], W[k], gravity_on,
                  velocity_on, mode, ws, TAU[k])
    return _first_bad_row(TAU, status)


@njit(**ENTRY)
def run_gravity_torques_batch(P, Q, ws, G, status):
    """Compute g for each row (see ``run_gravity_torques``)."""
    links, frames = _split(P)
    for k in range(Q.shape[0]):
        _gravity(links, frames, Q[k], ws, G[k])
    return _first_bad_row(G, status)


@njit(**ENTRY)
def run_mass_matrix_batch(P, Q, ws, DD, status):
    """D for each row, by CRBA."""
    links, frames = _split(P)
    for k in range(Q.shape[0]):
        code = mass_matrix_crba(links, frames, Q[k], ws, DD[k])
        if code >= 0:
            status[0] = code
            return k
    return -1


@njit(**ENTRY)
def run_coriolis_matrix_batch(P, Q, QD, ws, cw, CC, status):
    """C for each row, by composite bodies (O(n^2) each)."""
    links, frames = _split(P)
    for k in range(Q.shape[0]):
        code = coriolis_matrix_composite(links, frames, Q[k], QD[k], ws, cw,
                                         CC[k])
        if code >= 0:
            status[0] = code
            return k
    return -1


@njit(**ENTRY)
def run_forward_dynamics_batch(P, Q, QD, TAU, W, flags, ws, aw, QDD,
                               status):
    """Compute qdd for each row by the articulated-body algorithm."""
    links, frames = _split(P)
    n = links.shape[0]
    for k in range(Q.shape[0]):
        code = articulated_body(links, frames, Q[k], QD[k], TAU[k], W[k],
                                (flags & GRAVITY) != 0,
                                (flags & VELOCITY) != 0,
                                flags >> WRENCH_SHIFT, ws, aw, QDD[k])
        if code >= 0:
            status[0] = SINGULAR + code if code < n else code
            return k
    return -1
