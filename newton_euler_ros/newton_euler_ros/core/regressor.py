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
The torque regressor: rigid-body torques are linear in the parameters.

    tau = Y(q, qd, qdd) pi

``pi`` holds ten inertial parameters per link, in Pinocchio's order
(``Inertia.toDynamicParameters``)::

    m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz

with c the centre of mass and I the rotational inertia about the *link
frame's origin* (I = I_c + m S(c)^T S(c)), both in link-frame axes.  The
link frame is the model's: the URDF child link's frame for URDF models,
the DH frame for DH models (``model.com`` and ``model.inertia`` are given
in it).  Gravity is included (``model.gravity``), as in
``pinocchio.computeJointTorqueRegressor``.

Y comes from the same Newton-Euler recursion as the inverse dynamics:
the forward pass gives each link's angular velocity and acceleration and
the acceleration of its origin (gravity as an upward acceleration of the
base); the link's wrench about its origin is linear in its ten
parameters (a 6 x 10 block).  The backward pass accumulates these blocks
instead of numbers: joint j takes the moment about (revolute) or the force
along (prismatic) its axis of the wrenches of links j..n-1.  The blocks
are carried to frame 0 once, and each joint's share is the product with
its axis as a line (z_j, o_j x z_j): six products per entry, O(n^2)
entries.

Drive columns (``drives=True``: Y is n x 14n, the 4n drive columns after
the 10n inertial ones, four per joint j at 10n + 4j + k)::

    k = 0  viscous friction F_v        column qd_j
    k = 1  Coulomb friction F_c        column tanh(qd_j / eps)
    k = 2  constant torque offset      column 1
    k = 3  armature (rotor inertia)    column qdd_j

tanh(qd / eps) is a smooth sign: it is 0 at rest, +-0.76 at |qd| = eps and
within 1e-4 of +-1 from |qd| = 5 eps.  ``eps`` is the Coulomb width,
``COULOMB_WIDTH`` = 0.02 rad/s (or m/s) unless given.

