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
core.lqr.trajectory_gains: time-varying LQR gains along a trajectory.

Far from the horizon's end the gains on a pendulum held at its hanging
equilibrium are scipy's steady-state (discrete algebraic Riccati) gain;
the last one is the one-step gain; the feedforward equals the efforts
``core.trajectory`` fills; in closed loop on the library's forward
dynamics the LQR law tracks a moving Puma trajectory with a clearly
smaller error than a PD law given the same peak feedback torque; bad
inputs are refused in one line.
"""
import doctest
import json
import os
import warnings

from newton_euler_ros.core import Drives, forward_dynamics, load_robot
from newton_euler_ros.core import lqr
from newton_euler_ros.core.linearize import zero_order_hold
from newton_euler_ros.core.lqr import LqrError, trajectory_gains
from newton_euler_ros.core.trajectory import trajectory_efforts
import numpy as np
import pytest
from test_linearize import pendulum

MOVE = os.path.join(os.path.dirname(__file__), '..', '..', 'config',
                    'trajectories', 'puma560_move.json')


@pytest.fixture(scope='module')
def puma():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')     # the published inertias' note
        return load_robot('puma560')


def test_doctest():
    assert doctest.testmod(lqr).failed == 0


def test_pendulum_gains_converge_to_the_steady_state_gain():
    from scipy.linalg import solve_discrete_are
    model = pendulum()
    dt, m = 0.01, 1001
    times = np.arange(m) * dt
    Q = np.full((m, 1), -np.pi / 2)         # hanging straight down
    zero = np.zeros((m, 1))
    Qw, R = np.diag([10.0, 1.0]), np.array([[0.1]])
    gains = trajectory_gains(model, times, Q, zero, zero, Qw, R)
    np.testing.assert_allclose(gains.tau0, 0.0, atol=1e-12)
    inertia = 1 / 6 + 2.0 * 0.5 ** 2
    A = np.array([[0.0, 1.0], [-2.0 * 9.81 * 0.5 / inertia, 0.0]])
    B = np.array([[0.0], [1 / inertia]])
    Ad, Bd = zero_order_hold(A, B, dt)
    P = solve_discrete_are(Ad, Bd, Qw, R)
    K_inf = np.linalg.solve(R + Bd.T @ P @ Bd, Bd.T @ P @ Ad)
    for k in (0, 100, 300):             # 7 s or more before the end
        np.testing.assert_allclose(gains.K[k], K_inf, rtol=1e-8)
    np.testing.assert_allclose(gains.P0, P, rtol=1e-8)
    # the last: one step to the terminal cost P_N = Qw
    K_last = np.linalg.solve(R + Bd.T @ Qw @ Bd, Bd.T @ Qw @ Ad)
    np.testing.assert_allclose(gains.K[-1], K_last, rtol=1e-10)
    assert np.abs(gains.K[-1] - K_inf).max() > 0.1 * np.abs(K_inf).max()


def test_weights_in_their_short_forms_mean_the_same():
    model = pendulum()
    times = [0.0, 0.01, 0.02]
    Q = np.full((3, 1), -1.0)
    zero = np.zeros((3, 1))
    full = trajectory_gains(model, times, Q, zero, zero,
                            np.diag([10.0, 1.0]), [[0.1]])
    short = trajectory_gains(model, times, Q, zero, zero, [10.0, 1.0], 0.1)
    np.testing.assert_array_equal(full.K, short.K)
    np.testing.assert_array_equal(full.tau0, short.tau0)


def _move(puma):
    from newton_euler_ros.core.trajectory import trajectory_arrays
    with open(MOVE, encoding='utf-8') as fh:
        traj = json.load(fh)
    return traj, trajectory_arrays(puma, traj['joint_names'],
                                   traj['points'])


def test_feedforward_equals_the_filled_efforts(puma):
    traj, (times, Q, QD, QDD) = _move(puma)
    gains = trajectory_gains(puma, times, Q, QD, QDD, [100.0, 1.0], 0.01)
    efforts = trajectory_efforts(puma, traj['joint_names'], traj['points'])
    np.testing.assert_array_equal(gains.tau0, efforts)
    assert gains.K.shape == (len(times), 6, 12)
    wrench = [0.0, 0.0, -20.0, 0.0, 0.0, 0.0]
    loaded = trajectory_gains(puma, times, Q, QD, QDD, [100.0, 1.0], 0.01,
                              wrench=wrench)
    np.testing.assert_array_equal(
        loaded.tau0,
        trajectory_efforts(puma, traj['joint_names'], traj['points'],
                           wrench))
    assert np.abs(loaded.K - gains.K).max() > 0.0


def test_zero_drives_take_the_per_sample_path_to_the_same_gains(puma):
    _, (times, Q, QD, QDD) = _move(puma)
    batch = trajectory_gains(puma, times, Q, QD, QDD, [100.0, 1.0], 0.01)
    looped = trajectory_gains(puma, times, Q, QD, QDD, [100.0, 1.0], 0.01,
                              drives=Drives.zeros(6))
    np.testing.assert_allclose(looped.K, batch.K, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(looped.tau0, batch.tau0, rtol=0, atol=1e-12)


def smooth_reference(n, duration, dt, q0, amplitude):
    """q0 + a (1 - cos(w t)) / 2 per joint, different w: a moving target."""
    t = np.arange(int(round(duration / dt)) + 1) * dt
    w = np.pi * (1.0 + 0.3 * np.arange(n)) / duration
    Q = q0 + amplitude * (1.0 - np.cos(np.outer(t, w))) / 2
    QD = amplitude * w * np.sin(np.outer(t, w)) / 2
    QDD = amplitude * w ** 2 * np.cos(np.outer(t, w)) / 2
    return t, Q, QD, QDD


def closed_loop(model, t, Q, QD, tau0, gain, x0, substeps=4):
    """
    Semi-implicit Euler on forward dynamics, the law held each interval.

    ``gain(k)`` is the (n, 2n) gain of tau = tau0_k + K (x_ref_k - x).
    Returns (rms error, peak error, peak |tau - tau0|, rms error after
    0.25 s: once the start's transient is over).
    """
    n = model.n
    q, qd = x0[:n].copy(), x0[n:].copy()
    errors, peak_fb = [], 0.0
    for k in range(len(t) - 1):
        h = (t[k + 1] - t[k]) / substeps
        e = np.concatenate([Q[k] - q, QD[k] - qd])
        fb = gain(k) @ e
        peak_fb = max(peak_fb, np.abs(fb).max())
        errors.append(np.abs(Q[k] - q))
        for _ in range(substeps):
            qd = qd + h * forward_dynamics(model, q, qd, tau0[k] + fb)
            q = q + h * qd
    errors = np.array(errors)
    late = errors[t[:-1] >= 0.25]
    return (np.sqrt((errors ** 2).mean()), errors.max(), peak_fb,
            np.sqrt((late ** 2).mean()))


def test_lqr_tracks_better_than_pd_at_the_same_peak_torque(puma):
    n = puma.n
    q0 = np.array([0.0, 0.4, -0.6, 0.0, 0.3, 0.0])
    t, Q, QD, QDD = smooth_reference(n, 1.0, 0.004, q0, 0.8)
    gains = trajectory_gains(puma, t, Q, QD, QDD, [1e4, 1.0], 1e-2)
    x0 = np.concatenate([Q[0] + 0.05, QD[0]])
    lqr_rms, lqr_peak, lqr_fb, lqr_late = closed_loop(
        puma, t, Q, QD, gains.tau0, lambda k: gains.K[k], x0)
    # hand-tuned PD: critically damped on each joint's effective inertia
    # at the start, its bandwidth tuned to the LQR's peak feedback torque
    from newton_euler_ros.core import mass_matrix
    inertia = 1.0 / np.diag(np.linalg.inv(mass_matrix(puma, q0)))

    def pd(hz):
        w = 2 * np.pi * hz
        return np.hstack([np.diag(w ** 2 * inertia),
                          np.diag(2 * w * inertia)])
    hz = 10.0 * np.sqrt(lqr_fb / np.abs(pd(10.0)).max() / 0.05)
    for _ in range(6):
        K_pd = pd(hz)
        pd_rms, pd_peak, pd_fb, pd_late = closed_loop(
            puma, t, Q, QD, gains.tau0, lambda k: K_pd, x0)
        if abs(pd_fb / lqr_fb - 1.0) < 0.01:
            break
        hz *= np.sqrt(lqr_fb / pd_fb)
    message = (f'LQR rms {lqr_rms:.2e} peak {lqr_peak:.2e} rad, after '
               f'0.25 s rms {lqr_late:.2e} rad, peak feedback {lqr_fb:.1f} '
               f'N m; PD ({hz:.2f} Hz) rms {pd_rms:.2e} peak '
               f'{pd_peak:.2e} rad, after 0.25 s rms {pd_late:.2e} rad, '
               f'peak feedback {pd_fb:.1f} N m')
    assert abs(pd_fb / lqr_fb - 1.0) < 0.01, message
    # deterministic: 0.48 here (0.62 for the Panda in lqr_demo)
    assert lqr_rms < 0.6 * pd_rms, message
    assert lqr_late < 0.2 * pd_late, message     # 0.08 here


@pytest.mark.parametrize('change, match', [
    ({'state_weights': [1.0, 2.0, 3.0]}, 'state weights: 3 values, need 12'),
    ({'state_weights': -np.eye(12)}, 'state weights: must be positive '
                                     'semi-definite'),
    ({'input_weights': np.zeros((6, 6))}, 'input weights: must be positive '
                                          'definite'),
    ({'input_weights': np.ones((6, 5))}, r'input weights: shape \(6, 5\)'),
    ({'input_weights': np.triu(np.ones((6, 6)))}, 'must be symmetric'),
    ({'input_weights': 'heavy'}, 'input weights: must be numbers'),
    ({'state_weights': [np.nan, 1.0]}, 'state weights: must be finite'),
    ({'times': [0.0, 0.1, 0.1]}, 'times: sample 2 .* times must increase'),
    ({'times': [0.0]}, 'times: 1 sample'),
    ({'Q': np.zeros((3, 5))}, r'Q: shape \(3, 5\), need \(3, 6\)'),
    ({'QD': np.full((3, 6), np.inf)}, 'QD: must be finite'),
])
def test_input_errors_are_one_line(puma, change, match):
    args = {'times': [0.0, 0.1, 0.2], 'Q': np.zeros((3, 6)),
            'QD': np.zeros((3, 6)), 'QDD': np.zeros((3, 6)),
            'state_weights': [100.0, 1.0], 'input_weights': 0.01}
    args.update(change)
    if len(args['times']) == 1:
        for key in ('Q', 'QD', 'QDD'):
            args[key] = np.zeros((1, 6))
    with pytest.raises(LqrError, match=match) as info:
        trajectory_gains(puma, **args)
    assert '\n' not in str(info.value)
