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
Rigid-body dynamics of a serial chain, one function per equation term.

The equation of motion is

    D(q) qdd + C(q, qd) qd + g(q) + J(q)^T F_e = tau        (seed eq. 23)

Every term comes from the one Newton-Euler recursion in ``_kernels``:

==========================  =============================================
:func:`inverse_dynamics`    tau for (q, qd, qdd, F_e); O(n)
:func:`mass_matrix`         D(q), symmetric positive definite; the
                            composite-rigid-body algorithm, or n calls
:func:`coriolis_matrix`     C(q, qd), Christoffel form; n calls
:func:`velocity_products`   C(q, qd) qd; one call
:func:`gravity_torques`     g(q), the torque that holds the arm still
:func:`jacobian`            J(q), 6 x n, rows [v; w] of the tool origin
:func:`wrench_torques`      J(q)^T F_e
:func:`forward_dynamics`    qdd from tau by a Cholesky solve
==========================  =============================================

Conventions.  ``F_e = [f; n]`` is the wrench the end effector *exerts on
its environment*, the moment taken about the end-effector origin, in
base-frame axes (``wrench_frame='base'``) or end-effector axes
(``'end_effector'``); it adds ``+J^T F_e`` to tau.  Gravity is
``model.gravity`` in the base frame; ``g(q)`` is the torque the actuators
must apply to hold the arm still.  All matrices are full (not triangular).

Examples
--------
>>> from newton_euler_ros.core import (load_robot, inverse_dynamics,
...                                   gravity_torques)
>>> arm = load_robot('planar_2r')
>>> tau = inverse_dynamics(arm, [0.0, 0.0])     # at rest: gravity only
>>> bool(abs(tau[1] - gravity_torques(arm, [0.0, 0.0])[1]) < 1e-15)
True

