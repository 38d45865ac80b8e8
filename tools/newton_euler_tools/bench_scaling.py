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
How the cost of every operation grows with the chain length, against Pinocchio.

    python -m newton_euler_tools.bench_scaling [--quick] [--json PATH]

Random chains (``accuracy.chains.random_chain``: a fifth of the joints
prismatic, links 5-30 cm) of n = 6 .. 200 joints.  For each n it first
checks that Pinocchio's model gives the same tau, D, C, g and forward
dynamics as ours (a wrongly built peer would make its timing worthless),
then times one call from Python of each operation, ours and Pinocchio's
side by side (repeats interleaved, as in ``bench``), and fits the growth
exponent k of time ~ n^k on log-log axes over n >= 25, where the fixed
per-call cost no longer dominates.

Targets at n = 100 (PASS/MISS from this run): C <= 1.25x
``pin.computeCoriolisMatrix`` and forward dynamics (ABA) <= 1.5x
``pin.aba``.  Our n-recursion C and Cholesky forward dynamics are timed
too, to show what the O(n^2) and O(n) algorithms buy.
"""
import argparse
import json
import math
import sys
import warnings

from newton_euler_ros.core import (coriolis_matrix, forward_dynamics,
                                   gravity_torques, inverse_dynamics,
                                   mass_matrix)
import numpy as np

from . import peers
from .accuracy.chains import random_chain, random_states
from .bench import Timer

SIZES = (6, 12, 25, 50, 100, 200)
QUICK_SIZES = (6, 25, 100)
FIT_FROM = 25
TARGET_N = 100
TARGETS = {'C': 1.25, 'FD': 1.5}
OURS = {
    'tau': 'inverse_dynamics(model, q, qd, qdd, ws=ws, out=v)',
    'D': 'mass_matrix(model, q, ws=ws, out=M)',
    'C': 'coriolis_matrix(model, q, qd, ws=ws, out=M)',
    'C (n recursions)': "coriolis_matrix(model, q, qd, method='newton_euler',"
                        ' ws=ws, out=M)',
    'g': 'gravity_torques(model, q, ws=ws, out=v)',
    'FD': 'forward_dynamics(model, q, qd, qdd, ws=ws, out=v)',
    'FD (Cholesky)': "forward_dynamics(model, q, qd, qdd, method='cholesky',"
                     ' ws=ws, out=v)',
}
PIN = {'tau': 'pin.rnea(pm, pd, q, qd, qdd)', 'D': 'pin.crba(pm, pd, q)',
       'C': 'pin.computeCoriolisMatrix(pm, pd, q, qd)',
       'g': 'pin.computeGeneralizedGravity(pm, pd, q)',
       'FD': 'pin.aba(pm, pd, q, qd, qdd)'}


def _check(model, pin, pm, pd, state):
    """Return the worst relative difference ours vs Pinocchio."""
    q, qd, qdd = state
    M = np.array(pin.crba(pm, pd, q))
    M = np.triu(M) + np.triu(M, 1).T
    pairs = [
        (inverse_dynamics(model, q, qd, qdd), pin.rnea(pm, pd, q, qd, qdd)),
        (mass_matrix(model, q), M),
        (coriolis_matrix(model, q, qd),
         pin.computeCoriolisMatrix(pm, pd, q, qd)),
        (gravity_torques(model, q), pin.computeGeneralizedGravity(pm, pd, q)),
    ]
    worst = max(float(np.max(np.abs(a - np.asarray(b)))
                      / max(1.0, float(np.max(np.abs(a))))) for a, b in pairs)
    # forward dynamics: the error grows with cond(D); compare residuals
    a = forward_dynamics(model, q, qd, qdd)
    b = np.asarray(pin.aba(pm, pd, q, qd, qdd))
    D = mass_matrix(model, q)
    fd = float(np.max(np.abs(D @ (a - b)))) / max(
        1.0, float(np.max(np.abs(qdd))))
    return max(worst, fd)


def fit_exponent(ns, times):
    """Least-squares slope of log(time) against log(n)."""
    x = np.log(np.asarray(ns, dtype=float))
    y = np.log(np.asarray(times, dtype=float))
    return float(np.polyfit(x, y, 1)[0])


def run(sizes, timer, log):
    try:
        import pinocchio as pin
    except Exception as exc:           # the peers are optional
        log(f'Pinocchio not importable ({type(exc).__name__}): ours only')
        pin = None
    rows = {}
    for n in sizes:
        model = random_chain(n, seed=3)
        state = random_states(model, 1, seed=3)[0]
        q, qd, qdd = state
        ns = {'model': model, 'q': q, 'qd': qd, 'qdd': qdd,
              'ws': model.default_workspace, 'v': np.empty(n),
              'M': np.empty((n, n)), 'inverse_dynamics': inverse_dynamics,
              'mass_matrix': mass_matrix, 'coriolis_matrix': coriolis_matrix,
              'gravity_torques': gravity_torques,
              'forward_dynamics': forward_dynamics}
        entries = {('ours', op): (stmt, ns, None, 1)
                   for op, stmt in OURS.items()}
        check = None
        if pin is not None:
            pm = peers.pinocchio_model(model)
            pd = pm.createData()
            check = _check(model, pin, pm, pd, state)
            pns = {'pin': pin, 'pm': pm, 'pd': pd, 'q': q, 'qd': qd,
                   'qdd': qdd}
            entries.update({('pin', op): (stmt, pns, None, 1)
                            for op, stmt in PIN.items()})
        times = timer.group(entries)
        rows[n] = {'check': check,
                   'us': {f'{who} {op}': t['min_us']
                          for (who, op), t in times.items()}}
        log(f'n = {n:3d}: timed' + ('' if check is None else
                                    f'; Pinocchio agrees to {check:.1e}'))
    return rows


def report(rows, log):
    sizes = sorted(rows)
    keys = [f'ours {op}' for op in OURS] + [f'pin {op}' for op in PIN]
    keys = [k for k in keys if all(k in rows[n]['us'] for n in sizes)]
    log('\nmicroseconds per call from Python, min of the repeats')
    head = f'{"operation":<24}' + ''.join(f'{f"n={n}":>10}' for n in sizes) \
        + f'{"exponent":>10}'
    log(head)
    log('-' * len(head))
    fit_ns = [n for n in sizes if n >= FIT_FROM]
    exponents = {}
    for key in keys:
        ts = [rows[n]['us'][key] for n in sizes]
        k = (fit_exponent(fit_ns, [rows[n]['us'][key] for n in fit_ns])
             if len(fit_ns) >= 2 else math.nan)
        exponents[key] = k
        log(f'{key:<24}' + ''.join(f'{t:10.2f}' for t in ts) + f'{k:10.2f}')
    log(f'(exponent: slope of log time against log n over n >= {FIT_FROM})')
    verdicts = {}
    if TARGET_N in rows:
        us = rows[TARGET_N]['us']
        log(f'\ntargets at n = {TARGET_N}:')
        for op, limit in TARGETS.items():
            if f'pin {op}' not in us:
                continue
            ratio = us[f'ours {op}'] / us[f'pin {op}']
            verdict = 'PASS' if ratio <= limit else 'MISS'
            verdicts[op] = {'ratio': ratio, 'target': limit,
                            'verdict': verdict}
            log(f'  {op:<4} ours {us[f"ours {op}"]:8.2f} us, Pinocchio '
                f'{us[f"pin {op}"]:8.2f} us: {ratio:.2f}x (<= {limit:g}x) '
                f'{verdict}')
    return exponents, verdicts


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog='python -m newton_euler_tools.bench_scaling',
        description='Cost growth with the chain length, against Pinocchio.')
    parser.add_argument('--quick', action='store_true',
                        help=f'n in {QUICK_SIZES} and short repeats')
    parser.add_argument('--json', metavar='PATH',
                        help='write the figures to this JSON file')
    args = parser.parse_args(argv)

    def log(line=''):
        print(line, flush=True)

    log('newton_euler_ros scaling benchmark  ' + '  '.join(
        f'{k} {v}' for k, v in peers.versions().items()))
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        rows = run(QUICK_SIZES if args.quick else SIZES, Timer(args.quick),
                   log)
    exponents, verdicts = report(rows, log)
    if args.json:
        with open(args.json, 'w') as fh:
            json.dump({'rows': {str(n): r for n, r in rows.items()},
                       'exponents': exponents, 'verdicts': verdicts}, fh,
                      indent=1)
        log(f'wrote {args.json}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
