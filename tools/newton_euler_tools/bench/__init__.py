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
Benchmark our Newton-Euler dynamics and check the performance targets.

The peers are Pinocchio, Robotics Toolbox and a naive numpy recursion.

    python -m newton_euler_tools.bench [--quick] [--json PATH]
                                     [--robot NAME ...] [--seed N]

For each robot (default: the bundled ``puma560`` and ``panda``) it

1. checks that the peer models built by :mod:`newton_euler_tools.peers` give
   the same tau, D, C and g as ours at random states (a timing of a wrongly
   built peer model is worthless, so a peer that disagrees is marked
   INVALID and no verdict is drawn from it);
2. times one call from Python of each operation, warm (JIT compilation
   excluded): ``time.perf_counter_ns`` around a loop of N calls, repeated R
   times, reporting the minimum and the median per call;
3. times our batched tau, D, C, g and forward dynamics over 10 000 random
   states (per state);
4. measures where our time goes: numba dispatch of a do-nothing function
   with the same arguments, the public API against the raw kernel, and
   the first-call compile / cache-load time in a fresh interpreter;
5. prints the table and the targets with PASS/MISS computed from the
   numbers measured in this run: tau, D, C and g each <= 1.25x Pinocchio's
   Python call, forward dynamics <= 1.5x ``pin.aba``; batched tau <= 0.4x
   and batched D, C, g and forward dynamics <= 0.5x a Python loop of the
   matching Pinocchio function, per state.

Then the whole robots (:mod:`.trees`, default Centauro's 39 joints,
``--tree NAME``): a model of the whole URDF tree against Pinocchio's of
the same file, tau, D and forward dynamics each <= 0.8x its Python call.

Peers are optional: a missing library is reported and skipped.

