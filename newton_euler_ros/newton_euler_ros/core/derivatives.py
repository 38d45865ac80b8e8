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
Derivatives of the dynamics, analytically: for MPC, LQR and estimation.

==========================================  ================================
:func:`inverse_dynamics_derivatives`        dtau/dq, dtau/dqd (dtau/dqdd
                                            is D)
:func:`forward_dynamics_derivatives`        dqdd/dq, dqdd/dqd, dqdd/dtau
                                            (= D^-1)
``*_batch``                                 the same for (m, n) states, one
                                            compiled loop
==========================================  ================================

Both run the recursions of ``kernels/derivatives.py`` over the tree
(chains are the special case), with mimic joints through their leads,
the wrench terms (at the end effector or at links, in either axes, as
:func:`~newton_euler_ros.core.dynamics.inverse_dynamics` takes them) and,
with ``drives`` (a :class:`~newton_euler_ros.core.drives.Drives`), the
drive terms the feedforward adds: viscous and smooth Coulomb friction in
dtau/dqd, the rotor inertia in D (``docs/derivatives.md``).  Derivatives
are with respect to the model's coordinates, in its joint order; a
continuous joint's coordinate is its angle.  The cost is O(n^2): a few
O(n) passes and a few dozen multiply-adds per pair of joints on one path
(the forward derivatives add a Cholesky solve, O(n^3)).

