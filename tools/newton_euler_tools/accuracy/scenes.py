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
Scene experiments: what a modelling or simulation choice costs and buys.

Four experiments on a scene (a :class:`..sim.scene.Scene` or a bundled
scene's name), each returning records (plain dicts with ``section``,
``robot``, ``scene``, ``quantity``, ``method``, ``us``, ``error``,
``note`` and extra keys) for :mod:`.report`:

- :func:`effect_subsets` (section ``effects``): gravity only, gravity and
  velocity products, gravity and inertia, full, full and wrench; the cost
  of one call and the torque error along the scene's reference against
  the full model with the scene's wrench;
- :func:`single_vs_batch` (``batch``): a Python loop of single-state
  calls against one batched call over the same trajectory;
- :func:`feedforward_placement` (``feedforward``): the feedforward at the
  desired state, at the measured state, precomputed for the whole
  trajectory in one batch, and none;
- :func:`integrator_sweep` (``integrators``): RK4 and semi-implicit Euler
  over step sizes, against a converged RK4 solution, with the
  controller sampled at a fixed period so that every step size
  integrates the same closed loop.

:func:`run_all` runs the four on the bundled scenes.  Times come from
:class:`..bench.Timer` (interleaved repeats, the minimum reported), except
the whole-simulation wall times, which are one run each.
"""
import math
import warnings

from newton_euler_ros.core import (inverse_dynamics, inverse_dynamics_batch,
                                   Workspace)
from newton_euler_ros.core.effects import friction_torque
from newton_euler_ros.core.robot_file import RobotFileWarning
from newton_euler_ros.sim.run import simulate
from newton_euler_ros.sim.scene import INTEGRATORS, load_scene
from newton_euler_ros.sim.simulate import (integrator_step, SceneDynamics,
                                           tracking_controller)
import numpy as np

from ..bench import Timer

SCENES = ('puma_payload_press', 'panda_orbit_slow', 'panda_slow_earth')
CONTROL_PERIOD = 4e-3          # s: the sweep's controller, 250 Hz, held
FULL_STEPS = (0.25e-3, 0.5e-3, 1e-3, 2e-3, 4e-3)
QUICK_STEPS = (2e-3, 4e-3)
QUICK_SWEEP_DURATION = 0.2     # s
QUICK_FEEDFORWARD_DURATION = 1.0
REFINE = 4                     # converged solution: rk4, smallest step / 4
ORDER_FLOOR = 100 * np.finfo(float).eps   # times max |q|: round-off

# label: (velocity products, inertia D qdd, wrench)
SUBSETS = {
    'gravity only': (False, False, False),
    'gravity + velocity products': (True, False, False),
    'gravity + inertia': (False, True, False),
    'full': (True, True, False),
    'full + wrench': (True, True, True),
}
TRUTH = 'full + wrench'


# --------------------------------------------------------------------------
# helpers


def as_scene(scene):
    """Return ``scene`` itself, or the bundled scene of that name."""
    if isinstance(scene, str):
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', RobotFileWarning)
            return load_scene(scene)
    return scene


def record(section, scene, quantity, method, us, error=None, note='',
           **extra):
    """Return one result of the scene experiments as a plain dict."""
    out = {'section': section, 'robot': scene.model.name,
           'scene': scene.name, 'quantity': quantity, 'method': method,
           'us': None if us is None else float(us),
           'error': None if error is None else float(error), 'note': note}
    out.update(extra)
    return out


def reference_states(scene, duration=None, rate=None):
    """
    Sample the scene's reference trajectory.

    At ``rate`` (default the scene's) over ``duration`` (default the
    scene's), both ends included.  Returns (T, Q, QD, QDD), C-contiguous.
    """
    rate = scene.rate if rate is None else rate
    duration = scene.duration if duration is None else duration
    T = np.arange(int(round(duration * rate)) + 1) / rate
    return (T,) + states_at(scene, T)


def states_at(scene, T):
    """Return (Q, QD, QDD) of the scene's reference at the times ``T``."""
    rows = [scene.reference.at(t) for t in T]
    return tuple(np.ascontiguousarray([r[k] for r in rows])
                 for k in range(3))


def wrench_series(scene, T):
    """
    Return (W, frame): the scene's wrench at the times ``T``.

    ``W`` is (m, 6), or None when the scene has no wrench.  A wrench read
    from a topic is zero offline, as in :meth:`Scene.wrench_at`.
    """
    if not scene.effects.wrench:
        return None, 'base'
    W = np.array([scene.wrench.at(t) for t in np.asarray(T, dtype=float)])
    return np.ascontiguousarray(W.reshape(-1, 6)), scene.wrench.frame


def scene_torques_batch(scene, Q, QD, QDD, W=None, frame='base', ws=None,
                        out=None):
    """
    Return the scene's inverse dynamics for many states in one batch.

    The same torques as :meth:`SceneDynamics.torques` row by row: the
    scene's effects, the wrench ``W`` (ignored unless the scene has one),
    rotor inertia and friction.  The feedforward of a whole trajectory,
    precomputed.
    """
    eff = scene.effects
    tau = inverse_dynamics_batch(
        scene.model, Q, QD, QDD, W if eff.wrench else None, frame,
        gravity=eff.gravity, velocity_products=eff.velocity_products,
        ws=ws, out=out)
    if eff.armature:
        tau += scene.armature * QDD
    if eff.friction:
        tau += friction_torque(scene, QD)
    return tau


def held_controller(dyn, period, feedforward=None, feedforward_at='desired'):
    """
    Return :func:`tracking_controller`, sampled every ``period`` and held.

    The torques are computed at t = k period from the state then and held
    until the next sample (a digital controller at 1 / period Hz), however
    small the integration step: with steps that divide ``period``, every
    step size integrates the same sampled-data closed loop.
    """
    inner = tracking_controller(dyn, feedforward, feedforward_at)
    held = {'k': None, 'out': None}

    def control(t, q, qd):
        k = math.floor(t / period + 1e-9)
        if k != held['k']:
            held['k'] = k
            held['out'] = inner(t, q, qd)
        return held['out']
    return control


def fit_order(steps, errors, floor):
    """
    Return the slope of log error against log step, or None.

    Only errors above ``floor`` (round-off) count; None with fewer than
    two of them.
    """
    pts = [(h, e) for h, e in zip(steps, errors) if e > floor]
    if len(pts) < 2:
        return None
    x = np.log([h for h, _ in pts])
    y = np.log([e for _, e in pts])
    return float(np.polyfit(x, y, 1)[0])


def _rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


def _motion_rms(q_ref):
    """RMS of the reference's excursion from its start (a scale for q)."""
    return _rms(q_ref - q_ref[0])


# --------------------------------------------------------------------------
# 1. effect subsets


def _subset_args(label, Q, QD, QDD, W, i):
    velocity, inertia, wrench = SUBSETS[label]
    return (Q[i], QD[i] if velocity else None, QDD[i] if inertia else None,
            W[i] if wrench and W is not None else None)


def effect_subsets(scene, quick=False):
    """
    Rigid-body model subsets: cost per call and torque error.

    Along the scene's reference (sampled at the scene's rate over its
    duration), each subset of D qdd + C qd + g + J^T F_e is compared with
    the whole (the scene's gravity and wrench schedule; the payload is in
    the model): ``error`` = RMS of the difference / RMS of the truth,
    over samples and joints, ``abs_error`` = max |difference| (N m or N).
    ``us``: one call of :func:`inverse_dynamics` with the subset's flags
    at one state of the trajectory.  Friction and rotor inertia are
    outside these subsets (the notes give their size).
    """
    scene = as_scene(scene)
    model, eff = scene.model, scene.effects
    T, Q, QD, QDD = reference_states(scene)
    W, frame = wrench_series(scene, T)
    ws = Workspace(model)
    taus = {}
    for label, (velocity, _, _) in SUBSETS.items():
        tau = np.empty_like(Q)
        for i in range(T.size):
            inverse_dynamics(model, *_subset_args(label, Q, QD, QDD, W, i),
                             frame, gravity=eff.gravity,
                             velocity_products=velocity, ws=ws, out=tau[i])
        taus[label] = tau
    truth = taus[TRUTH]
    scale = _rms(truth)

    k = T.size // 2
    entries = {}
    for label, (velocity, _, _) in SUBSETS.items():
        if label == TRUTH and W is None:
            continue                        # the same call as 'full'
        q, qd, qdd, w = _subset_args(label, Q, QD, QDD, W, k)
        ns = {'inverse_dynamics': inverse_dynamics, 'model': model, 'q': q,
              'qd': qd, 'qdd': qdd, 'w': w, 'frame': frame,
              'g': eff.gravity, 'vp': velocity, 'ws': ws,
              'out': np.empty(model.n)}
        entries[label] = ('inverse_dynamics(model, q, qd, qdd, w, frame, '
                          'gravity=g, velocity_products=vp, ws=ws, out=out)',
                          ns, None, 1)
    times = Timer(quick).group(entries)

    outside = np.zeros_like(Q)
    if eff.armature:
        outside += scene.armature * QDD
    if eff.friction:
        outside += friction_torque(scene, QD)
    common = (f'truth: full + wrench along the reference, {T.size} states '
              f'at {scene.rate:g} Hz over {T[-1]:g} s')
    own = (eff.velocity_products, True, eff.wrench)
    records = []
    for label, flags in SUBSETS.items():
        diff = taus[label] - truth
        t = times.get(label, times['full'])
        notes = []
        if label == 'gravity only' and not eff.gravity:
            notes.append(f'{scene.name} has no gravity, so this model is '
                         f'tau = 0')
        if label == TRUTH:
            if W is None:
                notes.append(f'{scene.name} has no wrench: the same call '
                             f'as full')
            if eff.armature or eff.friction:
                notes.append(
                    f'{scene.name}: friction and rotor inertia, outside '
                    f'these subsets, add {_rms(outside):.3g} N m RMS '
                    f'({_rms(outside) / scale * 100:.3g}% of the '
                    f'rigid-body RMS torque {scale:.3g} N m)')
        scene_own = flags == own
        if scene_own:
            notes.append(f"{scene.name}'s own model")
        records.append(record(
            'effects', scene, 'tau', label, t['min_us'],
            _rms(diff) / scale if scale > 0.0 else None,
            '; '.join(notes) or common,
            abs_error=float(np.abs(diff).max()), truth_rms=scale,
            states=int(T.size), scene_model=bool(scene_own),
            median_us=t['median_us']))
    return records


# --------------------------------------------------------------------------
# 2. single state vs batch


def _loop(model, Q, QD, QDD, W, frame, g, vp, ws, out):
    for i in range(Q.shape[0]):
        inverse_dynamics(model, Q[i], QD[i], QDD[i],
                         None if W is None else W[i], frame, gravity=g,
                         velocity_products=vp, ws=ws, out=out[i])
    return out


def single_vs_batch(scene, quick=False):
    """
    Return records of a Python loop of single calls vs one batched call.

    Both evaluate the scene's rigid-body model (its gravity, velocity
    products and wrench) at the states of its reference trajectory;
    ``us`` is per state, ``error`` = max |batch - loop| / max |loop|
    (0 expected: the same arithmetic).
    """
    scene = as_scene(scene)
    model, eff = scene.model, scene.effects
    T, Q, QD, QDD = reference_states(scene)
    W, frame = wrench_series(scene, T)
    ws = Workspace(model)
    loop = np.empty_like(Q)
    batch = np.empty_like(Q)
    ns = {'loop': _loop, 'batch': inverse_dynamics_batch, 'model': model,
          'Q': Q, 'QD': QD, 'QDD': QDD, 'W': W, 'frame': frame,
          'g': eff.gravity, 'vp': eff.velocity_products, 'ws': ws,
          'L': loop, 'B': batch}
    m = T.size
    times = Timer(quick).group({
        'loop': ('loop(model, Q, QD, QDD, W, frame, g, vp, ws, L)', ns,
                 None, m),
        'batch': ('batch(model, Q, QD, QDD, W, frame, gravity=g, '
                  'velocity_products=vp, ws=ws, out=B)', ns, None, m)})
    _loop(model, Q, QD, QDD, W, frame, eff.gravity, eff.velocity_products,
          ws, loop)
    inverse_dynamics_batch(model, Q, QD, QDD, W, frame, gravity=eff.gravity,
                           velocity_products=eff.velocity_products, ws=ws,
                           out=batch)
    rel = float(np.abs(batch - loop).max() / np.abs(loop).max())
    note = (f'the scene model over {m} reference states; us per state; '
            f'error: max |batch - loop| / max |loop|')
    return [
        record('batch', scene, 'tau', 'loop of inverse_dynamics',
               times['loop']['min_us'], None, note, states=m,
               median_us=times['loop']['median_us']),
        record('batch', scene, 'tau', 'inverse_dynamics_batch',
               times['batch']['min_us'], rel, note, states=m,
               median_us=times['batch']['median_us'],
               speedup=times['loop']['min_us'] / times['batch']['min_us']),
    ]


# --------------------------------------------------------------------------
# 3. feedforward at the desired vs the measured state


def feedforward_placement(scene, quick=False):
    """
    Return records of the feedforward at the desired vs the measured state.

    The scene is simulated (its integrator and step; the controller runs
    every step, as :func:`simulate` does) with the feedforward at the
    desired state, at the measured state, and without one.  Records give
    the tracking RMS and max (rad or m), the RMS over the second half
    (``tracking_rms_late``, after any start-up transient), ``error`` =
    tracking RMS / RMS of the reference's excursion, and ``us`` = the
    feedforward's cost per control step: one
    :meth:`SceneDynamics.torques` call, or the whole trajectory's
    desired-state feedforward in one batch divided by its steps
    (``ff_mismatch``: its max difference from the online one, relative).
    """
    scene = as_scene(scene)
    duration = (min(scene.duration, QUICK_FEEDFORWARD_DURATION) if quick
                else scene.duration)
    runs = {'none (PD only)': (False, 'desired'),
            'desired state': (True, 'desired'),
            'measured state': (True, 'measured')}
    results = {label: simulate(scene, duration, feedforward=ff,
                               feedforward_at=at)
               for label, (ff, at) in runs.items()}
    des = results['desired state']
    steps = des.summary['steps']
    scale = _motion_rms(des.q_ref)

    # cost per control step
    dyn = SceneDynamics(scene)
    T = des.t[:steps]
    Q, QD, QDD = states_at(scene, T)
    W, frame = wrench_series(scene, T)
    k = steps // 2
    ff = np.empty_like(Q)
    ns = {'dyn': dyn, 'q_d': Q[k], 'qd_d': QD[k], 'qdd_d': QDD[k],
          't': T[k], 'q': des.q[k], 'qd': des.qd[k],
          'batch': scene_torques_batch, 'scene': scene, 'Q': Q, 'QD': QD,
          'QDD': QDD, 'W': W, 'frame': frame, 'ws': Workspace(scene.model),
          'FF': ff}
    times = Timer(quick).group({
        'desired state': (
            'dyn.torques(q_d, qd_d, qdd_d, *scene.wrench_at(t))', ns, None,
            1),
        'measured state': (
            'dyn.torques(q, qd, qdd_d, *scene.wrench_at(t))', ns, None, 1),
        'precomputed': ('batch(scene, Q, QD, QDD, W, frame, ws=ws, out=FF)',
                        ns, None, steps)})
    scene_torques_batch(scene, Q, QD, QDD, W, frame, out=ff)
    online = des.tau_ff[:steps]
    mismatch = float(np.abs(ff - online).max()
                     / max(np.abs(online).max(), 1e-300))

    base = (f'{scene.integrator} step {scene.step * 1e3:g} ms, controller '
            f'every step, {duration:g} s; error: tracking RMS / RMS of the '
            f'reference excursion; tracking_rms_late: the second half')
    q_d0, qd_d0, _ = scene.reference.at(0.0)
    off_q = float(np.abs(scene.q0 - q_d0).max())
    off_qd = float(np.abs(scene.qd0 - qd_d0).max())
    if off_q > 0.0 or off_qd > 0.0:
        base += (f'; {scene.name} starts off its reference (by up to '
                 f'{off_q:.3g} in q, {off_qd:.3g} /s in qd): a transient '
                 f'the feedforward does not remove')

    def tracking(r):
        err = r.q - r.q_ref
        late = err[err.shape[0] // 2:]
        return {'tracking_rms': r.summary['tracking_rms'],
                'tracking_max': r.summary['tracking_max'],
                'tracking_rms_late': _rms(late),
                'error': r.summary['tracking_rms'] / scale}

    records = []
    for label, r in results.items():
        us = times[label]['min_us'] if label in times else None
        note = base
        if label == 'measured state':
            note = ('inverse dynamics at the measured q, qd with the '
                    'reference qdd (friction at the measured velocity)')
        records.append(record(
            'feedforward', scene, 'q', label, us, note=note,
            duration=r.summary['duration'], step=r.summary['step'],
            steps=steps,
            median_us=None if us is None else times[label]['median_us'],
            **tracking(r)))
    records.append(record(
        'feedforward', scene, 'q', 'desired state, precomputed (one batch)',
        times['precomputed']['min_us'],
        note=f'the desired-state feedforward of all {steps} steps in one '
             f'batch call (plus a row lookup per step); the same torques '
             f'as online: max difference {mismatch:.1e} relative',
        duration=des.summary['duration'], step=des.summary['step'],
        steps=steps, ff_mismatch=mismatch,
        median_us=times['precomputed']['median_us'], **tracking(des)))
    return records


# --------------------------------------------------------------------------
# 4. integrators and step sizes


def _check_steps(steps, period, duration):
    for h in steps:
        ratio = period / h
        if abs(ratio - round(ratio)) > 1e-9 or round(ratio) < 1:
            raise ValueError(f'step {h} s does not divide the control '
                             f'period {period} s')
    cycles = duration / period
    if abs(cycles - round(cycles)) > 1e-9:
        raise ValueError(f'duration {duration} s is not a whole number of '
                         f'control periods ({period} s)')


def integrator_sweep(scene, quick=False, steps=None, duration=None,
                     period=CONTROL_PERIOD):
    """
    Return records of RK4 and semi-implicit Euler over step sizes.

    The controller (PD plus the desired-state feedforward) is sampled
    every ``period`` and held (:func:`held_controller`) at every step
    size, so each run integrates the same closed loop and differs only
    by the integrator's error (:func:`simulate` alone would re-run the
    controller every step and change the loop with the step).  Per
    (integrator, step): ``error`` = ``abs_error`` = max |q - q_conv| over
    the common sample times, against RK4 at the smallest step / REFINE;
    ``relative_error`` = that / max |q_conv - q_conv(0)|; ``drift`` = the
    energy drift relative to the energy scale; ``tracking_rms``;
    ``us`` = one integrator step (Timer, no energy bookkeeping),
    ``cost`` = us / step (s per simulated s); ``wall_per_sim_s`` = the
    whole :func:`simulate` run (with controller and energy bookkeeping)
    per simulated second; ``order`` = the fitted slope of log error on
    log step above round-off (None if fewer than two such points).
    """
    scene = as_scene(scene)
    steps = sorted(steps or (QUICK_STEPS if quick else FULL_STEPS))
    if duration is None:
        duration = QUICK_SWEEP_DURATION if quick else scene.duration
    _check_steps(steps, period, duration)

    def run(method, h):
        return simulate(scene, duration,
                        controller=held_controller(SceneDynamics(scene),
                                                   period),
                        integrator=method, step=h)

    h_ref = steps[0] / REFINE
    ref = run('rk4', h_ref)
    motion = float(np.abs(ref.q - ref.q[0]).max())
    floor = ORDER_FLOOR * max(1.0, float(np.abs(ref.q).max()))

    dyn = SceneDynamics(scene)
    k = ref.q.shape[0] // 2
    q, qd, tau = ref.q[k].copy(), ref.qd[k].copy(), ref.tau[k].copy()
    ns = {'q': q, 'qd': qd, 'tau': tau, 't': float(ref.t[k]),
          'h': steps[0]}
    entries = {}
    for method in INTEGRATORS:
        ns_m = dict(ns, step=integrator_step, dyn=dyn, method=method)
        entries[method] = ('step(dyn, method, q, qd, tau, t, h)', ns_m,
                           None, 1)
    times = Timer(quick).group(entries)

    results = {}
    for method in INTEGRATORS:
        for h in steps:
            r = run(method, h)
            ratio = int(round(h / h_ref))
            q_conv = ref.q[::ratio]
            if q_conv.shape != r.q.shape:
                raise RuntimeError('sample times do not match')
            results[method, h] = (r, float(np.abs(r.q - q_conv).max()))
    orders = {m: fit_order(steps, [results[m, h][1] for h in steps], floor)
              for m in INTEGRATORS}

    notes = [f'controller sampled every {period * 1e3:g} ms and held at '
             f'every step; converged: rk4 at {h_ref * 1e3:g} ms; '
             f'{duration:g} s']
    if scene.effects.friction and np.any(scene.coulomb > 0.0):
        notes.append(f'{scene.name}: Coulomb friction, sign(qd), is '
                     f'discontinuous, which caps the order of rk4 (fitted '
                     f'order {_fmt_order(orders["rk4"])})')
    if not scene.effects.velocity_products:
        notes.append(f'{scene.name} leaves velocity products out, so its '
                     f'model does not conserve energy: the drift floor is '
                     f'the work of the omitted C qd, not integrator error')
    if orders['rk4'] is None:
        notes.append(f'{scene.name}: rk4 at round-off at every step')
    note = '; '.join(notes)
    records = []
    for method in INTEGRATORS:
        t = times[method]
        for h in steps:
            r, err = results[method, h]
            s = r.summary
            records.append(record(
                'integrators', scene, 'q', method, t['min_us'], err, note,
                integrator=method, step=h, abs_error=err,
                relative_error=err / motion if motion > 0.0 else None,
                drift=s['energy_drift_relative'],
                drift_abs=s['energy_drift_max'],
                tracking_rms=s['tracking_rms'],
                cost=t['min_us'] * 1e-6 / h,
                wall_per_sim_s=s['wall_time_s'] / s['duration'],
                us_per_step_wall=s['wall_time_s'] / s['steps'] * 1e6,
                order=orders[method], period=period, duration=duration,
                reference_step=h_ref, median_us=t['median_us']))
    return records


def _fmt_order(p):
    return 'n/a' if p is None else f'{p:.2f}'


# --------------------------------------------------------------------------


def run_all(quick=False, scenes=None):
    """Return the records of the four experiments on each scene."""
    records = []
    for name in scenes or SCENES:
        scene = as_scene(name)
        for experiment in (effect_subsets, single_vs_batch,
                           feedforward_placement, integrator_sweep):
            records += experiment(scene, quick)
    return records
