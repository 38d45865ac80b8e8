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

Every term comes from the compiled kernels of ``kernels`` (the one
Newton-Euler recursion, and the composite-body and articulated-body
algorithms built on the same model; ``docs/how-it-is-computed.md`` maps
each to its file):

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

Cost per call.  Each function calls a *strict entry* of its kernel
(registered below, one line per term): a dispatcher compiled for exactly
float64, C-contiguous arrays, so such arguments go straight in and the
kernel checks sizes and finiteness itself, returning a status code.
Lists (and, for tau, g and forward dynamics, arrays of another dtype)
are converted once before the call; anything else numba's dispatcher
does not take (a read-only or strided array) is refused by it (its
TypeError), then converted once and the call made again; every error is decoded in
one place (``calling.status_error``).
See :mod:`newton_euler_ros.core.calling`.

Examples
--------
>>> from newton_euler_ros.core import (load_robot, inverse_dynamics,
...                                   gravity_torques)
>>> arm = load_robot('planar_2r')
>>> tau = inverse_dynamics(arm, [0.0, 0.0])     # at rest: gravity only
>>> bool(abs(tau[1] - gravity_torques(arm, [0.0, 0.0])[1]) < 1e-15)
True

"""
import numpy as np

from . import kernels as K
from .batch import (coriolis_matrix_batch, forward_dynamics_batch,
                    gravity_torques_batch, inverse_dynamics_batch,
                    mass_matrix_batch)
from .calling import (ARRAY, bad_method, BOOL, CORIOLIS_METHODS, EMPTY, F64,
                      FD_INPUTS, first_singular_pivot, foreign_workspace,
                      FORWARD_DYNAMICS_METHODS, INPUTS, inputs, INT,
                      MASS_MATRIX_METHODS, MAT, not_positive_definite,
                      out_array, PACKED, slow_inputs, status_error,
                      strict_entry, VEC, vector, workspace, wrench_mode)
from .frames import (end_effector_pose, frame_pose, jacobian, link_poses,
                     link_wrench_rows, wrench_torques)
from .workspace import Workspace

__all__ = [
    'CORIOLIS_METHODS', 'FORWARD_DYNAMICS_METHODS', 'MASS_MATRIX_METHODS',
    'coriolis_matrix', 'coriolis_matrix_batch', 'end_effector_pose',
    'first_singular_pivot', 'forward_dynamics', 'forward_dynamics_batch',
    'frame_pose',
    'gravity_torques', 'gravity_torques_batch', 'inverse_dynamics',
    'inverse_dynamics_batch', 'jacobian', 'link_poses', 'mass_matrix',
    'mass_matrix_batch', 'mass_matrix_condition', 'solve_mass_matrix',
    'velocity_products', 'wrench_torques',
]

# ---------------------------------------------------------------------------
# the strict entries: one registration per kernel entry point (argument
# types as the entry point takes them; see calling.strict_entry).  Each
# name is rebound here to its numba dispatcher on its first call.

_tau = strict_entry(K.run_inverse_dynamics, PACKED, VEC, VEC, VEC, VEC, INT,
                    MAT, VEC, home=globals())
_gravity = strict_entry(K.run_gravity_torques, PACKED, VEC, MAT, VEC,
                        home=globals())
_crba = strict_entry(K.run_mass_matrix_crba, PACKED, VEC, MAT, MAT,
                     home=globals())
_mass = strict_entry(K.run_mass_matrix, PACKED, VEC, BOOL, MAT, MAT, MAT,
                     home=globals())
_coriolis = strict_entry(K.run_coriolis_matrix, PACKED, VEC, VEC, BOOL, MAT,
                         MAT, MAT, MAT, home=globals())
_aba = strict_entry(K.run_forward_dynamics, PACKED, VEC, VEC, VEC, VEC, INT,
                    MAT, MAT, VEC, home=globals())
_tau_links = strict_entry(K.run_inverse_dynamics_links, PACKED, VEC, VEC,
                          VEC, VEC, MAT, INT, MAT, VEC, home=globals())
_aba_links = strict_entry(K.run_forward_dynamics_links, PACKED, VEC, VEC,
                          VEC, VEC, MAT, INT, MAT, MAT, VEC, home=globals())

assert (K.GRAVITY, K.VELOCITY, K.WRENCH_SHIFT) == (1, 2, 2)  # literals below


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
    wrench : (6,) array_like, dict or None
        [f; n], N and N m, exerted by the end effector; or wrenches at
        links, ``{frame name: [f; n]}`` (several at once: a force-torque
        sensor at each wrist), each exerted by that frame on its
        environment, the moment about its origin (see
        :mod:`~newton_euler_ros.core.frames`).
    wrench_frame : str or dict
        ``'base'`` or ``'end_effector'``: the axes of an end-effector
        ``wrench``; for wrenches at links ``'base'`` or ``'link'`` (the
        frame's own axes), for all, or a dict per frame name (default
        ``'base'``).
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
    w = model.default_workspace if ws is None else ws
    flags = 3 if gravity is True and velocity_products is True else (
        (1 if gravity else 0) | (2 if velocity_products else 0))
    if wrench is not None:
        if type(wrench) is dict:
            return _tau_at_links(model, ws, q, qd, qdd, wrench, wrench_frame,
                                 flags, out)
        flags |= wrench_mode(wrench, wrench_frame) << 2
    if type(q) is not ARRAY or q.dtype is not F64 or (
            wrench is not None and type(wrench) is not ARRAY):
        # lists, int arrays: converted at once, not tried first
        return _tau_converted(model, ws, q, qd, qdd, wrench, flags, out)
    try:
        tau = EMPTY(w.n) if out is None else out
        if _tau(model.packed, q, w.zeros if qd is None else qd,
                w.zeros if qdd is None else qdd,
                w.zero_wrench if wrench is None else wrench, flags, w.ws,
                tau) < 0:
            return tau
    except (TypeError, AttributeError) as exc:
        _fast_call_failed(exc, model, ws, (q, qd, qdd, wrench))
    return _tau_converted(model, ws, q, qd, qdd, wrench, flags, out)


def _fast_call_failed(exc, model, ws, values=(), names=INPUTS):
    """
    Settle what a fast entry raised: return, or raise the right error.

    numba's TypeError (an argument of another type: a read-only or
    strided array, a ``ws`` or ``out`` of another dtype) returns: the
    caller converts its arguments and calls again, for the error that
    names them.  An AttributeError is a ``ws`` that is not a Workspace (its
    one-line error), or else a bug, raised as it is.  Only the failing
    call comes here: the fast path costs no call more.
    """
    if not isinstance(exc, TypeError):
        foreign_workspace(model, ws)
        raise exc
    slow_inputs(values, names, stacklevel=4)


def _tau_converted(model, ws, q, qd, qdd, wrench, flags, out):
    """
    Call the Newton-Euler entry again, its arguments converted once.

    A given ``ws`` and ``out`` go in as they are (the entry refuses
    another type, the kernel another size); only then are they checked
    here, for the error that names them.
    """
    ws = model.default_workspace if ws is None else (
        ws if type(ws) is Workspace and ws.n == model.n
        and ws.nb == model.nb else workspace(model, ws))
    n = ws.n
    q, qd, qdd, wrench = inputs(ws, INPUTS, q, qd, qdd, wrench)
    tau = EMPTY(n) if out is None else out
    try:
        code = _tau(model.packed, q, qd, qdd, wrench, flags, ws.ws, tau)
    except TypeError:
        code = K.SIZE
    if code >= K.SIZE:      # another dtype or size of ws or out: say which
        workspace(model, ws)
        tau = out_array(out, (n,))
        code = _tau(model.packed, q, qd, qdd, wrench, flags, ws.ws, tau)
    if code >= 0:
        raise status_error(code, (q, qd, qdd, wrench))
    return tau


def _tau_at_links(model, ws, q, qd, qdd, wrenches, wrench_frame, flags,
                  out):
    """Newton-Euler with wrenches at links (``kernels`` ``fext`` rows)."""
    ws = workspace(model, ws)
    n = ws.n
    q = vector('q', q, n)
    qd = ws.zeros if qd is None else vector('qd', qd, n)
    qdd = ws.zeros if qdd is None else vector('qdd', qdd, n)
    fext = link_wrench_rows(model, q, wrenches, wrench_frame, ws)
    tau = out_array(out, (n,))
    code = _tau_links(model.packed, q, qd, qdd, ws.zero_wrench, fext,
                      flags | K.LINK_WRENCHES, ws.ws, tau)
    if code >= 0:
        raise status_error(code, (q, qd, qdd))
    return tau


def gravity_torques(model, q, *, ws=None, out=None):
    """g(q): the joint torques that hold the arm still against gravity."""
    w = model.default_workspace if ws is None else ws
    if type(q) is not ARRAY or q.dtype is not F64:
        # a list, an int array: converted at once, not tried first
        ws = workspace(model, ws)
        q = inputs(ws, INPUTS, q)[0]
        tau = out_array(out, (ws.n,))
        code = _gravity(model.packed, q, ws.ws, tau)
        if code >= 0:
            raise status_error(code, (q,))
        return tau
    try:
        tau = EMPTY(w.n) if out is None else out
        if _gravity(model.packed, q, w.ws, tau) < 0:
            return tau
    except (TypeError, AttributeError) as exc:
        _fast_call_failed(exc, model, ws, (q,))
    return _tau_converted(model, ws, q, None, None, None, K.GRAVITY, out)


def velocity_products(model, q, qd, *, ws=None, out=None):
    """C(q, qd) qd: Coriolis and centrifugal torques.  One recursion."""
    return inverse_dynamics(model, q, qd, None, gravity=False, ws=ws, out=out)


def mass_matrix(model, q, *, method='crba', ws=None, out=None):
    """
    Joint-space inertia matrix D(q), (n, n), symmetric positive definite.

    ``method='crba'`` (the default): the composite-rigid-body algorithm
    (``kernels/crba.py``), O(n^2) with a small constant and symmetric by
    construction.  ``method='newton_euler'``: column k is the
    Newton-Euler torque for qdd = e_k with no velocity and no gravity; n
    recursions, O(n^2) with a larger constant, then averaged with its
    transpose.  The two agree to round-off (within 10 n eps relative in
    the tests; ``make accuracy`` measures both against 50-digit truth and
    times them).  Any other ``method`` raises ValueError.
    """
    if method == 'crba':
        if type(q) is ARRAY:   # lists: below
            w = model.default_workspace if ws is None else ws
            try:
                D = EMPTY(w.square) if out is None else out
                if _crba(model.packed, q, w.ws, D) < 0:
                    return D
            except (TypeError, AttributeError) as exc:
                _fast_call_failed(exc, model, ws, (q,))
    elif method != 'newton_euler':
        raise bad_method(method)
    ws = workspace(model, ws)
    n = ws.n
    q = vector('q', q, n)
    D = out_array(out, (n, n))
    code = _mass(model.packed, q, method == 'crba', ws.ws, ws.scratch, D)
    if code >= 0:
        raise status_error(code, (q,))
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
    (``kernels/coriolis.py``).  ``method='newton_euler'``: column k from
    one recursion with the reference velocity e_k (see
    ``kernels/newton_euler.py``), n recursions.  The two agree to
    round-off.
    """
    if method == 'composite':
        composite = True
    elif method == 'newton_euler':
        composite = False
    else:
        raise bad_method(method, CORIOLIS_METHODS)
    if type(q) is ARRAY:   # lists: below
        w = model.default_workspace if ws is None else ws
        try:
            C = EMPTY(w.square) if out is None else out
            if _coriolis(model.packed, q, qd, composite, w.ws, w.cw,
                         w.scratch, C) < 0:
                return C
        except (TypeError, AttributeError) as exc:
            _fast_call_failed(exc, model, ws, (q, qd))
    ws = workspace(model, ws)
    n = ws.n
    q, qd = vector('q', q, n), vector('qd', qd, n)
    C = out_array(out, (n, n))
    code = _coriolis(model.packed, q, qd, composite, ws.ws, ws.cw,
                     ws.scratch, C)
    if code >= 0:
        raise status_error(code, (q, qd))
    return C


