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
Analytical derivatives of the joint torques and of the accelerations.

``rnea_derivatives`` gives dtau/dq and dtau/dqd of
tau = RNEA(q, qd, qdd) (+ the wrenches the links exert), in O(n^2) on
a chain and on a tree; ``aba_derivatives`` gives dqdd/dq, dqdd/dqd and
dqdd/dtau = D^-1 from them at qdd = FD(q, qd, tau).  Spatial algebra in
frame 0 about its origin, as ``coriolis.py``: a motion [angular; linear],
a force [moment; force].  ``docs/derivatives.md`` derives the steps.

In frame 0 every quantity of link k moves with the joints on its path:
the axis S_k of a joint below joint j turns with it, dS_k/dq_j =
S_j x S_k, and so do the link's inertia and the wrenches fixed to it.
Writing V, A for the links' velocities and accelerations (A with
gravity as the base's), c_j = S_j x A_lambda(j) + Sdot_j x V_lambda(j),
IC, BC the composite inertia and Coriolis matrices and F_j the wrench
joint j carries (``coriolis.wrench_step``), the derivatives of
tau_i = S_i . F_i are, for i and j on one path:

- j ancestor of i, or i itself:
  dtau_i/dq_j = -F1_i . c_j + 2 F2_i . Sdot_j + U_i . w_j
- i a strict ancestor of j:  dtau_i/dq_j = S_i . Y_j

