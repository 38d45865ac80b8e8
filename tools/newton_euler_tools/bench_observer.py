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
What the momentum observer adds per JointState.

    python -m newton_euler_tools.bench_observer [--robot NAME] [--quick]

Times one observer update as the node makes it (residual, wrench and
contact for one sample), and its parts: the model terms it needs (D, C,
g, J, each one compiled call) and the observer's own arithmetic.  The
target is 10 microseconds on a 7-joint arm.
"""
import argparse
import time
import warnings

from newton_euler_ros.core import load_robot
from newton_euler_ros.core.dynamics import (coriolis_matrix, gravity_torques,
                                            jacobian, mass_matrix)
from newton_euler_ros.core.observer import (contact_step, external_wrench,
                                            initial_contact, initial_state,
                                            MomentumObserver, observer_step)
import numpy as np

TARGET_US = 10.0


def _min_time(fn, number, repeat):
    """Return the best time per call of ``fn`` in microseconds."""
    fn()
    best = float('inf')
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(number):
            fn()
        best = min(best, (time.perf_counter() - start) / number)
    return best * 1e6


def measure(model, number, repeat):
    """Return [(label, microseconds)], the full update first."""
    obs = MomentumObserver(model, gain=50.0, thresholds=5.0)
    obs.warm_up()
    rng = np.random.default_rng(0)
    n = model.n
    q, qd, tau = rng.uniform(-1.0, 1.0, size=(3, n))
    state, contact = initial_state(obs), initial_contact(obs)
    clock = [0.0]

    def update():
        clock[0] += 1e-3
        r, _ = observer_step(obs, state, clock[0], q, qd, tau)
        external_wrench(obs, q, r, out=obs_F)
        contact_step(obs, contact, r)

    obs_F = np.zeros(6)
    ws = obs.ws
    rows = [('observer update (residual + wrench + contact)',
             _min_time(update, number, repeat))]
    parts = [
        ('  D(q), mass_matrix',
         lambda: mass_matrix(model, q, ws=ws, out=obs.D)),
        ('  C(q, qd), coriolis_matrix',
         lambda: coriolis_matrix(model, q, qd, ws=ws, out=obs.C)),
        ('  g(q), gravity_torques',
         lambda: gravity_torques(model, q, ws=ws, out=obs.g)),
        ('  J(q), jacobian', lambda: jacobian(model, q, ws=ws, out=obs.J)),
    ]
    for label, fn in parts:
        rows.append((label, _min_time(fn, number, repeat)))
    terms = sum(t for _, t in rows[1:])
    rows.append(('  observer arithmetic and Python (the rest)',
                 rows[0][1] - terms))
    return rows


def main(argv=None):
    """Print the table and the verdict against the 10 us target."""
    parser = argparse.ArgumentParser(prog='bench_observer',
                                     description=__doc__.strip().split(
                                         '\n')[0])
    parser.add_argument('--robot', default='panda',
                        help='bundled robot (default panda, 7 joints)')
    parser.add_argument('--quick', action='store_true',
                        help='fewer repetitions')
    args = parser.parse_args(argv)
    number, repeat = (500, 3) if args.quick else (20000, 7)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot(args.robot)
    rows = measure(model, number, repeat)
    print(f'\nmomentum observer, {model.name} ({model.n} joints): '
          f'microseconds per JointState, best of {repeat}')
    for label, us in rows:
        print(f'{label:<50}{us:>8.2f}')
    total = rows[0][1]
    verdict = 'meets' if total <= TARGET_US else 'MISSES'
    print(f'observer: {total:.2f} us per JointState, {verdict} the '
          f'{TARGET_US:.0f} us target')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
