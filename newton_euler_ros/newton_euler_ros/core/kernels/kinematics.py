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
Kinematics: the tree, joint placements, poses, inertias and the Jacobian.

Notation: every vector of link j is expressed in kernel frame j, whose z
axis is the axis of joint j through its origin O_j (see
``model.compile_arrays``); R, p are the rotation and origin of kernel
frame j in the frame of its parent body lambda(j) (frame 0 for a joint on
the base), stored in ``ws`` (``W_R``, ``W_P``) by the pass that computes
them (:func:`placement`) and read back by later passes
(:func:`stored_placement`).

The tree.  Bodies are numbered parent first (``L_PARENT``: lambda(j) < j,
-1 for the base), so a pass base to tip is a loop j = 0..nb-1 and a pass
tip to base j = nb-1..0, as on a chain (lambda(j) = j - 1).  Where
lambda(j) = j - 1 a pass keeps its running values in registers, as it
would on a chain; only at a branch point (``L_STORE``: a child of j is
not j + 1) does it store j's state in the workspace for the children
that come later, and a backward pass adds what such a child carries into
its parent's accumulator (``W_ACC``) instead of the registers.

Mimic joints (``L_LEAD``, ``L_MULT``, ``L_OFFSET``).  A model with mimic
joints has fewer coordinates n than bodies nb (``frames[F_TREE, T_NQ]``).
Body j's joint then moves by q_j = mult q[lead] + offset, qd_j = mult
qd[lead] (:func:`joint_rate`), and what it takes (a torque, a column of
D, C, J or Y) goes to its lead coordinate times mult (:func:`put`,
:func:`put_pair`): tau = G^T tau_b, D = G^T D_b G, J = J_b G with G the
nb x n matrix of the multipliers.
"""
import math

from ._jit import njit
from .layout import (C_ONE, C_ZERO, F_BASE, F_CONST, F_TOOL, F_TREE, L_BODY,
                     L_COM, L_INERTIA, L_LEAD, L_MASS, L_MULT, L_OFFSET, L_P,
                     L_PARENT, L_R, L_STORE, L_TYPE, T_BRANCHED, T_NQ, T_TOOL,
                     W_CT, W_DD, W_P, W_R, W_ST)
from .spatial import (cross, frame_rot, load3, load9, matmul, rot, rot_t,
                      transpose)


@njit(cache=True, inline='always')
def parent(links, j):
    """Return lambda(j), the parent body of body j (-1: the base)."""
    return int(links[j, L_PARENT])


@njit(cache=True, inline='always')
def branch_point(links, frames, j):
    """Tell whether body j has a child other than j + 1 (``L_STORE``)."""
    return links[j, L_STORE] != frames[F_CONST, C_ZERO]


@njit(cache=True, inline='always')
def tool_body(frames):
    """Return the body carrying the end-effector frame (-1: the base)."""
    return int(frames[F_TREE, T_TOOL])


@njit(cache=True, inline='always')
def branched(frames):
    """Tell whether some body's parent is not the body before it."""
    return frames[F_TREE, T_BRANCHED] != frames[F_CONST, C_ZERO]


@njit(cache=True, inline='always')
def has_mimic(links, frames):
    """Tell whether some joint follows another (fewer coordinates)."""
    return links.shape[0] != int(frames[F_TREE, T_NQ])


@njit(cache=True, inline='always')
def joint_rate(links, x, j, mimic):
    """Return body j's joint rate: x[j], or mult x[lead] (mimic)."""
    if mimic:
        return links[j, L_MULT] * x[int(links[j, L_LEAD])]
    return x[j]


@njit(cache=True, inline='always')
def rate_or_zero(links, frames, x, j, mimic):
    """
    Return :func:`joint_rate` of ``x``, or zero when ``x`` is None.

    A caller passing None (no velocity, no acceleration) gets code that
    reads nothing: numba compiles the branch for None alone.
    """
    if x is None:
        return frames[F_CONST, C_ZERO]
    return joint_rate(links, x, j, mimic)


@njit(cache=True, inline='always')
def put(links, out, j, x, mimic):
    """Put x, what body j's joint takes, into its coordinate of ``out``."""
    if mimic:
        out[int(links[j, L_LEAD])] += links[j, L_MULT] * x
    else:
        out[j] = x


@njit(cache=True, inline='always')
def put_pair(links, M, a, b, x, mimic):
    """Entry (a, b) of a body matrix into M: M[a, b], or the leads' (G^T M G)."""
    if mimic:
        M[int(links[a, L_LEAD]), int(links[b, L_LEAD])] += (
            links[a, L_MULT] * links[b, L_MULT]) * x
    else:
        M[a, b] = x


@njit(cache=True, inline='always')
def zero_matrix(frames, M):
    """Set every entry of the 2-D array M to zero."""
    zero = frames[F_CONST, C_ZERO]
    for i in range(M.shape[0]):
        for k in range(M.shape[1]):
            M[i, k] = zero


