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
Reporting: verdicts against the targets, the tables, the JSON file.

Everything here reads the result of one robot (``result['timings']``,
keyed (who, op)) and prints or converts it; nothing is timed here.
"""
import os

import numpy as np

from .prepare import (BATCH_STATES, BATCHES, OP_LABELS, OPS,
                      PIN_LOOP_STATES, SINGLE, TARGETS)


# --------------------------------------------------------------------------
# verdicts and report


def verdicts(result):
    """PASS/MISS per operation: ours / Pinocchio against ``TARGETS``."""
    T = result['timings']
    out = {}
    for op in OPS:
        limit = TARGETS[op]
        target = (f'<= {limit:g}x Pinocchio' if op in SINGLE
                  else f'<= {limit:g}x pin loop')
        ours, pin = T.get(('ours', op)), T.get(('pin', op))
        if pin is None:
            out[op] = {'target': target, 'verdict': 'n/a (no Pinocchio)'}
            continue
        ratio = ours['min_us'] / pin['min_us']
        ratio_med = ours['median_us'] / pin['median_us']
        if not result['valid'].get('pin'):
            verdict = 'INVALID peer'
        else:
            verdict = 'PASS' if ratio <= limit else 'MISS'
        out[op] = {'target': target, 'ratio_min': ratio,
                   'ratio_median': ratio_med, 'verdict': verdict,
                   'over_by': ratio / limit,
                   'needed_us': pin['min_us'] * limit}
    return out


def _cell(t, valid=True):
    if t is None:
        return '-'
    s = f'{_num(t["min_us"])} ({_num(t["median_us"])})'
    return s if valid in (True, None) else s + '!'


def _num(x):
    if x >= 100:
        return f'{x:.0f}'
    if x >= 10:
        return f'{x:.1f}'
    return f'{x:.2f}'


def log_head(log, extra=''):
    """Log a timing table's head (operation to verdict, then ``extra``)."""
    head = (f'{"operation":<22}{"ours":>16}{"Pinocchio":>16}{"ours/pin":>10}'
            f'  {"target":<22}{"verdict":<13}{extra}')
    log(head)
    log('-' * len(head))


def ratio_text(verdict):
    """Return a verdict's ours/Pinocchio ratio of minima as text, or -."""
    return f'{verdict["ratio_min"]:.2f}' if 'ratio_min' in verdict else '-'


def print_table(result, timer, log):
    T = result['timings']
    V = result['verdicts']
    valid = result['valid']
    log(f'\n{result["robot"]}: microseconds per call, min (median) of '
        f'{timer.reps} repeats; ratio and verdict from the minima; '
        f'"!" = peer model failed the correctness check')
    log_head(log, f'{"RTB":>18}{"naive numpy":>18}')
    for op in OPS:
        v = V[op]
        ratio = ratio_text(v)
        log(f'{OP_LABELS[op]:<22}{_cell(T.get(("ours", op))):>16}'
            f'{_cell(T.get(("pin", op)), valid.get("pin")):>16}{ratio:>10}'
            f'  {v["target"]:<22}{v["verdict"]:<13}'
            f'{_cell(T.get(("rtb", op)), valid.get("rtb")):>18}'
            f'{_cell(T.get(("naive", op)), valid.get("naive")):>18}')
    log(f'  batch rows: ours = one batched call over {BATCH_STATES} states; '
        f'Pinocchio = a Python loop of the matching function over '
        f'{PIN_LOOP_STATES} states (it has no batched calls); RTB = one rne '
        f'call with ({BATCH_STATES}, n) arrays.')
    log('  D: Pinocchio crba fills only the upper triangle; ours and RTB '
        'return the full matrix.  RTB inertia = n rne calls, coriolis = '
        'n(n+1)/2 rne calls from Python, accel = a solve with its inertia.')


def print_inputs(result, log):
    """Print the tau row from other input types, beside the float64 row."""
    T = result['timings']
    rows = [k[1] for k in T if k[0] == 'inputs']
    base = T[('inputs', 'float64 arrays')]['min_us']
    log(f'\n{result["robot"]}: tau = ID(q,qd,qdd) by input type, min '
        f'(median) us per call; the extra is the conversion')
    for key in rows:
        t = T[('inputs', key)]
        log(f'  {key:<16}{_cell(t):>16}  {t["min_us"] / base:5.2f}x')


