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
A contact threshold that grows with the joint's speed and acceleration.

A model's error while the arm moves grows with how fast it moves: a
friction that is not quite linear in the speed, a rotor or payload
inertia a little off, all scale with ``|qd|`` and ``|qdd|``.  One
number per joint must then cover the fastest motion, and is blind to
pushes at rest and in slow motion.  So joint j's threshold is

    thr_j = a_j + b_j s_j + c_j u_j

with ``s_j`` and ``u_j`` the joint's ``|qd|`` and ``|qdd|`` passed
through the residual's own lag (``x_k = e x_(k-1) + (1 - e) v_k``,
``e = exp(-K_j dt)``): if the model's error is at most ``a + b |qd| +
c |qdd|`` at every instant, the residual, its first-order lag, is at
most ``thr`` (the same argument as the static friction allowance's).
The observer has no measured acceleration: ``|qdd|`` over an interval
is the change of the measured ``qd`` over it divided by its length (the
lag filters its noise); the speed of an interval is the larger of its
two ends'.  A gap longer than the observer's ``max_gap``, or a stamp
going backwards, restarts the difference (the lagged values are kept).

``a``, ``b``, ``c`` are ``observer.thresholds``,
``observer.speed_thresholds`` and ``observer.acceleration_thresholds``;
with ``b = c = 0`` the threshold is ``a`` exactly, as before.
:func:`.thresholds.suggest_state_thresholds` fits them on a
free recording.
"""
import math

from numba import njit
import numpy as np

from ..kernels._jit import ENTRY

# rows of MotionState.rows (n columns)
_SPEED, _ACCEL, _QD_PREV = 0, 1, 2
_ROWS = 3


class MotionState:
    """The lagged speed and acceleration per joint: constant size."""

    def __init__(self, n):
        """Make the state of ``n`` joints, before any sample."""
        self.rows = np.zeros((_ROWS, n))
        self.t_prev = np.array([math.nan])

    @property
    def speed(self):
        """Per joint, the lagged ``|qd|`` (a view)."""
        return self.rows[_SPEED]

    @property
    def acceleration(self):
        """Per joint, the lagged ``|qdd|`` from differences of qd (a view)."""
        return self.rows[_ACCEL]


@njit(**ENTRY)
def _motion_step(t, qd, gain, max_gap, rows, t_prev):
    """Advance the lagged speed and acceleration by one sample."""
    dt = t - t_prev[0]
    if dt == 0.0:
        return
    t_prev[0] = t
    restart = not (0.0 < dt <= max_gap)     # also the first sample (NaN)
    for i in range(qd.shape[0]):
        if not restart:
            e = math.exp(-gain[i] * dt)
            speed = max(abs(qd[i]), abs(rows[_QD_PREV, i]))
            accel = abs(qd[i] - rows[_QD_PREV, i]) / dt
            rows[_SPEED, i] = e * rows[_SPEED, i] + (1.0 - e) * speed
            rows[_ACCEL, i] = e * rows[_ACCEL, i] + (1.0 - e) * accel
        rows[_QD_PREV, i] = qd[i]


def motion_step(obs, state, t, qd):
    """Advance ``state`` (:class:`MotionState`) by the sample at ``t``."""
    qd = np.ascontiguousarray(qd, dtype=np.float64)
    _motion_step(float(t), qd, obs.gain, float(obs.max_gap), state.rows,
                 state.t_prev)


def state_thresholds(obs, state, out):
    """
    Write joint thresholds at ``state`` into ``out`` (n,); return it.

    ``obs.thresholds`` alone (copied) when the observer has no speed or
    acceleration thresholds.
    """
    out[:] = obs.thresholds
    if obs.moving_thresholds:
        out += obs.speed_thresholds * state.speed
        out += obs.acceleration_thresholds * state.acceleration
    return out