The kernels work in kernel frames (joint axis on z); ``links[j, L_BODY:]``
gives the link frame in kernel frame j (see ``model.compile_arrays``).
This module keeps its kernel to itself and takes only the column and row
constants from ``kernels``.
"""
import math

from numba import njit
import numpy as np

from .errors import DynamicsInputError
from .kernels import C_ONE, C_ZERO, F_CONST, F_GRAV, L_BODY, W_WIDTH
from .kernels.kinematics import joint_trig, link_geometry, revolute
from .kernels.spatial import (cross, force_to_parent, load3, load9, matmul,
                              motion_to_child, rot, rot_t)

N_INERTIAL = 10            # parameters per link
N_DRIVE = 4                # drive parameters per joint
DRIVE_NAMES = ('viscous', 'coulomb', 'offset', 'armature')
INERTIAL_NAMES = ('m', 'mcx', 'mcy', 'mcz', 'Ixx', 'Ixy', 'Iyy', 'Ixz',
                  'Iyz', 'Izz')
COULOMB_WIDTH = 0.02       # rad/s (m/s for a prismatic joint)


# ---------------------------------------------------------------------------
# kernel

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
def _regressor(links, frames, q, qd, qdd, ws, line, acc, Y):
    """
    Fill Y (n, >= 10n) with the inertial regressor at one state.

    Scratch: ``ws`` (n, W_WIDTH) for the joints' trigonometry, ``line``
    (n, 6) for each joint's axis as a line in frame 0, ``acc`` (10n, 6)
    for each column's wrench in frame 0 (force, then moment about the
    origin of frame 0).  Y's first 10n columns are overwritten.
    """
    n = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    one = frames[F_CONST, C_ONE]
    two = one + one
    ae = (-frames[F_GRAV, 0], -frames[F_GRAV, 1], -frames[F_GRAV, 2])
    w = (zero, zero, zero)
    al = (zero, zero, zero)
    # pose of kernel frame j in frame 0
    R0 = (one, zero, zero, zero, one, zero, zero, zero, one)
    o0 = (zero, zero, zero)
    # forward pass, base to tip: kinematics in kernel frame j, the link's
    # 6 x 10 block in link axes, then its columns in frame 0
    joint_trig(links, frames, q, ws)
    for j in range(n):
        R, p = link_geometry(links, frames, j, ws)
        t = rot(R0, p[0], p[1], p[2])
        o0 = (o0[0] + t[0], o0[1] + t[1], o0[2] + t[2])
        R0 = matmul(R0, R)
        z = (R0[2], R0[5], R0[8])
        oz = cross(o0[0], o0[1], o0[2], z[0], z[1], z[2])
        line[j, 0] = z[0]
        line[j, 1] = z[1]
        line[j, 2] = z[2]
        line[j, 3] = oz[0]
        line[j, 4] = oz[1]
        line[j, 5] = oz[2]
        # (al, origin acceleration) carried into frame j, then the joint
        al, ae = _accel_to_child(R, p, w, al, ae)
        w = rot_t(R, w[0], w[1], w[2])
        if revolute(links, frames, j):
            al = (al[0] + w[1] * qd[j], al[1] - w[0] * qd[j],
                  al[2] + qdd[j])
            w = (w[0], w[1], w[2] + qd[j])
        else:
            ae = (ae[0] + two * w[1] * qd[j], ae[1] - two * w[0] * qd[j],
                  ae[2] + qdd[j])
        # the link frame B in kernel frame j: kinematics in link axes
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
    # each joint takes the moment about (revolute) or the force along
    # (prismatic) its axis of the wrenches of the links it carries
    for j in range(n):
        for col in range(10 * j):
            Y[j, col] = zero
        z0, z1, z2 = line[j, 0], line[j, 1], line[j, 2]
        if revolute(links, frames, j):
            m0, m1, m2 = line[j, 3], line[j, 4], line[j, 5]
            for col in range(10 * j, 10 * n):
                Y[j, col] = (z0 * acc[col, 3] + z1 * acc[col, 4]
                             + z2 * acc[col, 5] + m0 * acc[col, 0]
                             + m1 * acc[col, 1] + m2 * acc[col, 2])
        else:
            for col in range(10 * j, 10 * n):
                Y[j, col] = (z0 * acc[col, 0] + z1 * acc[col, 1]
                             + z2 * acc[col, 2])


@njit(cache=True, inline='always')
def _put(acc, col, RL, oL, f, mo):
    """Store a link-axes wrench (moment about the link origin) in frame 0."""
    f0, m0 = force_to_parent(RL, oL, f, mo)
    acc[col, 0] = f0[0]
    acc[col, 1] = f0[1]
    acc[col, 2] = f0[2]
    acc[col, 3] = m0[0]
    acc[col, 4] = m0[1]
    acc[col, 5] = m0[2]


@njit(cache=True, inline='always')
def _imom(Ia, Iw, w):
    t = cross(w[0], w[1], w[2], Iw[0], Iw[1], Iw[2])
    return (Ia[0] + t[0], Ia[1] + t[1], Ia[2] + t[2])


@njit(cache=True)
def _drives(qd, qdd, eps, Y, row0):
    """Drive columns after the 10n inertial ones (rows ``row0``.. of Y)."""
    n = qd.shape[0]
    base = 10 * n
    for j in range(n):
        for k in range(4 * n):
            Y[j, base + k] = 0.0
        Y[j, base + 4 * j] = qd[j]
        Y[j, base + 4 * j + 1] = math.tanh(qd[j] / eps)
        Y[j, base + 4 * j + 2] = 1.0
        Y[j, base + 4 * j + 3] = qdd[j]


@njit(cache=True)
def _regressor_batch(links, frames, Q, QD, QDD, drives, eps, Y):
    n = links.shape[0]
    ws = np.empty((max(n, 1), W_WIDTH), links.dtype)
    line = np.empty((max(n, 1), 6))
    acc = np.empty((max(10 * n, 1), 6))
    for i in range(Q.shape[0]):
        _regressor(links, frames, Q[i], QD[i], QDD[i], ws, line, acc,
                   Y[i])
        if drives:
            _drives(QD[i], QDD[i], eps, Y[i], 0)


# ---------------------------------------------------------------------------
# Python API

def _states(model, name, X, m=None):
    try:
        X = np.ascontiguousarray(X, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise DynamicsInputError(f'{name} must be numbers: {exc}') from None
    if X.ndim == 1:
        X = X[None, :]
    if X.ndim != 2 or X.shape[1] != model.n:
        raise DynamicsInputError(
            f'{name} must have {model.n} columns (one per joint), got shape '
            f'{X.shape}')
    if m is not None and X.shape[0] != m:
        raise DynamicsInputError(
            f'{name} must have {m} rows like Q, got {X.shape[0]}')
    bad = np.flatnonzero(~np.isfinite(X).all(axis=1))
    if bad.size:
        raise DynamicsInputError(
            f'{name} row {int(bad[0])} has a non-finite entry')
    return X


def n_parameters(model, drives=False):
    """Return the number of columns of Y: 10n, or 14n with drives."""
    return model.n * (N_INERTIAL + (N_DRIVE if drives else 0))


def _width(eps):
    eps = float(eps)
    if not (eps > 0 and math.isfinite(eps)):
        raise DynamicsInputError(
            f'coulomb_width must be a positive number, got {eps!r}')
    return eps


def regressor_batch(model, Q, QD, QDD, *, drives=False,
                    coulomb_width=COULOMB_WIDTH, out=None):
    """
    Y at each row of the (m, n) states: an (m, n, 10n) array.

    With ``drives=True`` (m, n, 14n): the drive columns follow (see the
    module docstring).  One compiled loop, no Python work per state.
    """
    Q = _states(model, 'Q', Q)
    m = Q.shape[0]
    QD = _states(model, 'QD', QD, m)
    QDD = _states(model, 'QDD', QDD, m)
    eps = _width(coulomb_width)
    shape = (m, model.n, n_parameters(model, drives))
    if out is None:
        out = np.empty(shape)
    elif (not isinstance(out, np.ndarray) or out.shape != shape
          or out.dtype != np.float64 or not out.flags.c_contiguous):
        raise DynamicsInputError(
            f'out must be a C-contiguous float64 array of shape {shape}')
    _regressor_batch(model.links_array, model.frames_array, Q, QD, QDD,
                     bool(drives), eps, out)
    return out


def regressor(model, q, qd, qdd, *, drives=False,
              coulomb_width=COULOMB_WIDTH):
    """Y(q, qd, qdd) at one state: (n, 10n), or (n, 14n) with drives."""
    return regressor_batch(model, q, qd, qdd, drives=drives,
                           coulomb_width=coulomb_width)[0]


def drive_regressor(QD, QDD, coulomb_width=COULOMB_WIDTH):
    """Drive columns alone at (m, n) states: (m, n, 4n)."""
    QD = np.atleast_2d(np.asarray(QD, dtype=np.float64))
    QDD = np.atleast_2d(np.asarray(QDD, dtype=np.float64))
    m, n = QD.shape
    eps = _width(coulomb_width)
    Y = np.zeros((m, n, N_DRIVE * n))
    j = np.arange(n)
    Y[:, j, N_DRIVE * j] = QD
    Y[:, j, N_DRIVE * j + 1] = np.tanh(QD / eps)
    Y[:, j, N_DRIVE * j + 2] = 1.0
    Y[:, j, N_DRIVE * j + 3] = QDD
    return Y


def link_parameters(mass, com, inertia_c):
    """Ten parameters of one link from m, c and the inertia about c."""
    m = float(mass)
    c = np.asarray(com, dtype=np.float64)
    Ic = np.asarray(inertia_c, dtype=np.float64)
    I = Ic + m * (np.dot(c, c) * np.eye(3) - np.outer(c, c))  # noqa: E741
    return np.array([m, m * c[0], m * c[1], m * c[2], I[0, 0], I[0, 1],
                     I[1, 1], I[0, 2], I[1, 2], I[2, 2]])


def link_inertials(pi):
    """
    Mass, centre of mass and inertia about it from ten parameters.

    The inverse of :func:`link_parameters` (for m > 0; c = 0 when m <= 0).
    """
    pi = np.asarray(pi, dtype=np.float64)
    m = float(pi[0])
    h = pi[1:4]
    c = h / m if m > 0 else np.zeros(3)
    I = np.array([[pi[4], pi[5], pi[7]], [pi[5], pi[6], pi[8]],  # noqa: E741
                  [pi[7], pi[8], pi[9]]])
    Ic = I - m * (np.dot(c, c) * np.eye(3) - np.outer(c, c))
    return m, c, Ic


def inertial_parameters(model):
    """Return the model's 10n inertial parameters, link by link."""
    return np.concatenate([
        link_parameters(model.mass[j], model.com[j], model.inertia[j])
        for j in range(model.n)]) if model.n else np.zeros(0)


def pseudo_inertia(pi):
    """4x4 pseudo-inertia [[S, h], [h^T, m]], S = tr(I)/2 1 - I."""
    m, c, Ic = link_inertials(pi)
    pi = np.asarray(pi, dtype=np.float64)
    I = np.array([[pi[4], pi[5], pi[7]], [pi[5], pi[6], pi[8]],  # noqa: E741
                  [pi[7], pi[8], pi[9]]])
    J = np.zeros((4, 4))
    J[:3, :3] = 0.5 * np.trace(I) * np.eye(3) - I
    J[:3, 3] = J[3, :3] = pi[1:4]
    J[3, 3] = pi[0]
    return J


def with_parameters(model, pi):
    """Return a copy of ``model`` with the 10n inertial parameters ``pi``."""
    pi = np.asarray(pi, dtype=np.float64).reshape(model.n, N_INERTIAL)
    mass, com, inertia = [], [], []
    for j in range(model.n):
        m, c, Ic = link_inertials(pi[j])
        mass.append(m)
        com.append(c)
        inertia.append(0.5 * (Ic + Ic.T))
    return model.replace(mass=np.array(mass), com=np.array(com),
                         inertia=np.array(inertia))
