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
The torque regressor's cost per state, batched, against Pinocchio.

    python -m newton_euler_tools.bench_regressor [--quick]

Ours: ``regressor_batch`` over m states (one compiled loop), divided by m.
Pinocchio: a Python loop of ``pin.computeJointTorqueRegressor``, the way
a user stacks it for identification, per state.  Both on the same
published URDFs (example-robot-data).  Target: ours <= 0.5x Pinocchio.
"""
import warnings

from newton_euler_ros.core import load_robot
from newton_euler_ros.core.regressor import regressor_batch
import numpy as np

from .timing import min_time, quick_option

TARGET = 0.5
ROBOTS = (('panda', 'panda_description/urdf/panda.urdf', 'panda_hand_tcp'),
          ('ur5', 'ur_description/urdf/ur5_robot.urdf', 'tool0'))


def measure(label, relative, tip, m, repeat):
    """Return (ours, pinocchio) seconds per state."""
    import pinocchio as pin
    from .peers import example_robot_urdf, PinocchioUrdf
    path = example_robot_urdf(relative)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot(path, tip=tip)
    peer = PinocchioUrdf(path, model.joint_names, model.info['urdf']['tip'])
    rng = np.random.default_rng(0)
    Q, QD, QDD = rng.uniform(-1, 1, (3, m, model.n))
    X = [peer.config(q) for q in Q]
    out = np.empty((m, model.n, 10 * model.n))

    def ours():
        regressor_batch(model, Q, QD, QDD, out=out)

    def theirs():
        for i in range(m):
            pin.computeJointTorqueRegressor(peer.model, peer.data, X[i],
                                            QD[i], QDD[i])

    return min_time(ours, 1, repeat) / m, min_time(theirs, 1, repeat) / m


def main(argv=None):
    """Print the per-state table."""
    quick = quick_option(__doc__, 'fewer states and repeats (noisier)', argv)
    m, repeat = (500, 3) if quick else (5000, 7)
    print(f'torque regressor per state, batch of {m}, best of {repeat} '
          f'(us); target ours <= {TARGET}x a Python loop of Pinocchio')
    print(f'{"robot":<8}{"n":>3}{"ours":>10}{"pinocchio":>12}{"ratio":>8}'
          f'  verdict')
    ok = True
    for label, relative, tip in ROBOTS:
        try:
            ours, theirs = measure(label, relative, tip, m, repeat)
        except ImportError as exc:
            print(f'{label}: skipped ({exc})')
            continue
        ratio = ours / theirs
        ok &= ratio <= TARGET
        n = 7 if label == 'panda' else 6
        print(f'{label:<8}{n:>3}{ours * 1e6:10.2f}{theirs * 1e6:12.2f}'
              f'{ratio:8.2f}  {"PASS" if ratio <= TARGET else "MISS"}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
