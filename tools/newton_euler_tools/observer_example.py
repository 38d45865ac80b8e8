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
A small example recording for ``newton-euler observe``.

    python -m newton_euler_tools.observer_example ROBOT OUT_BAG
        [--duration S] [--rate HZ] [--push FX FY FZ] [--push-at T0 T1]
        [--free] [--seed N]

The arm (a URDF or robot file, or a bundled robot) moves slowly about its
home pose; its drives apply the inverse-dynamics torques of that motion,
minus J^T F while the environment pushes on the tool with the force F
(base axes) between T0 and T1.  Sensor noise is added (encoder 1e-4 rad,
velocity 2e-3 rad/s, effort 0.05 N m) and the stamps jitter by 0.2 ms.
``--free`` records free motion only (to set thresholds).  Writes a
rosbag2 (MCAP) directory of sensor_msgs/JointState on /joint_states;
an existing recording at OUT_BAG is replaced.
"""
import argparse
import os
import shutil
import sys
import warnings

from newton_euler_ros.core import inspect_robot, NewtonEulerError
from newton_euler_ros.core.dynamics import inverse_dynamics, jacobian
from newton_euler_ros.ident.bag_write import write_joint_states
import numpy as np


def recording(model, duration, rate, push, push_at, seed=0):
    """Return stamps_ns, q, qd, effort (noisy) of the example motion."""
    rng = np.random.default_rng(seed)
    n = model.n
    t = np.arange(0.0, duration, 1.0 / rate)
    t = t + rng.uniform(-2e-4, 2e-4, t.size)
    t[0] = 0.0
    home = np.array([0.0, -0.6, 0.0, -2.0, 0.0, 1.5, 0.8, 0.0, 0.0,
                     0.0])[:n] if n <= 10 else np.zeros(n)
    amp = np.full(n, 0.2)
    w = 0.6 + 0.25 * np.arange(n)
    ph = w * t[:, None] + np.arange(n) * 0.9
    Q = home + amp * np.sin(ph)
    QD = amp * w * np.cos(ph)
    QDD = -amp * w ** 2 * np.sin(ph)
    TAU = np.empty_like(Q)
    F = np.zeros(6)
    F[:3] = push
    for k in range(t.size):
        on = push_at[0] <= t[k] < push_at[1]
        # drives: rigid-body torques, minus what the push provides
        TAU[k] = inverse_dynamics(model, Q[k], QD[k], QDD[k])
        if on:
            TAU[k] -= jacobian(model, Q[k]).T @ F
    Q += rng.normal(0.0, 1e-4, Q.shape)
    QD += rng.normal(0.0, 2e-3, QD.shape)
    TAU += rng.normal(0.0, 0.05, TAU.shape)
    stamps = (1_700_000_000_000_000_000 + np.round(t * 1e9)).astype(np.int64)
    return stamps, Q, QD, TAU


def main(argv=None):
    """Write the example bag; 0, or 2 with one line on bad input."""
    parser = argparse.ArgumentParser(
        prog='observer_example', description=__doc__.strip().split('\n')[0])
    parser.add_argument('robot')
    parser.add_argument('out', metavar='OUT_BAG')
    parser.add_argument('--base')
    parser.add_argument('--tip')
    parser.add_argument('--duration', type=float, default=6.0)
    parser.add_argument('--rate', type=float, default=500.0)
    parser.add_argument('--push', type=float, nargs=3,
                        default=[0.0, 0.0, -20.0])
    parser.add_argument('--push-at', type=float, nargs=2,
                        default=[2.5, 4.0], metavar=('T0', 'T1'))
    parser.add_argument('--free', action='store_true')
    parser.add_argument('--seed', type=int, default=0)
    args = parser.parse_args(argv)
    if not (0.0 < args.duration <= 600.0 and 1.0 <= args.rate <= 10000.0):
        print('observer_example: --duration must be in (0, 600] s and '
              '--rate in [1, 10000] Hz', file=sys.stderr)
        return 2
    try:
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            model, _, _ = inspect_robot(args.robot, base=args.base,
                                        tip=args.tip)
    except NewtonEulerError as exc:
        print(f'observer_example: {exc}', file=sys.stderr)
        return 2
    if os.path.exists(args.out):
        if not os.path.isfile(os.path.join(args.out, 'metadata.yaml')):
            print(f'observer_example: {args.out} exists and is not a '
                  f'rosbag2 recording; not replacing it', file=sys.stderr)
            return 2
        shutil.rmtree(args.out)
    push = np.zeros(3) if args.free else np.array(args.push)
    stamps, Q, QD, TAU = recording(model, args.duration, args.rate, push,
                                   args.push_at, args.seed)
    write_joint_states(args.out, stamps, model.joint_names, Q, QD, TAU)
    what = ('free motion' if args.free else
            f'a push {push.tolist()} N on the tool from '
            f'{args.push_at[0]} s to {args.push_at[1]} s')
    print(f'wrote {args.out}: {len(stamps)} JointStates of {model.name} '
          f'over {args.duration} s, {what}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