def forward_dynamics(model, q, qd, tau, wrench=None, wrench_frame='base', *,
                     method='aba', gravity=True, velocity_products=True,
                     ws=None, out=None):
    """
    Joint accelerations: solve D(q) qdd = tau - C qd - g - J^T F_e.

    ``method='aba'`` (the default): the articulated-body algorithm, O(n),
    without forming D (``kernels/aba.py``).
    ``method='cholesky'``: D by CRBA and a Cholesky factorisation of it
    (never an explicit inverse), O(n^3).  The two agree to round-off
    (relative to the conditioning of D).  Either raises
    :class:`NotPositiveDefiniteError` naming the first joint at which D
    is not positive definite (a joint that moves no mass or inertia).
    A model with mimic joints always takes the Cholesky path: the
    articulated-body algorithm does not apply to coupled joints (as in
    Pinocchio, whose ``aba`` refuses them).  ``wrench`` and
    ``wrench_frame`` as in :func:`inverse_dynamics` (wrenches at links
    too).
    """
    flags = 3 if gravity is True and velocity_products is True else (
        (1 if gravity else 0) | (2 if velocity_products else 0))
    if wrench is not None and type(wrench) is not dict:
        flags |= wrench_mode(wrench, wrench_frame) << 2
    if method == 'aba' and type(wrench) is dict:
        if model.n == model.nb:
            return _aba_at_links(model, ws, q, qd, tau, wrench, wrench_frame,
                                 flags, out)
        method = 'cholesky'
    if method == 'aba':
        w = model.default_workspace if ws is None else ws
        if type(q) is not ARRAY or q.dtype is not F64 or (
                wrench is not None and type(wrench) is not ARRAY):
            # lists, int arrays: converted at once, not tried first
            return _aba_converted(model, ws, q, qd, tau, wrench,
                                  wrench_frame, flags, out)
        try:
            qdd = EMPTY(w.n) if out is None else out
            if _aba(model.packed, q, qd, tau,
                    w.zero_wrench if wrench is None else wrench, flags,
                    w.ws, w.aw, qdd) < 0:
                return qdd
        except (TypeError, AttributeError) as exc:
            _fast_call_failed(exc, model, ws, (q, qd, tau, wrench),
                              FD_INPUTS)
        return _aba_converted(model, ws, q, qd, tau, wrench, wrench_frame,
                              flags, out)
    if method != 'cholesky':
        raise bad_method(method, FORWARD_DYNAMICS_METHODS)
    ws = workspace(model, ws)
    n = ws.n
    q, qd, tau = vector('q', q, n), vector('qd', qd, n), vector('tau', tau, n)
    i = K.first_nonfinite(tau)
    if i >= 0:
        raise status_error(2 * K.NONFINITE + i, (q, qd, tau), FD_INPUTS)
    qdd = out_array(out, (n,))
    bias = inverse_dynamics(model, q, qd, None, wrench, wrench_frame,
                            gravity=gravity,
                            velocity_products=velocity_products, ws=ws)
    return solve_mass_matrix(model, q, mass_matrix(model, q, ws=ws),
                             tau - bias, ws=ws, out=qdd)


