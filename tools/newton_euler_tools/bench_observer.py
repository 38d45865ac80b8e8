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
contact for one sample: ``observer_step``, ``external_wrench``,
``contact_step``) and its parts, side by side with the way it was made
before the combined pass: D, C, g and J each from its own dynamics call
(``mass_matrix``, ``coriolis_matrix``, ``gravity_torques``,
``jacobian``), D qd and C^T qd formed from the matrices.  Both run over
the same states in this one process; the two residuals are compared
(they agree to round-off).  The target is 10 microseconds on a 7-joint
arm.  Figures are best-of-N, so a busy machine shows in them less than
in a mean; the load average is printed beside them.
"""
import argparse
import math
import os
import warnings

from newton_euler_ros.core import load_robot
from newton_euler_ros.core.dynamics import (coriolis_matrix, gravity_torques,
                                            jacobian, mass_matrix)
from newton_euler_ros.core.kernels import (F_TOOL, run_jacobian,
                                           run_momentum_terms)
from newton_euler_ros.core.observer import contact as observer_contact
from newton_euler_ros.core.observer import (contact_step, external_wrench,
                                            initial_contact, initial_state,
                                            MomentumObserver, observer_step)
from newton_euler_ros.core.observer import momentum
from newton_euler_ros.core.observer import wrench as observer_wrench
from numba import njit
import numpy as np

from .timing import min_time

TARGET_US = 10.0


# ---------------------------------------------------------------------------
# the update as it was before the combined pass (separate term calls)

@njit(cache=True)
def _separate_arithmetic(D, C, g, qd, tau, lost, armature, gain, dt, restart,
                         p, beta, beta_prev, S, r):
    """Run the observer's arithmetic on D, C and g given as matrices."""
    n = qd.shape[0]
    for i in range(n):
        s = armature[i] * qd[i]
        c = 0.0
        for j in range(n):
            s += D[i, j] * qd[j]
            c += C[j, i] * qd[j]
        p[i] = s
        beta[i] = tau[i] - lost[i] + c - g[i]
        if not (math.isfinite(p[i]) and math.isfinite(beta[i])):
            return i
    ok = True
    if not restart:
        for i in range(n):
            k = gain[i]
            a = math.exp(-k * dt)
            b = 1.0 - a
            known = 0.5 * dt * (beta[i] + beta_prev[i])
            u = (p[i] - (S[i] + r[i] / k) - known) / dt
            S[i] += known + r[i] * b / k + u * (dt - b / k)
            r[i] = a * r[i] + b * u
            ok &= math.isfinite(r[i]) and math.isfinite(S[i])
    for i in range(n):
        if not ok or not math.isfinite(r[i]):
            r[i] = 0.0
        if restart or not ok:
            S[i] = p[i] - r[i] / gain[i]
        beta_prev[i] = beta[i]
    return -1 if ok else -2


# the solve and the contact as they were compiled then (with numba's
# reference-counting runtime; uncached: numba's cache does not tell two
# compilations of one function with other options apart)
_dls_then = njit(observer_wrench._dls_wrench.py_func)
_contact_then = njit(observer_contact._contact.py_func)


class SeparatePasses:
    """The observer update made from separate D, C, g and J calls."""

    def __init__(self, obs):
        n = obs.n
        self.obs = obs
        self.D = np.zeros((n, n))
        self.C = np.zeros((n, n))
        self.g = np.zeros(n)
        self.J = np.zeros((6, n))
        self.p = np.zeros(n)
        self.beta = np.zeros(n)
        self.F = np.zeros(6)

    def step(self, state, t, q, qd, tau):
        """``observer_step`` as it was: four term calls, then arithmetic."""
        obs = self.obs
        dt = None if state.t_prev is None else t - state.t_prev
        m, ws = obs.model, obs.ws
        mass_matrix(m, q, ws=ws, out=self.D)
        coriolis_matrix(m, q, qd, ws=ws, out=self.C)
        gravity_torques(m, q, ws=ws, out=self.g)
        qd = momentum._vector('qd', qd, obs.n)
        tau = momentum._vector('tau', tau, obs.n)
        restart = dt is None or dt < 0.0 or dt > obs.max_gap
        bad = _separate_arithmetic(
            self.D, self.C, self.g, qd, tau, obs.lost, obs.armature,
            obs.gain, 0.0 if restart else dt, restart, self.p, self.beta,
            state.beta_prev, state.S, state.r)
        if bad >= 0:
            raise ValueError(f'non-finite torque at joint {bad}')
        state.t_prev = t
        state.samples += 1
        return state.r

    def wrench(self, q, r):
        """``external_wrench`` as it was: ``jacobian``, then the solve."""
        obs = self.obs
        J = jacobian(obs.model, q, 'base', ws=obs.ws, out=self.J)
        r = momentum._vector('r', r, obs.n)
        if not _dls_then(J, r, obs.damping, obs._A, obs._y, self.F):
            self.F[:] = 0.0
        return self.F

    def contact(self, contact, r, _t=None):
        """``contact_step`` as it was (before the rest reference)."""
        obs = self.obs
        now = _contact_then(r, obs.thresholds, obs.hysteresis,
                            obs._no_allowance, contact.active)
        if now and not contact.in_contact:
            contact.count += 1
        contact.in_contact = bool(now)
        return contact.in_contact


# ---------------------------------------------------------------------------
# timing

def _min_time(fn, number, repeat):
    """Return the best time per call of ``fn`` in microseconds."""
    return min_time(fn, number, repeat) * 1e6


