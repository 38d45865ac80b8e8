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

Every term comes from the compiled kernels of ``_kernels`` (the one
Newton-Euler recursion, and the composite-body and articulated-body
algorithms built on the same model):

==========================  =============================================
:func:`inverse_dynamics`    tau for (q, qd, qdd, F_e); O(n)
:func:`mass_matrix`         D(q), symmetric positive definite; the
                            composite-rigid-body algorithm, or n calls
:func:`coriolis_matrix`     C(q, qd), Christoffel form; O(n^2) from
                            composite bodies, or n calls
:func:`velocity_products`   C(q, qd) qd; one call
:func:`gravity_torques`     g(q), the torque that holds the arm still
:func:`jacobian`            J(q), 6 x n, rows [v; w] of the tool origin
:func:`wrench_torques`      J(q)^T F_e
:func:`forward_dynamics`    qdd from tau; the articulated-body
                            algorithm, O(n), or a Cholesky solve of D
==========================  =============================================

Conventions.  ``F_e = [f; n]`` is the wrench the end effector *exerts on
its environment*, the moment taken about the end-effector origin, in
base-frame axes (``wrench_frame='base'``) or end-effector axes
(``'end_effector'``); it adds ``+J^T F_e`` to tau.  Gravity is
``model.gravity`` in the base frame; ``g(q)`` is the torque the actuators
must apply to hold the arm still.  All matrices are full (not triangular).

Batches.  ``inverse_dynamics_batch``, ``mass_matrix_batch``,
``coriolis_matrix_batch``, ``gravity_torques_batch`` and
``forward_dynamics_batch`` take (m, n) arrays of states and run one
compiled loop over them: no Python work per state.

Cost per call.  The kernels are called through dispatchers compiled for
exactly float64, C-contiguous arrays (``_strict``): such arguments go
straight in, and the kernels check sizes and finiteness themselves and
return a status code.  Anything else (lists, other dtypes, read-only or
strided arrays) is refused by the dispatcher, converted once here, and
the call repeated; bad arguments get the same one-line errors either way.

Examples
--------
>>> from newton_euler_ros.core import (load_robot, inverse_dynamics,
...                                   gravity_torques)
>>> arm = load_robot('planar_2r')
>>> tau = inverse_dynamics(arm, [0.0, 0.0])     # at rest: gravity only
>>> bool(abs(tau[1] - gravity_torques(arm, [0.0, 0.0])[1]) < 1e-15)
True

