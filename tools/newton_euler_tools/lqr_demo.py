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
Time-varying LQR along a trajectory against PD at the same peak torque.

    python -m newton_euler_tools.lqr_demo [--quick]

A Panda arm follows a smooth moving trajectory (every joint, 0.8 rad
swings at different rates) from 0.05 rad off on every joint, with the
inverse-dynamics feedforward plus either the LQR gains of
``core.lqr.trajectory_gains`` (tau = tau0 + K (x_ref - x)) or a PD law
(critically damped on each joint's effective inertia 1 / (D^-1)_jj at
the start) whose bandwidth is tuned until its peak feedback torque
equals the LQR run's.  The plants:
the library's forward dynamics (semi-implicit Euler, four steps per
control period) and, when MuJoCo is installed, MuJoCo's physics of the
same robot.  Prints the RMS and peak position error and the peak
feedback torque of each run, and the RMS error once the start's
transient is over.  ``--quick``: 1 s instead of 2 s.
"""
import os
import time
import warnings

# small matrices: BLAS threads only contend (a 21 x 21 expm took 1.6 ms
# with them on two loaded cores, 0.09 ms without); before numpy loads
os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')

from newton_euler_ros.core import (forward_dynamics, load_robot,  # noqa: E402
                                   mass_matrix)
from newton_euler_ros.core.lqr import trajectory_gains  # noqa: E402
import numpy as np  # noqa: E402

from .timing import quick_option  # noqa: E402

ROBOT = 'panda'
Q0 = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.8])
AMPLITUDE = 0.8          # rad
OFFSET = 0.05            # rad, the start off the reference on every joint
CONTROL_DT = 0.002       # s, 500 Hz
SUBSTEPS = 4
STATE_WEIGHTS = [1e4, 1.0]      # per rad^2, per (rad/s)^2
INPUT_WEIGHT = 1e-2             # per (N m)^2
PD_HZ = 10.0            # the first guess
SETTLED = 0.25          # s: the rms error after the start's transient


def smooth_reference(n, duration, dt):
    """q0 + a (1 - cos(w t)) / 2 per joint, a different w on each."""
    t = np.arange(int(round(duration / dt)) + 1) * dt
    w = np.pi * (1.0 + 0.3 * np.arange(n)) / duration
    Q = Q0 + AMPLITUDE * (1.0 - np.cos(np.outer(t, w))) / 2
    QD = AMPLITUDE * w * np.sin(np.outer(t, w)) / 2
    QDD = AMPLITUDE * w ** 2 * np.cos(np.outer(t, w)) / 2
    return t, Q, QD, QDD


class LibraryPlant:
    """The library's forward dynamics, semi-implicit Euler."""

    name = 'library forward dynamics'

    def __init__(self, model, q0):
        self.model, self.q, self.qd = model, q0.copy(), np.zeros(model.n)

    def advance(self, tau, duration):
        h = duration / SUBSTEPS
        for _ in range(SUBSTEPS):
            self.qd = self.qd + h * forward_dynamics(self.model, self.q,
                                                     self.qd, tau)
            self.q = self.q + h * self.qd

    def state(self):
        return self.q, self.qd


def mujoco_plant_factory(model):
    """Return a factory of MuJoCo plants of ``model``, or None."""
    try:
        import mujoco  # noqa: F401 (only whether it is there)
        from newton_euler_ros.sim.mujoco_model import load_mujoco
        from newton_euler_ros.sim.mujoco_plant import MujocoPlant
    except ImportError:
        return None
    robot = load_mujoco(model, timestep=CONTROL_DT / SUBSTEPS)
    order = [list(robot.joints).index(j) for j in model.joint_names]

    class Plant:
        name = 'MuJoCo'

        def __init__(self, q0):
            q = np.empty(model.n)
            q[order] = q0
            self.plant = MujocoPlant(robot, q)
            self.plant.release()

        def advance(self, tau, duration):
            u = np.empty(model.n)
            u[order] = tau
            self.plant.advance(u, duration)

        def state(self):
            q, qd = self.plant.state()
            return q[order], qd[order]

    return Plant


