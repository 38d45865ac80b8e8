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
Kinematics: joint placements, link poses, spatial inertias and the Jacobian.

Notation: every vector of link j is expressed in kernel frame j, whose z
axis is the axis of joint j through its origin O_j (see
``model.compile_arrays``); R, p are the rotation and origin of kernel
frame j in frame j-1, stored in ``ws`` (``W_R``, ``W_P``) by the pass that
computes them (:func:`placement`) and read back by later passes
(:func:`stored_placement`).
"""
import math

from ._jit import njit
from .layout import (C_ONE, C_ZERO, F_BASE, F_CONST, F_TOOL, L_BODY, L_COM,
                     L_INERTIA, L_MASS, L_P, L_R, L_TYPE, W_CT, W_DD, W_P, W_R,
                     W_ST)
from .spatial import (cross, frame_rot, load3, load9, matmul, rot, rot_t,
                      transpose)


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
    A prismatic joint needs no trigonometry per call.
    """
    n = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    one = frames[F_CONST, C_ONE]
    for j in range(n):
        if revolute(links, frames, j):
            ws[j, W_CT] = math.cos(q[j])
            ws[j, W_ST] = math.sin(q[j])
            ws[j, W_DD] = zero
        else:
            ws[j, W_CT] = one
            ws[j, W_ST] = zero
            ws[j, W_DD] = q[j]


@njit(cache=True, inline='always')
def link_geometry(links, frames, j, ws):
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
def placement(links, frames, j, ws):
    """Return R, p of kernel frame j in j-1 (``link_geometry``), stored."""
    R, p = link_geometry(links, frames, j, ws)
    for k in range(9):
        ws[j, W_R + k] = R[k]
    for k in range(3):
        ws[j, W_P + k] = p[k]
    return R, p


@njit(cache=True, inline='always')
def stored_placement(ws, j):
    """Return R, p of kernel frame j in j-1 as a pass stored them in ws."""
    return load9(ws, j, W_R), load3(ws, j, W_P)


@njit(cache=True, inline='always')
def link_inertia(links, j):
    """Return link j's rotational inertia about its com, row-major 3x3."""
    return load9(links, j, L_INERTIA)


@njit(cache=True, inline='always')
def body_inertia(links, j, R, o, out, row, col):
    """
    Write link j's spatial inertia into ``out[row, col:col + 36]``.

    About the origin o of the frame whose rotation (to link j's kernel
    frame axes) is R: the link's centre of mass is o + R c and its
    rotational inertia R I_c R^T.  Blocks [[I_o, m [c]], [m [c]^T, m 1]].
    """
    m = links[j, L_MASS]
    c = rot(R, links[j, L_COM], links[j, L_COM + 1], links[j, L_COM + 2])
    c = (o[0] + c[0], o[1] + c[1], o[2] + c[2])
    Ic = matmul(matmul(R, link_inertia(links, j)), transpose(R))
    mc = (m * c[0], m * c[1], m * c[2])
    cc = c[0] * mc[0] + c[1] * mc[1] + c[2] * mc[2]
    zero = m - m
    for r in range(3):
        for s in range(3):
            v = Ic[3 * r + s] - mc[r] * c[s]
            if r == s:
                v = v + cc
            out[row, col + 6 * r + s] = v
            out[row, col + 6 * (r + 3) + s + 3] = m if r == s else zero
    # m [c] (top right) and its transpose (bottom left)
    X = (zero, -mc[2], mc[1], mc[2], zero, -mc[0], -mc[1], mc[0], zero)
    for r in range(3):
        for s in range(3):
            out[row, col + 6 * r + s + 3] = X[3 * r + s]
            out[row, col + 6 * (s + 3) + r] = X[3 * r + s]


@njit(cache=True)
def chain_poses(links, frames, q, ws, Ts, link_frames):
    """
    Walk the chain and store the poses of its frames in ``Ts``.

    Rows 1..n get kernel frames 1..n (or, with ``link_frames``, the link
    frames of the model, B_j applied), row 0 frame 0, row n+1 the end
    effector; all in the base frame, each row R (9, row-major) then p (3).
    """
    n = links.shape[0]
    joint_trig(links, frames, q, ws)
    Rw = frame_rot(frames, F_BASE)
    pw = (frames[F_BASE, 9], frames[F_BASE, 10], frames[F_BASE, 11])
    for k in range(9):
        Ts[0, k] = Rw[k]
    for k in range(3):
        Ts[0, 9 + k] = pw[k]
    for j in range(n + 1):
        if j < n:
            R, p = link_geometry(links, frames, j, ws)
        else:
            R = frame_rot(frames, F_TOOL)
            p = (frames[F_TOOL, 9], frames[F_TOOL, 10], frames[F_TOOL, 11])
        t = rot(Rw, p[0], p[1], p[2])
        pw = (pw[0] + t[0], pw[1] + t[1], pw[2] + t[2])
        Rw = matmul(Rw, R)
        Ro = Rw
        po = pw
        if link_frames and j < n:
            RB = load9(links, j, L_BODY)
            t = rot(Rw, links[j, L_BODY + 9], links[j, L_BODY + 10],
                    links[j, L_BODY + 11])
            po = (pw[0] + t[0], pw[1] + t[1], pw[2] + t[2])
            Ro = matmul(Rw, RB)
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
    chain_poses(links, frames, q, ws, Ts, True)


@njit(cache=True)
def jacobian(links, frames, q, in_ee_axes, ws, Ts, J):
    """
    Geometric Jacobian of the end-effector origin, rows [v; w].

    Base-frame axes, or end-effector axes when ``in_ee_axes``.  Cost O(n).
    Joint j moves about z of kernel frame j, through its origin.
    """
    n = links.shape[0]
    chain_poses(links, frames, q, ws, Ts, False)
    pe = (Ts[n + 1, 9], Ts[n + 1, 10], Ts[n + 1, 11])
    zero = frames[F_CONST, C_ZERO]
    for j in range(n):
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
        if in_ee_axes:
            Re = load9(Ts, n + 1, 0)
            lin = rot_t(Re, lin[0], lin[1], lin[2])
            ang = rot_t(Re, ang[0], ang[1], ang[2])
        for k in range(3):
            J[k, j] = lin[k]
            J[3 + k, j] = ang[k]
