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
``newton-euler feedforward --gains Q R``: LQR gains beside the efforts.

Q is ``P,V`` (a position and a velocity weight, each times the
identity) or 2n comma-separated values (the n position weights, then the
n velocity weights, in the trajectory's joint order); R is one torque
weight (times the identity) or n values.  Each point gets ``"gains"``,
the n x 2n matrix K (a list of rows) of tau = effort + K (x_ref - x),
x = (q, qd) in the trajectory's joint order (core.lqr).
"""
import numpy as np

from .core.errors import NewtonEulerError
from .core.lqr import LqrError, trajectory_gains
from .core.robot_file import to_number
from .core.trajectory import _column_map, trajectory_arrays


class GainsOptionError(NewtonEulerError):
    """A malformed --gains value (exit status 2)."""


def _values(text, what):
    try:
        return np.array([to_number(v, f'--gains {what}')
                         for v in str(text).split(',')], dtype=np.float64)
    except NewtonEulerError as exc:
        raise GainsOptionError(str(exc)) from None


def weights(state_text, input_text, k):
    """Return (state diagonal 2k, input diagonal k), trajectory order."""
    state = _values(state_text, 'Q')
    if state.shape[0] == 2:
        state = np.repeat(state, k)
    if state.shape[0] != 2 * k:
        raise GainsOptionError(
            f'--gains Q: {state.shape[0]} values for {k} joints; give P,V '
            f'or {2 * k} values (positions, then velocities)')
    torque = _values(input_text, 'R')
    if torque.shape[0] == 1:
        torque = np.repeat(torque, k)
    if torque.shape[0] != k:
        raise GainsOptionError(f'--gains R: {torque.shape[0]} values for '
                               f'{k} joints; give one or {k}')
    return state, torque


def add_gains(model, filled, gains, wrench, wrench_frame, where, hold,
              drives=None):
    """
    Write ``"gains"`` into every point of ``filled`` (in place).

    ``drives`` (a ``core.drives.Drives`` or None) join the linearised
    dynamics as they joined the efforts.
    """
    names = filled['joint_names']
    if hold is not None and len(names) != model.n:
        raise GainsOptionError(
            f'{where}joint_names: --gains needs every joint of the robot '
            f'in the trajectory ({len(names)} of {model.n})')
    n = model.n
    state, torque = weights(gains[0], gains[1], n)
    cols, named = _column_map(model, names, where)
    perm = np.empty(n, dtype=np.intp)       # trajectory column -> model
    perm[cols] = named
    state_model = np.empty(2 * n)
    state_model[perm] = state[:n]
    state_model[n + perm] = state[n:]
    torque_model = np.empty(n)
    torque_model[perm] = torque
    times, Q, QD, QDD = trajectory_arrays(model, names, filled['points'],
                                          where)
    try:
        result = trajectory_gains(model, times, Q, QD, QDD, state_model,
                                  torque_model, wrench=wrench,
                                  wrench_frame=wrench_frame, drives=drives)
    except LqrError as exc:
        text = str(exc).replace('state weights', '--gains Q')
        raise GainsOptionError(text.replace('input weights', '--gains R')) \
            from None
    x = np.concatenate([perm, n + perm])
    K = result.K[:, perm][:, :, x]
    for point, gain in zip(filled['points'], K):
        point['gains'] = gain.tolist()
    return filled