def track(plant, t, Q, QD, tau0, gain):
    """
    Run the law; return the errors and the peak |tau - tau0|.

    (rms error, peak error, peak feedback, rms error after ``SETTLED``).
    """
    errors, peak_fb = [], 0.0
    for k in range(len(t) - 1):
        q, qd = plant.state()
        fb = gain(k) @ np.concatenate([Q[k] - q, QD[k] - qd])
        peak_fb = max(peak_fb, float(np.abs(fb).max()))
        errors.append(np.abs(Q[k] - q))
        plant.advance(tau0[k] + fb, t[k + 1] - t[k])
    errors = np.array(errors)
    late = errors[t[:-1] >= SETTLED]
    return (float(np.sqrt((errors ** 2).mean())), float(errors.max()),
            peak_fb, float(np.sqrt((late ** 2).mean())))


def pd_gains(model, hz):
    """Critically damped PD at ``hz`` on each joint's effective inertia."""
    m = 1.0 / np.diag(np.linalg.inv(mass_matrix(model, Q0)))
    w = 2 * np.pi * hz
    return np.hstack([np.diag(w ** 2 * m), np.diag(2 * w * m)])


def compare(make_plant, model, t, Q, QD, gains):
    """LQR, then PD tuned to the LQR's peak feedback torque."""
    x0 = Q[0] + OFFSET
    lqr = track(make_plant(x0), t, Q, QD, gains.tau0, lambda k: gains.K[k])
    # the first feedback is Kp * OFFSET: start there, then adjust
    hz = PD_HZ * np.sqrt(lqr[2] / np.abs(pd_gains(model, PD_HZ)).max()
                         / OFFSET)
    for _ in range(6):
        pd = pd_gains(model, hz)
        result = track(make_plant(x0), t, Q, QD, gains.tau0, lambda k: pd)
        if abs(result[2] / lqr[2] - 1.0) < 0.01:
            break
        hz *= np.sqrt(lqr[2] / result[2])
    return lqr, result, hz


def main(argv=None):
    quick = quick_option(__doc__, 'simulate 1 s instead of 2 s', argv)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot(ROBOT)
    duration = 1.0 if quick else 2.0
    t, Q, QD, QDD = smooth_reference(model.n, duration, CONTROL_DT)
    start = time.perf_counter()
    gains = trajectory_gains(model, t, Q, QD, QDD, STATE_WEIGHTS,
                             INPUT_WEIGHT)
    took = time.perf_counter() - start
    print(f'{ROBOT}: {len(t)} samples at {1 / CONTROL_DT:.0f} Hz over '
          f'{duration:g} s, start {OFFSET} rad off on every joint; gains '
          f'(Q = {STATE_WEIGHTS[0]:g},{STATE_WEIGHTS[1]:g}, R = '
          f'{INPUT_WEIGHT:g}) in {took:.2f} s')
    plants = [('library forward dynamics',
               lambda x0: LibraryPlant(model, x0))]
    factory = mujoco_plant_factory(model)
    if factory is None:
        print('MuJoCo: not installed, skipped')
    else:
        plants.append(('MuJoCo', factory))
    print(f'{"plant":<26} {"law":<4} {"rms error":>12} {"peak error":>12} '
          f'{"peak feedback":>14} {"rms after " + str(SETTLED) + " s":>16}')
    for name, make in plants:
        lqr, pd, hz = compare(make, model, t, Q, QD, gains)
        for law, (rms, peak, fb, late) in (('LQR', lqr), ('PD', pd)):
            print(f'{name:<26} {law:<4} {rms:>8.2e} rad {peak:>8.2e} rad '
                  f'{fb:>10.1f} N m {late:>12.2e} rad')
        print(f'{name:<26} PD at {hz:.2f} Hz; LQR rms error '
              f'{lqr[0] / pd[0]:.2f} of the PD one, after {SETTLED} s '
              f'{lqr[3] / pd[3]:.2f}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
