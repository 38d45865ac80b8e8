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
Per-call cost of two checkouts side by side (did a change cost time).

    python -m newton_euler_tools.bench_compare BEFORE [--rounds N]

BEFORE is another checkout of the repository (``git worktree add
build/before COMMIT``).  Each round times the public single-state calls
(τ, D, C, g, forward dynamics, the regressor Y and the momentum
observer's terms on the Puma, the Panda, a random 100-link chain and
Centauro's whole tree, minimum of 60 × 2000 calls; 15 × 200 for the
100-link chain and Centauro) and the batch calls (τ, D and forward
dynamics of 100 Panda states) once in a process importing BEFORE's package and once in one
importing this one, alternately, so both see the same machine; the
table keeps each figure's minimum over the rounds.  Each checkout
compiles into a numba cache of its own (under ``build/``).
"""
import argparse
import json
import os
import subprocess
import sys

# run in the child: prints {"robot op": ns}
CHILD = r"""
import json, timeit
import warnings
import numpy as np
import newton_euler_ros.core as c
from newton_euler_ros.core import kernels as K
from newton_euler_tools.accuracy.chains import random_chain
from newton_euler_tools.peers import example_robot_urdf
out = {}
for name in ('puma560', 'panda', 'chain100', 'centauro'):
    if name == 'chain100':
        arm = random_chain(100, seed=3)
    elif name == 'centauro':
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            arm = c.load_urdf(example_robot_urdf(
                'centauro_description/urdf/centauro.urdf'))
    else:
        arm = c.load_robot(name)
    number, repeat = (2000, 60) if name in ('puma560', 'panda') else \
        (200, 15)
    ws = c.Workspace(arm)
    q, qd, qdd = np.random.default_rng(1).uniform(-1, 1, (3, arm.n))
    tau = c.inverse_dynamics(arm, q, qd, qdd, ws=ws)
    calls = {
        'tau': lambda: c.inverse_dynamics(arm, q, qd, qdd, ws=ws),
        'D': lambda: c.mass_matrix(arm, q, ws=ws),
        'C': lambda: c.coriolis_matrix(arm, q, qd, ws=ws),
        'g': lambda: c.gravity_torques(arm, q, ws=ws),
        'FD': lambda: c.forward_dynamics(arm, q, qd, tau, ws=ws),
        'Y': lambda: c.regressor(arm, q, qd, qdd),
        'terms': lambda: K.run_momentum_terms(arm.packed, q, qd, ws.ws,
                                              ws.cw, terms),
    }
    terms = np.empty((3, arm.n))
    if name == 'panda':
        Q, QD, QDD = np.random.default_rng(2).uniform(-1, 1, (3, 100, arm.n))
        TAU = c.inverse_dynamics_batch(arm, Q, QD, QDD, ws=ws)
        calls.update({
            'tau x100': lambda: c.inverse_dynamics_batch(arm, Q, QD, QDD,
                                                         ws=ws),
            'D x100': lambda: c.mass_matrix_batch(arm, Q, ws=ws),
            'FD x100': lambda: c.forward_dynamics_batch(arm, Q, QD, TAU,
                                                        ws=ws)})
    for op, f in calls.items():
        f()
        n_, r_ = (number, repeat) if 'x100' not in op else (20, 30)
        out[f'{name} {op}'] = min(timeit.repeat(f, number=n_,
                                                repeat=r_)) / n_ * 1e9
print(json.dumps(out))
"""

HERE = os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))))


def measure(package_root, cache):
    """Run CHILD importing the package under ``package_root``."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    env['PYTHONPATH'] = os.pathsep.join(
        [os.path.join(package_root, 'newton_euler_ros'),
         os.path.join(package_root, 'tools')]
        + [p for p in env.get('PYTHONPATH', '').split(os.pathsep) if p])
    proc = subprocess.run([sys.executable, '-c', CHILD], env=env,
                          capture_output=True, text=True, timeout=1200)
    if proc.returncode != 0:
        raise RuntimeError(f'{package_root}: {proc.stderr.strip()[-500:]}')
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main(argv=None):
    """Time both checkouts alternately; print the table; return 0."""
    parser = argparse.ArgumentParser(
        prog='python -m newton_euler_tools.bench_compare',
        description=__doc__.strip().split('\n')[0])
    parser.add_argument('before', help='another checkout of the repository')
    parser.add_argument('--rounds', type=int, default=5)
    args = parser.parse_args(argv)
    before = os.path.abspath(args.before)
    if not os.path.isdir(os.path.join(before, 'newton_euler_ros',
                                      'newton_euler_ros')):
        print(f'bench_compare: {args.before}: not a checkout of this '
              f'repository (no newton_euler_ros/newton_euler_ros)',
              file=sys.stderr)
        return 2
    build = os.path.join(HERE, 'build')
    runs = {'before': [], 'after': []}
    for r in range(args.rounds):
        runs['before'].append(measure(before, os.path.join(
            build, 'compare-cache-before')))
        runs['after'].append(measure(HERE, os.path.join(
            build, 'compare-cache-after')))
        print(f'round {r + 1} of {args.rounds}', flush=True)
    best = {k: {op: min(run[op] for run in v) for op in v[0]}
            for k, v in runs.items()}
    print(f'ns per call from Python, minimum over {args.rounds} alternating '
          f'rounds; before = {args.before}')
    print(f'{"call":18s} {"before":>8s} {"after":>8s}  change')
    worst = -1e9
    for op, b in best['before'].items():
        a = best['after'][op]
        change = 100 * (a / b - 1)
        worst = max(worst, change)
        print(f'{op:18s} {b:8.0f} {a:8.0f}  {change:+6.1f} %')
    print(f'largest increase: {worst:+.1f} %')
    return 0


if __name__ == '__main__':
    sys.exit(main())
