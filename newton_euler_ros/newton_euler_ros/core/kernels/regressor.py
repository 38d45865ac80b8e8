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
The joint-torque regressor Y(q, qd, qdd), tau = Y pi, as a compiled pass.

One forward pass, base to tip: each link's kinematics in its own axes
give its 6 x 10 block (the wrench each inertial parameter causes), which
the one force carry (``force_to_parent``) takes to frame 0; each joint
then takes the moment about (revolute) or the force along (prismatic) its
axis of the links it carries: on a tree, its descendants (the columns of
the other links are zero), and a mimic joint's share goes to its lead
coordinate times its multiplier (Y = G^T Y_b, ten columns per body).
The drive columns (viscous, Coulomb, offset, armature) follow the 10nb
inertial ones when asked for.  Its row
step is ``entry.regressor_row``, its batch loop ``run_regressor_batch``
is written from it (``generate.batch``); ``core.regressor`` is the API.
"""
import math

from ._jit import njit
from .kinematics import (branch_point, has_mimic, joint_rate, joint_trig,
                         link_geometry, parent, revolute)
from .layout import (C_ONE, C_ZERO, F_CONST, F_GRAV, L_BODY, L_LEAD, L_MULT,
                     W_X)
from .spatial import (cross, force_to_parent, load3, load9, matmul,
                      motion_to_child, rot, rot_t)


@njit(cache=True, inline='always')
def _store(a, row, x, y):
    """a[row, 0:3] = x, a[row, 3:6] = y (two 3-tuples)."""
    for k in range(3):
        a[row, k] = x[k]
        a[row, 3 + k] = y[k]


@njit(cache=True, inline='always')
def _accel_to_child(R, p, w, al, ae):
    """
    (al, ae) of frame j-1 in frame j (R, p: j in j-1), w frame j-1's.

    ae is the classical acceleration of the origin, so the moved origin
    adds w x (w x p) to the one motion carry's al x p.
    """
    t = cross(w[0], w[1], w[2], p[0], p[1], p[2])
    t = cross(w[0], w[1], w[2], t[0], t[1], t[2])
    x = motion_to_child(R, p, (al[0], al[1], al[2],
                               ae[0] + t[0], ae[1] + t[1], ae[2] + t[2]))
    return (x[0], x[1], x[2]), (x[3], x[4], x[5])


@njit(cache=True)
def regressor_columns(links, frames, q, qd, qdd, ws, line, acc, Y):
    """
    Fill Y (n, >= 10nb) with the inertial regressor at one state.

    Scratch: ``ws`` (nb, W_WIDTH) for the joints' trigonometry (and a
    branch point's state, ``W_X``), ``line`` (nb, 6) for each joint's
    axis as a line in frame 0, ``acc`` (10nb, 6) for each column's wrench
    in frame 0 (force, then moment about the origin of frame 0).  Y's
    first 10nb columns are overwritten.

    The steps: per body from the base, :func:`regressor_start` picks the
    state it starts from, :func:`regressor_step` takes it on (its pose
    in frame 0, its joint's axis, its kinematics) and
    :func:`link_columns` writes its ten wrenches; then
    :func:`joint_rows` gives each joint its share.
    """
    zero = frames[F_CONST, C_ZERO]
    one = frames[F_CONST, C_ONE]
    mimic = has_mimic(links, frames)
    a_base = (-frames[F_GRAV, 0], -frames[F_GRAV, 1], -frames[F_GRAV, 2])
    z3 = (zero, zero, zero)
    # pose of kernel frame j in frame 0, w, al, origin acceleration
    ident = (one, zero, zero, zero, one, zero, zero, zero, one)
    base = (ident, z3, z3, z3, a_base)
    state = base
    joint_trig(links, frames, q, ws)
    for j in range(links.shape[0]):
        state = regressor_start(links, ws, j, state, base)
        state = regressor_step(links, frames, qd, qdd, ws, line, j, mimic,
                               state)
        link_columns(links, frames, j, state, acc)
    joint_rows(links, frames, line, acc, Y, mimic)


@njit(cache=True, inline='always')
def regressor_start(links, ws, j, state, base):
    """
    Return body j's starting ``(R0, o0, w, al, ae)``: its parent's.

    A branch point's is stored (``W_X``); a root starts from ``base``.
    """
    par = parent(links, j)
    if par == j - 1:
        return state
    if par < 0:
        return base
    return (load9(ws, par, W_X), load3(ws, par, W_X + 9),
            load3(ws, par, W_X + 12), load3(ws, par, W_X + 15),
            load3(ws, par, W_X + 18))


@njit(cache=True, inline='always')
def regressor_step(links, frames, qd, qdd, ws, line, j, mimic, state):
    """
    Take the state from body j's parent to body j; return body j's.

    Kernel frame j's pose in frame 0 (R0, o0), joint j's axis as a line
    in frame 0 (``line[j]``: z, o0 x z), then w, al and the acceleration
    of O_j in frame j axes; a branch point stores its state (``W_X``).
    """
    R0, o0, w, al, ae = state
    one = frames[F_CONST, C_ONE]
    two = one + one
    R, p = link_geometry(links, frames, j, ws)
    t = rot(R0, p[0], p[1], p[2])
    o0 = (o0[0] + t[0], o0[1] + t[1], o0[2] + t[2])
    R0 = matmul(R0, R)
    z = (R0[2], R0[5], R0[8])
    oz = cross(o0[0], o0[1], o0[2], z[0], z[1], z[2])
    _store(line, j, z, oz)
    # (al, origin acceleration) carried into frame j, then the joint
    al, ae = _accel_to_child(R, p, w, al, ae)
    w = rot_t(R, w[0], w[1], w[2])
    qdj = joint_rate(links, qd, j, mimic)
    qddj = joint_rate(links, qdd, j, mimic)
    if revolute(links, frames, j):
        al = (al[0] + w[1] * qdj, al[1] - w[0] * qdj, al[2] + qddj)
        w = (w[0], w[1], w[2] + qdj)
    else:
        ae = (ae[0] + two * w[1] * qdj, ae[1] - two * w[0] * qdj,
              ae[2] + qddj)
    if branch_point(links, frames, j):
        for k in range(9):
            ws[j, W_X + k] = R0[k]
        for k in range(3):
            ws[j, W_X + 9 + k] = o0[k]
            ws[j, W_X + 12 + k] = w[k]
            ws[j, W_X + 15 + k] = al[k]
            ws[j, W_X + 18 + k] = ae[k]
    return (R0, o0, w, al, ae)


@njit(cache=True, inline='always')
def link_columns(links, frames, j, state, acc):
    """
    Write link j's ten columns, the wrenches of its 6 x 10 block, in frame 0.

    In the link frame B (``L_BODY``: B in kernel frame j), the wrench
    each inertial parameter (m, m c, the six entries of I about B's
    origin) causes, carried to frame 0 into ``acc[10 j:10 j + 10]``.
    """
    R0, o0, w, al, ae = state
    zero = frames[F_CONST, C_ZERO]
    RB = load9(links, j, L_BODY)
    pB = load3(links, j, L_BODY + 9)
    ll, a = _accel_to_child(RB, pB, w, al, ae)
    wl = rot_t(RB, w[0], w[1], w[2])
    RL = matmul(R0, RB)
    t = rot(R0, pB[0], pB[1], pB[2])
    oL = (o0[0] + t[0], o0[1] + t[1], o0[2] + t[2])
    col = 10 * j
    # m: force a, no moment about the link origin
    _put(acc, col, RL, oL, a, (zero, zero, zero))
    # m c_i: force al x e_i + w x (w x e_i), moment e_i x a
    _put(acc, col + 1, RL, oL,
         (zero - wl[1] * wl[1] - wl[2] * wl[2],
          ll[2] + wl[0] * wl[1], wl[0] * wl[2] - ll[1]),
         (zero, zero - a[2], a[1]))
    _put(acc, col + 2, RL, oL,
         (wl[0] * wl[1] - ll[2],
          zero - wl[0] * wl[0] - wl[2] * wl[2],
          ll[0] + wl[1] * wl[2]),
         (a[2], zero, zero - a[0]))
    _put(acc, col + 3, RL, oL,
         (ll[1] + wl[0] * wl[2], wl[1] * wl[2] - ll[0],
          zero - wl[0] * wl[0] - wl[1] * wl[1]),
         (zero - a[1], a[0], zero))
    # inertia entries: moment I al + w x (I w), no force
    a0, a1, a2 = ll
    w0, w1, w2 = wl
    zz = (zero, zero, zero)
    _put(acc, col + 4, RL, oL, zz,
         _imom((a0, zero, zero), (w0, zero, zero), wl))      # Ixx
    _put(acc, col + 5, RL, oL, zz,
         _imom((a1, a0, zero), (w1, w0, zero), wl))          # Ixy
    _put(acc, col + 6, RL, oL, zz,
         _imom((zero, a1, zero), (zero, w1, zero), wl))      # Iyy
    _put(acc, col + 7, RL, oL, zz,
         _imom((a2, zero, a0), (w2, zero, w0), wl))          # Ixz
    _put(acc, col + 8, RL, oL, zz,
         _imom((zero, a2, a1), (zero, w2, w1), wl))          # Iyz
    _put(acc, col + 9, RL, oL, zz,
         _imom((zero, zero, a2), (zero, zero, w2), wl))      # Izz


@njit(cache=True, inline='always')
def joint_rows(links, frames, line, acc, Y, mimic):
    """
    Give each joint the wrenches of the links it carries: Y's 10nb columns.

    Joint j takes the moment about (revolute) or the force along
    (prismatic) its axis (``line[j]``): link k's ten columns go to k and
    its ancestors, every other entry is zero; a mimic joint's share goes
    to its lead's row times its multiplier.
    """
    zero = frames[F_CONST, C_ZERO]
    one = frames[F_CONST, C_ONE]
    nb = links.shape[0]
    for r in range(Y.shape[0]):
        for col in range(10 * nb):
            Y[r, col] = zero
    for k in range(nb):
        j = k
        while j >= 0:
            z0, z1, z2 = line[j, 0], line[j, 1], line[j, 2]
            row = int(links[j, L_LEAD]) if mimic else j
            s = links[j, L_MULT] if mimic else one
            if revolute(links, frames, j):
                m0, m1, m2 = line[j, 3], line[j, 4], line[j, 5]
                for col in range(10 * k, 10 * k + 10):
                    x = (z0 * acc[col, 3] + z1 * acc[col, 4]
                         + z2 * acc[col, 5] + m0 * acc[col, 0]
                         + m1 * acc[col, 1] + m2 * acc[col, 2])
                    if mimic:
                        Y[row, col] += s * x
                    else:
                        Y[row, col] = x
            else:
                for col in range(10 * k, 10 * k + 10):
                    x = (z0 * acc[col, 0] + z1 * acc[col, 1]
                         + z2 * acc[col, 2])
                    if mimic:
                        Y[row, col] += s * x
                    else:
                        Y[row, col] = x
            j = parent(links, j)


@njit(cache=True, inline='always')
def _put(acc, col, RL, oL, f, mo):
    """Store a link-axes wrench (moment about the link origin) in frame 0."""
    f0, m0 = force_to_parent(RL, oL, f, mo)
    _store(acc, col, f0, m0)


@njit(cache=True, inline='always')
def _imom(Ia, Iw, w):
    t = cross(w[0], w[1], w[2], Iw[0], Iw[1], Iw[2])
    return (Ia[0] + t[0], Ia[1] + t[1], Ia[2] + t[2])


@njit(cache=True)
def drive_columns(links, frames, qd, qdd, eps, Y):
    """Fill the 4n drive columns after the 10nb inertial ones of Y."""
    n = qd.shape[0]
    zero = frames[F_CONST, C_ZERO]
    one = frames[F_CONST, C_ONE]
    base = 10 * links.shape[0]
    for j in range(n):
        for k in range(4 * n):
            Y[j, base + k] = zero
        Y[j, base + 4 * j] = qd[j]
        Y[j, base + 4 * j + 1] = math.tanh(qd[j] / eps)
        Y[j, base + 4 * j + 2] = one
        Y[j, base + 4 * j + 3] = qdd[j]
