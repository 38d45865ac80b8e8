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
A URDF arm costs what a DH arm of the same size costs, per call.

    python -m newton_euler_tools.bench_urdf [--quick]

Times tau, D (CRBA), C and g side by side in one run on: the Puma 560 from
its DH table; the same Puma written as URDF and loaded back (every joint a
general placement, not DH); and, when ``make peers`` installed
``example-robot-data``, the UR5 and the Panda from their published URDFs.
Both kinds compile to the same kernel arrays, so the per-call cost should
not depend on the source: the ratio column shows it.
"""
import warnings

from newton_euler_ros.core import (coriolis_matrix, gravity_torques,
                                   inverse_dynamics, load_robot, mass_matrix)
from newton_euler_ros.core.urdf import load_urdf, model_to_urdf
import numpy as np

from .bench_effects import _min_time
from .timing import quick_option

PUBLISHED = (('ur5 (URDF)', 'ur_description/urdf/ur5_robot.urdf', 'tool0'),
             ('panda (URDF)', 'panda_description/urdf/panda.urdf',
              'panda_hand_tcp'))


def robots():
    """Yield (label, model): the DH reference first."""
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        puma = load_robot('puma560')
        yield 'puma560 (DH)', puma
        yield 'puma560 (URDF)', load_urdf(model_to_urdf(puma))
        try:
            from .peers import example_robot_urdf
            for label, relative, tip in PUBLISHED:
                yield label, load_robot(example_robot_urdf(relative),
                                        tip=tip)
        except ImportError:
            print('(example-robot-data not installed: make peers adds the '
                  'UR5 and Panda URDFs)')


def main(argv=None):
    """Print the per-call table."""
    quick = quick_option(__doc__, 'fewer repeats (noisier)', argv)
    number, repeat = (2000, 3) if quick else (20000, 7)
    rng = np.random.default_rng(0)
    rows = []
    for label, model in robots():
        q, qd, qdd = rng.uniform(-1, 1, size=(3, model.n))
        calls = {
            'tau': lambda m=model: inverse_dynamics(m, q, qd, qdd),
            'D': lambda m=model: mass_matrix(m, q),
            'C': lambda m=model: coriolis_matrix(m, q, qd),
            'g': lambda m=model: gravity_torques(m, q),
        }
        rows.append((label, model.n, {k: _min_time(f, number, repeat)
                                      for k, f in calls.items()}))
    ref = rows[0][2]
    print(f'per call from Python, best of {repeat} x {number} (us); '
          f'ratio to {rows[0][0]}')
    print(f'{"robot":<16}{"n":>3}' + ''.join(
        f'{k:>16}' for k in ('tau', 'D', 'C', 'g')))
    for label, n, times in rows:
        cells = ''.join(f'{times[k]:8.2f} ({times[k] / ref[k]:4.2f}x)'
                        for k in ('tau', 'D', 'C', 'g'))
        print(f'{label:<16}{n:>3}{cells}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
