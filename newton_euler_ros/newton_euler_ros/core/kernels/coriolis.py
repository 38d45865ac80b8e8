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
The Christoffel Coriolis matrix C(q, qd) in O(n^2) from composite bodies.

Spatial (6-vector) algebra in frame 0: a motion vector is [angular;
linear] and a force [moment; force], at the origin of frame 0 (the
convention of Featherstone's book).
"""
from ._jit import njit
from .kinematics import (branch_point, branched, has_mimic, inertia_parts,
                         joint_rate, joint_trig, link_geometry, parent,
                         put_pair, revolute, zero_matrix)
from .layout import (C_HALF, C_ONE, C_ZERO, CS_BC, CS_H, CS_IC, CW_F1, CW_F2,
                     CW_G, CW_I, CW_ICA, CW_OW, CW_RW, CW_S, CW_SD, CW_V,
                     DS_F, DS_W, DW_A, DW_ACC, DW_C, DW_E, DW_T, DW_U, DW_W,
                     DW_Y,
                     F_CONST, OVERFLOW)
from .spatial import cross, load3, load9, matmul, rot, rot_t, vec6
from .status import matrix_status

# The composites' columns, IC then BC (``CS_IC`` = 0): what a branch's
# later children carry back to it (``CW_ICA``, ``CW_BCA``, in that order).
SUMS = CS_H


@njit(cache=True, inline='always')
def inertia_times(arr, row, col, x):
    """
    Return I x of a spatial inertia ``arr[row, col:col + 10]`` (``CW_I``).

    With J its rotational inertia about the origin, h = m c and m:
    I [w; v] = [J w + h x v; m v - h x w], 24 multiplications.
    """
    J = vec6(arr, row, col)     # xx, xy, xz, yy, yz, zz
    h = load3(arr, row, col + 6)
    m = arr[row, col + 9]
    a = cross(h[0], h[1], h[2], x[3], x[4], x[5])
    b = cross(h[0], h[1], h[2], x[0], x[1], x[2])
    return (J[0] * x[0] + J[1] * x[1] + J[2] * x[2] + a[0],
            J[1] * x[0] + J[3] * x[1] + J[4] * x[2] + a[1],
            J[2] * x[0] + J[4] * x[1] + J[5] * x[2] + a[2],
            m * x[3] - b[0], m * x[4] - b[1], m * x[5] - b[2])


@njit(cache=True, inline='always')
def coriolis_times(cw, n, x):
    """
    Return BC x of the running composite (scratch row n, ``CS_BC``).

    BC = [[P, 0], [-[h_f], 0]], so BC [w; v] = [P w; w x h_f].
    """
    P = load9(cw, n, CS_BC)
    hf = load3(cw, n, CS_BC + 9)
    a = rot(P, x[0], x[1], x[2])
    b = cross(x[0], x[1], x[2], hf[0], hf[1], hf[2])
    return (a[0], a[1], a[2], b[0], b[1], b[2])


@njit(cache=True, inline='always')
def coriolis_forward(links, frames, qd, ws, cw):
    """
    Coriolis pass 1, base to tip, everything in frame 0 about its origin.

    Stores each kernel frame's pose, each joint's motion subspace S_j
    ([z; o x z] revolute, [0; z] prismatic), each link's velocity
    V_j = V_lambda(j) + S_j qd_j and Sdot_j = V_j x S_j.
    """
    nb = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    one = frames[F_CONST, C_ONE]
    mimic = has_mimic(links, frames)
    ident = (one, zero, zero, zero, one, zero, zero, zero, one)
    Rw = ident
    ow = (zero, zero, zero)
    V = (zero, zero, zero, zero, zero, zero)
    for j in range(nb):
        par = parent(links, j)
        if par != j - 1:        # a branch: start from the parent's
            if par < 0:
                Rw = ident
                ow = (zero, zero, zero)
                V = (zero, zero, zero, zero, zero, zero)
            else:
                Rw = load9(cw, par, CW_RW)
                ow = load3(cw, par, CW_OW)
                V = vec6(cw, par, CW_V)
        if branch_point(links, frames, j):
            for k in range(SUMS):
                cw[j, CW_ICA + k] = zero
        R, p = link_geometry(links, frames, j, ws)
        t = rot(Rw, p[0], p[1], p[2])
        ow = (ow[0] + t[0], ow[1] + t[1], ow[2] + t[2])
        Rw = matmul(Rw, R)
        z = (Rw[2], Rw[5], Rw[8])
        if revolute(links, frames, j):
            v = cross(ow[0], ow[1], ow[2], z[0], z[1], z[2])
            S = (z[0], z[1], z[2], v[0], v[1], v[2])
        else:
            S = (zero, zero, zero, z[0], z[1], z[2])
        s = joint_rate(links, qd, j, mimic)
        V = (V[0] + S[0] * s, V[1] + S[1] * s, V[2] + S[2] * s,
             V[3] + S[3] * s, V[4] + S[4] * s, V[5] + S[5] * s)
        # motion cross product V x S = [w x s_w; w x s_v + v x s_w]
        a = cross(V[0], V[1], V[2], S[0], S[1], S[2])
        b = cross(V[0], V[1], V[2], S[3], S[4], S[5])
        c = cross(V[3], V[4], V[5], S[0], S[1], S[2])
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
def coriolis_backward(links, frames, cw, dw, derivatives):
    """
    Coriolis pass 2, tip to base: composite inertia and Coriolis matrices.

    With I_k the spatial inertia of link k and
    B_k = (Y + Y^T + [I_k V_k]^) / 2, Y = (V_k x*) I_k, where
    [h]^ x = x x* h (Echeandia and Wensing's body Coriolis matrix in a
    fixed frame), the composites IC_j = sum_k I_k and BC_j = sum_k B_k
    over j and its descendants k give each joint's three vectors
    F1 = IC S, F2 = BC^T S and G = IC Sdot + BC S.  The running composite
    is kept in the scratch row nb; at a branch it is added into the
    parent's ``CW_ICA``, ``CW_BCA`` sums, which the parent adds in turn.
    With ``derivatives`` the composite wrench is summed beside them in
    ``dw`` (:func:`wrench_step`; ``derivatives.derivative_forward`` must
    have filled ``dw``).
    """
    n = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    for k in range(SUMS):
        cw[n, k] = zero
    if derivatives:
        for k in range(21):
            dw[n, k] = zero
    for j in range(n - 1, -1, -1):
        if branch_point(links, frames, j):      # the later children's
            for k in range(SUMS):
                cw[n, k] += cw[j, CW_ICA + k]
            if derivatives:
                for k in range(21):
                    dw[n, k] += dw[j, DW_ACC + k]
        body_step(links, frames, cw, j, n)
        if derivatives:
            wrench_step(links, frames, cw, dw, j, n)
        coriolis_vectors(cw, j, n)
        par = parent(links, j)
        if par != j - 1:        # a branch: into the parent's sums
            if par >= 0:
                for k in range(SUMS):
                    cw[par, CW_ICA + k] += cw[n, k]
                if derivatives:
                    for k in range(21):
                        dw[par, DW_ACC + k] += dw[n, k]
            for k in range(SUMS):
                cw[n, k] = zero
            if derivatives:
                for k in range(21):
                    dw[n, k] = zero


@njit(cache=True, inline='always')
def body_step(links, frames, cw, j, n):
    """
    Add body j to the running composites IC and BC (scratch row n).

    Writes I_j (frame 0, ``CW_I``) and h_j = I_j V_j (scratch ``CS_H``).
    With I_j = [[J, [h]], [[h]^T, m 1]] and V_j = [w; v], the body's
    B = (Y + Y^T + [I_j V_j]^) / 2 has the blocks (``docs/derivatives.md``)
    [[P, 0], [-[h_f], 0]]: h_f = m v + w x h, the linear part of I_j V_j,
    and P = sym([w] J) - sym(h v^T) + (h . v) 1 - [h_n] / 2, h_n its
    angular part and sym(X) = (X + X^T) / 2.  So BC keeps 12 numbers.
    """
    half = frames[F_CONST, C_HALF]
    J, h, m = inertia_parts(links, j, load9(cw, j, CW_RW),
                            load3(cw, j, CW_OW))
    for k in range(3):
        cw[j, CW_I + k] = J[k]
        cw[j, CW_I + 6 + k] = h[k]
    cw[j, CW_I + 3] = J[4]
    cw[j, CW_I + 4] = J[5]
    cw[j, CW_I + 5] = J[8]
    cw[j, CW_I + 9] = m
    V = vec6(cw, j, CW_V)
    hv = inertia_times(cw, j, CW_I, V)
    for k in range(6):
        cw[n, CS_H + k] = hv[k]
    # [w] J column by column, then P entry by entry
    x0 = cross(V[0], V[1], V[2], J[0], J[3], J[6])
    x1 = cross(V[0], V[1], V[2], J[1], J[4], J[7])
    x2 = cross(V[0], V[1], V[2], J[2], J[5], J[8])
    X = (x0[0], x1[0], x2[0], x0[1], x1[1], x2[1], x0[2], x1[2], x2[2])
    for r in range(3):
        for s in range(3):
            if r == s:      # (h . v) - h_r v_r, without the cancellation
                a = (r + 1) % 3
                b = (r + 2) % 3
                p = (half * (X[4 * r] + X[4 * r])
                     + (h[a] * V[3 + a] + h[b] * V[3 + b]))
            else:
                p = half * ((X[3 * r + s] + X[3 * s + r])
                            - (h[r] * V[3 + s] + V[3 + r] * h[s]))
            cw[n, CS_BC + 3 * r + s] += p
    # - [h_n] / 2
    cw[n, CS_BC + 1] += half * hv[2]
    cw[n, CS_BC + 2] -= half * hv[1]
    cw[n, CS_BC + 3] -= half * hv[2]
    cw[n, CS_BC + 5] += half * hv[0]
    cw[n, CS_BC + 6] += half * hv[1]
    cw[n, CS_BC + 7] -= half * hv[0]
    for k in range(3):
        cw[n, CS_BC + 9 + k] += hv[3 + k]
    for k in range(10):
        cw[n, CS_IC + k] += cw[j, CW_I + k]


@njit(cache=True, inline='always')
def coriolis_vectors(cw, j, n):
    """
    F1 = IC S, F2 = BC^T S, G = IC Sdot + BC S of joint j (composites).

    F2's linear part is zero (BC's right-hand column of blocks is zero);
    only its angular part is stored.
    """
    S = vec6(cw, j, CW_S)
    Sd = vec6(cw, j, CW_SD)
    f1 = inertia_times(cw, n, CS_IC, S)
    g = inertia_times(cw, n, CS_IC, Sd)
    b = coriolis_times(cw, n, S)
    # BC^T = [[P^T, [h_f]], [0, 0]]
    P = load9(cw, n, CS_BC)
    hf = load3(cw, n, CS_BC + 9)
    a = rot_t(P, S[0], S[1], S[2])
    c = cross(hf[0], hf[1], hf[2], S[3], S[4], S[5])
    for r in range(6):
        cw[j, CW_F1 + r] = f1[r]
        cw[j, CW_G + r] = g[r] + b[r]
    for r in range(3):
        cw[j, CW_F2 + r] = a[r] + c[r]


@njit(cache=True, inline='always')
def wrench_step(links, frames, cw, dw, j, n):
    """
    Add link j's wrench to the composite wrench; Y_j and U_j for dtau/dq.

    The link's wrench from its motion, f_j = I_j A_j + V_j x* h_j, and the
    one it exerts on its environment (``DW_E``) go into the running
    composite F (the wrench joint j carries: tau_j = S_j . F_j, written
    to ``DW_T``), its fixed-direction wrenches' data into W.  Then, with the composites at
    j (body j's already added):

    - Y_j = S_j x* F_j - IC_j c_j + 2 BC_j Sdot_j + Delta_j, where
      Delta_j = [M w_j - w_j x n; -w_j x f] (n, f, M: the W sums and
      w_j the angular part of S_j) corrects the rigid carry of wrenches
      whose directions stay fixed;
    - U_j = M^T s_w - n x s_w - f x s_v (S_j = [s_w; s_v]).
    """
    A = vec6(dw, j, DW_A)
    V = vec6(cw, j, CW_V)
    h = vec6(cw, n, CS_H)
    # V x* h = [w x h_n + v x h_f; w x h_f]
    a = cross(V[0], V[1], V[2], h[0], h[1], h[2])
    b = cross(V[3], V[4], V[5], h[3], h[4], h[5])
    c = cross(V[0], V[1], V[2], h[3], h[4], h[5])
    vh = (a[0] + b[0], a[1] + b[1], a[2] + b[2], c[0], c[1], c[2])
    ia = inertia_times(cw, j, CW_I, A)
    for r in range(6):
        dw[n, DS_F + r] += vh[r] + dw[j, DW_E + r] + ia[r]
    for k in range(15):
        dw[n, DS_W + k] += dw[j, DW_W + k]
    S = vec6(cw, j, CW_S)
    Sd = vec6(cw, j, CW_SD)
    C = vec6(dw, j, DW_C)
    F = vec6(dw, n, DS_F)
    dw[j, DW_T] = ((S[0] * F[0] + S[1] * F[1] + S[2] * F[2])
                   + (S[3] * F[3] + S[4] * F[4] + S[5] * F[5]))
    nw = load3(dw, n, DS_W)
    fw = load3(dw, n, DS_W + 3)
    M = load9(dw, n, DS_W + 6)
    # S x* F = [s_w x n + s_v x f; s_w x f]
    a = cross(S[0], S[1], S[2], F[0], F[1], F[2])
    b = cross(S[3], S[4], S[5], F[3], F[4], F[5])
    c = cross(S[0], S[1], S[2], F[3], F[4], F[5])
    Mw = rot(M, S[0], S[1], S[2])
    dn = cross(S[0], S[1], S[2], nw[0], nw[1], nw[2])
    df = cross(S[0], S[1], S[2], fw[0], fw[1], fw[2])
    y = (a[0] + b[0] + Mw[0] - dn[0], a[1] + b[1] + Mw[1] - dn[1],
         a[2] + b[2] + Mw[2] - dn[2], c[0] - df[0], c[1] - df[1],
         c[2] - df[2])
    bs = coriolis_times(cw, n, Sd)
    ic = inertia_times(cw, n, CS_IC, C)
    for r in range(6):
        dw[j, DW_Y + r] = y[r] + (bs[r] + bs[r]) - ic[r]
    Mt = rot_t(M, S[0], S[1], S[2])
    a = cross(nw[0], nw[1], nw[2], S[0], S[1], S[2])
    b = cross(fw[0], fw[1], fw[2], S[3], S[4], S[5])
    for r in range(3):
        dw[j, DW_U + r] = Mt[r] - a[r] - b[r]


@njit(cache=True, inline='always')
def coriolis_matrix_composite(links, frames, q, qd, ws, cw, C):
    """
    Christoffel C(q, qd) in O(n^2) from composite bodies.

    With body Jacobians in a fixed frame, C = sum_k J_k^T (I_k Jdot_k +
    B_k J_k) (see ``coriolis_backward``).  Column b of J_k is S_b for the
    joints b on the path from k to the base, so C[a, b] is zero unless one
    of a, b is an ancestor of the other (or a == b), and only the links
    beyond the farther one contribute:

    - b ancestor of a, or b == a: C[a, b] = S_a^T (IC_a Sdot_b + BC_a S_b)
      = F1_a . Sdot_b + F2_a . S_b
    - a ancestor of b: C[a, b] = S_a^T (IC_b Sdot_b + BC_b S_b) = S_a . G_b

    Two O(nb) passes and 15 multiply-adds per ancestor pair, against the n
    recursions of ``coriolis_matrix_columns``; the same C up to round-off.
    ``cw`` is an (nb + 1, CW_WIDTH) workspace.  Returns -1 or OVERFLOW.
    """
    nb = links.shape[0]
    mimic = has_mimic(links, frames)
    joint_trig(links, frames, q, ws)
    coriolis_forward(links, frames, qd, ws, cw)
    coriolis_backward(links, frames, cw, cw, False)
    tree = branched(frames)
    if mimic or tree:
        zero_matrix(frames, C)
    zero = frames[F_CONST, C_ZERO]
    check = zero        # zero times each entry: zero unless one is not finite
    for a in range(nb):
        f10 = cw[a, CW_F1]
        f11 = cw[a, CW_F1 + 1]
        f12 = cw[a, CW_F1 + 2]
        f13 = cw[a, CW_F1 + 3]
        f14 = cw[a, CW_F1 + 4]
        f15 = cw[a, CW_F1 + 5]
        f20 = cw[a, CW_F2]
        f21 = cw[a, CW_F2 + 1]
        f22 = cw[a, CW_F2 + 2]
        # row a left of the diagonal: b = a, then a's ancestors (on a
        # chain every b < a, in order, row a written contiguously)
        b = a if tree else 0
        while b >= 0:
            x = ((f10 * cw[b, CW_SD] + f11 * cw[b, CW_SD + 1]
                  + f12 * cw[b, CW_SD + 2] + f13 * cw[b, CW_SD + 3]
                  + f14 * cw[b, CW_SD + 4] + f15 * cw[b, CW_SD + 5])
                 + (f20 * cw[b, CW_S] + f21 * cw[b, CW_S + 1]
                    + f22 * cw[b, CW_S + 2]))
            put_pair(links, C, a, b, x, mimic)
            check = check + zero * x
            if tree:
                b = parent(links, b)
            else:
                b = b + 1 if b < a else -1
        # column a above the diagonal, C[b, a] = S_b . G_a for a's
        # ancestors b; on a chain row a right of it, C[a, b] = S_a . G_b
        if tree:
            g0 = cw[a, CW_G]
            g1 = cw[a, CW_G + 1]
            g2 = cw[a, CW_G + 2]
            g3 = cw[a, CW_G + 3]
            g4 = cw[a, CW_G + 4]
            g5 = cw[a, CW_G + 5]
            b = parent(links, a)
            while b >= 0:
                x = (cw[b, CW_S] * g0 + cw[b, CW_S + 1] * g1
                     + cw[b, CW_S + 2] * g2 + cw[b, CW_S + 3] * g3
                     + cw[b, CW_S + 4] * g4 + cw[b, CW_S + 5] * g5)
                put_pair(links, C, b, a, x, mimic)
                check = check + zero * x
                b = parent(links, b)
        else:
            s0 = cw[a, CW_S]
            s1 = cw[a, CW_S + 1]
            s2 = cw[a, CW_S + 2]
            s3 = cw[a, CW_S + 3]
            s4 = cw[a, CW_S + 4]
            s5 = cw[a, CW_S + 5]
            for b in range(a + 1, nb):
                x = (s0 * cw[b, CW_G] + s1 * cw[b, CW_G + 1]
                     + s2 * cw[b, CW_G + 2] + s3 * cw[b, CW_G + 3]
                     + s4 * cw[b, CW_G + 4] + s5 * cw[b, CW_G + 5])
                put_pair(links, C, a, b, x, mimic)
                check = check + zero * x
    if mimic:       # sums of finite entries may still overflow
        return matrix_status(C)
    return -1 if check == zero else OVERFLOW
