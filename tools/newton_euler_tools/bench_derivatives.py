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
Analytical derivatives per call from Python, against Pinocchio's.

    python -m newton_euler_tools.bench_derivatives [--quick]

Per call, best of several rounds, side by side in one run (each round
times every call in turn):
``inverse_dynamics_derivatives`` against ``pin.computeRNEADerivatives``
and ``forward_dynamics_derivatives`` against ``pin.computeABADerivatives``,
on the Panda arm (7 joints, the chain to its flange) and on Centauro's
whole tree (39 joints); then the batched forms per state against a
Python loop of Pinocchio's calls, in one thread and shared among one
thread a core (their default).  Both read the same published URDFs
(example-robot-data).  Targets (issue 39): per call <= 1.0x Pinocchio on
the arm and <= 0.8x on Centauro; batched at least 3x faster per state.
"""
import warnings

from newton_euler_ros.core import (forward_dynamics_derivatives,
                                   forward_dynamics_derivatives_batch,
                                   inverse_dynamics_derivatives,
                                   inverse_dynamics_derivatives_batch,
                                   load_robot, load_urdf, Workspace)
from newton_euler_ros.core.batch import usable_cores
import numpy as np

from .timing import min_times, quick_option

ROBOTS = (('panda', 'panda_description/urdf/panda.urdf', 'panda_link8',
           1.0),
          ('centauro', 'centauro_description/urdf/centauro.urdf', None, 0.8))
BATCH_TARGET = 1 / 3


def _peer(relative, tip):
    """Return (our model, Pinocchio model, data, config of our q)."""
    from .peers import example_robot_urdf, PinocchioTree, PinocchioUrdf
    path = example_robot_urdf(relative)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        if tip is None:
            model = load_urdf(path)
            peer = PinocchioTree(path, model)
            return model, peer.model, peer.data, peer.config, peer.vector
        model = load_robot(path, tip=tip)
    peer = PinocchioUrdf(path, model.joint_names, tip)
    return model, peer.model, peer.data, peer.config, np.asarray


def measure(relative, tip, number, repeat, m):
    """Return seconds per call: ours and Pinocchio's, single and batched."""
    import pinocchio as pin
    model, pm, pd, config, vector = _peer(relative, tip)
    n = model.n
    rng = np.random.default_rng(0)
    Q, QD, QDD, TAU = rng.uniform(-1, 1, (4, m, n))
    q, qd, qdd, tau = Q[0], QD[0], QDD[0], TAU[0]
    x = config(q)
    v, a, t = vector(qd), vector(qdd), vector(tau)
    ws = Workspace(model)
    out2 = np.empty((2, n, n))
    out3 = np.empty((3, n, n))
    X = [config(r) for r in Q]
    V = [vector(r) for r in QD]
    A = [vector(r) for r in QDD]
    T = [vector(r) for r in TAU]
    outb2 = np.empty((m, 2, n, n))
    outb3 = np.empty((m, 3, n, n))

    def loop_rnea():
        for i in range(m):
            pin.computeRNEADerivatives(pm, pd, X[i], V[i], A[i])

    def loop_aba():
        for i in range(m):
            pin.computeABADerivatives(pm, pd, X[i], V[i], T[i])

    calls = {
        'ours dtau': lambda: inverse_dynamics_derivatives(
            model, q, qd, qdd, ws=ws, out=out2),
        'pin dtau': lambda: pin.computeRNEADerivatives(pm, pd, x, v, a),
        'ours dqdd': lambda: forward_dynamics_derivatives(
            model, q, qd, tau, ws=ws, out=out3),
        'pin dqdd': lambda: pin.computeABADerivatives(pm, pd, x, v, t),
    }
    times = min_times(calls, number, repeat)
    batches = {}
    for tag, threads in (('batch1', 1), ('batch', None)):
        batches[f'ours dtau {tag}'] = (
            lambda t=threads: inverse_dynamics_derivatives_batch(
                model, Q, QD, QDD, threads=t, ws=ws, out=outb2))
        batches[f'ours dqdd {tag}'] = (
            lambda t=threads: forward_dynamics_derivatives_batch(
                model, Q, QD, TAU, threads=t, ws=ws, out=outb3))
    batches['pin dtau batch'] = loop_rnea
    batches['pin dqdd batch'] = loop_aba
    for name, seconds in min_times(batches, 1, repeat).items():
        times[name] = seconds / m
    times['pin dtau batch1'] = times['pin dtau batch']
    times['pin dqdd batch1'] = times['pin dqdd batch']
    return n, times


def main(argv=None):
    """Print the table: us per call, ratios, verdicts."""
    quick = quick_option(__doc__, 'fewer calls and rounds (noisier)', argv)
    number, repeat, m = (200, 5, 50) if quick else (2000, 7, 500)
    print(f'derivatives per call from Python, best of {repeat} rounds of '
          f'{number} calls (batches: {m} states), us')
    print(f'{"robot":<9}{"n":>3}  {"call":<6}{"ours":>8}{"pinocchio":>11}'
          f'{"ratio":>7}{"target":>8}  verdict')
    for label, relative, tip, target in ROBOTS:
        try:
            n, t = measure(relative, tip, number, repeat, m)
        except ImportError as exc:
            print(f'{label}: skipped ({exc})')
            continue
        for call, limit in (('dtau', target), ('dqdd', target),
                            ('dtau batch1', BATCH_TARGET),
                            ('dqdd batch1', BATCH_TARGET),
                            ('dtau batch', BATCH_TARGET),
                            ('dqdd batch', BATCH_TARGET)):
            ours, theirs = t[f'ours {call}'], t[f'pin {call}']
            ratio = ours / theirs
            name = call.replace(' batch', '/b')
            print(f'{label:<9}{n:>3}  {name:<6}{ours * 1e6:8.2f}'
                  f'{theirs * 1e6:11.2f}{ratio:7.2f}{limit:8.2f}  '
                  f'{"PASS" if ratio <= limit else "MISS"}')
    print('dtau: inverse_dynamics_derivatives vs computeRNEADerivatives; '
          'dqdd: forward_dynamics_derivatives vs computeABADerivatives; /b: '
          'batched, per state, vs a Python loop of Pinocchio calls (/b1: '
          f'in one thread; /b: shared among {usable_cores()} threads, one a '
          'core)')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