(F1 = IC S, F2 = BC^T S; w_j the angular part of S_j; Y, U from
``coriolis.wrench_step``), and zero otherwise.  The velocity derivative
is twice the Christoffel Coriolis matrix, dtau/dqd = 2 C (the velocity
products are Gamma_ijk qd_j qd_k, symmetric in j, k), read off the same
composites as ``coriolis_matrix_composite`` does.  A mimic joint adds
its entries to its lead's, times the multipliers (G^T X G).
"""
import math

from ._jit import njit
from .cholesky import (cholesky_factor, cholesky_inverse,
                       cholesky_solve_factored)
from .coriolis import coriolis_backward, coriolis_forward
from .crba import mass_matrix_crba
from .kinematics import (branch_point, branched, has_mimic, joint_rate, joint_trig,
                         parent, put_pair, tool_body)
from .layout import (C_ONE, C_ZERO, CW_F1, CW_F2, CW_G, CW_OW, CW_RW, CW_S,
                     CW_SD, CW_V, DW_A, DW_ACC, DW_C, DW_E, DW_U, DW_W,
                     DW_Y, F_BASE, F_CONST, F_GRAV, F_TOOL, OVERFLOW, SINGULAR,
                     WRENCH_EE, WRENCH_NONE)
from .newton_euler import link_wrench, recursion, tip_wrench
from .spatial import cross, frame_rot, load3, load9, rot, rot_t, vec6
from .status import block_status, matrix_status


@njit(cache=True, inline='always')
def motion_cross(a, b):
    """Return a x b of two motion vectors [w; v] (6-tuples)."""
    w = cross(a[0], a[1], a[2], b[0], b[1], b[2])
    u = cross(a[0], a[1], a[2], b[3], b[4], b[5])
    t = cross(a[3], a[4], a[5], b[0], b[1], b[2])
    return (w[0], w[1], w[2], u[0] + t[0], u[1] + t[1], u[2] + t[2])


@njit(cache=True, inline='always')
def dot6(a, b):
    """Return a . b of two 6-tuples."""
    return ((a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
            + (a[3] * b[3] + a[4] * b[4] + a[5] * b[5]))


@njit(cache=True, inline='always')
def add_fixed_wrench(dw, j, R, o, e):
    """
    Add a wrench fixed to link j, [n; f] about O_j in its axes, to DW_E.

    ``R``, ``o``: kernel frame j in frame 0.  In frame 0 about its
    origin: f0 = R f, n0 = R n + o x f0.
    """
    f = rot(R, e[3], e[4], e[5])
    n = rot(R, e[0], e[1], e[2])
    t = cross(o[0], o[1], o[2], f[0], f[1], f[2])
    for k in range(3):
        dw[j, DW_E + k] += n[k] + t[k]
        dw[j, DW_E + 3 + k] += f[k]


@njit(cache=True, inline='always')
def add_direction_wrench(dw, j, n, f, p):
    """
    Add a wrench of fixed direction to link j: [n; f] (frame 0), at p.

    ``n`` is the moment about the point p (frame 0) where the wrench acts,
    a point of link j.  Into DW_E as [n + p x f; f] and into DW_W as
    (n + p x f, f, p f^T - (p . f) 1).
    """
    t = cross(p[0], p[1], p[2], f[0], f[1], f[2])
    pf = p[0] * f[0] + p[1] * f[1] + p[2] * f[2]
    for k in range(3):
        dw[j, DW_E + k] += n[k] + t[k]
        dw[j, DW_E + 3 + k] += f[k]
        dw[j, DW_W + k] += n[k] + t[k]
        dw[j, DW_W + 3 + k] += f[k]
        for s in range(3):
            dw[j, DW_W + 6 + 3 * k + s] += p[k] * f[s]
        dw[j, DW_W + 6 + 4 * k] -= pf


@njit(cache=True, inline='always')
def derivative_forward(links, frames, qd, qdd, wrench, fext, wext, gravity_on,
                       wrench_mode, link_wrenches, cw, dw):
    """
    Run derivative pass 1 (after ``coriolis_forward``), base to tip.

    Each link's acceleration A_j = A_lambda(j) + S_j qdd_j + Sdot_j qd_j
    (frame 0; the base's is -g with gravity), c_j, and the wrenches it
    exerts on its environment: the end effector's (``wrench``: fixed to
    the tool in its axes, ``WRENCH_EE``; of fixed direction in base axes
    at the tool's origin, ``WRENCH_BASE``), and with ``link_wrenches``
    the rows ``fext`` (fixed to the link, its axes about its origin, as
    the recursion takes them) and ``wext`` (fixed direction: each row
    the 15 numbers ``add_direction_wrench`` adds, summed over the link's
    wrenches; see ``core.frames.derivative_wrench_rows``).  ``fext`` and
    ``wext`` are both arrays or both None (no wrenches at links).
    """
    nb = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    mimic = has_mimic(links, frames)
    tool = tool_body(frames) if wrench_mode != WRENCH_NONE else -2
    z6 = (zero, zero, zero, zero, zero, zero)
    if gravity_on:
        a0 = (zero, zero, zero, -frames[F_GRAV, 0], -frames[F_GRAV, 1],
              -frames[F_GRAV, 2])
    else:
        a0 = z6
    for j in range(nb):
        par = parent(links, j)
        if par < 0:
            Ap = a0
            Vp = z6
        else:
            Ap = vec6(dw, par, DW_A)
            Vp = vec6(cw, par, CW_V)
        S = vec6(cw, j, CW_S)
        Sd = vec6(cw, j, CW_SD)
        s = joint_rate(links, qd, j, mimic)
        sdd = joint_rate(links, qdd, j, mimic)
        c1 = motion_cross(S, Ap)
        c2 = motion_cross(Sd, Vp)
        for k in range(6):
            dw[j, DW_A + k] = Ap[k] + S[k] * sdd + Sd[k] * s
            dw[j, DW_C + k] = c1[k] + c2[k]
            dw[j, DW_E + k] = zero
        for k in range(15):
            dw[j, DW_W + k] = zero
        if branch_point(links, frames, j):
            for k in range(21):
                dw[j, DW_ACC + k] = zero
        Rw = load9(cw, j, CW_RW)
        ow = load3(cw, j, CW_OW)
        if j == tool:
            if wrench_mode == WRENCH_EE:
                add_fixed_wrench(dw, j, Rw, ow,
                                 tip_wrench(frames, wrench, WRENCH_EE, Rw))
            else:
                RB = frame_rot(frames, F_BASE)
                f = rot_t(RB, wrench[0], wrench[1], wrench[2])
                n = rot_t(RB, wrench[3], wrench[4], wrench[5])
                t = rot(Rw, frames[F_TOOL, 9], frames[F_TOOL, 10],
                        frames[F_TOOL, 11])
                p = (ow[0] + t[0], ow[1] + t[1], ow[2] + t[2])
                add_direction_wrench(dw, j, n, f, p)
        if fext is not None:        # (compiled away when None)
            if link_wrenches:
                fe, ne = link_wrench(links, fext, j)
                add_fixed_wrench(dw, j, Rw, ow,
                                 (ne[0], ne[1], ne[2], fe[0], fe[1], fe[2]))
                for k in range(6):
                    dw[j, DW_E + k] += wext[j, k]
                for k in range(15):
                    dw[j, DW_W + k] += wext[j, k]


@njit(cache=True, inline='always')
def composite_pass(links, frames, q, qd, qdd, wrench, fext, wext, gravity_on,
                   wrench_mode, link_wrenches, ws, cw, dw):
    """Run the three passes both derivative kernels start with."""
    joint_trig(links, frames, q, ws)
    coriolis_forward(links, frames, qd, ws, cw)
    derivative_forward(links, frames, qd, qdd, wrench, fext, wext,
                       gravity_on, wrench_mode, link_wrenches, cw, dw)
    coriolis_backward(links, frames, cw, dw, True)


@njit(cache=True)
def rnea_derivatives(links, frames, q, qd, qdd, wrench, fext, wext,
                     gravity_on, wrench_mode, link_wrenches, damping, ws, cw,
                     dw, DQ, DV):
    """
    dtau/dq into DQ and dtau/dqd into DV (n x n), analytically.

    ``damping`` (n) is added to DV's diagonal: the drives' d tau/d qd
    (viscous friction and the slope of the smooth Coulomb term).  Cost:
    three O(nb) passes and about 60 multiply-adds per pair of joints on
    one path.  Returns -1 or OVERFLOW.  Not inlined: both entry points
    and both batch loops call the one compilation (numba compiles an
    inlined kernel again into each caller, minutes for this one).
    """
    nb = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    mimic = has_mimic(links, frames)
    composite_pass(links, frames, q, qd, qdd, wrench, fext, wext,
                   gravity_on, wrench_mode, link_wrenches, ws, cw, dw)
    n = DQ.shape[0]
    for i in range(n):
        for k in range(n):
            DQ[i, k] = zero
            DV[i, k] = zero
    check = zero
    for a in range(nb):
        F1 = vec6(cw, a, CW_F1)
        F2 = load3(cw, a, CW_F2)       # its linear part is zero
        G = vec6(cw, a, CW_G)
        Y = vec6(dw, a, DW_Y)
        U = load3(dw, a, DW_U)
        b = a
        while b >= 0:      # b = a, then a's ancestors
            Sb = vec6(cw, b, CW_S)
            Sd = vec6(cw, b, CW_SD)
            f = F2[0] * Sd[0] + F2[1] * Sd[1] + F2[2] * Sd[2]
            x = (f + f - dot6(F1, vec6(dw, b, DW_C))
                 + (U[0] * Sb[0] + U[1] * Sb[1] + U[2] * Sb[2]))
            y = dot6(F1, Sd) + (F2[0] * Sb[0] + F2[1] * Sb[1]
                                + F2[2] * Sb[2])
            put_pair(links, DQ, a, b, x, mimic)
            put_pair(links, DV, a, b, y + y, mimic)
            check = check + zero * (x + y)
            if b != a:
                x = dot6(Sb, Y)
                y = dot6(Sb, G)
                put_pair(links, DQ, b, a, x, mimic)
                put_pair(links, DV, b, a, y + y, mimic)
                check = check + zero * (x + y)
            b = parent(links, b)
    for i in range(n):
        DV[i, i] += damping[i]
    if mimic:
        return matrix_status(DQ) if matrix_status(DV) < 0 else OVERFLOW
    return -1 if check == zero else OVERFLOW


@njit(cache=True, inline='always')
def depth_first(links):
    """
    Tell whether the bodies are numbered depth first (each subtree a run).

    Each body's parent then lies on the path of the body numbered just
    before it.  ``load_urdf`` numbers so; a model in another order
    takes the general loops.  With it (and no mimic joints) D^-1 is
    block diagonal, one block a root's run (Centauro's legs and torso
    share no inertia), and the inverse dynamics' derivatives are zero
    off each joint's path.
    """
    for i in range(1, links.shape[0]):
        par = parent(links, i)
        if par >= 0:
            a = i - 1
            while a >= 0 and a != par:
                a = parent(links, a)
            if a != par:
                return False
    return True


@njit(cache=True, inline='always')
def run_end(links, lo, n, blocks):
    """
    Return the end of the run of coordinates that starts at root ``lo``.

    With ``blocks`` (``depth_first``) the next root's number, or n: where
    the columns of D^-1 from lo on stop being nonzero; otherwise n (one
    run, all coordinates).
    """
    if not blocks:
        return n
    hi = lo + 1
    while hi < n and parent(links, hi) >= 0:
        hi += 1
    return hi


@njit(cache=True, inline='always')
def ltl_factor(links, H):
    """
    Factor H = L^T L in place, L lower triangular with the tree's sparsity.

    Featherstone's LTL factorisation (no mimic joints: coordinates are
    bodies): from the tip, row k of L has entries only at k's ancestors,
    so nothing fills in and it costs the sum over joints of their depth
    squared, against n^3 / 6 for a dense Cholesky.  Only the entries of
    H at (k, ancestor of k) and the diagonal are read and overwritten.
    Returns -1, or the first (from the tip) pivot that is not positive.
    """
    n = H.shape[0]
    for k in range(n - 1, -1, -1):
        if not H[k, k] > 0:     # an int literal: exact in any dtype
            return k
        d = math.sqrt(H[k, k])
        H[k, k] = d
        i = parent(links, k)
        while i >= 0:
            H[k, i] = H[k, i] / d
            i = parent(links, i)
        i = parent(links, k)
        while i >= 0:
            j = i
            while j >= 0:
                H[i, j] -= H[k, i] * H[k, j]
                j = parent(links, j)
            i = parent(links, i)
    return -1


@njit(cache=True, inline='always')
def ltl_solve(links, L, x):
    """Solve L^T L x = b in place (x holds b), L from ``ltl_factor``."""
    for k in range(L.shape[0] - 1, -1, -1):      # L^T y = b, from the tip
        y = x[k] / L[k, k]
        x[k] = y
        i = parent(links, k)
        while i >= 0:
            x[i] -= L[k, i] * y
            i = parent(links, i)
    ltl_forward(links, L, x, 0, L.shape[0])


@njit(cache=True, inline='always')
def ltl_forward(links, L, x, lo, hi):
    """
    Solve L x = y in place (x holds y), from the base.

    Only rows lo..hi-1: those of one root's run (``run_end``) when y is
    zero outside it, all of them (0, n) otherwise.
    """
    for k in range(lo, hi):
        acc = x[k]
        i = parent(links, k)
        while i >= 0:
            acc -= L[k, i] * x[i]
            i = parent(links, i)
        x[k] = acc / L[k, k]


@njit(cache=True, inline='always')
def ltl_inverse_column(links, frames, L, k, x, lo, hi):
    """
    Column k of (L^T L)^-1 into x, L from ``ltl_factor``.

    L^T y = e_k touches only k and its ancestors (walked up from k), then
    L x = y from the base, on rows lo..hi-1 only (k's run: ``run_end``;
    the column is zero elsewhere): O(depth^2 + m depth) for a run of m
    coordinates, rather than a full solve.
    """
    zero = frames[F_CONST, C_ZERO]
    one = frames[F_CONST, C_ONE]
    for i in range(L.shape[0]):
        x[i] = zero
    x[k] = one
    m = k
    while m >= 0:
        y = x[m] / L[m, m]
        x[m] = y
        i = parent(links, m)
        while i >= 0:
            x[i] -= L[m, i] * y
            i = parent(links, i)
        m = parent(links, m)
    ltl_forward(links, L, x, lo, hi)


@njit(cache=True, inline='always')
def subtract_row(Minv, m, x, col, lo, hi):
    """col[lo:hi] -= x Minv[m, lo:hi]."""
    for i in range(lo, hi):
        col[i] -= Minv[m, i] * x


@njit(cache=True, inline='always')
def times_minus_inverse(links, frames, Minv, X, col, blocks):
    """
    X <- -Minv X in place, column by column (Minv symmetric).

    With ``blocks`` (``depth_first``) column k of X is nonzero only on
    k's path, its ancestors and its subtree (a run from k), and the
    result only on the run of k's root, where Minv has its block: only
    those cost.  Otherwise only X's nonzero entries cost.
    """
    zero = frames[F_CONST, C_ZERO]
    n = X.shape[0]
    lo = 0
    while lo < n:
        hi = run_end(links, lo, n, blocks)
        for k in range(lo, hi):
            for i in range(lo, hi):
                col[i] = zero
            if blocks:
                m = parent(links, k)
                while m >= 0:
                    subtract_row(Minv, m, X[m, k], col, lo, hi)
                    m = parent(links, m)
                m = k
                while m < hi and (m == k or parent(links, m) >= k):
                    subtract_row(Minv, m, X[m, k], col, lo, hi)
                    m += 1
            else:
                for m in range(n):
                    x = X[m, k]
                    if x != zero:
                        subtract_row(Minv, m, x, col, lo, hi)
            for i in range(lo, hi):
                X[i, k] = col[i]
        lo = hi


@njit(cache=True, inline='always')
def minus_product(Minv, X, T):
    """
    X <- -Minv X through T (n x n scratch), dense.

    Each entry summed in a register, no test per entry (a chain's dtau/dx
    has few zeros): 0.3-0.4 us against 0.5 for ``times_minus_inverse`` at
    n = 7.
    """
    n = X.shape[0]
    for i in range(n):
        for k in range(n):
            acc = Minv[i, 0] * X[0, k]
            for m in range(1, n):
                acc += Minv[i, m] * X[m, k]
            T[i, k] = -acc
    for i in range(n):
        for k in range(n):
            X[i, k] = T[i, k]


@njit(cache=True)
def aba_derivatives(links, frames, q, qd, tau, wrench, fall, fext, wext,
                    gravity_on, wrench_mode, link_wrenches, armature, damping,
                    ws, cw, dw, chol, scratch, DQ, DV, DT):
    """
    dqdd/dq, dqdd/dqd into DQ, DV and dqdd/dtau = (D + I_a)^-1 into DT.

    D by the composite-rigid-body algorithm, ``armature`` I_a on its
    diagonal, and the bias torques by one recursion (``fall``: every
    wrench at links in link axes, as the recursion takes them) give
    qdd = (D + I_a)^-1 (tau - bias); then with tau(q, qd, qdd) the
    inverse dynamics at that qdd, dqdd/dx = -(D + I_a)^-1 dtau/dx for
    x = q, qd (``fext``, ``wext`` as ``rnea_derivatives`` takes them).
    D + I_a is factored once, and its inverse formed from the factor's
    (``cholesky_inverse``): by a dense Cholesky on a chain and with mimic
    joints (their coordinates couple branches), and on a tree numbered
    depth first (``depth_first``) block by block, one block a root's run
    of coordinates (D has no entries between them; a run's entries
    across its branches are zeros, which the dense factor fills in: on
    Centauro's 15-coordinate torso block that costs less than the sparse
    walks).  A tree numbered otherwise takes ``ltl_factor`` and its
    inverse by n sparse solves.  The inverse then multiplies the inverse
    dynamics' derivatives (``times_minus_inverse`` on a tree, which skips
    the zeros; ``minus_product`` dense), and only the blocks' entries are
    checked for overflow (the others are zero).
    ``tau`` must hold the drives' other torques already subtracted (the
    caller does).  Returns -1, SINGULAR + j (no positive pivot at
    coordinate j), or OVERFLOW.
    """
    n = DT.shape[0]
    zero = frames[F_CONST, C_ZERO]
    one = frames[F_CONST, C_ONE]
    mimic = has_mimic(links, frames)
    qdd = scratch[0]
    bias = scratch[1]
    col = scratch[2]
    for i in range(n):
        qdd[i] = zero
    joint_trig(links, frames, q, ws)
    recursion(links, frames, qd, qd, qdd, wrench, fall, gravity_on, True,
              wrench_mode, link_wrenches, ws, bias)
    code = mass_matrix_crba(links, frames, q, ws, chol)
    if code >= 0:
        return code
    for i in range(n):
        chol[i, i] += armature[i]
        qdd[i] = tau[i] - bias[i]
    dense = mimic or not branched(frames)
    blocks = not dense and depth_first(links)
    if dense or blocks:     # a dense Cholesky of each root's block
        lo = 0
        while lo < n:
            hi = n if dense else run_end(links, lo, n, True)
            bad = cholesky_factor(chol, chol, lo, hi)
            if bad >= 0:
                return SINGULAR + bad
            cholesky_solve_factored(chol, qdd, qdd, lo, hi)
            lo = hi
    else:
        bad = ltl_factor(links, chol)
        if bad >= 0:
            return SINGULAR + bad
        ltl_solve(links, chol, qdd)
    code = rnea_derivatives(links, frames, q, qd, qdd, wrench, fext, wext,
                            gravity_on, wrench_mode, link_wrenches, damping,
                            ws, cw, dw, DQ, DV)
    if code >= 0:
        return code
    if blocks:      # zero between the blocks
        for i in range(n):
            for k in range(n):
                DT[i, k] = zero
    lo = 0
    while lo < n:                       # (D + I_a)^-1, block by block
        hi = n if dense else run_end(links, lo, n, blocks)
        if dense or blocks:
            cholesky_inverse(chol, DT, bias, one, lo, hi)
        else:
            for k in range(lo, hi):     # column by column
                ltl_inverse_column(links, frames, chol, k, col, lo, hi)
                for i in range(n):
                    DT[i, k] = col[i]
        lo = hi
    if dense:                   # the factor's memory is free by now
        minus_product(DT, DQ, chol)
        minus_product(DT, DV, chol)
        return matrix_status(DQ) if matrix_status(DV) < 0 else OVERFLOW
    times_minus_inverse(links, frames, DT, DQ, col, blocks)
    times_minus_inverse(links, frames, DT, DV, col, blocks)
    if blocks:      # only the blocks' entries can be other than zero
        lo = 0
        while lo < n:
            hi = run_end(links, lo, n, True)
            if block_status(DQ, lo, hi) >= 0 or block_status(DV, lo, hi) >= 0:
                return OVERFLOW
            lo = hi
        return -1
    code = matrix_status(DQ)
    if code < 0:
        code = matrix_status(DV)
    return code
