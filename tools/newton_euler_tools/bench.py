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

Peers are optional: a missing library is reported and skipped.
"""
import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
import timeit
import warnings

import newton_euler_ros
from newton_euler_ros.core import calling as _calling
from newton_euler_ros.core import (coriolis_matrix, coriolis_matrix_batch,
                                   forward_dynamics, forward_dynamics_batch,
                                   gravity_torques, gravity_torques_batch,
                                   inverse_dynamics, inverse_dynamics_batch,
                                   load_robot, mass_matrix, mass_matrix_batch,
                                   NewtonEulerError, Workspace)
from newton_euler_ros.core import kernels as K
from newton_euler_ros.core.model import REVOLUTE, STANDARD
import numpy as np

from . import peers

DEFAULT_ROBOTS = ('puma560', 'panda')
BATCH_STATES = 10_000
PIN_LOOP_STATES = 1_000      # states in the Python loops over Pinocchio
SINGLE = ('tau', 'D', 'C', 'g', 'FD')
BATCHES = ('batch', 'batch_D', 'batch_C', 'batch_g', 'batch_FD')
OPS = SINGLE + BATCHES
# targets, ours / Pinocchio's Python call (batches: per state, against a
# Python loop of the matching Pinocchio function)
TARGETS = {'tau': 1.25, 'D': 1.25, 'C': 1.25, 'g': 1.25, 'FD': 1.5,
           'batch': 0.4, 'batch_D': 0.5, 'batch_C': 0.5, 'batch_g': 0.5,
           'batch_FD': 0.5}
OP_LABELS = {
    'tau': 'tau = ID(q,qd,qdd)',
    'D': 'D(q) mass matrix',
    'C': 'C(q,qd) Coriolis',
    'g': 'g(q) gravity',
    'FD': 'FD qdd (ABA)',
    'batch': 'batch ID, per state',
    'batch_D': 'batch D, per state',
    'batch_C': 'batch C, per state',
    'batch_g': 'batch g, per state',
    'batch_FD': 'batch FD, per state',
}


# --------------------------------------------------------------------------
# timing


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


# --------------------------------------------------------------------------
# a naive reference: the textbook recursion, one numpy operation at a time


def _naive_dh(model, j, qj):
    """4x4 DH transform of joint j at joint value qj (allocates)."""
    a, alpha = model.a[j], model.alpha[j]
    d, theta = model.d[j], model.theta[j]
    if model.joint_types[j] == REVOLUTE:
        theta = theta + qj
    else:
        d = d + qj
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(alpha), np.sin(alpha)
    if model.convention == STANDARD:
        return np.array([[ct, -st * ca, st * sa, a * ct],
                         [st, ct * ca, -ct * sa, a * st],
                         [0.0, sa, ca, d],
                         [0.0, 0.0, 0.0, 1.0]])
    return np.array([[ct, -st, 0.0, a],
                     [st * ca, ct * ca, -sa, -sa * d],
                     [st * sa, ct * sa, ca, ca * d],
                     [0.0, 0.0, 0.0, 1.0]])


def naive_rnea(model, q, qd, qdd, gravity=True):
    """
    Newton-Euler in base-frame vectors with ``np.cross`` and ``@``.

    Forward: pose of every link by 4x4 products, then the angular velocity
    and acceleration and the acceleration of each centre of mass, passed
    from link to link through a point P on the joint axis.  Backward:
    forces and moments about the base origin, projected on each axis.
    Written for clarity, not speed: the reference the compiled kernel is
    measured against.
    """
    n = model.n
    T = np.array(model.base)
    w = np.zeros(3)
    wd = np.zeros(3)
    # acceleration of the reference point o of the previous body (the base
    # accelerates upwards at -g in place of gravity pulling every link)
    a = -np.asarray(model.gravity) if gravity else np.zeros(3)
    o = T[:3, 3].copy()
    z_axes, points, coms, forces, moments = [], [], [], [], []
    for j in range(n):
        T_prev = T
        T = T_prev @ _naive_dh(model, j, q[j])
        if model.convention == STANDARD:     # joint j moves about z_{j-1}
            z, P = T_prev[:3, 2], T_prev[:3, 3]
        else:                                # modified: about z_j
            z, P = T[:3, 2], T[:3, 3]
        R = T[:3, :3]
        c = R @ model.com[j] + T[:3, 3]
        r = P - o
        aP = a + np.cross(wd, r) + np.cross(w, np.cross(w, r))
        if model.joint_types[j] == REVOLUTE:
            wd = wd + np.cross(w, z) * qd[j] + z * qdd[j]
            w = w + z * qd[j]
        else:
            aP = aP + 2.0 * np.cross(w, z) * qd[j] + z * qdd[j]
        r = c - P
        ac = aP + np.cross(wd, r) + np.cross(w, np.cross(w, r))
        Iw = R @ model.inertia[j] @ R.T
        forces.append(model.mass[j] * ac)
        moments.append(Iw @ wd + np.cross(w, Iw @ w))
        z_axes.append(z)
        points.append(P)
        coms.append(c)
        a, o = ac, c
    tau = np.empty(n)
    f = np.zeros(3)
    m_o = np.zeros(3)          # moment about the base origin
    for j in range(n - 1, -1, -1):
        f = f + forces[j]
        m_o = m_o + moments[j] + np.cross(coms[j], forces[j])
        if model.joint_types[j] == REVOLUTE:
            tau[j] = z_axes[j] @ (m_o - np.cross(points[j], f))
        else:
            tau[j] = z_axes[j] @ f
    return tau


def naive_mass_matrix(model, q):
    """D(q) by n naive recursions with qdd = e_k."""
    n = model.n
    zero = np.zeros(n)
    D = np.empty((n, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = 1.0
        D[:, k] = naive_rnea(model, q, zero, e, gravity=False)
    return D


# --------------------------------------------------------------------------
# numba dispatch floor: do-nothing functions with our kernels' arguments


def _dispatch_probes():
    """
    Do-nothing njit functions with the entry points' argument lists.

    Compiled with the entry points' options (``K.ENTRY``, not cached), so
    that they pay the same dispatch as the kernels do.
    """
    from numba import njit
    options = dict(K.ENTRY, cache=False)

    @njit(**options)
    def noop0():
        return -1

    @njit(**options)
    def noop1(x):
        return -1

    @njit(**options)
    def noop4(P, q, ws, out):
        return -1

    @njit(**options)
    def noop_tau(P, q, qd, qdd, wrench, flags, ws, tau):
        return -1

    @njit(**options)
    def noop_c(P, q, qd, composite, ws, cw, scratch, C):
        return -1

    @njit(**options)
    def noop_fd(P, q, qd, tau, wrench, flags, ws, aw, qdd):
        return -1

    return {'noop0': noop0, 'noop1': noop1, 'noop4': noop4,
            'noop_tau': noop_tau, 'noop_c': noop_c, 'noop_fd': noop_fd}


# --------------------------------------------------------------------------
# states, checks


def random_state(model, rng):
    n = model.n
    lo = np.empty(n)
    hi = np.empty(n)
    for j in range(n):
        lim = model.limits[j] if j < len(model.limits) else {}
        default = np.pi if model.joint_types[j] == REVOLUTE else 0.5
        lo[j] = lim.get('lower', -default)
        hi[j] = lim.get('upper', default)
    q = rng.uniform(lo, hi)
    return q, rng.normal(size=n), rng.normal(size=n)


def random_states(model, rng, m):
    rows = [random_state(model, rng) for _ in range(m)]
    return tuple(np.ascontiguousarray(np.array([r[i] for r in rows]))
                 for i in range(3))


def _maxdiff(x, y):
    return float(np.max(np.abs(np.asarray(x) - np.asarray(y))))


def _tolerance(ref):
    return 1e-9 * max(1.0, float(np.max(np.abs(ref))))


def ours_reference(model, states):
    """tau, D, C, g and FD (qdd as the torque) at each (q, qd, qdd)."""
    out = []
    for q, qd, qdd in states:
        out.append({'tau': inverse_dynamics(model, q, qd, qdd),
                    'D': mass_matrix(model, q),
                    'C': coriolis_matrix(model, q, qd),
                    'g': gravity_torques(model, q),
                    'FD': forward_dynamics(model, q, qd, qdd),
                    'Cqd': inverse_dynamics(model, q, qd, None,
                                            gravity=False)})
    return out


def compare(ref, got):
    """{term: max abs diff over states}, {term: ok} for the terms in got."""
    diffs, ok = {}, {}
    for term in got[0]:
        diffs[term] = max(_maxdiff(r[term], g[term]) for r, g in zip(ref, got))
        ok[term] = all(_maxdiff(r[term], g[term]) <= _tolerance(r[term])
                       for r, g in zip(ref, got))
    return diffs, ok


# --------------------------------------------------------------------------
# one robot


# statements timed for every robot: one line each.  ``ns`` names (see
# ``setup_robot``): model, q, qd, qdd, ws, outputs tau D C g, batches Q QD
# QDD TAU DD W, raw kernel arguments P wsa cw aw scratch zero_w status.
PUBLIC = {
    'tau': 'inverse_dynamics(model, q, qd, qdd, ws=ws, out=tau)',
    'D': 'mass_matrix(model, q, ws=ws, out=D)',
    'C': 'coriolis_matrix(model, q, qd, ws=ws, out=C)',
    'g': 'gravity_torques(model, q, ws=ws, out=g)',
    'FD': 'forward_dynamics(model, q, qd, qdd, ws=ws, out=g)',
}
RAW = {
    'tau': 'K.run_inverse_dynamics(P, q, qd, qdd, zero_w, 3, wsa, tau)',
    'D': 'K.run_mass_matrix_crba(P, q, wsa, D)',
    'C': 'K.run_coriolis_matrix(P, q, qd, True, wsa, cw, scratch, C)',
    'g': 'K.run_gravity_torques(P, q, wsa, g)',
    'FD': 'K.run_forward_dynamics(P, q, qd, qdd, zero_w, 3, wsa, aw, g)',
}
NAIVE = {'tau': 'naive_rnea(model, q, qd, qdd)',
         'D': 'naive_mass_matrix(model, q)',
         'g': 'naive_rnea(model, q, zeros, zeros)'}
PIN = {'tau': 'rnea(pm, pd, q, qd, qdd)', 'D': 'crba(pm, pd, q)',
       'C': 'computeCoriolisMatrix(pm, pd, q, qd)',
       'g': 'computeGeneralizedGravity(pm, pd, q)',
       'FD': 'aba(pm, pd, q, qd, qdd)'}
RTB = {'tau': 'robot.rne(q, qd, qdd)', 'D': 'robot.inertia(q)',
       'C': 'robot.coriolis(q, qd)', 'g': 'robot.gravload(q)',
       'FD': 'robot.accel(q, qd, qdd)'}
# (ours, our raw kernel, one Pinocchio call in its Python loop)
BATCH_STMTS = {
    'batch': ('inverse_dynamics_batch(model, Q, QD, QDD, ws=ws, out=TAU)',
              'K.run_inverse_dynamics_batch(P, Q, QD, QDD, W, 3, wsa, TAU, '
              'status)', 'rnea(pm, pd, Q[i], QD[i], QDD[i])'),
    'batch_D': ('mass_matrix_batch(model, Q, ws=ws, out=DD)',
                'K.run_mass_matrix_batch(P, Q, wsa, DD, status)',
                'crba(pm, pd, Q[i])'),
    'batch_C': ('coriolis_matrix_batch(model, Q, QD, ws=ws, out=DD)',
                'K.run_coriolis_matrix_batch(P, Q, QD, wsa, cw, DD, status)',
                'computeCoriolisMatrix(pm, pd, Q[i], QD[i])'),
    'batch_g': ('gravity_torques_batch(model, Q, ws=ws, out=TAU)',
                'K.run_gravity_torques_batch(P, Q, wsa, TAU, status)',
                'computeGeneralizedGravity(pm, pd, Q[i])'),
    'batch_FD': ('forward_dynamics_batch(model, Q, QD, QDD, ws=ws, out=TAU)',
                 'K.run_forward_dynamics_batch(P, Q, QD, QDD, W, 3, wsa, aw, '
                 'TAU, status)', 'aba(pm, pd, Q[i], QD[i], QDD[i])'),
}
# tau with its inputs given otherwise than as float64 arrays, beside the
# float64 row: a list or an int array costs one conversion more
INPUT_ROWS = {
    'q list': 'inverse_dynamics(model, q_list, qd, qdd, ws=ws, out=tau)',
    'q int array': 'inverse_dynamics(model, q_int, qd, qdd, ws=ws, out=tau)',
    'all lists': 'inverse_dynamics(model, q_list, qd_list, qdd_list, '
                 'wrench_list, ws=ws, out=tau)',
    'wrench array': 'inverse_dynamics(model, q, qd, qdd, wrench, ws=ws, '
                    'out=tau)',
    'wrench list': 'inverse_dynamics(model, q, qd, qdd, wrench_list, ws=ws, '
                   'out=tau)',
}
PROBES = {
    'empty_loop': 'pass',
    'njit_0_args': 'noop0()',
    'njit_1_array': 'noop1(q)',
    'njit_tau_args': 'noop_tau(P, q, qd, qdd, zero_w, 3, wsa, tau)',
    'njit_D_args': 'noop4(P, q, wsa, D)',
    'njit_C_args': 'noop_c(P, q, qd, True, wsa, cw, scratch, C)',
    'njit_g_args': 'noop4(P, q, wsa, g)',
    'njit_FD_args': 'noop_fd(P, q, qd, qdd, zero_w, 3, wsa, aw, g)',
    '_vector_one_arg': "_vector('q', q, n)",
    'np_empty_n': 'np.empty(n)',
}


def setup_robot(name, rng, log):
    """Load a robot; return (result skeleton, our namespace, states)."""
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')     # e.g. the Puma's published
        model = load_robot(name)            # triangle-inequality oddities
    n = model.n
    result = {'robot': name, 'convention': model.convention, 'dof': n,
              'timings': {}, 'correctness': {}, 'valid': {}}
    log(f'\n=== {name}: {model.convention} DH, {n} DoF '
        f'({", ".join(sorted(set(model.joint_types)))}) ===')
    ws = Workspace(model)
    q, qd, qdd = random_state(model, rng)
    Q, QD, QDD = random_states(model, rng, BATCH_STATES)
    m = BATCH_STATES
    wrench = np.array([0.0, 0.0, 10.0, 0.0, 0.0, 0.0])
    ns = {'model': model, 'q': q, 'qd': qd, 'qdd': qdd, 'ws': ws,
          'tau': np.empty(n), 'D': np.empty((n, n)), 'C': np.empty((n, n)),
          'g': np.empty(n), 'Q': Q, 'QD': QD, 'QDD': QDD,
          'TAU': np.empty((m, n)), 'W': np.zeros((m, 6)), 'K': K,
          'P': model.packed, 'DD': np.empty((m, n, n)),
          'inverse_dynamics': inverse_dynamics, 'mass_matrix': mass_matrix,
          'coriolis_matrix': coriolis_matrix,
          'gravity_torques': gravity_torques,
          'forward_dynamics': forward_dynamics,
          'inverse_dynamics_batch': inverse_dynamics_batch,
          'mass_matrix_batch': mass_matrix_batch,
          'coriolis_matrix_batch': coriolis_matrix_batch,
          'gravity_torques_batch': gravity_torques_batch,
          'forward_dynamics_batch': forward_dynamics_batch,
          'naive_rnea': naive_rnea, 'naive_mass_matrix': naive_mass_matrix,
          'zeros': np.zeros(n), 'zero_w': np.zeros(6), 'wsa': ws.ws,
          'scratch': ws.scratch, 'cw': ws.cw, 'aw': ws.aw,
          'status': ws.status, '_vector': _calling.vector, 'n': n,
          'np': np, 'wrench': wrench, 'wrench_list': wrench.tolist(),
          'q_list': q.tolist(), 'qd_list': qd.tolist(),
          'qdd_list': qdd.tolist(),
          'q_int': np.round(q).astype(np.int64)}
    ns.update(_dispatch_probes())
    check_states = [random_state(model, rng) for _ in range(3)]
    return result, ns, check_states


def check_references(result, ns, states, log):
    """Check the naive recursion and the peers against ours; peer spaces."""
    model = ns['model']
    n = model.n
    ref = ours_reference(model, states)
    log('correctness, max |ours - other| over 3 random states '
        '(tolerance 1e-9 x max(1, |ours|)):')
    naive_out = [{'tau': naive_rnea(model, *s),
                  'g': naive_rnea(model, s[0], np.zeros(n), np.zeros(n)),
                  'D': naive_mass_matrix(model, s[0])} for s in states]
    diffs, ok = compare(ref, naive_out)
    result['correctness']['naive'] = diffs
    result['valid']['naive'] = all(ok.values())
    log('  naive numpy : ' + _fmt_diffs(diffs, ok))
    Qc = np.array([s[0] for s in states])
    bat = inverse_dynamics_batch(model, Qc, [s[1] for s in states],
                                 [s[2] for s in states])
    bdiff = max(_maxdiff(bat[i], ref[i]['tau']) for i in range(len(ref)))
    log(f'  our batch   : tau {bdiff:.1e} vs single-state')
    result['correctness']['ours_batch_vs_single'] = bdiff
    pin_ns = _setup_pinocchio(model, states, ref, result, log)
    rtb_ns = _setup_rtb(model, states, ref, result, log)
    for extra in (pin_ns, rtb_ns):
        if extra is not None:
            extra.update({k: ns[k] for k in ('q', 'qd', 'qdd', 'Q', 'QD',
                                             'QDD')})
    return pin_ns, rtb_ns


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


def _fmt_diffs(diffs, ok):
    return '  '.join(f'{k} {v:.1e}{"" if ok[k] else " MISMATCH"}'
                     for k, v in diffs.items())


def _setup_pinocchio(model, states, ref, result, log):
    try:
        import pinocchio as pin
    except Exception as exc:
        log(f'  Pinocchio   : not importable ({type(exc).__name__}: {exc}); '
            f'skipped')
        result['valid']['pin'] = None
        return None
    pm = peers.pinocchio_model(model)
    pd = pm.createData()
    got = []
    upper_only = False
    for q, qd, qdd in states:
        M = np.array(pin.crba(pm, pd, q))
        upper_only = upper_only or (np.any(np.triu(M, 1) != 0.0)
                                    and np.all(np.tril(M, -1) == 0.0))
        Cp = np.array(pin.computeCoriolisMatrix(pm, pd, q, qd))
        got.append({
            'tau': np.array(pin.rnea(pm, pd, q, qd, qdd)),
            'D': np.triu(M) + np.triu(M, 1).T,
            'g': np.array(pin.computeGeneralizedGravity(pm, pd, q)),
            'C': Cp,
            'Cqd': Cp @ qd,
            'FD': np.array(pin.aba(pm, pd, q, qd, qdd)),
        })
    diffs, ok = compare(ref, got)
    result['correctness']['pin'] = diffs
    valid = ok['tau'] and ok['D'] and ok['g'] and ok['Cqd'] and ok['FD']
    result['valid']['pin'] = valid
    result['valid']['pin_C_is_christoffel'] = ok['C']
    log('  Pinocchio   : ' + _fmt_diffs(diffs, ok))
    if upper_only:
        log('                (crba fills only the upper triangle of D; '
            'symmetrised for this check, not in the timing)')
    if ok['C']:
        log('                computeCoriolisMatrix equals our Christoffel C')
    else:
        log(f'                computeCoriolisMatrix DIFFERS from our '
            f'Christoffel C by up to {diffs["C"]:.3e} '
            f'(C qd agrees to {diffs["Cqd"]:.1e})')
    if not valid:
        log('                Pinocchio model disagrees with ours: its '
            'timings are marked INVALID')
    return {'pm': pm, 'pd': pd, 'rnea': pin.rnea, 'crba': pin.crba,
            'computeCoriolisMatrix': pin.computeCoriolisMatrix,
            'computeGeneralizedGravity': pin.computeGeneralizedGravity,
            'aba': pin.aba}


def _setup_rtb(model, states, ref, result, log):
    try:
        import roboticstoolbox  # noqa: F401
        from roboticstoolbox.robot import frne
    except Exception as exc:
        log(f'  RTB         : not importable ({type(exc).__name__}: {exc}); '
            f'skipped')
        result['valid']['rtb'] = None
        return None
    robot = peers.rtb_robot(model)
    got = []
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        for q, qd, qdd in states:
            C = np.array(robot.coriolis(q, qd))
            got.append({'tau': np.array(robot.rne(q, qd, qdd)),
                        'D': np.array(robot.inertia(q)),
                        'C': C, 'g': np.array(robot.gravload(q)),
                        'Cqd': C @ qd,
                        'FD': np.array(robot.accel(q, qd, qdd))})
    c_ext = bool(getattr(frne, '_C_AVAILABLE', False)) and \
        robot._frne is not None
    diffs, ok = compare(ref, got)
    result['correctness']['rtb'] = diffs
    result['correctness']['rtb_c_extension'] = c_ext
    valid = all(ok.values())
    result['valid']['rtb'] = valid
    log('  RTB         : ' + _fmt_diffs(diffs, ok)
        + ('' if c_ext else '   (C extension NOT in use: pure-Python rne)'))
    if not valid:
        log('                RTB model disagrees with ours: its timings are '
            'marked INVALID')
    return {'robot': robot}


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


def print_table(result, timer, log):
    T = result['timings']
    V = result['verdicts']
    valid = result['valid']
    log(f'\n{result["robot"]}: microseconds per call, min (median) of '
        f'{timer.reps} repeats; ratio and verdict from the minima; '
        f'"!" = peer model failed the correctness check')
    head = (f'{"operation":<22}{"ours":>16}{"Pinocchio":>16}{"ours/pin":>10}'
            f'  {"target":<22}{"verdict":<13}{"RTB":>18}{"naive numpy":>18}')
    log(head)
    log('-' * len(head))
    for op in OPS:
        v = V[op]
        ratio = f'{v["ratio_min"]:.2f}' if 'ratio_min' in v else '-'
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


def _jsonable(result):
    out = dict(result)
    timings = {}
    for (who, op), t in result['timings'].items():
        timings.setdefault(who, {})[op] = t
    out['timings'] = timings
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog='python -m newton_euler_tools.bench',
        description='Time our dynamics against Pinocchio, Robotics Toolbox '
                    'and naive numpy, and check the performance targets.')
    parser.add_argument('--quick', action='store_true',
                        help='fewer and shorter repeats (under 15 s); skips '
                             'the cold-compile measurement')
    parser.add_argument('--json', metavar='PATH',
                        help='write every figure to this JSON file')
    parser.add_argument('--robot', action='append', metavar='NAME',
                        help='robot to benchmark (repeatable; default: '
                             + ', '.join(DEFAULT_ROBOTS) + ')')
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
    load_start = _loadavg()
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
    print_first_call(first, log)

    log('\ntargets: ' + '; '.join(
        f'{r["robot"]} ' + ', '.join(f'{op} {r["verdicts"][op]["verdict"]}'
                                     for op in OPS) for r in results))
    elapsed = time.perf_counter() - t_start
    load_end = _loadavg()
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
                   'robots': [_jsonable(r) for r in results]}
        with open(args.json, 'w') as fh:
            json.dump(payload, fh, indent=1, default=_json_default)
        log(f'wrote {args.json}')
    return 0


def _loadavg():
    try:
        return os.getloadavg()[0]
    except (AttributeError, OSError):
        return None


def _json_default(x):
    if isinstance(x, (np.floating, np.integer, np.bool_)):
        return x.item()
    raise TypeError(f'not JSON serialisable: {type(x).__name__}')


if __name__ == '__main__':
    sys.exit(main())
