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

``pi`` holds ten inertial parameters per link (per body of a tree: each
moving joint's link with what is fixed to it, ``model.moving_joints``
order, mimic joints' bodies too), in Pinocchio's order
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
along (prismatic) its axis of the wrenches of the links it carries (j and
its descendants; a mimic joint's share goes to its leader's row, times
its multiplier).  The blocks
are carried to frame 0 once, and each joint's share is the product with
its axis as a line (z_j, o_j x z_j): six products per entry, O(n^2)
entries.

Drive columns (``drives=True``: Y is n x (10nb + 4n), the 4n drive
columns after the 10nb inertial ones, four per coordinate j at
10nb + 4j + k; on a model without mimic joints nb = n, 14n columns)::

    k = 0  viscous friction F_v        column qd_j
    k = 1  Coulomb friction F_c        column tanh(qd_j / eps)
    k = 2  constant torque offset      column 1
    k = 3  armature (rotor inertia)    column qdd_j

tanh(qd / eps) is a smooth sign: it is 0 at rest, +-0.76 at |qd| = eps and
within 1e-4 of +-1 from |qd| = 5 eps.  ``eps`` is the Coulomb width,
``COULOMB_WIDTH`` = 0.02 rad/s (or m/s) unless given.

The kernels work in kernel frames (joint axis on z); ``links[j, L_BODY:]``
gives the link frame in kernel frame j (see ``model.compile_arrays``).
The compiled pass is ``kernels/regressor.py`` (``regressor_columns``,
``drive_columns``), called through ``kernels.run_regressor_batch``; this
module checks the inputs and owns the parameter helpers.
"""
import math

import numpy as np

from . import kernels as K
from .errors import DynamicsInputError

N_INERTIAL = 10            # parameters per link
N_DRIVE = 4                # drive parameters per joint
DRIVE_NAMES = ('viscous', 'coulomb', 'offset', 'armature')
INERTIAL_NAMES = ('m', 'mcx', 'mcy', 'mcz', 'Ixx', 'Ixy', 'Iyy', 'Ixz',
                  'Iyz', 'Izz')
COULOMB_WIDTH = 0.02       # rad/s (m/s for a prismatic joint)


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
    """
    Return the number of columns of Y: 10nb, or 10nb + 4n with drives.

    Ten inertial parameters per body (nb moving joints, mimic ones too)
    and four drive parameters per coordinate (n independent joints); on a
    model without mimic joints nb = n.
    """
    return N_INERTIAL * model.nb + (N_DRIVE * model.n if drives else 0)


def _width(eps):
    eps = float(eps)
    if not (eps > 0 and math.isfinite(eps)):
        raise DynamicsInputError(
            f'coulomb_width must be a positive number, got {eps!r}')
    return eps


def regressor_batch(model, Q, QD, QDD, *, drives=False,
                    coulomb_width=COULOMB_WIDTH, out=None):
    """
    Y at each row of the (m, n) states: an (m, n, 10nb) array.

    With ``drives=True`` (m, n, 10nb + 4n): the drive columns follow (see
    the module docstring).  One compiled loop, no Python work per state.
    Columns 10b..10b+9 are the parameters of body b (``model.moving_joints``
    order); a mimic joint's body acts through its leader's row.
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
    nb = max(model.nb, 1)
    ws = np.empty((nb, K.W_WIDTH))
    line = np.empty((nb, 6))
    acc = np.empty((10 * nb, 6))
    status = np.zeros(1, dtype=np.int64)
    row = K.run_regressor_batch(model.packed, Q, QD, QDD, bool(drives), eps,
                                ws, line, acc, out, status)
    if row != -1:       # the row step has no failure: cannot happen
        raise DynamicsInputError(f'regressor kernel refused row {row} '
                                 f'(status {int(status[0])})')
    return out


def regressor(model, q, qd, qdd, *, drives=False,
              coulomb_width=COULOMB_WIDTH):
    """Y(q, qd, qdd) at one state: (n, 10nb), or (n, 10nb + 4n), drives."""
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
    """Return the model's 10nb inertial parameters, body by body."""
    return np.concatenate([
        link_parameters(model.mass[j], model.com[j], model.inertia[j])
        for j in range(model.nb)]) if model.nb else np.zeros(0)


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
    """Return a copy of ``model`` with the 10nb inertial parameters ``pi``."""
    pi = np.asarray(pi, dtype=np.float64).reshape(model.nb, N_INERTIAL)
    mass, com, inertia = [], [], []
    for j in range(model.nb):
        m, c, Ic = link_inertials(pi[j])
        mass.append(m)
        com.append(c)
        inertia.append(0.5 * (Ic + Ic.T))
    return model.replace(mass=np.array(mass), com=np.array(com),
                         inertia=np.array(inertia))