@njit(cache=True)
def frame_rotation(links, frames, ws, j):
    """
    Rotation of kernel frame j in the base frame, from stored placements.

    Walks up from j to the base (the placements of j and its ancestors
    must be in ``ws``); frame 0's own rotation for j = -1.
    """
    Racc = frame_rot(frames, F_BASE)
    if j < 0:
        return Racc
    R = load9(ws, j, W_R)
    k = parent(links, j)
    while k >= 0:
        R = matmul(load9(ws, k, W_R), R)
        k = parent(links, k)
    return matmul(Racc, R)


@njit(cache=True)
def revolute(links, frames, j):
    """Tell whether joint j turns: its type code is zero (revolute)."""
    return links[j, L_TYPE] == frames[F_CONST, C_ZERO]


@njit(cache=True)
def axis_index(links, frames, j):
    """Index of joint j's motion subspace in a spatial vector: 2 or 5."""
    return 2 if revolute(links, frames, j) else 5


@njit(cache=True, inline='always')
def joint_trig(links, frames, q, ws):
    """
    Fill cos(q_j), sin(q_j) and the slide of every joint into ``ws``.

    A revolute joint's constant offset is part of its placement, so its
    angle is q itself: a large q is never rounded by adding an offset.
    A prismatic joint needs no trigonometry per call.  A mimic joint's
    angle is mult q[lead] + offset (the URDF's ``<mimic>``).
    """
    nb = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    one = frames[F_CONST, C_ONE]
    mimic = has_mimic(links, frames)
    for j in range(nb):
        if mimic:
            x = (links[j, L_MULT] * q[int(links[j, L_LEAD])]
                 + links[j, L_OFFSET])
        else:
            x = q[j]
        if revolute(links, frames, j):
            ws[j, W_CT] = math.cos(x)
            ws[j, W_ST] = math.sin(x)
            ws[j, W_DD] = zero
        else:
            ws[j, W_CT] = one
            ws[j, W_ST] = zero
            ws[j, W_DD] = x


@njit(cache=True, inline='always')
def link_geometry(links, frames, j, ws):
    """
    R, p of kernel frame j in its parent's at the trig values in ``ws``.

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
def placement(links, frames, j, ws):
    """Return R, p of kernel frame j in its parent's, stored in ``ws``."""
    R, p = link_geometry(links, frames, j, ws)
    for k in range(9):
        ws[j, W_R + k] = R[k]
    for k in range(3):
        ws[j, W_P + k] = p[k]
    return R, p


@njit(cache=True, inline='always')
def stored_placement(ws, j):
    """Return R, p of kernel frame j in its parent's, as stored in ws."""
    return load9(ws, j, W_R), load3(ws, j, W_P)


@njit(cache=True, inline='always')
def link_inertia(links, j):
    """Return link j's rotational inertia about its com, row-major 3x3."""
    return load9(links, j, L_INERTIA)


@njit(cache=True, inline='always')
def inertia_parts(links, j, R, o):
    """
    Return link j's J (row-major 3x3), h = m c and m about a point o.

    The frame's rotation (to link j's kernel frame axes) is R: the link's
    centre of mass is c = o + R c_j and J = R I_c R^T + m ([c]^T [c]),
    its rotational inertia about o.
    """
    m = links[j, L_MASS]
    c = rot(R, links[j, L_COM], links[j, L_COM + 1], links[j, L_COM + 2])
    c = (o[0] + c[0], o[1] + c[1], o[2] + c[2])
    Ic = matmul(matmul(R, link_inertia(links, j)), transpose(R))
    mc = (m * c[0], m * c[1], m * c[2])
    cc = c[0] * mc[0] + c[1] * mc[1] + c[2] * mc[2]
    J = (Ic[0] - mc[0] * c[0] + cc, Ic[1] - mc[0] * c[1],
         Ic[2] - mc[0] * c[2], Ic[3] - mc[1] * c[0],
         Ic[4] - mc[1] * c[1] + cc, Ic[5] - mc[1] * c[2],
         Ic[6] - mc[2] * c[0], Ic[7] - mc[2] * c[1],
         Ic[8] - mc[2] * c[2] + cc)
    return J, mc, m


@njit(cache=True, inline='always')
def body_inertia(links, j, R, o, out, row, col):
    """
    Write link j's spatial inertia into ``out[row, col:col + 36]``.

    About the origin o of the frame whose rotation (to link j's kernel
    frame axes) is R (:func:`inertia_parts`): blocks
    [[J, [h]], [[h]^T, m 1]].
    """
    J, mc, m = inertia_parts(links, j, R, o)
    zero = m - m
    for r in range(3):
        for s in range(3):
            out[row, col + 6 * r + s] = J[3 * r + s]
            out[row, col + 6 * (r + 3) + s + 3] = m if r == s else zero
    # [h] (top right) and its transpose (bottom left)
    X = (zero, -mc[2], mc[1], mc[2], zero, -mc[0], -mc[1], mc[0], zero)
    for r in range(3):
        for s in range(3):
            out[row, col + 6 * r + s + 3] = X[3 * r + s]
            out[row, col + 6 * (s + 3) + r] = X[3 * r + s]