"""
from numba import njit, types
import numpy as np

from . import _kernels as K
from .errors import DynamicsInputError, NotPositiveDefiniteError
from .workspace import Workspace


_WRENCH_FRAMES = {'base': K.WRENCH_BASE, 'end_effector': K.WRENCH_EE}
_INPUTS = ('q', 'qd', 'qdd', 'wrench')
_FD_INPUTS = ('q', 'qd', 'tau', 'wrench')

# ---------------------------------------------------------------------------
# strict dispatchers: float64 C arrays only, compiled (or loaded from the
# cache) on first use

_F8 = types.float64
_V = types.Array(_F8, 1, 'C')
_M = types.Array(_F8, 2, 'C')
_T = types.Array(_F8, 3, 'C')
_P = types.Array(_F8, 2, 'C', readonly=True)
_I = types.int64
_B = types.boolean


def _strict(name, kernel, *argtypes):
    """
    Return a loader that replaces global ``name`` by a strict dispatcher.

    The dispatcher is compiled for ``argtypes`` only and compiles nothing
    else: other argument types raise TypeError at once, which the callers
    take as the cue to convert their arguments.  It takes the entry
    points' options (``_kernels.ENTRY``): numba's cache does not tell
    compilations of one function with other options apart.
    """
    def load(*args):
        strict = njit(types.int64(*argtypes), **K.ENTRY)(kernel.py_func)
        globals()[name] = strict
        return strict(*args)
    return load


_tau = _strict('_tau', K.run_inverse_dynamics, _P, _V, _V, _V, _V, _I, _M,
               _V)
_gravity = _strict('_gravity', K.run_gravity_torques, _P, _V, _M, _V)
_crba = _strict('_crba', K.run_mass_matrix_crba, _P, _V, _M, _M)
_mass = _strict('_mass', K.run_mass_matrix, _P, _V, _B, _M, _M, _M)
_coriolis = _strict('_coriolis', K.run_coriolis_matrix, _P, _V, _V, _B, _M,
                    _M, _M, _M)
_aba = _strict('_aba', K.run_forward_dynamics, _P, _V, _V, _V, _V, _I, _M,
               _M, _V)
_jac = _strict('_jac', K.run_jacobian, _P, _V, _B, _M, _M, _M)
_poses = _strict('_poses', K.run_link_poses, _P, _V, _M, _M)


# ---------------------------------------------------------------------------
# arguments, conversions and errors

def _workspace(model, ws):
    """Return ``ws`` once checked against the model (None: the default)."""
    if ws is None:
        return model.default_workspace
    if type(ws) is not Workspace or ws.n != model.n \
            or ws.dtype != np.float64:
        raise DynamicsInputError(
            f'ws must be a float64 Workspace for a model of {model.n} '
            f'joints, got {ws!r}')
    return ws


def _vector(name, x, size):
    """Return x as a contiguous float64 vector of the given size, or raise."""
    if (type(x) is np.ndarray and x.dtype == np.float64 and x.ndim == 1
            and x.flags.c_contiguous and x.flags.writeable):
        arr = x
    else:
        try:
            arr = np.array(x, dtype=np.float64)
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


def _out(out, shape, dtype=np.float64):
    """Return a new array of ``shape``, or ``out`` once checked."""
    if out is None:
        return np.empty(shape, dtype)
    if (type(out) is not np.ndarray or out.dtype != dtype
            or out.shape != shape or not out.flags.c_contiguous
            or not out.flags.writeable):
        raise DynamicsInputError(
            f'out must be a writeable, C-contiguous {np.dtype(dtype).name} '
            f'array of shape {shape}, got '
            + (f'{out.dtype} {out.shape}' if isinstance(out, np.ndarray)
               else type(out).__name__))
    return out


def _raise_nonfinite(code, values, precision='float64', names=_INPUTS):
    if code == K.OVERFLOW:
        raise DynamicsInputError(
            f'the result overflows {precision} (inputs too large); nothing '
            f'is returned')
    arg, i = divmod(code, 1000)
    raise DynamicsInputError(
        f'{names[arg]}[{i}] is {float(values[arg][i])!r}; every entry must '
        f'be finite')


def _raise_status(code, values, names=_INPUTS):
    """Raise the error a kernel's status code (>= 0) stands for."""
    if K.SIZE <= code < K.SIZE + 6:
        # sizes are checked in Python before a retry; only a workspace of
        # another size can get here
        raise DynamicsInputError(
            'ws does not fit this model (made for another number of joints)')
    _raise_nonfinite(code, values, names=names)


def _wrench_mode(wrench, wrench_frame):
    if wrench is None:
        return K.WRENCH_NONE
    try:
        return _WRENCH_FRAMES[wrench_frame]
    except KeyError:
        raise DynamicsInputError(
            f"wrench_frame must be 'base' or 'end_effector', "
            f'got {wrench_frame!r}') from None


def _flags(gravity, velocity_products, mode):
    return ((K.GRAVITY if gravity else 0)
            | (K.VELOCITY if velocity_products else 0)
            | (mode << K.WRENCH_SHIFT))


def first_singular_pivot(D, rtol=1e-12):
    """
    Return the first joint where D is not positive definite, or None.

    The Cholesky factorisation of the kernels on D - rtol max|diag D| 1:
    a pivot that is not clearly positive (relative to D's scale) counts.
    """
    D = np.asarray(D, dtype=np.float64)
    n = D.shape[0]
    scale = max(float(np.abs(np.diag(D)).max()), 1e-300) if n else 1.0
    shifted = D - rtol * scale * np.eye(n)
    bad = K.cholesky_solve(shifted, np.zeros(n), np.zeros((n, n)),
                           np.empty(n))
    return None if bad < 0 else int(bad)


