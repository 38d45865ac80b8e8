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
Forward dynamics by the articulated-body algorithm (ABA), O(n).

Featherstone's three passes: velocities base to tip
(:func:`aba_velocities`), articulated inertias tip to base
(:func:`aba_inertias`), accelerations base to tip
(:func:`aba_accelerations`).  Spatial vectors are [angular; linear]
(motion) or [moment; force] (force) at the origin of the frame whose axes
they are given in; 6x6 matrices are stored row-major in 36 consecutive
columns of an ``aw`` row.
"""
from ._jit import njit
from .kinematics import (axis_index, body_inertia, branch_point,
                         frame_rotation, has_mimic, joint_trig, parent,
                         placement, revolute, stored_placement, tool_body)
from .layout import (A_A, A_C, A_D, A_IA, A_PA, A_U, A_UU, A_V, C_ONE,
                     C_ZERO, F_CONST, F_GRAV, MIMIC, OVERFLOW, WRENCH_NONE)
from .newton_euler import link_wrench, tip_wrench
from .spatial import (add_block, block, cross, force_to_parent, mat6_vec,
                      matmul, motion_to_child, skew, transpose, vec6)
from .status import first_nonfinite


@njit(cache=True, inline='always')
def aba_velocities(links, frames, qd, wrench, fext, velocity_on,
                   wrench_mode, link_wrenches, ws, aw):
    """
    ABA pass 1, base to tip: poses, velocities, bias accelerations.

    Per body, :func:`aba_velocity_step` from its parent's velocity (a
    branch point's as stored in ``aw``; a root's is zero).
    """
    zero = frames[F_CONST, C_ZERO]
    z6 = (zero, zero, zero, zero, zero, zero)
    v = z6
    tool = tool_body(frames) if wrench_mode != WRENCH_NONE else -2
    for j in range(links.shape[0]):
        par = parent(links, j)
        if par != j - 1:        # a branch: start from the parent's
            v = z6 if par < 0 else vec6(aw, par, A_V)
        v = aba_velocity_step(links, frames, qd, wrench, fext, velocity_on,
                              wrench_mode, link_wrenches, ws, aw, j, tool, v)


@njit(cache=True, inline='always')
def aba_velocity_step(links, frames, qd, wrench, fext, velocity_on,
                      wrench_mode, link_wrenches, ws, aw, j, tool, v):
    """
    Take the parent's velocity v to body j; return body j's.

    Stores R, p (``ws``), v_j, c_j = v_j x S_j qd_j, the link's spatial
    inertia as the starting articulated inertia IA_j and its bias force
    pA_j = v_j x* (I_j v_j), plus the tip's wrench on the tool's body
    (``tool``) and the links' own wrenches (``fext``; None: none).
    """
    zero = frames[F_CONST, C_ZERO]
    one = frames[F_CONST, C_ONE]
    ident = (one, zero, zero, zero, one, zero, zero, zero, one)
    origin = (zero, zero, zero)
    R, p = placement(links, frames, j, ws)
    body_inertia(links, j, ident, origin, aw, j, A_IA)
    c = (zero, zero, zero, zero, zero, zero)
    if velocity_on:
        v = motion_to_child(R, p, v)
        s = qd[j]
        if revolute(links, frames, j):
            c = (v[1] * s, -v[0] * s, zero, v[4] * s, -v[3] * s, zero)
            v = (v[0], v[1], v[2] + s, v[3], v[4], v[5])
        else:
            c = (zero, zero, zero, v[1] * s, -v[0] * s, zero)
            v = (v[0], v[1], v[2], v[3], v[4], v[5] + s)
        # pA = v x* (I v): [w x h_n + v_o x h_f; w x h_f]
        mat6_vec(aw, j, A_IA, v, aw, j, A_PA)
        h = vec6(aw, j, A_PA)
        t1 = cross(v[0], v[1], v[2], h[0], h[1], h[2])
        t2 = cross(v[3], v[4], v[5], h[3], h[4], h[5])
        t3 = cross(v[0], v[1], v[2], h[3], h[4], h[5])
        pa = (t1[0] + t2[0], t1[1] + t2[1], t1[2] + t2[2],
              t3[0], t3[1], t3[2])
    else:
        pa = (zero, zero, zero, zero, zero, zero)
    if j == tool:
        e = tip_wrench(frames, wrench, wrench_mode,
                       frame_rotation(links, frames, ws, j))
        pa = (pa[0] + e[0], pa[1] + e[1], pa[2] + e[2],
              pa[3] + e[3], pa[4] + e[4], pa[5] + e[5])
    if fext is not None:        # (compiled away when None)
        if link_wrenches:
            fe, ne = link_wrench(links, fext, j)
            pa = (pa[0] + ne[0], pa[1] + ne[1], pa[2] + ne[2],
                  pa[3] + fe[0], pa[4] + fe[1], pa[5] + fe[2])
    for k in range(6):
        aw[j, A_V + k] = v[k]
        aw[j, A_C + k] = c[k]
        aw[j, A_PA + k] = pa[k]
    return v


@njit(cache=True, inline='always')
def aba_inertias(links, frames, tau, ws, aw):
    """
    ABA pass 2, tip to base: articulated inertias and bias forces.

    Per body, :func:`articulated_step` (joint j's U, d and u, and what
    body j hands on) then :func:`articulated_to_parent`.  Returns -1,
    or the index of the joint whose d = S^T IA S is not positive (no
    inertia moves with it: the mass matrix is singular).
    """
    n = links.shape[0]
    for j in range(n - 1, -1, -1):
        if not articulated_step(links, frames, tau, aw, j):
            return j
        if parent(links, j) >= 0:
            articulated_to_parent(links, ws, aw, j)
    return -1


@njit(cache=True, inline='always')
def articulated_step(links, frames, tau, aw, j):
    """
    Joint j's U = IA S, d = S^T U and u = tau - S^T pA into ``aw``.

    Then, for a body with a parent, the articulated inertia and bias
    force it hands on, in place: Ia = IA - U U^T / d and
    pa = pA + Ia c + U u / d.  Returns False (and stores nothing) when d
    is not positive.
    """
    n = links.shape[0]
    k = axis_index(links, frames, j)
    U = (aw[j, A_IA + k], aw[j, A_IA + 6 + k], aw[j, A_IA + 12 + k],
         aw[j, A_IA + 18 + k], aw[j, A_IA + 24 + k],
         aw[j, A_IA + 30 + k])
    d = U[k]
    if not d > 0:       # an int literal: exact in any dtype
        return False
    u = tau[j] - aw[j, A_PA + k]
    for r in range(6):
        aw[j, A_U + r] = U[r]
    aw[j, A_D] = d
    aw[j, A_UU] = u
    if parent(links, j) < 0:
        return True
    for r in range(6):
        Ur = U[r] / d
        for s in range(6):
            aw[j, A_IA + 6 * r + s] -= Ur * U[s]
    c = vec6(aw, j, A_C)
    mat6_vec(aw, j, A_IA, c, aw, n, 0)
    ud = u / d
    for r in range(6):
        aw[j, A_PA + r] += aw[n, r] + U[r] * ud
    return True


@njit(cache=True, inline='always')
def articulated_to_parent(links, ws, aw, j):
    """
    Add body j's Ia and pa, carried to its parent's frame, into the parent's.

    X_F = [[R, [p] R], [0, R]] about the parent's origin:
    X_F Ia X_F^T blockwise, and pa by the one force carry.
    """
    par = parent(links, j)
    R, p = stored_placement(ws, j)
    Rt = transpose(R)
    P = skew(p)
    A = matmul(matmul(R, block(aw, j, A_IA, 0, 0)), Rt)
    B = matmul(matmul(R, block(aw, j, A_IA, 0, 3)), Rt)
    Mr = matmul(matmul(R, block(aw, j, A_IA, 3, 3)), Rt)
    PB = matmul(P, transpose(B))           # P B^T
    PM = matmul(P, Mr)                      # P M
    PMP = matmul(PM, transpose(P))         # P M P^T
    TL = (A[0] + PB[0] + PB[0] + PMP[0], A[1] + PB[1] + PB[3] + PMP[1],
          A[2] + PB[2] + PB[6] + PMP[2], A[3] + PB[3] + PB[1] + PMP[3],
          A[4] + PB[4] + PB[4] + PMP[4], A[5] + PB[5] + PB[7] + PMP[5],
          A[6] + PB[6] + PB[2] + PMP[6], A[7] + PB[7] + PB[5] + PMP[7],
          A[8] + PB[8] + PB[8] + PMP[8])
    TR = (B[0] + PM[0], B[1] + PM[1], B[2] + PM[2],
          B[3] + PM[3], B[4] + PM[4], B[5] + PM[5],
          B[6] + PM[6], B[7] + PM[7], B[8] + PM[8])
    add_block(aw, par, A_IA, 0, 0, TL)
    add_block(aw, par, A_IA, 0, 3, TR)
    add_block(aw, par, A_IA, 3, 0, transpose(TR))
    add_block(aw, par, A_IA, 3, 3, Mr)
    f, m = force_to_parent(
        R, p, (aw[j, A_PA + 3], aw[j, A_PA + 4], aw[j, A_PA + 5]),
        (aw[j, A_PA], aw[j, A_PA + 1], aw[j, A_PA + 2]))
    for k in range(3):
        aw[par, A_PA + k] += m[k]
        aw[par, A_PA + 3 + k] += f[k]


@njit(cache=True, inline='always')
def aba_accelerations(links, frames, gravity_on, ws, aw, qdd):
    """
    ABA pass 3, base to tip: a_j = X a_lambda(j) + c_j + S qdd_j.

    Per body, :func:`acceleration_step` from its parent's acceleration
    (a branch point's as stored; a root's is the base's, -g).
    """
    zero = frames[F_CONST, C_ZERO]
    if gravity_on:      # gravity as an upward acceleration of the base
        a0 = (zero, zero, zero, -frames[F_GRAV, 0], -frames[F_GRAV, 1],
              -frames[F_GRAV, 2])
    else:
        a0 = (zero, zero, zero, zero, zero, zero)
    a = a0
    for j in range(links.shape[0]):
        par = parent(links, j)
        if par != j - 1:        # a branch: start from the parent's
            a = a0 if par < 0 else vec6(aw, par, A_A)
        a = acceleration_step(links, frames, ws, aw, qdd, j, a)


@njit(cache=True, inline='always')
def acceleration_step(links, frames, ws, aw, qdd, j, a):
    """Joint j's qdd_j = (u - U^T a') / d from the parent's a; body j's a."""
    R, p = stored_placement(ws, j)
    a = motion_to_child(R, p, a)
    a = (a[0] + aw[j, A_C], a[1] + aw[j, A_C + 1], a[2] + aw[j, A_C + 2],
         a[3] + aw[j, A_C + 3], a[4] + aw[j, A_C + 4],
         a[5] + aw[j, A_C + 5])
    Ua = (aw[j, A_U] * a[0] + aw[j, A_U + 1] * a[1]
          + aw[j, A_U + 2] * a[2] + aw[j, A_U + 3] * a[3]
          + aw[j, A_U + 4] * a[4] + aw[j, A_U + 5] * a[5])
    x = (aw[j, A_UU] - Ua) / aw[j, A_D]
    qdd[j] = x
    if revolute(links, frames, j):
        a = (a[0], a[1], a[2] + x, a[3], a[4], a[5])
    else:
        a = (a[0], a[1], a[2], a[3], a[4], a[5] + x)
    if branch_point(links, frames, j):
        for k in range(6):
            aw[j, A_A + k] = a[k]
    return a


@njit(cache=True, inline='always')
def articulated_body(links, frames, q, qd, tau, wrench, fext, gravity_on,
                     velocity_on, wrench_mode, link_wrenches, ws, aw, qdd):
    """
    Forward dynamics by the articulated-body algorithm: O(n).

    Solves D(q) qdd = tau - C(q, qd) qd - g(q) - J^T F_e without forming D
    (Featherstone's three passes: velocities base to tip, articulated
    inertias tip to base, accelerations base to tip).  Every spatial
    quantity of link j is in kernel frame j about O_j, where the joint's
    motion subspace S_j is a unit vector (z angular, or z linear).
    ``aw`` is an (n + 1, A_WIDTH) workspace.  On a tree each body starts
    from its parent's velocity and acceleration and hands its articulated
    inertia and bias force to its parent (Featherstone's parent array).

    Returns -1; or the index of the first joint (from the tip) with no
    inertia to move (D singular there); or OVERFLOW when finite inputs
    overflow in qdd; or MIMIC for a model with mimic joints, which this
    algorithm does not take (Pinocchio's ``aba`` refuses them too): the
    caller solves with D instead.
    """
    if has_mimic(links, frames):
        return MIMIC
    joint_trig(links, frames, q, ws)
    aba_velocities(links, frames, qd, wrench, fext, velocity_on, wrench_mode,
                   link_wrenches, ws, aw)
    bad = aba_inertias(links, frames, tau, ws, aw)
    if bad >= 0:
        return bad
    aba_accelerations(links, frames, gravity_on, ws, aw, qdd)
    if first_nonfinite(qdd) >= 0:
        return OVERFLOW
    return -1