def states(model, count, seed=0):
    """Return random states: ``count`` rows of q, qd, tau within +-1."""
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.0, 1.0, size=(count, 3, model.n))


def agreement(model, count=200):
    """
    Largest difference of the two updates' residuals and wrenches.

    Over ``count`` samples 1 ms apart, relative to the largest |r| and
    |F| (at least 1).
    """
    obs = MomentumObserver(model, gain=50.0, thresholds=5.0)
    old = SeparatePasses(MomentumObserver(model, gain=50.0,
                                          thresholds=5.0))
    s_new, s_old = initial_state(obs), initial_state(old.obs)
    worst, scale = 0.0, 1.0
    for k, (q, qd, tau) in enumerate(states(model, count, seed=1)):
        r_new, _ = observer_step(obs, s_new, 1e-3 * k, q, qd, tau)
        r_old = old.step(s_old, 1e-3 * k, q, qd, tau)
        F_new = external_wrench(obs, q, r_new)
        F_old = old.wrench(q, r_old)
        worst = max(worst, float(np.abs(r_new - r_old).max()),
                    float(np.abs(F_new - F_old).max()))
        scale = max(scale, float(np.abs(r_old).max()),
                    float(np.abs(F_old).max()))
    return worst / scale


def measure(model, number, repeat):
    """
    Return the rows [(label, combined us, separate us)].

    The first row is the full update (residual + wrench + contact); a part
    that one of the two does not have is None.
    """
    obs = MomentumObserver(model, gain=50.0, thresholds=5.0)
    obs.warm_up()
    old = SeparatePasses(MomentumObserver(model, gain=50.0, thresholds=5.0))
    q, qd, tau = states(model, 1)[0]
    n = model.n
    F = np.zeros(6)

    def updater(step, wrench, contact_fn, o):
        state, contact = initial_state(o), initial_contact(o)
        clock = [0.0]

        def update():
            clock[0] += 1e-3
            r = step(state, clock[0])
            wrench(r)
            contact_fn(contact, r, clock[0])
        return update

    new_update = updater(
        lambda s, t: observer_step(obs, s, t, q, qd, tau)[0],
        lambda r: external_wrench(obs, q, r, out=F),
        lambda c, r, t: contact_step(obs, c, r, None, t, q, qd), obs)
    old_update = updater(
        lambda s, t: old.step(s, t, q, qd, tau), lambda r: old.wrench(q, r),
        old.contact, old.obs)
    ws = obs.ws
    P = model.packed
    terms = np.zeros((3, n))
    tool = model.frames_array[F_TOOL]
    new_parts = {
        'model terms': lambda: run_momentum_terms(P, q, qd, ws.ws, ws.cw,
                                                  terms),
        'J': lambda: run_jacobian(P, q, model.tool_body, tool, False, ws.ws,
                                  ws.frames, obs.J),
    }
    ows = old.obs.ws
    old_parts = {
        'D': lambda: mass_matrix(model, q, ws=ows, out=old.D),
        'C': lambda: coriolis_matrix(model, q, qd, ws=ows, out=old.C),
        'g': lambda: gravity_torques(model, q, ws=ows, out=old.g),
        'J': lambda: jacobian(model, q, 'base', ws=ows, out=old.J),
    }
    t = {}
    # interleaved, so that a change in the machine's load hits both
    for _ in range(2):
        for key, fn in [('new', new_update), ('old', old_update)]:
            t[key] = min(t.get(key, math.inf),
                         _min_time(fn, number, repeat))
    for key, fn in list(new_parts.items()):
        t['new ' + key] = _min_time(fn, number, repeat)
    for key, fn in old_parts.items():
        t['old ' + key] = _min_time(fn, number, repeat)
    new_terms = t['new model terms'] + t['new J']
    old_terms = sum(t['old ' + k] for k in old_parts)
    return [
        ('observer update (residual + wrench + contact)', t['new'],
         t['old']),
        ('  D qd, C^T qd, g: one recursion (compiled call)',
         t['new model terms'], None),
        ('  D(q), mass_matrix', None, t['old D']),
        ('  C(q, qd), coriolis_matrix', None, t['old C']),
        ('  g(q), gravity_torques', None, t['old g']),
        ('  J(q): run_jacobian | jacobian', t['new J'], t['old J']),
        ('  observer arithmetic and Python (the rest)',
         t['new'] - new_terms, t['old'] - old_terms),
    ]


def _fmt(us):
    return f'{"-":>10}' if us is None else f'{us:>10.2f}'


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
    load0 = os.getloadavg()[0]
    rows = measure(model, number, repeat)
    load1 = os.getloadavg()[0]
    diff = agreement(model)
    print(f'\nmomentum observer, {model.name} ({model.n} joints): '
          f'microseconds per JointState, best of {repeat} x {number}; '
          f'load average {load0:.2f} -> {load1:.2f} on {os.cpu_count()} '
          f'cpus')
    print(f'{"":<52}{"combined":>10}{"separate":>10}')
    for label, new, old in rows:
        print(f'{label:<52}{_fmt(new)}{_fmt(old)}')
    total, before = rows[0][1], rows[0][2]
    verdict = 'meets' if total <= TARGET_US else 'MISSES'
    print(f'observer: {total:.2f} us per JointState ({before:.2f} us with '
          f'separate D, C, g, J calls: {before / total:.1f}x), {verdict} '
          f'the {TARGET_US:.0f} us target')
    print(f'combined vs separate: largest difference in residual and '
          f'wrench over 200 samples {diff:.1e} (relative)')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
