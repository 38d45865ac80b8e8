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
Measuring: the timer, the timed groups of one robot, the first call.

:class:`Timer` interleaves the repeats of the statements of one group
(ours, Pinocchio, RTB, ... for one operation); the ``measure_*``
functions time the tables of :mod:`.prepare`; :func:`first_call_times`
runs the first calls in a fresh interpreter.
"""
import json
import os
import statistics
import subprocess
import sys
import time
import timeit

import newton_euler_ros

from .prepare import (BATCH_STATES, BATCH_STMTS, INPUT_ROWS, NAIVE,
                      PIN, PIN_LOOP_STATES, PROBES, PUBLIC, RAW, RTB, SINGLE)


class Timer:
    """
    ``perf_counter_ns`` around a loop of N calls, repeated R times.

    N is chosen so that one repeat lasts about ``target_ns``; two calls
    before that are a warm-up.  The loop is ``timeit``'s compiled one
    (garbage collection off), so its own cost is a few nanoseconds per
    call; the cost of an empty statement is measured and reported.

    :meth:`group` interleaves the repeats of the statements it is given
    (ours, Pinocchio, RTB, ... for one operation), so that a slower spell of
    a shared machine hits all of them alike rather than one library.
    """

    def __init__(self, quick):
        self.target_ns = 3e6 if quick else 40e6
        self.reps = 5 if quick else 15

    def _prepare(self, stmt, ns, number):
        timer = timeit.Timer(stmt, globals=ns, timer=time.perf_counter_ns)
        timer.timeit(2)
        if number is None:
            number = 1
            while True:
                elapsed = timer.timeit(number)
                if elapsed >= self.target_ns / 10 or number >= 10 ** 7:
                    break
                number *= 10
            number = max(1, int(number * self.target_ns / max(elapsed, 1)))
        return timer, number

    def group(self, entries):
        """
        Time several statements with their repeats interleaved.

        {key: (stmt, namespace, number or None, states per call)} ->
        {key: {'min_us', 'median_us', 'number', 'reps', 'states'}}, the
        times per state (per call when states is 1).
        """
        prepared = {key: self._prepare(stmt, ns, number)
                    for key, (stmt, ns, number, _) in entries.items()}
        samples = {key: [] for key in entries}
        for _ in range(self.reps):
            for key, (timer, number) in prepared.items():
                samples[key].append(timer.timeit(number) / number / 1e3)
        out = {}
        for key, (_, _, _, states) in entries.items():
            per = [x / states for x in samples[key]]
            out[key] = {'min_us': min(per),
                        'median_us': statistics.median(per),
                        'number': prepared[key][1], 'reps': self.reps,
                        'states': states}
        return out


def measure_single(timer, ns, pin_ns, rtb_ns):
    """One group per operation: ours, our raw kernel and every peer."""
    T = {}
    for op in SINGLE:
        entries = {('ours', op): (PUBLIC[op], ns, None, 1),
                   ('ours_raw', op): (RAW[op], ns, None, 1)}
        if pin_ns is not None:
            entries[('pin', op)] = (PIN[op], pin_ns, None, 1)
        if rtb_ns is not None:
            entries[('rtb', op)] = (RTB[op], rtb_ns, None, 1)
        if op in NAIVE:
            entries[('naive', op)] = (NAIVE[op], ns, None, 1)
        T.update(timer.group(entries))
    return T


def measure_batches(timer, ns, pin_ns, rtb_ns):
    """Per state: our batch call, its raw kernel and a Pinocchio loop."""
    T = {}
    m = BATCH_STATES
    for op, (public, kernel, pin_call) in BATCH_STMTS.items():
        entries = {('ours', op): (public, ns, 1, m),
                   ('ours_raw', op): (kernel, ns, 1, m)}
        if pin_ns is not None:
            entries[('pin', op)] = (
                f'for i in range({PIN_LOOP_STATES}): {pin_call}', pin_ns, 1,
                PIN_LOOP_STATES)
        if rtb_ns is not None and op == 'batch':
            entries[('rtb', op)] = ('robot.rne(Q, QD, QDD)', rtb_ns, 1, m)
        T.update(timer.group(entries))
    return T


def measure_inputs(timer, ns):
    """Time tau from float64 arrays, lists and int arrays, interleaved."""
    entries = {('inputs', 'float64 arrays'): (PUBLIC['tau'], ns, None, 1)}
    entries.update({('inputs', key): (stmt, ns, None, 1)
                    for key, stmt in INPUT_ROWS.items()})
    return timer.group(entries)


def measure_probes(timer, ns):
    """Where the time goes: dispatch of do-nothing functions, pieces."""
    return timer.group({('probe', key): (stmt, ns, None, 1)
                        for key, stmt in PROBES.items()})


# --------------------------------------------------------------------------
# first-call compile / cache-load time, in a fresh interpreter

_FIRST_CALL = r"""
import json, time, warnings
t0 = time.perf_counter()
from newton_euler_ros.core import (load_robot, inverse_dynamics, mass_matrix,
    coriolis_matrix, inverse_dynamics_batch, Workspace)
import numpy as np
t1 = time.perf_counter()
with warnings.catch_warnings():
    warnings.simplefilter('ignore')
    model = load_robot(%(robot)r)
t2 = time.perf_counter()
q = np.full(model.n, 0.1)
ws = Workspace(model)
tau = np.empty(model.n)
inverse_dynamics(model, q, q, q, ws=ws, out=tau)
t3 = time.perf_counter()
mass_matrix(model, q, ws=ws)
t4 = time.perf_counter()
coriolis_matrix(model, q, q, ws=ws)
t5 = time.perf_counter()
inverse_dynamics_batch(model, np.zeros((2, model.n)), ws=ws)
t6 = time.perf_counter()
inverse_dynamics(model, q, q, q, ws=ws, out=tau)
t7 = time.perf_counter()
print(json.dumps({'import_s': t1 - t0, 'load_robot_s': t2 - t1,
                  'first_inverse_dynamics_s': t3 - t2,
                  'first_mass_matrix_s': t4 - t3,
                  'first_coriolis_matrix_s': t5 - t4,
                  'first_batch_s': t6 - t5,
                  'second_inverse_dynamics_s': t7 - t6,
                  'import_to_first_tau_s': t3 - t0}))
"""


def first_call_times(robot, cache_dir=None):
    """Run ``_FIRST_CALL`` in a fresh interpreter; dict of seconds."""
    env = dict(os.environ)
    # the source tree of newton_euler_ros (not of these tools) goes first
    pkg_root = os.path.dirname(os.path.dirname(
        os.path.abspath(newton_euler_ros.__file__)))
    env['PYTHONPATH'] = os.pathsep.join(
        [pkg_root] + [p for p in env.get('PYTHONPATH', '').split(os.pathsep)
                      if p])
    if cache_dir is not None:
        env['NUMBA_CACHE_DIR'] = cache_dir
    t = time.perf_counter()
    code = _FIRST_CALL % {'robot': robot}
    proc = subprocess.run([sys.executable, '-c', code], env=env,
                          capture_output=True, text=True, timeout=600)
    wall = time.perf_counter() - t
    if proc.returncode != 0:
        return {'error': proc.stderr.strip().splitlines()[-1:]}
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    out['process_wall_s'] = wall
    return out