def _not_positive_definite(model, q, j, ws):
    """
    Return the NotPositiveDefiniteError for a singular D (first joint).

    The articulated-body algorithm meets the singularity from the tip; the
    joint named is the first one (from the base) at which the leading
    block of D stops being positive definite, as a Cholesky factorisation
    finds it, so both methods name the same joint.
    """
    D = mass_matrix(model, q, ws=ws)
    bad = K.cholesky_solve(D, ws.zeros, ws.chol, np.empty(model.n))
    if bad < 0:
        bad = j
    return NotPositiveDefiniteError(
        f'the mass matrix is not positive definite at joint {bad} '
        f'({model.joint_names[bad]}): no mass or inertia moves with that '
        f'joint given the joints before it', bad)


# ---------------------------------------------------------------------------
# one state

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
        Scratch memory; without it, ``model.default_workspace``.
    out : (n,) float64 array, optional
        Array to write tau into.

    Returns
    -------
    (n,) float64
        N m for revolute and N for prismatic joints.

    """
    # the fast path: no Python checks (the kernel checks sizes and values)
    w = model.default_workspace if ws is None else ws
    flags = (1 if gravity else 0) | (2 if velocity_products else 0)
    if wrench is not None:
        flags |= _wrench_mode(wrench, wrench_frame) << K.WRENCH_SHIFT
    try:
        tau = np.empty(w.n) if out is None else out
        if _tau(model.packed, q, w.zeros if qd is None else qd,
                w.zeros if qdd is None else qdd,
                w.zero_wrench if wrench is None else wrench, flags, w.ws,
                tau) < 0:
            return tau
    except (TypeError, AttributeError):
        pass
    return _rnea_converted(model, ws, q, qd, qdd, wrench, flags, out)


assert (K.GRAVITY, K.VELOCITY) == (1, 2)    # the literals above


def _rnea_converted(model, ws, q, qd, qdd, wrench, flags, out):
    """
    Call the Newton-Euler kernel again, arguments converted and checked.

    Taken when the strict dispatcher refuses an argument's type or the
    kernel reports a problem: every error is raised from here, naming the
    argument and the index.
    """
    ws = _workspace(model, ws)
    n = ws.n
    q = _vector('q', q, n)
    qd = ws.zeros if qd is None else _vector('qd', qd, n)
    qdd = ws.zeros if qdd is None else _vector('qdd', qdd, n)
    wrench = (ws.zero_wrench if wrench is None
              else _vector('wrench', wrench, 6))
    tau = _out(out, (n,))
    bad = _tau(model.packed, q, qd, qdd, wrench, flags, ws.ws, tau)
    if bad >= 0:
        _raise_status(bad, (q, qd, qdd, wrench))
    return tau


def gravity_torques(model, q, *, ws=None, out=None):
    """g(q): the joint torques that hold the arm still against gravity."""
    w = model.default_workspace if ws is None else ws
    try:
        tau = np.empty(w.n) if out is None else out
        if _gravity(model.packed, q, w.ws, tau) < 0:
            return tau
    except (TypeError, AttributeError):
        pass
    return _rnea_converted(model, ws, q, None, None, None, K.GRAVITY, out)


def velocity_products(model, q, qd, *, ws=None, out=None):
    """C(q, qd) qd: Coriolis and centrifugal torques.  One recursion."""
    return inverse_dynamics(model, q, qd, None, gravity=False, ws=ws, out=out)


MASS_MATRIX_METHODS = ('newton_euler', 'crba')
CORIOLIS_METHODS = ('composite', 'newton_euler')
FORWARD_DYNAMICS_METHODS = ('aba', 'cholesky')


def _bad_method(method, methods=MASS_MATRIX_METHODS):
    return ValueError(
        f'method must be one of {", ".join(map(repr, methods))}'
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
    if method == 'crba':
        w = model.default_workspace if ws is None else ws
        try:
            D = np.empty((w.n, w.n)) if out is None else out
            if _crba(model.packed, q, w.ws, D) < 0:
                return D
        except (TypeError, AttributeError):
            pass
    elif method != 'newton_euler':
        raise _bad_method(method)
    ws = _workspace(model, ws)
    n = ws.n
    q = _vector('q', q, n)
    D = _out(out, (n, n))
    bad = _mass(model.packed, q, method == 'crba', ws.ws, ws.scratch, D)
    if bad >= 0:
        _raise_status(bad, (q,))
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


def coriolis_matrix(model, q, qd, *, method='composite', ws=None, out=None):
    """
    Coriolis/centrifugal matrix C(q, qd) built from Christoffel symbols.

    ``C[k, j] = sum_i c_ijk qd_i`` with
    ``c_ijk = (dD_kj/dq_i + dD_ki/dq_j - dD_ij/dq_k) / 2``, so that
    ``Ddot - 2C`` is skew-symmetric and ``C qd`` are the velocity-product
    torques.

    ``method='composite'`` (the default): two O(n) passes over composite
    bodies and 18 multiply-adds per entry, O(n^2) with a small constant
    (``_kernels.coriolis_matrix_composite``).  ``method='newton_euler'``:
    column k from one recursion with the reference velocity e_k (see
    ``_kernels``), n recursions.  The two agree to round-off.
    """
    if method == 'composite':
        composite = True
    elif method == 'newton_euler':
        composite = False
    else:
        raise _bad_method(method, CORIOLIS_METHODS)
    w = model.default_workspace if ws is None else ws
    try:
        C = np.empty((w.n, w.n)) if out is None else out
        if _coriolis(model.packed, q, qd, composite, w.ws, w.cw, w.scratch,
                     C) < 0:
            return C
    except (TypeError, AttributeError):
        pass
    ws = _workspace(model, ws)
    n = ws.n
    q, qd = _vector('q', q, n), _vector('qd', qd, n)
    C = _out(out, (n, n))
    bad = _coriolis(model.packed, q, qd, composite, ws.ws, ws.cw, ws.scratch,
                    C)
    if bad >= 0:
        _raise_status(bad, (q, qd))
    return C


def jacobian(model, q, frame='base', *, ws=None, out=None):
    """
    Geometric Jacobian J(q), (6, n), of the end-effector origin.

    Rows are [linear velocity; angular velocity] such that
    ``[v; w] = J(q) qd``, in base-frame axes (``frame='base'``) or
    end-effector axes (``frame='end_effector'``).  Cost: O(n).
    """
    ws = model.default_workspace if ws is None else _workspace(model, ws)
    if frame not in _WRENCH_FRAMES:
        raise DynamicsInputError(
            f"frame must be 'base' or 'end_effector', got {frame!r}")
    n = ws.n
    q = _vector('q', q, n)
    J = _out(out, (6, n))
    bad = _jac(model.packed, q, frame == 'end_effector', ws.ws, ws.frames, J)
    if bad >= 0:
        _raise_status(bad, (q,))
    return J


def wrench_torques(model, q, wrench, wrench_frame='base', *, ws=None):
    """
    J(q)^T F_e: the joint forces that balance an end-effector wrench.

    Computed from the Jacobian (virtual work); :func:`inverse_dynamics`
    applies the same wrench as f_{n+1}, tau_{n+1} in its backward pass, and
    the two agree to round-off.
    """
    F = _vector('wrench', wrench, 6)
    i = K.first_nonfinite(F)
    if i >= 0:
        _raise_nonfinite(3000 + i, (None, None, None, F))
    J = jacobian(model, q, wrench_frame, ws=ws)
    return J.T @ F


def _poses_array(model, q, ws):
    ws = model.default_workspace if ws is None else _workspace(model, ws)
    q = _vector('q', q, ws.n)
    bad = _poses(model.packed, q, ws.ws, ws.frames)
    if bad >= 0:
        _raise_status(bad, (q,))
    return ws.frames


def end_effector_pose(model, q, *, ws=None):
    """4x4 pose of the end-effector frame in the base frame."""
    frames = _poses_array(model, q, ws)
    T = np.eye(4)
    T[:3, :3] = frames[-1, :9].reshape(3, 3)
    T[:3, 3] = frames[-1, 9:]
    return T


def link_poses(model, q, *, ws=None):
    """
    Poses of frames 0..n and of the end effector in the base frame.

    Returns an (n + 2, 4, 4) array of homogeneous transforms.
    """
    frames = _poses_array(model, q, ws)
    T = np.zeros((frames.shape[0], 4, 4))
    T[:, :3, :3] = frames[:, :9].reshape(-1, 3, 3)
    T[:, :3, 3] = frames[:, 9:]
    T[:, 3, 3] = 1.0
    return T


def forward_dynamics(model, q, qd, tau, wrench=None, wrench_frame='base', *,
                     method='aba', gravity=True, velocity_products=True,
                     ws=None, out=None):
    """
    Joint accelerations: solve D(q) qdd = tau - C qd - g - J^T F_e.

    ``method='aba'`` (the default): the articulated-body algorithm, O(n),
    without forming D (``_kernels.articulated_body``).
    ``method='cholesky'``: D by CRBA and a Cholesky factorisation of it
    (never an explicit inverse), O(n^3).  The two agree to round-off
    (relative to the conditioning of D).  Either raises
    :class:`NotPositiveDefiniteError` naming the first joint at which D
    is not positive definite (a joint that moves no mass or inertia).
    """
    flags = (1 if gravity else 0) | (2 if velocity_products else 0)
    if wrench is not None:
        flags |= _wrench_mode(wrench, wrench_frame) << K.WRENCH_SHIFT
    if method == 'aba':
        w = model.default_workspace if ws is None else ws
        try:
            qdd = np.empty(w.n) if out is None else out
            if _aba(model.packed, q, qd, tau,
                    w.zero_wrench if wrench is None else wrench, flags,
                    w.ws, w.aw, qdd) < 0:
                return qdd
        except (TypeError, AttributeError):
            pass
        return _aba_converted(model, ws, q, qd, tau, wrench, flags, out)
    if method != 'cholesky':
        raise _bad_method(method, FORWARD_DYNAMICS_METHODS)
    ws = _workspace(model, ws)
    n = ws.n
    q, qd, tau = (_vector('q', q, n), _vector('qd', qd, n),
                  _vector('tau', tau, n))
    i = K.first_nonfinite(tau)
    if i >= 0:
        _raise_nonfinite(2000 + i, (q, qd, tau), names=_FD_INPUTS)
    qdd = _out(out, (n,))
    bias = inverse_dynamics(model, q, qd, None, wrench, wrench_frame,
                            gravity=gravity,
                            velocity_products=velocity_products, ws=ws)
    return solve_mass_matrix(model, q, mass_matrix(model, q, ws=ws),
                             tau - bias, ws=ws, out=qdd)


def solve_mass_matrix(model, q, D, rhs, *, ws=None, out=None):
    """
    Solve D x = rhs by Cholesky; D is the mass matrix at q.

    D may carry a rotor inertia on its diagonal.  Raises
    :class:`NotPositiveDefiniteError` naming the first joint where D is not
    positive definite.  The Cholesky path of :func:`forward_dynamics` and
    the simulator's forward dynamics.
    """
    ws = _workspace(model, ws)
    x = _out(out, (ws.n,))
    bad = K.cholesky_solve(D, np.ascontiguousarray(rhs, dtype=np.float64),
                           ws.chol, x)
    if bad >= 0:
        raise _not_positive_definite(model, q, bad, ws)
    return x


def _aba_converted(model, ws, q, qd, tau, wrench, flags, out):
    """Call the articulated-body kernel again, arguments converted."""
    ws = _workspace(model, ws)
    n = ws.n
    q, qd, tau = (_vector('q', q, n), _vector('qd', qd, n),
                  _vector('tau', tau, n))
    w = ws.zero_wrench if wrench is None else _vector('wrench', wrench, 6)
    qdd = _out(out, (n,))
    bad = _aba(model.packed, q, qd, tau, w, flags, ws.ws, ws.aw, qdd)
    if bad >= K.SINGULAR:
        raise _not_positive_definite(model, q, bad - K.SINGULAR, ws)
    if bad >= 0:
        _raise_status(bad, (q, qd, tau, w), _FD_INPUTS)
    return qdd


# ---------------------------------------------------------------------------
# batches of states

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
    if not X.flags.writeable:
        X = X.copy()
    bad = np.argwhere(~np.isfinite(X))
    if bad.size:
        r, c = bad[0]
        raise DynamicsInputError(
            f'{name}[{r}, {c}] is {float(X[r, c])!r}; every entry must be '
            f'finite')
    return X


def _batch_states(model, ws, Q, QD, name_qd='QD'):
    ws = model.default_workspace if ws is None else _workspace(model, ws)
    Q = _matrix('Q', Q, ws.n)
    QD = None if QD is None else _matrix(name_qd, QD, ws.n, Q.shape[0])
    return ws, Q, QD


def _batch_wrenches(W, wrench_frame, m):
    if W is None:
        return np.zeros((m, 6)), K.WRENCH_NONE
    return _matrix('W', W, 6, m), _wrench_mode(W, wrench_frame)


def _batch_failed(row, code, label):
    if code == K.OVERFLOW:
        raise DynamicsInputError(
            f'the result for row {row} overflows float64 (inputs too '
            f'large); nothing is returned')
    raise DynamicsInputError(f'{label} failed at row {row} (code {code})')


def inverse_dynamics_batch(model, Q, QD=None, QDD=None, W=None,
                           wrench_frame='base', *, gravity=True,
                           velocity_products=True, ws=None, out=None):
    """
    :func:`inverse_dynamics` for each row of (m, n) arrays of states.

    ``W`` is an (m, 6) array of wrenches or None.  Returns (m, n).  One
    compiled loop: no Python work per state.
    """
    ws, Q, QD = _batch_states(model, ws, Q, QD)
    m = Q.shape[0]
    QD = np.zeros_like(Q) if QD is None else QD
    QDD = np.zeros_like(Q) if QDD is None else _matrix('QDD', QDD, ws.n, m)
    W, mode = _batch_wrenches(W, wrench_frame, m)
    TAU = _out(out, Q.shape)
    row = K.run_inverse_dynamics_batch(
        model.packed, Q, QD, QDD, W, _flags(gravity, velocity_products, mode),
        ws.ws, TAU, ws.status)
    if row >= 0:
        _batch_failed(row, ws.status[0], 'inverse dynamics')
    return TAU


def gravity_torques_batch(model, Q, *, ws=None, out=None):
    """:func:`gravity_torques` for each row of an (m, n) array; (m, n)."""
    ws, Q, _ = _batch_states(model, ws, Q, None)
    G = _out(out, Q.shape)
    row = K.run_gravity_torques_batch(model.packed, Q, ws.ws, G, ws.status)
    if row >= 0:
        _batch_failed(row, ws.status[0], 'the gravity torques')
    return G


def mass_matrix_batch(model, Q, *, ws=None, out=None):
    """:func:`mass_matrix` (CRBA) for each row of Q; returns (m, n, n)."""
    ws, Q, _ = _batch_states(model, ws, Q, None)
    DD = _out(out, (Q.shape[0], ws.n, ws.n))
    row = K.run_mass_matrix_batch(model.packed, Q, ws.ws, DD, ws.status)
    if row >= 0:
        _batch_failed(row, ws.status[0], 'the mass matrix')
    return DD


def coriolis_matrix_batch(model, Q, QD, *, ws=None, out=None):
    """:func:`coriolis_matrix` (composite) for each row; (m, n, n)."""
    ws, Q, QD = _batch_states(model, ws, Q, QD)
    QD = np.zeros_like(Q) if QD is None else QD
    CC = _out(out, (Q.shape[0], ws.n, ws.n))
    row = K.run_coriolis_matrix_batch(model.packed, Q, QD, ws.ws, ws.cw, CC,
                                      ws.status)
    if row >= 0:
        _batch_failed(row, ws.status[0], 'the Coriolis matrix')
    return CC


def forward_dynamics_batch(model, Q, QD, TAU, W=None, wrench_frame='base', *,
                           gravity=True, velocity_products=True, ws=None,
                           out=None):
    """
    :func:`forward_dynamics` (articulated-body) for each row; (m, n).

    Raises :class:`NotPositiveDefiniteError` for the first row where D is
    singular, naming the row and the joint.
    """
    ws, Q, QD = _batch_states(model, ws, Q, QD)
    m = Q.shape[0]
    QD = np.zeros_like(Q) if QD is None else QD
    TAU = _matrix('TAU', TAU, ws.n, m)
    W, mode = _batch_wrenches(W, wrench_frame, m)
    QDD = _out(out, Q.shape)
    row = K.run_forward_dynamics_batch(
        model.packed, Q, QD, TAU, W, _flags(gravity, velocity_products, mode),
        ws.ws, ws.aw, QDD, ws.status)
    if row >= 0:
        code = int(ws.status[0])
        if code >= K.SINGULAR:
            err = _not_positive_definite(model, Q[row], code - K.SINGULAR,
                                         ws)
            raise NotPositiveDefiniteError(f'row {row}: {err}', err.joint)
        _batch_failed(row, code, 'forward dynamics')
    return QDD