The package: :mod:`.prepare` (the rows, as one statement each, their
targets and the states), :mod:`.references` (the naive recursion and
the peers, checked against ours), :mod:`.measure` (the timer and the
timed groups), :mod:`.report` (verdicts and tables); here, one robot
(:func:`bench_robot`) and the command (:func:`main`).
"""
import json
import os
import platform
import sys
import tempfile
import time

from newton_euler_ros.core import NewtonEulerError
import numpy as np

from .measure import (first_call_times, measure_batches, measure_inputs,
                      measure_probes, measure_single, Timer)
from .prepare import (BATCH_STATES, BATCHES, DEFAULT_ROBOTS, OPS,
                      random_state, random_states, setup_robot, SINGLE,
                      TARGETS)
from .references import check_references, naive_mass_matrix, naive_rnea
from .report import (json_default, jsonable, loadavg, print_breakdown,
                     print_first_call, print_inputs, print_misses,
                     print_table, verdicts)
from .trees import bench_tree, DEFAULT_TREES, print_tree_table, TREES
from .. import peers
from ..timing import tool_parser

__all__ = ['BATCH_STATES', 'BATCHES', 'bench_robot', 'DEFAULT_ROBOTS',
           'first_call_times', 'main', 'naive_mass_matrix', 'naive_rnea',
           'OPS', 'random_state', 'random_states', 'SINGLE', 'TARGETS',
           'Timer', 'verdicts']


def bench_robot(name, timer, rng, log):
    """Set up, check and time one robot; the result of :func:`main`."""
    result, ns, states = setup_robot(name, rng, log)
    pin_ns, rtb_ns = check_references(result, ns, states, log)
    T = result['timings']
    T.update(measure_single(timer, ns, pin_ns, rtb_ns))
    T.update(measure_batches(timer, ns, pin_ns, rtb_ns))
    T.update(measure_inputs(timer, ns))
    T.update(measure_probes(timer, ns))
    result['verdicts'] = verdicts(result)
    return result


def main(argv=None):
    parser = tool_parser(
        'bench', 'Time our dynamics against Pinocchio, Robotics Toolbox '
                 'and naive numpy, and check the performance targets.',
        'fewer and shorter repeats (under 15 s); skips the cold-compile '
        'measurement')
    parser.add_argument('--json', metavar='PATH',
                        help='write every figure to this JSON file')
    parser.add_argument('--robot', action='append', metavar='NAME',
                        help='robot to benchmark (repeatable; default: '
                             + ', '.join(DEFAULT_ROBOTS) + ')')
    parser.add_argument('--tree', action='append', metavar='NAME',
                        choices=sorted(TREES) + ['none'],
                        help='whole robot (URDF tree) to benchmark '
                             '(repeatable; default: '
                             + ', '.join(DEFAULT_TREES) + '; none: skip)')
    parser.add_argument('--seed', type=int, default=12345,
                        help='seed of the random states (default 12345)')
    args = parser.parse_args(argv)
    robots = args.robot or list(DEFAULT_ROBOTS)

    def log(line=''):
        print(line, flush=True)

    t_start = time.perf_counter()
    import numba
    versions = {'python': platform.python_version(), 'numpy': np.__version__,
                'numba': numba.__version__, **peers.versions()}
    log('newton_euler_ros benchmark  ' + '  '.join(
        f'{k} {v}' for k, v in versions.items()))
    log(f'machine: {platform.machine()} {platform.processor() or ""} '
        f'{os.cpu_count()} cpus; {platform.platform()}')
    load_start = loadavg()
    if load_start is not None:
        log(f'load average at start: {load_start:.2f} on {os.cpu_count()} '
            f'cpus' + ('  (WARNING: other work is running; figures will be '
                       'noisy and our Python-side costs hit hardest)'
                       if load_start > 0.5 else ''))
    timer = Timer(args.quick)
    rng = np.random.default_rng(args.seed)
    try:
        results = [bench_robot(name, timer, rng, log)
                   for name in robots]
        trees = [bench_tree(name, timer, rng, log)
                 for name in (args.tree or DEFAULT_TREES) if name != 'none']
    except NewtonEulerError as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2

    # the first calls above have filled the kernel cache: time its load in a
    # fresh interpreter, and (full run only) a compile from an empty cache
    first = {'cache warm (compile cached on disk)':
             first_call_times(robots[0])}
    if args.quick:
        first['cold (empty numba cache, real compile)'] = None
    else:
        with tempfile.TemporaryDirectory() as tmp:
            first['cold (empty numba cache, real compile)'] = \
                first_call_times(robots[0], cache_dir=tmp)

    log('\n' + '=' * 78)
    log('RESULTS')
    log('=' * 78)
    for result in results:
        print_table(result, timer, log)
        print_inputs(result, log)
        print_breakdown(result, log)
        print_misses(result, log)
    for tree in trees:
        print_tree_table(tree, timer, log)
    print_first_call(first, log)

    log('\ntargets: ' + '; '.join(
        [f'{r["robot"]} ' + ', '.join(f'{op} {r["verdicts"][op]["verdict"]}'
                                      for op in OPS) for r in results]
        + [f'{t["robot"]} tree ' + ', '.join(
            f'{op} {v["verdict"]}' for op, v in t['verdicts'].items()
            if v['verdict'] != '-') for t in trees]))
    elapsed = time.perf_counter() - t_start
    load_end = loadavg()
    if load_end is not None:
        log(f'load average at end: {load_end:.2f} (1-minute; includes this '
            f'benchmark)')
    log(f'benchmark took {elapsed:.1f} s')
    if args.json:
        payload = {'versions': versions, 'quick': args.quick,
                   'loadavg_start': load_start, 'loadavg_end': load_end,
                   'seed': args.seed, 'batch_states': BATCH_STATES,
                   'targets': TARGETS,
                   'first_call': first, 'elapsed_s': elapsed,
                   'robots': [jsonable(r) for r in results],
                   'trees': [jsonable(t) for t in trees]}
        with open(args.json, 'w') as fh:
            json.dump(payload, fh, indent=1, default=json_default)
        log(f'wrote {args.json}')
    return 0
