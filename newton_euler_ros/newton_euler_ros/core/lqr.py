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
Time-varying LQR gains along a sampled joint trajectory.

With the state x = (q, qd) and the input u = tau, the dynamics are
linearised at every sample k of the reference (q_k, qd_k, qdd_k, tau0_k)
by the batched analytical derivatives::

    A_k = [[0, I], [dqdd/dq, dqdd/dqd]],   B_k = [[0], [dqdd/dtau]]

and each interval [t_k, t_k+1] is discretised by the zero-order hold
over its own length (:func:`~newton_euler_ros.core.linearize.
zero_order_hold`); the last sample's interval repeats the one before it.
The discrete finite-horizon LQR on the deviations (x - x_ref, u - tau0)
with the weights Qw (2n x 2n, on x) and R (n x n, on tau) is the backward
Riccati recursion::

    P_N = Qw
    K_k = (R + Bd_k^T P_k+1 Bd_k)^-1 Bd_k^T P_k+1 Ad_k
    P_k = Qw + Ad_k^T P_k+1 (Ad_k - Bd_k K_k)

and the control law, with the gains held over each interval, is::

    tau = tau0_k + K_k (x_ref_k - x),     x = (q, qd)

the form a linear feedback controller takes (ros2_control's
linear_feedback_controller).  tau0_k are the feedforward torques,
computed as ``newton-euler feedforward`` computes its efforts.

