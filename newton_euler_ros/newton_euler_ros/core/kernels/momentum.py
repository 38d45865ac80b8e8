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
The momentum observer's terms: D qd, C(q, qd)^T qd and g(q) at once.

:func:`momentum_terms` carries each link's velocity out from the base,
then the composite momentum and gravity wrench in from the tip, and
reads the three terms off each joint's axis (its docstring has the
algebra).
"""
from ._jit import njit
from .kinematics import (branch_point, has_mimic, joint_rate, joint_trig,
                         link_inertia, parent, placement, put, revolute,
                         stored_placement, zero_matrix)
from .layout import C_ZERO, CW_V, F_CONST, F_GRAV, L_COM, L_MASS, W_ACC, \
    W_F, W_X
from .spatial import cross, force_to_parent, load3, rot, rot_t
from .status import matrix_status


@njit(cache=True)
def momentum_terms(links, frames, q, qd, ws, cw, out):
    """
    Compute D(q) qd, C(q, qd)^T qd and g(q) in one O(n) recursion.

    What the momentum observer needs at each sample, into the rows 0, 1,
    2 of ``out`` (3, n), without forming D or C; on a tree the composites
    are summed at branch points as in ``recursion``.  With the body Jacobians
    J_k (column b the joint motion S_b for b <= k) and each link's spatial
    momentum h_k = I_k J_k qd:

    - p = D qd = sum_k J_k^T h_k, so p_j = S_j . H_j with H_j the
      momentum of the links j..n-1 (the composite body of joint j);
    - C^T qd = Ddot qd - C qd = sum_k Jdot_k^T h_k (differentiating p
      and taking away the Newton-Euler torques D qdd + C qd), so
      (C^T qd)_j = Sdot_j . H_j with Sdot_j = V_j x S_j;
    - g_j = S_j . G_j with G_j the wrench gravity takes off the same
      links (the recursion at rest with gravity: ``gravity``).

    Forward, base to tip: each link's angular velocity w and the
    velocity v of its origin O_j, in frame j axes (into
    ``cw[j, CW_V:CW_V + 6]``), and the base's upward acceleration -g in
    frame j (link j's force m (-g) into ``ws[j, W_F:]``, as ``gravity``
    has it).  Backward, tip to base, in frame j about O_j: the composite
    momentum (linear L, angular K: each link adds m v_c and
    I_c w + c x m v_c, v_c = v + w x c) and the composite gravity wrench
    are carried like the recursion's force (``force_to_parent``).  In
    frame j, S_j = [z; 0] (revolute, at O_j on the axis) or [0; z]
    (prismatic), so Sdot_j = [w x z; v x z] or [0; w x z]:

    - revolute: p_j = K_z, (C^T qd)_j = (w x z) . K + (v x z) . L;
    - prismatic: p_j = L_z, (C^T qd)_j = (w x z) . L.

    The same values as D qd, C^T qd and g from the matrices, up to
    round-off, at about a third of their cost.  Returns -1, or OVERFLOW
    when a result is not finite.

    The steps: :func:`momentum_forward_step` per body from the base
    (after :func:`momentum_forward_start`), then
    :func:`momentum_backward_step` per body from the tip (before
    :func:`momentum_carry`), the composites ``(L, K, f, nm)`` in
    registers along a chain.
    """
    nb = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    mimic = has_mimic(links, frames)
    joint_trig(links, frames, q, ws)
    z3 = (zero, zero, zero)
    a0 = (-frames[F_GRAV, 0], -frames[F_GRAV, 1], -frames[F_GRAV, 2])
    state = (z3, z3, a0)
    for j in range(nb):
        state = momentum_forward_start(links, ws, cw, j, state, a0, z3)
        state = momentum_forward_step(links, frames, qd, ws, cw, j, mimic,
                                      state)
    if mimic:
        zero_matrix(frames, out)
    sums = (z3, z3, z3, z3)
    for j in range(nb - 1, -1, -1):
        sums = momentum_backward_step(links, frames, ws, cw, j, mimic, sums,
                                      out)
        sums = momentum_carry(links, ws, j, sums, z3)
    return matrix_status(out)


@njit(cache=True, inline='always')
def momentum_forward_start(links, ws, cw, j, state, a0, z3):
    """
    Return body j's starting ``(w, v, a)``: its parent's (a branch: stored).

    A root starts at rest with the base's upward acceleration ``a0``.
    """
    par = parent(links, j)
    if par == j - 1:
        return state
    if par < 0:
        return (z3, z3, a0)
    return (load3(cw, par, CW_V), load3(cw, par, CW_V + 3),
            load3(ws, par, W_X))


@njit(cache=True, inline='always')
def momentum_forward_step(links, frames, qd, ws, cw, j, mimic, state):
    """
    Take ``(w, v, a)`` from body j's parent to body j; return body j's.

    w and v (the velocity of O_j) go into ``cw[j, CW_V:]``, gravity's
    force on link j, m a, into ``ws[j, W_F:]``; a branch point keeps a
    for its later children (``W_X``) and zeroes their sums (``W_ACC``).
    """
    w, v, a = state
    zero = frames[F_CONST, C_ZERO]
    R, p = placement(links, frames, j, ws)
    t = cross(w[0], w[1], w[2], p[0], p[1], p[2])
    v = rot_t(R, v[0] + t[0], v[1] + t[1], v[2] + t[2])
    w = rot_t(R, w[0], w[1], w[2])
    a = rot_t(R, a[0], a[1], a[2])
    s = joint_rate(links, qd, j, mimic)
    if revolute(links, frames, j):
        w = (w[0], w[1], w[2] + s)
    else:
        v = (v[0], v[1], v[2] + s)
    m = links[j, L_MASS]
    for k in range(3):
        cw[j, CW_V + k] = w[k]
        cw[j, CW_V + 3 + k] = v[k]
        ws[j, W_F + k] = m * a[k]
    if branch_point(links, frames, j):
        for k in range(3):
            ws[j, W_X + k] = a[k]
        for k in range(12):
            ws[j, W_ACC + k] = zero
    return (w, v, a)


@njit(cache=True, inline='always')
def momentum_backward_step(links, frames, ws, cw, j, mimic, sums, out):
    """
    Add link j to the composite sums; put joint j's three terms in ``out``.

    ``sums`` are the composite momentum (linear L, angular K about O_j)
    and gravity wrench (f, nm) of what body j carries, in frame j; a
    branch point adds what its later children left in ``W_ACC``.  Link j
    adds m v_c and I_c w + c x m v_c (v_c = v + w x c) and its weight.
    """
    L, K, f, nm = sums
    if branch_point(links, frames, j):
        L = (L[0] + ws[j, W_ACC], L[1] + ws[j, W_ACC + 1],
             L[2] + ws[j, W_ACC + 2])
        K = (K[0] + ws[j, W_ACC + 3], K[1] + ws[j, W_ACC + 4],
             K[2] + ws[j, W_ACC + 5])
        f = (f[0] + ws[j, W_ACC + 6], f[1] + ws[j, W_ACC + 7],
             f[2] + ws[j, W_ACC + 8])
        nm = (nm[0] + ws[j, W_ACC + 9], nm[1] + ws[j, W_ACC + 10],
              nm[2] + ws[j, W_ACC + 11])
    w = (cw[j, CW_V], cw[j, CW_V + 1], cw[j, CW_V + 2])
    v = (cw[j, CW_V + 3], cw[j, CW_V + 4], cw[j, CW_V + 5])
    m = links[j, L_MASS]
    c0 = links[j, L_COM]
    c1 = links[j, L_COM + 1]
    c2 = links[j, L_COM + 2]
    t = cross(w[0], w[1], w[2], c0, c1, c2)
    lc = (m * (v[0] + t[0]), m * (v[1] + t[1]), m * (v[2] + t[2]))
    Iw = rot(link_inertia(links, j), w[0], w[1], w[2])
    t = cross(c0, c1, c2, lc[0], lc[1], lc[2])
    L = (L[0] + lc[0], L[1] + lc[1], L[2] + lc[2])
    K = (K[0] + Iw[0] + t[0], K[1] + Iw[1] + t[1], K[2] + Iw[2] + t[2])
    F0 = ws[j, W_F]
    F1 = ws[j, W_F + 1]
    F2 = ws[j, W_F + 2]
    t = cross(c0, c1, c2, F0, F1, F2)
    f = (f[0] + F0, f[1] + F1, f[2] + F2)
    nm = (nm[0] + t[0], nm[1] + t[1], nm[2] + t[2])
    if revolute(links, frames, j):
        put(links, out[0], j, K[2], mimic)
        put(links, out[1], j, (w[1] * K[0] - w[0] * K[1])
            + (v[1] * L[0] - v[0] * L[1]), mimic)
        put(links, out[2], j, nm[2], mimic)
    else:
        put(links, out[0], j, L[2], mimic)
        put(links, out[1], j, w[1] * L[0] - w[0] * L[1], mimic)
        put(links, out[2], j, f[2], mimic)
    return (L, K, f, nm)


@njit(cache=True, inline='always')
def momentum_carry(links, ws, j, sums, z3):
    """
    Hand body j's sums to its parent (``force_to_parent``); return them.

    Along a chain they stay in registers; at a branch they go into the
    parent's ``W_ACC`` and, as at a root, the zero sums come back.
    """
    par = parent(links, j)
    if par < 0:
        return (z3, z3, z3, z3)
    L, K, f, nm = sums
    R, p = stored_placement(ws, j)
    L, K = force_to_parent(R, p, L, K)
    f, nm = force_to_parent(R, p, f, nm)
    if par == j - 1:
        return (L, K, f, nm)
    for k in range(3):      # a branch: into the parent's sums
        ws[par, W_ACC + k] += L[k]
        ws[par, W_ACC + 3 + k] += K[k]
        ws[par, W_ACC + 6 + k] += f[k]
        ws[par, W_ACC + 9 + k] += nm[k]
    return (z3, z3, z3, z3)