>>> import numpy as np
>>> from newton_euler_ros.core import load_robot
>>> arm = load_robot('planar_2r')
>>> dq, dqd = inverse_dynamics_derivatives(arm, [0.3, 0.2], [0.0, 0.0],
...                                        [0.0, 0.0])
>>> bool(np.allclose(dqd, 0.0))         # no velocity, no viscous friction
True
"""
from numba import types
import numpy as np

from . import kernels as K
from .batch import run_split
from .calling import (ARRAY, EMPTY, F64, FD_INPUTS, foreign_workspace, INPUTS, inputs,
                      INT, MAT, matrix, out_array, PACKED, slow_inputs,
                      status_error, strict_entry, VEC, vector, workspace,
                      wrench_mode)
from .frames import derivative_wrench_rows

__all__ = ['forward_dynamics_derivatives',
           'forward_dynamics_derivatives_batch',
           'inverse_dynamics_derivatives',
           'inverse_dynamics_derivatives_batch']

ARRAY3 = types.Array(types.float64, 3, 'C')
_dtau = strict_entry(K.run_inverse_dynamics_derivatives, PACKED, VEC, VEC,
                     VEC, VEC, VEC, INT, MAT, MAT, MAT, ARRAY3, home=globals())
_dtau_links = strict_entry(K.run_inverse_dynamics_derivatives_links, PACKED,
                           VEC, VEC, VEC, VEC, MAT, MAT, VEC, INT, MAT, MAT,
                           MAT, ARRAY3, home=globals())
_dqdd = strict_entry(K.run_forward_dynamics_derivatives, PACKED, VEC, VEC,
                     VEC, VEC, VEC, VEC, INT, MAT, MAT, MAT, MAT, MAT,
                     ARRAY3, home=globals())
_dqdd_links = strict_entry(K.run_forward_dynamics_derivatives_links, PACKED,
                           VEC, VEC, VEC, VEC, MAT, MAT, MAT, VEC, VEC, INT,
                           MAT, MAT, MAT, MAT, MAT, ARRAY3, home=globals())


def drive_slopes(drives, qd, out=None):
    """
    Return d tau_drive / d qd of a Drives at velocities qd (..., n).

    F_v + F_c / eps (1 - tanh^2(qd / eps)): the viscous term and the
    slope of the smooth Coulomb term (``core.drives``).
    """
    t = np.tanh(np.asarray(qd, dtype=np.float64) / drives.coulomb_width)
    slope = drives.viscous + drives.coulomb / drives.coulomb_width * (
        1.0 - t * t)
    if out is None:
        return slope
    out[...] = slope
    return out


def _flags(gravity, wrench, wrench_frame):
    flags = K.GRAVITY if gravity else 0
    if wrench is not None and type(wrench) is not dict:
        flags |= wrench_mode(wrench, wrench_frame) << K.WRENCH_SHIFT
    return flags


def inverse_dynamics_derivatives(model, q, qd=None, qdd=None, wrench=None,
                                 wrench_frame='base', *, gravity=True,
                                 drives=None, ws=None, out=None):
    """
    dtau/dq and dtau/dqd of tau = D qdd + C qd + g + J^T F_e, analytically.

    Parameters as :func:`~newton_euler_ros.core.dynamics.inverse_dynamics`
    (``wrench`` an end-effector [f; n] or ``{frame name: [f; n]}``,
    ``wrench_frame`` their axes); ``drives``: add the drive terms'
    dtau/dqd (viscous, smooth Coulomb; the rotor inertia only adds to
    dtau/dqdd = D).  ``out``: a (2, n, n) float64 array to write into.

    Returns
    -------
    (dtau_dq, dtau_dqd) : two (n, n) arrays (views of one (2, n, n))
        Row i, column j: d tau_i / d q_j.  dtau/dqd is 2 C(q, qd) (plus
        the drives' slopes on the diagonal).

    """
    w = model.default_workspace if ws is None else ws
    flags = _flags(gravity, wrench, wrench_frame)
    if (type(wrench) is not dict and type(q) is ARRAY
            and q.dtype is F64):    # lists, float32, link wrenches: below
        try:
            n = w.n
            res = EMPTY((2, n, n)) if out is None else out
            damping = w.zeros if drives is None else drive_slopes(
                drives, w.zeros if qd is None else qd, w.scratch[2])
            if _dtau(model.packed, q, w.zeros if qd is None else qd,
                     w.zeros if qdd is None else qdd,
                     w.zero_wrench if wrench is None else wrench,
                     damping, flags, w.ws, w.cw, w.dw, res) < 0:
                return res[0], res[1]
        except TypeError:
            slow_inputs((q, qd, qdd, wrench))
        except AttributeError:
            foreign_workspace(model, ws)
            raise
    return _converted(model, ws, INPUTS, (q, qd, qdd), wrench, wrench_frame,
                      flags, drives, out)


def forward_dynamics_derivatives(model, q, qd, tau, wrench=None,
                                 wrench_frame='base', *, gravity=True,
                                 drives=None, ws=None, out=None):
    """
    dqdd/dq, dqdd/dqd and dqdd/dtau of qdd = FD(q, qd, tau), analytically.

    qdd solves (D + I_a) qdd = tau - C qd - g - J^T F_e - tau_drive
    (with ``drives``: I_a their rotor inertia, tau_drive their friction
    and offset; without, none).  The derivatives are those of the inverse
    dynamics at that qdd, times -(D + I_a)^-1; dqdd/dtau = (D + I_a)^-1.
    ``out``: a (3, n, n) float64 array.  Raises
    :class:`~newton_euler_ros.core.errors.NotPositiveDefiniteError` where
    D is singular, naming the joint.

    Returns
    -------
    (dqdd_dq, dqdd_dqd, dqdd_dtau) : three (n, n) arrays

    """
    w = model.default_workspace if ws is None else ws
    flags = _flags(gravity, wrench, wrench_frame)
    if (drives is None and type(wrench) is not dict
            and type(q) is ARRAY and q.dtype is F64):
        try:
            n = w.n
            res = EMPTY((3, n, n)) if out is None else out
            if _dqdd(model.packed, q, qd, tau,
                     w.zero_wrench if wrench is None else wrench, w.zeros,
                     w.zeros, flags, w.ws, w.cw, w.dw, w.chol, w.scratch,
                     res) < 0:
                return res[0], res[1], res[2]
        except TypeError:
            slow_inputs((q, qd, tau, wrench), FD_INPUTS)
        except AttributeError:
            foreign_workspace(model, ws)
            raise
    return _converted(model, ws, FD_INPUTS, (q, qd, tau), wrench,
                      wrench_frame, flags, drives, out)


def _converted(model, ws, names, given, wrench, wrench_frame, flags, drives,
               out):
    """Convert the inputs once, then call the entry (at links, or not)."""
    ws = workspace(model, ws)
    n = ws.n
    forward = names is FD_INPUTS
    if forward:
        for name, x in zip(names, given):
            if x is None:
                vector(name, x, n)      # raises: each is required
    dict_wrench = type(wrench) is dict
    q, qd, third, w = inputs(ws, names, *given,
                             None if dict_wrench else wrench)
    res = out_array(out, (3 if forward else 2, n, n))
    damping = np.zeros(n) if drives is None else drive_slopes(drives, qd)
    if forward:
        armature = np.zeros(n) if drives is None else np.array(
            drives.armature, dtype=np.float64)
        if drives is not None:
            third = third - (drives.torques(qd, np.zeros(n)))
    if dict_wrench:
        fall, fext, wext = derivative_wrench_rows(model, q, wrench,
                                                  wrench_frame, ws)
        flags |= K.LINK_WRENCHES
        if forward:
            code = _dqdd_links(
                model.packed, q, qd, third, ws.zero_wrench, fall, fext, wext,
                armature, damping, flags, ws.ws, ws.cw, ws.dw, ws.chol,
                ws.scratch, res)
        else:
            code = _dtau_links(
                model.packed, q, qd, third, ws.zero_wrench, fext, wext,
                damping, flags, ws.ws, ws.cw, ws.dw, res)
    elif forward:
        code = _dqdd(model.packed, q, qd, third, w, armature, damping,
                     flags, ws.ws, ws.cw, ws.dw, ws.chol, ws.scratch,
                     res)
    else:
        code = _dtau(model.packed, q, qd, third, w, damping, flags,
                     ws.ws, ws.cw, ws.dw, res)
    if code >= 0:
        raise status_error(code, (q, qd, third, w), names, model=model,
                           q=q, ws=ws)
    return tuple(res)


def inverse_dynamics_derivatives_batch(model, Q, QD, QDD, W=None,
                                       wrench_frame='base', *, gravity=True,
                                       drives=None, threads=None, ws=None,
                                       out=None):
    """
    :func:`inverse_dynamics_derivatives` for each row of (m, n) states.

    ``W``: (m, 6) end-effector wrenches or None.  Returns (DQ, DQD), two
    (m, n, n) arrays (views of one (m, 2, n, n), or ``out``).  One
    compiled loop: no Python work per state (with ``drives``, their
    slopes added to the diagonals in numpy).  ``threads``: share the
    rows among that many threads (None: one a core, at least 32 rows
    each; 1: this thread only); the result is the same bit for bit.
    """
    ws, Q, QD, X, W, flags = _batch_inputs(model, ws, Q, QD, QDD, 'QDD', W,
                                           wrench_frame, gravity)
    m = Q.shape[0]
    res = out_array(out, (m, 2, ws.n, ws.n))
    P = model.packed

    def arguments(lo, hi, w):
        return (P, Q[lo:hi], QD[lo:hi], X[lo:hi], W[lo:hi], w.zeros, flags,
                w.ws, w.cw, w.dw, res[lo:hi], w.status)

    run_split(model, ws, m, threads, K.run_inverse_dynamics_derivatives_batch,
              arguments, Q)
    if drives is not None:
        i = np.arange(ws.n)
        res[:, 1, i, i] += drive_slopes(drives, QD)
    return res[:, 0], res[:, 1]


def forward_dynamics_derivatives_batch(model, Q, QD, TAU, W=None,
                                       wrench_frame='base', *, gravity=True,
                                       threads=None, ws=None, out=None):
    """
    :func:`forward_dynamics_derivatives` for each row of (m, n) states.

    Returns (DQ, DQD, DTAU), three (m, n, n) arrays (views of one
    (m, 3, n, n), or ``out``).  One compiled loop; ``threads`` as
    :func:`inverse_dynamics_derivatives_batch` takes it.
    """
    ws, Q, QD, X, W, flags = _batch_inputs(model, ws, Q, QD, TAU, 'TAU', W,
                                           wrench_frame, gravity)
    m = Q.shape[0]
    res = out_array(out, (m, 3, ws.n, ws.n))
    P = model.packed

    def arguments(lo, hi, w):
        return (P, Q[lo:hi], QD[lo:hi], X[lo:hi], W[lo:hi], w.zeros, w.zeros,
                flags, w.ws, w.cw, w.dw, w.chol, w.scratch, res[lo:hi],
                w.status)

    run_split(model, ws, m, threads, K.run_forward_dynamics_derivatives_batch,
              arguments, Q)
    return res[:, 0], res[:, 1], res[:, 2]


def _batch_inputs(model, ws, Q, QD, X, name, W, wrench_frame, gravity):
    ws = workspace(model, ws)
    Q = matrix('Q', Q, ws.n)
    m = Q.shape[0]
    QD = matrix('QD', QD, ws.n, m)
    X = matrix(name, X, ws.n, m)
    if W is None:
        W, mode = np.zeros((m, 6)), K.WRENCH_NONE
    else:
        W, mode = matrix('W', W, 6, m), wrench_mode(W, wrench_frame)
    flags = (K.GRAVITY if gravity else 0) | (mode << K.WRENCH_SHIFT)
    return ws, Q, QD, X, W, flags