>>> import numpy as np
>>> from newton_euler_ros.core import load_robot
>>> arm = load_robot('planar_2r')
>>> t = np.linspace(0.0, 1.0, 11)
>>> Q = np.zeros((11, 2)); Q[:, 0] = 0.2 * t
>>> QD = np.zeros((11, 2)); QD[:, 0] = 0.2
>>> gains = trajectory_gains(arm, t, Q, QD, np.zeros((11, 2)),
...                          [100.0, 1.0], 0.01)
>>> gains.tau0.shape, gains.K.shape
((11, 2), (11, 2, 4))
"""
from dataclasses import dataclass

import numpy as np

from .derivatives import (forward_dynamics_derivatives,
                          forward_dynamics_derivatives_batch)
from .dynamics import inverse_dynamics_batch, wrench_torques
from .errors import DynamicsInputError
from .linearize import zero_order_hold

__all__ = ['LqrError', 'TrajectoryGains', 'riccati_gains',
           'state_weight_matrix', 'input_weight_matrix', 'trajectory_gains']


class LqrError(DynamicsInputError):
    """The weights or the samples are unusable; the message says which."""


@dataclass(frozen=True, eq=False)
class TrajectoryGains:
    """
    The feedforward and the gains at every sample (model order).

    ``tau0`` (m, n) the feedforward torques, ``K`` (m, n, 2n) the gains
    of tau = tau0_k + K_k (x_ref_k - x), x = (q, qd); ``Ad`` (m, 2n, 2n)
    and ``Bd`` (m, 2n, n) the discrete pairs the gains were designed on,
    ``P0`` (2n, 2n) the cost-to-go at the first sample.
    """

    tau0: np.ndarray
    K: np.ndarray
    Ad: np.ndarray
    Bd: np.ndarray
    P0: np.ndarray


def _weights(name, w, size, strict):
    """Return the (size, size) symmetric weight from a matrix or diagonal."""
    try:
        w = np.array(w, dtype=np.float64)
    except (TypeError, ValueError):
        raise LqrError(f'{name}: must be numbers') from None
    if w.ndim == 0:
        w = np.full(size, float(w))
    if w.ndim == 1:
        if w.shape[0] != size:
            raise LqrError(f'{name}: {w.shape[0]} values, need {size} (or '
                           f'one, or a {size} x {size} matrix)')
        w = np.diag(w)
    if w.shape != (size, size):
        raise LqrError(f'{name}: shape {w.shape}, need ({size}, {size})')
    if not np.isfinite(w).all():
        raise LqrError(f'{name}: must be finite')
    if not np.allclose(w, w.T, rtol=1e-12, atol=0.0):
        raise LqrError(f'{name}: must be symmetric')
    low = np.linalg.eigvalsh(w).min()
    scale = max(np.abs(w).max(), 1e-300)
    if strict and not low > 1e-12 * scale:
        raise LqrError(f'{name}: must be positive definite (smallest '
                       f'eigenvalue {low:.3g})')
    if not strict and low < -1e-12 * scale:
        raise LqrError(f'{name}: must be positive semi-definite (smallest '
                       f'eigenvalue {low:.3g})')
    return w


def state_weight_matrix(weights, n):
    """
    Return Qw (2n, 2n) from a matrix, 2n diagonal values or (pos, vel).

    Two values are one position and one velocity weight, each
    times the identity; 2n values the diagonal; a (2n, 2n) matrix as is.
    """
    try:
        w = np.asarray(weights, dtype=np.float64)
    except (TypeError, ValueError):
        raise LqrError('state weights: must be numbers') from None
    if w.ndim == 1 and w.shape[0] == 2:
        w = np.repeat(w, n)
    return _weights('state weights', w, 2 * n, strict=False)


def input_weight_matrix(weights, n):
    """Return R (n, n) from a matrix, n diagonal values or one scalar."""
    return _weights('input weights', weights, n, strict=True)


def riccati_gains(Ad, Bd, Qw, R, P_end=None):
    """
    Return (K, P0): the backward recursion over the discrete pairs.

    ``Ad`` (N, s, s), ``Bd`` (N, s, n); ``P_end`` the terminal cost
    (default ``Qw``).  K (N, n, s).
    """
    N, s, n = Bd.shape
    K = np.empty((N, n, s))
    P = np.array(Qw if P_end is None else P_end, dtype=np.float64)
    for k in range(N - 1, -1, -1):
        A, B = Ad[k], Bd[k]
        PB = P @ B
        S = R + B.T @ PB
        K[k] = np.linalg.solve(S, PB.T @ A)
        P = Qw + A.T @ P @ (A - B @ K[k])
        P = 0.5 * (P + P.T)         # keep it symmetric against round-off
    return K, P


def _samples(model, times, Q, QD, QDD):
    n = model.n
    t = np.array(times, dtype=np.float64).reshape(-1)
    m = t.shape[0]
    if m < 2:
        raise LqrError(f'times: {m} sample(s); the gains need at least 2')
    if not np.isfinite(t).all():
        raise LqrError('times: must be finite')
    steps = np.diff(t)
    if not (steps > 0.0).all():
        k = int(np.flatnonzero(~(steps > 0.0))[0]) + 1
        raise LqrError(f'times: sample {k} ({t[k]} s) is not after the '
                       f'previous one ({t[k - 1]} s); times must increase')
    arrays = []
    for name, X in (('Q', Q), ('QD', QD), ('QDD', QDD)):
        X = np.array(X, dtype=np.float64)
        if X.shape != (m, n):
            raise LqrError(f'{name}: shape {X.shape}, need ({m}, {n}): one '
                           f'row per time, one column per joint')
        if not np.isfinite(X).all():
            raise LqrError(f'{name}: must be finite')
        arrays.append(X)
    return t, steps, arrays


def feedforward_torques(model, Q, QD, QDD, wrench=None, wrench_frame='base',
                        *, drives=None, gravity=True, ws=None):
    """
    tau0 (m, n) in model order, as ``core.trajectory`` fills efforts.

    D qdd + C qd + g (+ J^T F_e for a held end-effector ``wrench`` or
    wrenches at links ``{link: [f; n]}``) (+ the drive terms).
    """
    m = Q.shape[0]
    W = None
    if wrench is not None and not isinstance(wrench, dict):
        W = np.tile(np.asarray(wrench, dtype=np.float64), (m, 1))
    tau = inverse_dynamics_batch(model, Q, QD, QDD, W,
                                 'base' if W is None else wrench_frame,
                                 gravity=gravity, ws=ws)
    if isinstance(wrench, dict):
        for k in range(m):
            tau[k] += wrench_torques(model, Q[k], wrench, wrench_frame,
                                     ws=ws)
    if drives is not None:
        tau = tau + drives.torques(QD, QDD)
    return tau


def _derivatives(model, Q, QD, tau, wrench, wrench_frame, drives, gravity,
                 ws):
    """(dqdd/dq, dqdd/dqd, dqdd/dtau), (m, n, n) each."""
    if drives is None and not isinstance(wrench, dict):
        W = None
        if wrench is not None:
            W = np.tile(np.asarray(wrench, dtype=np.float64),
                        (Q.shape[0], 1))
        # one thread: a node beside a robot's stack takes no other core
        return forward_dynamics_derivatives_batch(
            model, Q, QD, tau, W, wrench_frame, gravity=gravity, threads=1,
            ws=ws)
    # the batch takes neither drive terms nor wrenches at links
    m, n = Q.shape
    out = np.empty((3, m, n, n))
    for k in range(m):
        d = forward_dynamics_derivatives(model, Q[k], QD[k], tau[k], wrench,
                                         wrench_frame, gravity=gravity,
                                         drives=drives, ws=ws)
        for i in range(3):
            out[i, k] = d[i]
    return out[0], out[1], out[2]


def trajectory_gains(model, times, Q, QD, QDD, state_weights, input_weights,
                     *, drives=None, wrench=None, wrench_frame='base',
                     gravity=True, ws=None):
    """
    Feedforward torques and finite-horizon LQR gains at every sample.

    ``times`` (m,) strictly increasing (s), ``Q``, ``QD``, ``QDD`` (m, n)
    the reference in model order (``core.trajectory.trajectory_arrays``
    gives them from a JointTrajectory).  ``state_weights``: a (2n, 2n)
    matrix on x = (q, qd), its 2n diagonal values, or two values (a
    position and a velocity weight, each times the identity);
    ``input_weights``: an (n, n) matrix on tau, n diagonal values or one
    scalar (times the identity), positive definite.  ``drives``,
    ``wrench``, ``wrench_frame`` and ``gravity`` as
    :func:`~newton_euler_ros.core.trajectory.trajectory_efforts` takes
    them; they join the linearised dynamics too.

    Returns
    -------
    TrajectoryGains
        ``tau0`` (m, n) and ``K`` (m, n, 2n): tau = tau0_k +
        K_k (x_ref_k - x), held over [t_k, t_k+1).

    """
    n = model.n
    _, steps, (Q, QD, QDD) = _samples(model, times, Q, QD, QDD)
    Qw = state_weight_matrix(state_weights, n)
    R = input_weight_matrix(input_weights, n)
    tau0 = feedforward_torques(model, Q, QD, QDD, wrench, wrench_frame,
                               drives=drives, gravity=gravity, ws=ws)
    dq, dqd, dtau = _derivatives(model, Q, QD, tau0, wrench, wrench_frame,
                                 drives, gravity, ws)
    m = Q.shape[0]
    dts = np.append(steps, steps[-1])
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    B = np.zeros((2 * n, n))
    Ad = np.empty((m, 2 * n, 2 * n))
    Bd = np.empty((m, 2 * n, n))
    for k in range(m):
        A[n:, :n] = dq[k]
        A[n:, n:] = dqd[k]
        B[n:] = dtau[k]
        Ad[k], Bd[k] = zero_order_hold(A, B, dts[k])
    K, P0 = riccati_gains(Ad, Bd, Qw, R)
    return TrajectoryGains(tau0, K, Ad, Bd, P0)