@njit(cache=True)
def chain_poses(links, frames, q, ws, Ts, link_frames):
    """
    Walk the tree and store the poses of its frames in ``Ts``.

    Rows 1..nb get kernel frames 1..nb (or, with ``link_frames``, the link
    frames of the model, B_j applied), row 0 frame 0, row nb+1 the end
    effector; all in the base frame, each row R (9, row-major) then p (3).
    """
    nb = links.shape[0]
    joint_trig(links, frames, q, ws)
    Rw = frame_rot(frames, F_BASE)
    pw = (frames[F_BASE, 9], frames[F_BASE, 10], frames[F_BASE, 11])
    for k in range(9):
        Ts[0, k] = Rw[k]
    for k in range(3):
        Ts[0, 9 + k] = pw[k]
    for j in range(nb):
        par = parent(links, j)
        if par != j - 1:        # a branch: start from the parent's frame
            Rw = load9(Ts, par + 1, 0)
            pw = load3(Ts, par + 1, 9)
        R, p = link_geometry(links, frames, j, ws)
        t = rot(Rw, p[0], p[1], p[2])
        pw = (pw[0] + t[0], pw[1] + t[1], pw[2] + t[2])
        Rw = matmul(Rw, R)
        for k in range(9):
            Ts[j + 1, k] = Rw[k]
        for k in range(3):
            Ts[j + 1, 9 + k] = pw[k]
    # the end effector, on its body's kernel frame
    row = tool_body(frames) + 1
    Rw = load9(Ts, row, 0)
    pw = load3(Ts, row, 9)
    t = rot(Rw, frames[F_TOOL, 9], frames[F_TOOL, 10], frames[F_TOOL, 11])
    Ro = matmul(Rw, frame_rot(frames, F_TOOL))
    for k in range(9):
        Ts[nb + 1, k] = Ro[k]
    for k in range(3):
        Ts[nb + 1, 9 + k] = pw[k] + t[k]
    if link_frames:
        for j in range(nb):
            Rw = load9(Ts, j + 1, 0)
            pw = load3(Ts, j + 1, 9)
            t = rot(Rw, links[j, L_BODY + 9], links[j, L_BODY + 10],
                    links[j, L_BODY + 11])
            Ro = matmul(Rw, load9(links, j, L_BODY))
            for k in range(9):
                Ts[j + 1, k] = Ro[k]
            for k in range(3):
                Ts[j + 1, 9 + k] = pw[k] + t[k]


@njit(cache=True)
def forward_kinematics(links, frames, q, ws, Ts):
    """
    Poses of frame 0, the link frames 1..nb and the end effector.

    ``Ts`` is (nb + 2, 12), in the base frame: row 0 frame 0, rows 1..nb
    the model's link frames (where its inertial parameters are given), row
    nb+1 the end effector; each row R (9, row-major) then p (3).
    """
    chain_poses(links, frames, q, ws, Ts, True)


@njit(cache=True)
def jacobian(links, frames, q, body, target, local, ws, Ts, J):
    """
    Geometric Jacobian of a frame on body ``body``, rows [v; w], (6, n).

    ``target`` is that frame's pose in kernel frame ``body`` (R, 9
    row-major, then p); the end effector is ``frames[F_TOOL]`` on
    ``tool_body``.  Base-frame axes, or the frame's own axes when
    ``local``.  Only the joints on the path from the body to the base
    move it: the other columns are zero (a mimic joint's column adds to
    its lead's, times its multiplier).  Cost O(nb).
    """
    chain_poses(links, frames, q, ws, Ts, False)
    mimic = has_mimic(links, frames)
    zero = frames[F_CONST, C_ZERO]
    zero_matrix(frames, J)
    Rb = load9(Ts, body + 1, 0)
    t = rot(Rb, target[9], target[10], target[11])
    pe = (Ts[body + 1, 9] + t[0], Ts[body + 1, 10] + t[1],
          Ts[body + 1, 11] + t[2])
    Re = matmul(Rb, (target[0], target[1], target[2], target[3], target[4],
                     target[5], target[6], target[7], target[8]))
    j = body
    while j >= 0:
        row = j + 1
        z = (Ts[row, 2], Ts[row, 5], Ts[row, 8])
        if revolute(links, frames, j):
            rel = (pe[0] - Ts[row, 9], pe[1] - Ts[row, 10],
                   pe[2] - Ts[row, 11])
            lin = cross(z[0], z[1], z[2], rel[0], rel[1], rel[2])
            ang = z
        else:
            lin = z
            ang = (zero, zero, zero)
        if local:
            lin = rot_t(Re, lin[0], lin[1], lin[2])
            ang = rot_t(Re, ang[0], ang[1], ang[2])
        if mimic:
            col = int(links[j, L_LEAD])
            s = links[j, L_MULT]
            for k in range(3):
                J[k, col] += s * lin[k]
                J[3 + k, col] += s * ang[k]
        else:
            for k in range(3):
                J[k, j] = lin[k]
                J[3 + k, j] = ang[k]
        j = parent(links, j)