def _aba_converted(model, ws, q, qd, tau, wrench, wrench_frame, flags, out):
    """Call the articulated-body entry again, arguments converted once."""
    ws = workspace(model, ws)
    n = ws.n
    for name, x in (('q', q), ('qd', qd), ('tau', tau)):
        if x is None:
            vector(name, x, n)      # raises: each is required
    q, qd, tau, w = inputs(ws, FD_INPUTS, q, qd, tau, wrench)
    qdd = out_array(out, (n,))
    code = _aba(model.packed, q, qd, tau, w, flags, ws.ws, ws.aw, qdd)
    if code == K.MIMIC:     # coupled joints: the Cholesky path
        return forward_dynamics(model, q, qd, tau, wrench, wrench_frame,
                                method='cholesky', gravity=bool(flags & 1),
                                velocity_products=bool(flags & 2), ws=ws,
                                out=qdd)
    if code >= 0:
        raise status_error(code, (q, qd, tau, w), FD_INPUTS, model=model,
                           q=q, ws=ws)
    return qdd


def _aba_at_links(model, ws, q, qd, tau, wrenches, wrench_frame, flags, out):
    """Call the articulated-body entry with wrenches at links."""
    ws = workspace(model, ws)
    n = ws.n
    q, qd, tau = vector('q', q, n), vector('qd', qd, n), vector('tau', tau, n)
    fext = link_wrench_rows(model, q, wrenches, wrench_frame, ws)
    qdd = out_array(out, (n,))
    code = _aba_links(model.packed, q, qd, tau, ws.zero_wrench, fext,
                      flags | K.LINK_WRENCHES, ws.ws, ws.aw, qdd)
    if code >= 0:
        raise status_error(code, (q, qd, tau), FD_INPUTS, model=model, q=q,
                           ws=ws)
    return qdd


def solve_mass_matrix(model, q, D, rhs, *, ws=None, out=None):
    """
    Solve D x = rhs by Cholesky; D is the mass matrix at q.

    D may carry a rotor inertia on its diagonal.  Raises
    :class:`NotPositiveDefiniteError` naming the first joint where D is not
    positive definite.  The Cholesky path of :func:`forward_dynamics` and
    the simulator's forward dynamics.
    """
    ws = workspace(model, ws)
    x = out_array(out, (ws.n,))
    bad = K.cholesky_solve(D, np.ascontiguousarray(rhs, dtype=np.float64),
                           ws.chol, x)
    if bad >= 0:
        raise not_positive_definite(model, q, bad, ws)
    return x
