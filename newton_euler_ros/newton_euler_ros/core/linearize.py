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
The dynamics linearised at one state: A, B and their discrete pair.

With the state x = (q, qd) and the input u = tau, the robot's dynamics
are xdot = f(x, u) = (qd, qdd(q, qd, tau)), where qdd solves

    (D(q) + I_a) qdd = tau - C(q, qd) qd - g(q) - J^T F_e - tau_drive

(I_a the rotor inertia and tau_drive = F_v qd + F_c tanh(qd / eps) +
offset the drive terms, with ``drives``; ``core.drives``).  At a point
(x0, u0)::

    A = df/dx = [[0, I], [dqdd/dq, dqdd/dqd]],   B = df/du = [[0], [dqdd/dtau]]

from :func:`~newton_euler_ros.core.derivatives.forward_dynamics_derivatives`
(analytical, not finite differences).  The discrete pair for a sampling
period dt is the zero-order hold (u held over each step), the exact
exponential::

    [[Ad, Bd], [0, I]] = expm([[A, B], [0, 0]] dt)

so that dx[k+1] = Ad dx[k] + Bd du[k] for the deviations dx = x - x0,
du = u - u0; the drift f(x0, u0) = (qd0, qdd0), zero only at an
equilibrium, adds integral_0^dt expm(A s) ds f(x0, u0) to each step.
``gravity=False`` linearises a robot that adds g(q) itself (Franka's
torque interface): u is then the torque sent, without g(q).

>>> from newton_euler_ros.core import load_robot
>>> arm = load_robot('planar_2r')
>>> lin = state_space(arm, [0.3, 0.2], [0.0, 0.0], dt=0.01)
>>> lin.A.shape, lin.B.shape, lin.Ad.shape, lin.Bd.shape
((4, 4), (4, 2), (4, 4), (4, 2))
"""
from dataclasses import dataclass

import numpy as np

from .derivatives import forward_dynamics_derivatives
from .dynamics import (forward_dynamics, inverse_dynamics, mass_matrix,
                       solve_mass_matrix)

__all__ = ['StateSpace', 'state_space', 'zero_order_hold']

ZERO_ORDER_HOLD = 'zero-order hold'


@dataclass(frozen=True, eq=False)
class StateSpace:
    """
    The linearised dynamics at one point, x = (q, qd), u = tau.

    ``A`` (2n, 2n) and ``B`` (2n, n) of xdot = A dx + B du + f(x0, u0);
    ``Ad``, ``Bd`` their discrete pair for ``dt`` by ``discretisation``
    (None without a time step); ``tau0`` and ``qdd0`` the input and the
    accelerations at the point (model order).
    """

    A: np.ndarray
    B: np.ndarray
    Ad: np.ndarray
    Bd: np.ndarray
    tau0: np.ndarray
    qdd0: np.ndarray
    dt: float = None
    discretisation: str = ZERO_ORDER_HOLD


def zero_order_hold(A, B, dt):
    """
    Return (Ad, Bd): the exact zero-order-hold pair of (A, B) for ``dt``.

    The blocks of expm([[A, B], [0, 0]] dt): Ad = expm(A dt) and Bd =
    integral_0^dt expm(A s) ds B.
    """
    from scipy.linalg import expm       # on demand: scipy loads slowly
    m, k = B.shape
    M = np.zeros((m + k, m + k))
    M[:m, :m] = A
    M[:m, m:] = B
    E = expm(M * dt)
    return E[:m, :m].copy(), E[:m, m:].copy()


def _point(model, q, qd, tau, qdd, wrench, wrench_frame, gravity, drives,
           ws):
    """Return (tau0, qdd0): the missing one of the two from the other."""
    n = model.n
    if tau is not None and qdd is not None:
        raise ValueError('state_space: give tau or qdd, not both')
    if tau is None:
        qdd = np.zeros(n) if qdd is None else np.array(qdd, dtype=float)
        tau = inverse_dynamics(model, q, qd, qdd, wrench, wrench_frame,
                               gravity=gravity, ws=ws)
        if drives is not None:
            tau = tau + drives.torques(qd, qdd)
        return tau, qdd
    tau = np.array(tau, dtype=float)
    if drives is None:
        return tau, forward_dynamics(model, q, qd, tau, wrench,
                                     wrench_frame, gravity=gravity, ws=ws)
    # (D + I_a) qdd = tau - bias - friction - offset
    bias = inverse_dynamics(model, q, qd, None, wrench, wrench_frame,
                            gravity=gravity, ws=ws)
    D = mass_matrix(model, q, ws=ws)
    D.flat[::n + 1] += drives.armature
    rhs = tau - bias - drives.torques(qd, np.zeros(n))
    return tau, solve_mass_matrix(model, q, D, rhs, ws=ws)


def state_space(model, q, qd, tau=None, qdd=None, dt=None, wrench=None,
                wrench_frame='base', drives=None, ws=None, *,
                gravity=True):
    """
    Linearise xdot = f(x, u), x = (q, qd), u = tau, at one point.

    The point's input is ``tau`` (qdd0 then follows by forward dynamics)
    or ``qdd`` (tau0 by inverse dynamics, drive terms included), at most
    one of the two; neither means qdd0 = 0.  ``wrench`` and
    ``wrench_frame`` as :func:`~newton_euler_ros.core.dynamics.
    inverse_dynamics` takes them (held constant: it is no input);
    ``drives`` a :class:`~newton_euler_ros.core.drives.Drives` whose
    terms join the dynamics; ``dt`` > 0 adds the zero-order-hold pair
    (:func:`zero_order_hold`).  ``gravity=False``: the robot adds g(q)
    itself, and u is the torque sent without it.

    Returns
    -------
    StateSpace
        A (2n, 2n), B (2n, n), Ad and Bd (None without ``dt``), tau0,
        qdd0 (model order).

    """
    n = model.n
    q = np.array(q, dtype=float)
    qd = np.zeros(n) if qd is None else np.array(qd, dtype=float)
    if dt is not None and not (np.isfinite(dt) and dt >= 0.0):
        raise ValueError(f'state_space: dt must be finite and >= 0, got '
                         f'{dt!r}')
    tau0, qdd0 = _point(model, q, qd, tau, qdd, wrench, wrench_frame,
                        gravity, drives, ws)
    dq, dqd, dtau = forward_dynamics_derivatives(
        model, q, qd, tau0, wrench, wrench_frame, gravity=gravity,
        drives=drives, ws=ws)
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = dq
    A[n:, n:] = dqd
    B = np.zeros((2 * n, n))
    B[n:] = dtau
    Ad = Bd = None
    if dt:
        Ad, Bd = zero_order_hold(A, B, float(dt))
    return StateSpace(A, B, Ad, Bd, tau0, qdd0,
                      float(dt) if dt else None)