"""
import weakref

import numpy as np

from . import _kernels as K
from .errors import DynamicsInputError, NotPositiveDefiniteError

_WRENCH_FRAMES = {'base': K.WRENCH_BASE, 'end_effector': K.WRENCH_EE}
_ARG_NAMES = ('q', 'qd', 'qdd', 'wrench')


class Workspace:
    """
    Preallocated scratch memory for one model; reuse it across calls.

    Not thread-safe: give each thread its own.  Every dynamics function
    takes ``ws=``; without it, a workspace cached on the model is used.
    """

    def __init__(self, model):
        n = model.n
        self.n = n
        self.ws = np.zeros((n, K.W_WIDTH))
        self.scratch = np.zeros((3, n))
        self.frames = np.zeros((n + 2, 12))
        self.chol = np.zeros((n, n))
        self.zeros = np.zeros(n)
        self.zero_wrench = np.zeros(6)


_workspaces = weakref.WeakKeyDictionary()


def _default_ws(model):
    ws = _workspaces.get(model)
    if ws is None:
        ws = _workspaces[model] = Workspace(model)
    return ws


def _vector(name, x, size):
    """Return x as a contiguous float64 vector of the given size, or raise."""
    if (type(x) is np.ndarray and x.dtype == np.float64 and x.ndim == 1
            and x.flags.c_contiguous):
        arr = x
    else:
        try:
            arr = np.ascontiguousarray(x, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise DynamicsInputError(
                f'{name} must be a sequence of {size} numbers: {exc}') from None
        if arr.ndim != 1:
            raise DynamicsInputError(
                f'{name} must be a vector of {size} numbers, '
                f'got shape {arr.shape}')
    if arr.shape[0] != size:
        raise DynamicsInputError(
            f'{name} must have {size} entries, got {arr.shape[0]}')
    return arr


def _raise_nonfinite(code, values, precision='float64'):
    if code == K.OVERFLOW:
        raise DynamicsInputError(
            f'the result overflows {precision} (inputs too large); nothing '
            f'is returned')
    arg, i = divmod(code, 1000)
    name = _ARG_NAMES[arg]
    raise DynamicsInputError(
        f'{name}[{i}] is {float(values[arg][i])!r}; every entry must be finite')


def _finite_result(x):
    """Return x, or raise if finite inputs overflowed float64 in it."""
    if not np.isfinite(x).all():
        _raise_nonfinite(K.OVERFLOW, ())
    return x


def _check_finite(q, qd, qdd, wrench):
    bad = K.check_finite(q, qd, qdd, wrench)
    if bad >= 0:
        _raise_nonfinite(bad, (q, qd, qdd, wrench))


def _wrench_args(wrench, wrench_frame, ws):
    if wrench is None:
        return ws.zero_wrench, K.WRENCH_NONE
    try:
        mode = _WRENCH_FRAMES[wrench_frame]
    except KeyError:
        raise DynamicsInputError(
            f"wrench_frame must be 'base' or 'end_effector', "
            f'got {wrench_frame!r}') from None
    return _vector('wrench', wrench, 6), mode


def inverse_dynamics(model, q, qd=None, qdd=None, wrench=None,
                     wrench_frame='base', *, gravity=True,
                     velocity_products=True, ws=None, out=None):
    """
    Joint forces tau = D qdd + C qd + g + J^T F_e, by Newton-Euler.

    Cost: one forward and one backward pass, O(n).

    Parameters
    ----------
    model : RobotModel
        The robot.
    q, qd, qdd : (n,) array_like
        Joint positions, velocities, accelerations (rad or m, and their
        rates); ``None`` (the default for qd and qdd) means zeros.
    wrench : (6,) array_like or None
        [f; n], N and N m, exerted by the end effector.
    wrench_frame : str
        ``'base'`` or ``'end_effector'``: the axes of ``wrench``.
    gravity, velocity_products : bool
        Set False to leave that term out (it is then not computed at all).
    ws : Workspace, optional
        Scratch memory; without it, the workspace cached on the model.
    out : (n,) array, optional
        Array to write tau into.

    Returns
    -------
    (n,) float64
        N m for revolute and N for prismatic joints.

    """
    ws = ws or _default_ws(model)
    n = ws.n
    q = _vector('q', q, n)
    qd = ws.zeros if qd is None else _vector('qd', qd, n)
    qdd = ws.zeros if qdd is None else _vector('qdd', qdd, n)
    w, mode = _wrench_args(wrench, wrench_frame, ws)
    tau = np.empty(n) if out is None else out
    bad = K.inverse_dynamics(model.links_array, model.frames_array, q, qd,
                             qdd, w, gravity, velocity_products, mode,
                             ws.ws, tau)
    if bad >= 0:
        _raise_nonfinite(bad, (q, qd, qdd, w))
    return tau


def inverse_dynamics_batch(model, Q, QD=None, QDD=None, W=None,
                           wrench_frame='base', *, gravity=True,
                           velocity_products=True, ws=None, out=None):
    """
    :func:`inverse_dynamics` for each row of (m, n) arrays of states.

    ``W`` is an (m, 6) array of wrenches or None.  Returns (m, n).  One
    compiled loop: no Python work per state.
    """
    ws = ws or _default_ws(model)
    n = ws.n
    Q = _matrix('Q', Q, n)
    m = Q.shape[0]
    QD = np.zeros_like(Q) if QD is None else _matrix('QD', QD, n, m)
    QDD = np.zeros_like(Q) if QDD is None else _matrix('QDD', QDD, n, m)
    if W is None:
        W, mode = np.zeros((m, 6)), K.WRENCH_NONE
    else:
        W, mode = _matrix('W', W, 6, m), _WRENCH_FRAMES.get(wrench_frame)
        if mode is None:
            raise DynamicsInputError(
                f"wrench_frame must be 'base' or 'end_effector', "
                f'got {wrench_frame!r}')
    for name, X in (('Q', Q), ('QD', QD), ('QDD', QDD), ('W', W)):
        bad = np.argwhere(~np.isfinite(X))
        if bad.size:
            r, c = bad[0]
            raise DynamicsInputError(
                f'{name}[{r}, {c}] is {float(X[r, c])!r}; every entry must be finite')
    TAU = np.empty((m, n)) if out is None else out
    K.inverse_dynamics_batch(model.links_array, model.frames_array, Q, QD,
                             QDD, W, gravity, velocity_products, mode, ws.ws,
                             TAU)
    return _finite_result(TAU)


def _matrix(name, X, cols, rows=None):
    try:
        X = np.ascontiguousarray(X, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise DynamicsInputError(f'{name} must be numeric: {exc}') from None
    if X.ndim != 2 or X.shape[1] != cols or (rows is not None
                                             and X.shape[0] != rows):
        want = f'({rows if rows is not None else "m"}, {cols})'
        raise DynamicsInputError(
            f'{name} must have shape {want}, got {X.shape}')
    return X


MASS_MATRIX_METHODS = ('newton_euler', 'crba')


def _bad_method(method):
    return ValueError(
        f'method must be one of {", ".join(map(repr, MASS_MATRIX_METHODS))}'
        f', got {method!r}')


def mass_matrix(model, q, *, method='crba', ws=None, out=None):
    """
    Joint-space inertia matrix D(q), (n, n), symmetric positive definite.

    ``method='crba'`` (the default): the composite-rigid-body algorithm
    (``_kernels.mass_matrix_crba``), O(n^2) with a small constant and
    symmetric by construction.  ``method='newton_euler'``: column k is the
    Newton-Euler torque for qdd = e_k with no velocity and no gravity; n
    recursions, O(n^2) with a larger constant, then averaged with its
    transpose.  The two agree to round-off (within 10 n eps relative in
    the tests; ``make accuracy`` measures both against 50-digit truth and
    times them).  Any other ``method`` raises ValueError.
    """
    ws = ws or _default_ws(model)
    q = _vector('q', q, ws.n)
    _check_finite(q, ws.zeros, ws.zeros, ws.zero_wrench)
    D = np.empty((ws.n, ws.n)) if out is None else out
    if method == 'crba':
        bad = K.mass_matrix_crba(model.links_array, model.frames_array, q,
                                 ws.ws, D)
    elif method == 'newton_euler':
        bad = K.mass_matrix(model.links_array, model.frames_array, q, ws.ws,
                            ws.scratch, D)
    else:
        raise _bad_method(method)
    if bad >= 0:
        _raise_nonfinite(K.OVERFLOW, ())
    return D


def mass_matrix_condition(model, q, *, ws=None):
    """
    Return the 2-norm condition number of D(q), lambda_max / lambda_min.

    It bounds how much a relative error in the torques can grow in the
    accelerations of :func:`forward_dynamics`; ``inf`` when D is singular.
    Cost: D plus a symmetric eigenvalue solve, O(n^3).
    """
    eig = np.linalg.eigvalsh(mass_matrix(model, q, ws=ws))
    return float(eig[-1] / eig[0]) if eig[0] > 0.0 else float('inf')


def coriolis_matrix(model, q, qd, *, ws=None, out=None):
    """
    Coriolis/centrifugal matrix C(q, qd) built from Christoffel symbols.

    ``C[k, j] = sum_i c_ijk qd_i`` with
    ``c_ijk = (dD_kj/dq_i + dD_ki/dq_j - dD_ij/dq_k) / 2``, so that
    ``Ddot - 2C`` is skew-symmetric and ``C qd`` are the velocity-product
    torques.  Column k comes from one recursion with the reference
    velocity e_k (see ``_kernels``).  Cost: n recursions, O(n^2).
    """
    ws = ws or _default_ws(model)
    q = _vector('q', q, ws.n)
    qd = _vector('qd', qd, ws.n)
    _check_finite(q, qd, ws.zeros, ws.zero_wrench)
    C = np.empty((ws.n, ws.n)) if out is None else out
    if K.coriolis_matrix(model.links_array, model.frames_array, q, qd,
                         ws.ws, ws.scratch, C) >= 0:
        _raise_nonfinite(K.OVERFLOW, ())
    return C


def velocity_products(model, q, qd, *, ws=None, out=None):
    """C(q, qd) qd: Coriolis and centrifugal torques.  One recursion."""
    return inverse_dynamics(model, q, qd, None, gravity=False, ws=ws, out=out)


def gravity_torques(model, q, *, ws=None, out=None):
    """g(q): the joint torques that hold the arm still against gravity."""
    return inverse_dynamics(model, q, velocity_products=False, ws=ws,
                            out=out)


def jacobian(model, q, frame='base', *, ws=None, out=None):
    """
    Geometric Jacobian J(q), (6, n), of the end-effector origin.

    Rows are [linear velocity; angular velocity] such that
    ``[v; w] = J(q) qd``, in base-frame axes (``frame='base'``) or
    end-effector axes (``frame='end_effector'``).  Cost: O(n).
    """
    ws = ws or _default_ws(model)
    q = _vector('q', q, ws.n)
    _check_finite(q, ws.zeros, ws.zeros, ws.zero_wrench)
    if frame not in _WRENCH_FRAMES:
        raise DynamicsInputError(
            f"frame must be 'base' or 'end_effector', got {frame!r}")
    J = np.empty((6, ws.n)) if out is None else out
    K.jacobian(model.links_array, model.frames_array, q,
               frame == 'end_effector', ws.ws, ws.frames, J)
    return J


def wrench_torques(model, q, wrench, wrench_frame='base', *, ws=None):
    """
    J(q)^T F_e: the joint forces that balance an end-effector wrench.

    Computed from the Jacobian (virtual work); :func:`inverse_dynamics`
    applies the same wrench as f_{n+1}, tau_{n+1} in its backward pass, and
    the two agree to round-off.
    """
    ws = ws or _default_ws(model)
    F = _vector('wrench', wrench, 6)
    _check_finite(ws.zeros, ws.zeros, ws.zeros, F)
    J = jacobian(model, q, wrench_frame, ws=ws)
    return J.T @ F


def end_effector_pose(model, q, *, ws=None):
    """4x4 pose of the end-effector frame in the base frame."""
    ws = ws or _default_ws(model)
    q = _vector('q', q, ws.n)
    _check_finite(q, ws.zeros, ws.zeros, ws.zero_wrench)
    K.forward_kinematics(model.links_array, model.frames_array, q, ws.ws,
                         ws.frames)
    T = np.eye(4)
    T[:3, :3] = ws.frames[-1, :9].reshape(3, 3)
    T[:3, 3] = ws.frames[-1, 9:]
    return T


def link_poses(model, q, *, ws=None):
    """
    Poses of frames 0..n and of the end effector in the base frame.

    Returns an (n + 2, 4, 4) array of homogeneous transforms.
    """
    ws = ws or _default_ws(model)
    q = _vector('q', q, ws.n)
    _check_finite(q, ws.zeros, ws.zeros, ws.zero_wrench)
    K.forward_kinematics(model.links_array, model.frames_array, q, ws.ws,
                         ws.frames)
    T = np.zeros((ws.n + 2, 4, 4))
    T[:, :3, :3] = ws.frames[:, :9].reshape(-1, 3, 3)
    T[:, :3, 3] = ws.frames[:, 9:]
    T[:, 3, 3] = 1.0
    return T


def forward_dynamics(model, q, qd, tau, wrench=None, wrench_frame='base', *,
                     gravity=True, velocity_products=True, ws=None):
    """
    Joint accelerations: solve D(q) qdd = tau - C qd - g - J^T F_e.

    Uses a Cholesky factorisation of D, never an explicit inverse.  Raises
    :class:`NotPositiveDefiniteError` naming the joint where D is not
    positive definite.  Cost: O(n^2) for D plus O(n^3 / 6) for the solve.
    """
    ws = ws or _default_ws(model)
    n = ws.n
    tau = _vector('tau', tau, n)
    i = K.first_nonfinite(tau)
    if i >= 0:
        raise DynamicsInputError(
            f'tau[{i}] is {float(tau[i])!r}; every entry must be finite')
    bias = inverse_dynamics(model, q, qd, None, wrench, wrench_frame,
                            gravity=gravity,
                            velocity_products=velocity_products, ws=ws)
    D = mass_matrix(model, q, ws=ws)
    rhs = tau - bias
    qdd = np.empty(n)
    bad = K.cholesky_solve(D, rhs, ws.chol, qdd)
    if bad >= 0:
        name = model.joint_names[bad]
        raise NotPositiveDefiniteError(
            f'the mass matrix is not positive definite at joint {bad} '
            f'({name}): no mass or inertia moves with that joint given '
            f'the joints before it', bad)
    return qdd