def print_breakdown(result, log):
    T = result['timings']
    P = {k[1]: v['min_us'] for k, v in T.items() if k[0] == 'probe'}
    log(f'\n{result["robot"]}: where our time goes (min us per call)')
    log(f'  timing loop, empty statement: {P["empty_loop"]:.3f}')
    log(f'  numba dispatch of a do-nothing njit function: no args '
        f'{P["njit_0_args"]:.3f}, one array {P["njit_1_array"]:.3f}; with '
        f'the entry points\' arguments: tau (8) {P["njit_tau_args"]:.3f}, '
        f'D and g (4) {P["njit_D_args"]:.3f}, C (8) '
        f'{P["njit_C_args"]:.3f}, FD (9) {P["njit_FD_args"]:.3f}')
    log(f'  Python pieces: _vector() of one ready array '
        f'{P["_vector_one_arg"]:.3f} (the fallback only); np.empty(n) '
        f'{P["np_empty_n"]:.3f}')
    log(f'  {"op":<6}{"public":>9}{"raw kernel":>12}{"wrapper":>10}'
        f'{"dispatch":>10}{"compute":>10}')
    result['breakdown'] = {}
    for op in SINGLE:
        pub = T[('ours', op)]['min_us']
        raw = T[('ours_raw', op)]['min_us']
        disp = P[f'njit_{op}_args' if op != 'g' else 'njit_D_args']
        compute = max(raw - disp, 0.0)
        wrapper = pub - raw
        log(f'  {op:<6}{pub:>9.3f}{raw:>12.3f}{wrapper:>10.3f}{disp:>10.3f}'
            f'{compute:>10.3f}')
        result['breakdown'][op] = {
            'public_us': pub, 'raw_kernel_us': raw, 'wrapper_us': wrapper,
            'dispatch_us': disp, 'compute_us': compute,
            'share_wrapper': wrapper / pub, 'share_dispatch': disp / pub,
            'share_compute': compute / pub}
    for op in BATCHES:
        bp = T[('ours', op)]['min_us']
        br = T[('ours_raw', op)]['min_us']
        log(f'  {op} per state: public {bp:.3f}, raw kernel {br:.3f}, '
            f'validation/copies in Python {bp - br:.3f}')
        result['breakdown'][op] = {'public_us': bp, 'raw_kernel_us': br,
                                   'wrapper_us': bp - br}


def print_misses(result, log):
    V = result['verdicts']
    B = result['breakdown']
    T = result['timings']
    misses = [op for op in OPS if V[op]['verdict'] == 'MISS']
    if not misses:
        passed = [op for op in OPS if V[op]['verdict'] == 'PASS']
        other = [f'{op} {V[op]["verdict"]}' for op in OPS
                 if V[op]['verdict'] != 'PASS']
        log(f'\n{result["robot"]}: no target missed: '
            f'{len(passed)} of {len(OPS)} checked and passed'
            + (f'; not checked: {", ".join(other)}' if other else ''))
        return
    log(f'\n{result["robot"]}: targets missed')
    for op in misses:
        v = V[op]
        b = B[op]
        pub = b['public_us']
        pin = T[('pin', op)]['min_us']
        log(f'  {op}: {pub:.3f} us vs Pinocchio {pin:.3f} = '
            f'{v["ratio_min"]:.2f}x (target {TARGETS[op]:g}x); needs <= '
            f'{v["needed_us"]:.3f} us, i.e. {pub - v["needed_us"]:.3f} us '
            f'less')
        if op in BATCHES:
            continue
        parts = sorted((('Python wrapper', b['wrapper_us']),
                        ('numba dispatch', b['dispatch_us']),
                        ('kernel compute', b['compute_us'])),
                       key=lambda kv: -kv[1])
        log('     split: ' + ', '.join(
            f'{k} {x:.3f} ({100 * x / pub:.0f}%)' for k, x in parts))


def print_first_call(first, log):
    log('\nfirst call in a fresh interpreter (seconds; JIT excluded from '
        'every timing above):')
    for label, f in first.items():
        if f is None:
            log(f'  {label}: skipped (--quick)')
            continue
        if 'error' in f:
            log(f'  {label}: failed: {f["error"]}')
            continue
        log(f'  {label}: import {f["import_s"]:.3f}, load_robot '
            f'{f["load_robot_s"]:.3f}, first inverse_dynamics '
            f'{f["first_inverse_dynamics_s"]:.3f}, first mass_matrix '
            f'{f["first_mass_matrix_s"]:.3f}, first coriolis_matrix '
            f'{f["first_coriolis_matrix_s"]:.3f}, first batch '
            f'{f["first_batch_s"]:.3f}, second inverse_dynamics '
            f'{1e6 * f["second_inverse_dynamics_s"]:.1f} us; import to '
            f'first tau {f["import_to_first_tau_s"]:.3f}; whole process '
            f'{f["process_wall_s"]:.3f}')


# --------------------------------------------------------------------------
# the JSON file


def jsonable(result):
    """Return a result with its timings keyed {who: {op: ...}}."""
    out = dict(result)
    timings = {}
    for (who, op), t in result['timings'].items():
        timings.setdefault(who, {})[op] = t
    out['timings'] = timings
    return out


def loadavg():
    """Return the 1-minute load average, or None."""
    try:
        return os.getloadavg()[0]
    except (AttributeError, OSError):
        return None


def json_default(x):
    """Convert numpy scalars for ``json.dump``."""
    if isinstance(x, (np.floating, np.integer, np.bool_)):
        return x.item()
    raise TypeError(f'not JSON serialisable: {type(x).__name__}')
