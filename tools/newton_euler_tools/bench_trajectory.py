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
What trajectory feedforward costs per point.

    python -m newton_euler_tools.bench_trajectory [--quick]

Times :func:`~newton_euler_ros.core.trajectory.trajectory_efforts` (the
CLI's ``feedforward`` and the node's ``~/trajectory_in`` path) on a
1000-point trajectory, with the derivatives given and with them derived
from the positions, against a Python loop of single ``inverse_dynamics``
calls over the same points, side by side in one run.
"""
import warnings

from newton_euler_ros.core import inverse_dynamics, load_robot
from newton_euler_ros.core.trajectory import trajectory_efforts
import numpy as np

from .timing import min_time, quick_option

POINTS = 1000


def main(argv=None):
    """Print microseconds per trajectory point."""
    quick = quick_option(__doc__, 'fewer repeats', argv)
    repeat = 3 if quick else 15
    print(f'trajectory efforts, {POINTS} points, best of {repeat} '
          f'(us per point)')
    print(f'{"robot":<10}{"given qd, qdd":>16}{"derived":>12}'
          f'{"loop of ID":>14}')
    for name in ('puma560', 'panda'):
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            model = load_robot(name)
        t = np.linspace(0.0, 10.0, POINTS)
        Q = 0.5 * np.sin(np.outer(t, np.arange(1, model.n + 1) * 0.3))
        QD = np.gradient(Q, t, axis=0)
        QDD = np.gradient(QD, t, axis=0)
        names = list(model.joint_names)
        full = [{'time_from_start': t[k], 'positions': Q[k],
                 'velocities': QD[k], 'accelerations': QDD[k]}
                for k in range(POINTS)]
        bare = [{'time_from_start': t[k], 'positions': Q[k]}
                for k in range(POINTS)]

        def loop():
            for k in range(POINTS):
                inverse_dynamics(model, Q[k], QD[k], QDD[k])
        cells = [min_time(lambda: trajectory_efforts(model, names, full),
                          1, repeat),
                 min_time(lambda: trajectory_efforts(model, names, bare),
                          1, repeat),
                 min_time(loop, 1, repeat)]
        print(f'{name:<10}' + ''.join(
            f'{c / POINTS * 1e6:>{w}.2f}' for c, w in zip(cells,
                                                          (16, 12, 14))))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
