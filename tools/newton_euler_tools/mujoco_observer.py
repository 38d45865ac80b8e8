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
The node's observer against MuJoCo's contacts, over DDS.

    python -m newton_euler_tools.mujoco_observer [--quick] [--out DIR]
        [--real-time-factor X]

Three ROS processes in a domain of their own (ROS_DOMAIN_ID and the next
ids, else 1 + pid % 100; discovery on localhost), on the plant's
simulated time, the plant in lockstep: mujoco_sim_node with
``panda_mujoco_push`` (a Panda tracking a 0.6 Hz sinusoid, a pusher
pressing link 7 with 20 N through a MuJoCo contact), inverse_dynamics_node
with its observer on (wrench at link 7), tracking_controller_node (PD +
the node's feedforward).  A probe records joint_states, /clock, the
plant's true contact wrench at link 7 and the node's ``~/external_torque``,
``~/external_wrench`` and ``~/contact``.  Runs: **free** (no pusher; the
library's ``suggest_thresholds`` on it gives the thresholds, no hand
tuning), **push** (the node's observer with them), **held-out** (not with
``--quick``: the free motion again; any contact is a false one).

Figures (issue 36): the onset delay (first ``~/contact`` true after the
first tick MuJoCo's force exceeds 0.5 N: at most 50 ms); the node's
wrench at link 7 against each tick's mean contact force (:func:`tick_means`,
in link 7's axes, through the observer's lag) from 50 ms after the onset
to the end of the full push (within 10 % + 1 N); contacts in free motion
at full speed (0).  A table is printed and ``summary.json`` written to DIR
(default out/mujoco_observer); exit status 1 when a target is missed or
the graph failed, 2 on bad usage.
"""
import argparse
import json
import math
import os
import sys
import time

from newton_euler_ros.graph import (EFFORT_COMMANDS, ID,
                                    MUJOCO_CONTROLLER_REMAPS, MUJOCO_SIM,
                                    ros_args)
import numpy as np

from .demo import (check_exits, Child, DemoError, Recorder, run_to,
                   start_controller, start_runs, stop_children, wait_for)
from .processes import first_domain

SCENE = 'panda_mujoco_push'
LINK = 'link7'
GAIN = 100.0                # observer gain, 1/s: the offline test's
ONSET_FORCE = 0.5           # N: MuJoCo's contact force that is a touch
TARGET_DELAY = 0.05         # s
TARGET_RELATIVE, TARGET_ABSOLUTE = 0.10, 1.0    # 10 % + 1 N
SETTLE = 0.05               # s after the onset before comparing wrenches
QUICK_DURATION = 2.0        # s: the push (1.2 to 1.92 s) and its fading
STARTUP_TIMEOUT = 120.0
NO_THRESHOLD = 1.0e6        # N m: the free run reports no contact
#: PD gains over DDS: the scene's are for a controller in each 1 ms
#: physics step; a 500 Hz driver holds a command 2 ms, one tick after its
#: state (lockstep too), and the scene's wrist kd (4 on 0.005 kg m2)
#: would change its speed by 1.6 times itself a tick.  Feedforward tracks.

LOOP_GAINS = {'kp': [100.0] * 4 + [5.0, 5.0, 1.0],
              'kd': [10.0] * 4 + [0.5, 0.5, 0.1]}
LOCKSTEP_WAIT = 10.0        # wall s a lockstep tick may wait (warm-up)
#: the plant's pace: 0, as fast as the lockstep loop answers (each tick
#: waits for the command, which waits for the node's feedforward; the
#: plant paces its braked ticks before the first command itself)
RTF = 0.0


class Probe(Recorder):
    """The demo's recorder plus /clock, contact wrenches and the observer."""

    def __init__(self, domain, link):
        super().__init__(domain, states_after_commands=True,
                         name='observer_probe', start=f'{MUJOCO_SIM}/start',
                         commands=EFFORT_COMMANDS)
        from geometry_msgs.msg import WrenchStamped
        from rosgraph_msgs.msg import Clock
        from sensor_msgs.msg import JointState
        from std_msgs.msg import Bool
        self.clock = None           # the latest simulated time heard, s
        self.truth = {}             # stamp key -> MuJoCo's wrench (6,)
        self.wrench = {}            # stamp key -> the node's wrench (6,)
        self.residual = {}          # stamp key -> the node's residual (n,)
        self.contact = []           # (simulated time heard, bool)
        sub = self.node.create_subscription
        sub(Clock, '/clock', self._on_clock, 100)
        sub(WrenchStamped, f'{MUJOCO_SIM}/contact_wrenches/{link}',
            lambda m: self._on_wrench(self.truth, m), 1000)
        sub(WrenchStamped, f'{ID}/external_wrench',
            lambda m: self._on_wrench(self.wrench, m), 1000)
        sub(JointState, f'{ID}/external_torque', self._on_residual, 1000)
        sub(Bool, f'{ID}/contact', self._on_contact, 1000)

    def _on_clock(self, msg):
        self.clock = msg.clock.sec + msg.clock.nanosec * 1e-9

    def _on_wrench(self, into, msg):
        f, m = msg.wrench.force, msg.wrench.torque
        into[key(msg.header.stamp)] = np.array([f.x, f.y, f.z,
                                                m.x, m.y, m.z])

    def _on_residual(self, msg):
        self.residual[key(msg.header.stamp)] = np.array(msg.effort)

    def _on_contact(self, msg):
        self.contact.append((self.clock, bool(msg.data)))


def key(stamp):
    """Return a message stamp as integer microseconds (a dictionary key)."""
    return stamp.sec * 1_000_000 + int(round(stamp.nanosec * 1e-3))


def observer_args(thresholds):
    """Return the inverse-dynamics node's observer parameters."""
    values = ', '.join(repr(float(x)) for x in thresholds)
    return ['-p', 'observer.enabled:=true',
            '-p', f'observer.gain:={GAIN!r}',
            '-p', f'observer.thresholds:=[{values}]',
            '-p', f'observer.end_effectors:=[{LINK}]']


def plant(scenes, pusher, label, domain, log_dir, rtf):
    """Start mujoco_sim_node; it waits for its three subscribers."""
    return Child(f'{label}_mujoco_sim_node',
                 'newton_euler_ros.nodes.mujoco_sim_node',
                 ['-p', f'scene:={scenes[pusher][0]}',
                  '-p', 'wait_for_subscribers:=3',
                  '-p', 'lockstep:=true',
                  '-p', f'command_timeout:={LOCKSTEP_WAIT!r}',
                  '-p', f'real_time_factor:={rtf!r}'], domain, log_dir)


def run_graph(scenes, sim, label, duration, domain, log_dir, thresholds):
    """Run plant, inverse dynamics and controller once; return the probe."""
    id_scene = scenes[True][1]
    sim_time = ['-p', 'use_sim_time:=true']
    children = [sim]
    status = {}
    try:
        probe = Probe(domain, LINK)
    except BaseException:
        status[sim.label] = sim.stop()
        raise
    try:
        # demo.run_graph's order: the plant waits for three joint_states
        # subscribers, the controller starts last
        children.append(Child(
            f'{label}_inverse_dynamics_node',
            'newton_euler_ros.nodes.inverse_dynamics_node',
            ['-p', f'scene:={id_scene}',
             '-p', 'acceleration_source:=reference', *sim_time,
             # reliable and deep: the probe hears every sample's outputs
             '-p', 'qos.depth:=1000',
             *observer_args(thresholds)], domain, log_dir))
        # the node's kernels loaded (or compiled): it keeps up from t = 0
        wait_for(probe, children,
                 lambda: 'kernels ready' in children[1].log()
                 and probe.publishers(f'{ID}/torques') >= 1
                 and probe.subscribers(EFFORT_COMMANDS) >= 1
                 and probe.publishers(f'{ID}/contact') >= 1,
                 'mujoco_sim_node and inverse_dynamics_node')
        controller = start_controller(
            probe, children, label, domain, log_dir, duration,
            scene=id_scene, feedforward='true',
            tail=[*sim_time, *ros_args(MUJOCO_CONTROLLER_REMAPS)])
        run_to(probe, children, duration, STARTUP_TIMEOUT + 10.0 * duration,
               f'[{label}] simulation did not reach t = {duration} s in time')
        # what is in flight: the node's outputs up to the last state
        last = int(round(probe.states[-1][0] * 1e6))
        until = time.monotonic() + 10.0
        while time.monotonic() < until and \
                max(probe.residual, default=-1) < last:
            probe.spin_once(0.02)
        status[controller.label] = controller.stop()
    finally:
        stop_children(children, probe, status)
    check_exits(label, status, log_dir)
    if probe.t0 is None or len(probe.states) < 2:
        raise DemoError(f'[{label}] too few joint states recorded')
    return probe


def arrays(probe, duration):
    """Return the run's samples, sorted by stamp, from the start to duration."""
    rows = {}
    for s in probe.states:
        rows[int(round(s[0] * 1e6))] = s
    t0 = int(round(probe.t0 * 1e6))
    keys = sorted(k for k in rows if 0 < k - t0 <= duration * 1e6 + 1)
    n = len(rows[keys[0]][1])
    run = {'keys': keys, 't0': probe.t0,
           't': (np.array(keys, dtype=float) - t0) * 1e-6,
           'q': np.array([rows[k][1] for k in keys]),
           'qd': np.array([rows[k][2] for k in keys]),
           'tau': np.array([rows[k][3] for k in keys])}
    zero6 = np.zeros(6)
    run['truth'] = np.array([probe.truth.get(k, zero6) for k in keys])
    nan = np.full(6, np.nan)
    run['wrench'] = np.array([probe.wrench.get(k, nan) for k in keys])
    run['residual'] = np.array([probe.residual.get(k, np.full(n, np.nan))
                                for k in keys])
    run['contact'] = [(t - probe.t0, on) for t, on in probe.contact
                      if t is not None]
    return run


def suggest(scene, run, start):
    """
    Thresholds from the free run: the library's, on the node's settings.

    The observer runs from ``start`` (the brakes' release).  Returns
    (thresholds, largest difference from the node's residual on the same
    samples, the share of samples whose residual the probe heard).
    """
    from newton_euler_ros.core import MomentumObserver, observe_recording
    from newton_euler_ros.core.observer.thresholds import suggest_thresholds
    obs = MomentumObserver(scene.model, GAIN, thresholds=NO_THRESHOLD,
                           rest_reference=True)
    k = run['t'] >= start
    rec = observe_recording(obs, run['t'][k], run['q'][k], run['qd'][k],
                            run['tau'][k])
    # the node ran the same observer on all the samples (from its first);
    # after its lag the two agree
    late = run['t'][k] >= start + 10.0 / GAIN
    node = run['residual'][k][late]
    seen = np.isfinite(node).all(axis=1)
    agree = float(np.abs(rec.residual[late][seen] - node[seen]).max(
        initial=0.0))
    return suggest_thresholds(rec), agree, float(seen.mean())


def episodes(contact, start=-math.inf, stop=math.inf):
    """Return the times contact began (false to true) within [start, stop)."""
    began, before = [], False
    for t, on in contact:
        if on and not before and start <= t < stop:
            began.append(t)
        before = on
    return began


def replay(scene, run, thresholds):
    """
    Return the node's contact flag per sample, from its own residual.

    ``~/contact`` has no stamp: the library's contact test (the node's
    thresholds, hysteresis, rest reference) over the residual the node
    published dates each change.  Unheard samples hold the flag.
    """
    from newton_euler_ros.core import MomentumObserver
    from newton_euler_ros.core.observer.contact import (contact_step,
                                                        initial_contact)
    obs = MomentumObserver(scene.model, GAIN, thresholds=thresholds,
                           rest_reference=True)
    contact = initial_contact(obs)
    flags = np.zeros(len(run['t']), dtype=bool)
    for k, r in enumerate(run['residual']):
        if np.isfinite(r).all():
            contact_step(obs, contact, r, None, run['t'][k], run['q'][k],
                         run['qd'][k])
        flags[k] = contact.in_contact
    return list(zip(run['t'].tolist(), flags.tolist()))


def push_window(data):
    """Return (first time of the full force, last) of the scene's pusher."""
    rows = data['contacts']['pusher']['schedule']
    top = max(r['force'] for r in rows)
    full = [r['t'] for r in rows if r['force'] == top]
    return min(full), max(full), max(r['t'] for r in rows)


def tick_means(run):
    """
    Return MuJoCo's contact wrench at the link, the mean of each tick.

    The plant publishes a tick's last physics step's wrench; the
    observer balances the tick's impulse, and the pusher's ball chatters
    (a 28 N step after a light one, every 14 ms or so).  In lockstep the
    plant is a function of the efforts joint_states carried: the scene
    replayed on them gives each step's wrench.  Returns (means (N, 6),
    largest position difference from the run, rad: 0 if it is the run).
    """
    from newton_euler_ros.sim.mujoco_scene import scene_plant
    from newton_euler_ros.sim.scene import load_scene
    t, tau = run['t'], run['tau']
    plant = scene_plant(load_scene(SCENE))
    plant.hold()
    k0 = int(np.argmax(np.abs(tau).max(axis=1) > 0.0))
    plant.data.time = run['t0'] + t[k0 - 1] if k0 else run['t0']
    plant.release()
    step = plant.model.opt.timestep
    steps = max(1, int(round((t[1] - t[0]) / step)))
    means, zero, off = np.zeros((len(t), 6)), np.zeros(6), 0.0
    for k in range(k0, len(t)):
        for _ in range(steps):
            plant.advance(tau[k], step)
            means[k] += plant.contact_wrenches().get(LINK, zero)
        means[k] /= steps
        off = max(off, float(np.abs(plant.state()[0] - run['q'][k]).max()))
    return means, off


def wrench_error(scene, run, release, truth=None):
    """Compare the node's wrench with ``truth`` (None: as published)."""
    from newton_euler_ros.core.frames import frame_pose
    t = run['t']
    truth = run['truth'] if truth is None else truth
    touching = np.linalg.norm(truth[:, :3], axis=1) > ONSET_FORCE
    if not touching.any():
        return None
    onset = float(t[np.argmax(touching)])
    lagged = np.zeros(3)
    worst, worst_n, peak, compared, missing, where = 0, 0, 0, 0, 0, None
    for k in range(len(t)):
        a = math.exp(-GAIN * (t[k] - t[k - 1])) if k else 0.0
        lagged = a * lagged + (1.0 - a) * truth[k, :3]
        if not onset + SETTLE <= t[k] <= release + 1e-9:
            continue
        F = run['wrench'][k, :3]
        if not np.isfinite(F).all():
            missing += 1
            continue
        R = frame_pose(scene.model, run['q'][k], LINK)[:3, :3]
        expected = R.T @ lagged         # world axes -> link 7's
        err = float(np.abs(F - expected).max())
        bound = TARGET_RELATIVE * np.linalg.norm(expected) + TARGET_ABSOLUTE
        if err / bound > worst:
            worst, where = err / bound, {
                't': float(t[k]), 'axis': 'xyz'[np.argmax(abs(F - expected))],
                'max_speed_rad_s': float(np.abs(run['qd'][k]).max())}
        worst_n = max(worst_n, err)
        peak = max(peak, float(np.linalg.norm(expected)))
        compared += 1
    return {'onset': onset, 'compared': compared, 'missing': missing,
            'worst_ratio': worst, 'worst_error_n': worst_n,
            'lagged_force_peak_n': peak, 'worst_at': where}


def twins(data, out):
    """
    Write the scenes of the runs; return {pusher: (plant's, nodes')}.

    The plant takes the bundled scene, or it without its pusher (free);
    the nodes one scene: the Panda as a URDF (``observer.end_effectors``
    names a link), :data:`LOOP_GAINS`, the sinusoid a quarter period on
    around q0 - amplitude (it starts at rest where the arm does: the
    brakes let go at the first command, ticks after t = 0).
    """
    import yaml
    from newton_euler_ros.core import load_robot, model_to_urdf
    urdf = os.path.join(out, 'panda.urdf')
    with open(urdf, 'w') as fh:
        fh.write(model_to_urdf(load_robot(data['robot'])))

    def write(name, scene):
        path = os.path.join(out, f'{name}.yaml')
        with open(path, 'w') as fh:
            yaml.safe_dump(scene, fh, sort_keys=False)
        return path

    free = json.loads(json.dumps(data))
    free['name'] = f'{SCENE}_free'
    free['description'] = f'{SCENE} without its pusher'
    free['contacts'].pop('pusher')
    loop = json.loads(json.dumps(free))
    loop['name'] = f'{SCENE}_loop'
    loop['description'] = (f"{SCENE}'s motion as the nodes see it over "
                           'DDS (mujoco_observer.py)')
    loop['robot'] = urdf
    loop['controller'] = dict(LOOP_GAINS, feedforward=True)
    ref = loop['reference']
    amp = np.broadcast_to(np.asarray(ref['amplitude'], dtype=float), (7,))
    ref['offset'] = (np.asarray(loop['initial']['q']) - amp).tolist()
    ref['phase'] = [math.pi / 2.0] * 7
    nodes = write(loop['name'], loop)
    return {True: (SCENE, nodes), False: (write(free['name'], free), nodes)}


def data_path():
    """Return the bundled push scene's file."""
    from newton_euler_ros.sim.scene import scene_dirs
    return next(os.path.join(d, f'{SCENE}.yaml') for d in scene_dirs()
                if os.path.isfile(os.path.join(d, f'{SCENE}.yaml')))


def free_from(release):
    """When free motion counts: 10 observer time constants after release."""
    return release + 10.0 / GAIN


def released(run):
    """Return the first stamp with an effort: the brakes' release."""
    moving = np.abs(run['tau']).max(axis=1) > 0.0
    if not moving.any():
        raise DemoError('the plant never applied a torque (no command?)')
    return float(run['t'][np.argmax(moving)])


def save(out, runs):
    """Write the runs' samples to runs.npz (label_name arrays)."""
    np.savez(os.path.join(out, 'runs.npz'), **{
        f'{label}_{name}': np.asarray(run[name])
        for label, run in runs.items()
        for name in ('t', 'q', 'qd', 'tau', 'truth', 'wrench', 'residual',
                     'contact')})


def measure(data, out, log_dir, base, quick, rtf):
    """Run the graph twice (three times without quick); return the summary."""
    from newton_euler_ros.sim.scene import load_scene
    scenes = twins(data, out)
    scene = load_scene(scenes[True][1])     # the nodes': link 7 named
    duration = QUICK_DURATION if quick else scene.duration
    started = time.monotonic()
    runs = {}
    # the push run's plant starts with the free run's, and waits
    sims = [plant(scenes, False, 'free', base, log_dir, rtf),
            plant(scenes, True, 'push', base + 1, log_dir, rtf)]
    try:
        run = runs['free'] = arrays(run_graph(
            scenes, sims[0], 'free', duration, base, log_dir,
            [NO_THRESHOLD]), duration)
        # the brakes hold the arm with no effort: thresholds from motion
        start = released(run)
        thresholds, agree, covered = suggest(scene, run, start)
        if covered < 0.99:
            raise DemoError(
                f'[free] the node observed only {100 * covered:.0f} % of '
                'the joint states (it drops implausible speeds: the loop '
                'fell behind and the arm rang?); thresholds from it would '
                'mean nothing: run again with --real-time-factor 0.25 '
                f'(logs in {log_dir})')
    except BaseException:
        sims[1].stop()
        raise
    print(f'[free] brakes released at t = {start:.3f} s; suggested '
          f'thresholds (N m): {", ".join(f"{x:g}" for x in thresholds)}; '
          f"the node's residual within {agree:.1e} N m of the library's "
          f'on the same samples', flush=True)
    push = runs['push'] = arrays(run_graph(
        scenes, sims[1], 'push', duration, base + 1, log_dir, thresholds),
        duration)
    full, release, faded = push_window(data)
    means, replay_off = tick_means(push)
    result = wrench_error(scene, push, release, means)
    last_step = wrench_error(scene, push, release)
    if result is None:
        save(out, runs)
        raise DemoError('[push] MuJoCo reported no contact at '
                        f'{LINK}; see {log_dir}')
    onset, moving = result['onset'], released(push)
    flags = replay(scene, push, thresholds)
    heard = len(episodes(push['contact']))
    reported = episodes(flags, onset)
    delay = reported[0] - onset if reported else math.inf
    # free motion: from 10 time constants after the release (until then
    # the residual still holds the brakes' torque, which the observer
    # rightly sees as external) to the onset, and once the push faded
    settled = faded + 10.0 / GAIN
    free = free_from(moving)
    false = episodes(flags, free, onset) + episodes(flags, settled)
    braked = episodes(flags, -math.inf, free)
    replayed = len(episodes(flags))
    held = None
    if not quick:
        check = runs['held_out'] = arrays(run_graph(
            scenes, plant(scenes, False, 'held_out', base + 2, log_dir, rtf),
            'held-out', duration, base + 2, log_dir, thresholds), duration)
        held = episodes(replay(scene, check, thresholds),
                        free_from(released(check)))
        heard += len(episodes(check['contact']))
        replayed += len(episodes(replay(scene, check, thresholds)))
    save(out, runs)
    return {
        'scene': SCENE, 'link': LINK, 'gain': GAIN, 'quick': quick,
        'duration_s': duration, 'real_time_factor': rtf,
        'thresholds': [float(x) for x in thresholds],
        'residual_agreement_nm': agree, 'residual_samples_seen': covered,
        'brakes_released_s': {'free': start, 'push': moving},
        'onset_s': onset, 'contact_reported_s': reported[0] if reported
        else None, 'onset_delay_s': delay,
        'wrench': result, 'replay_max_position_error_rad': replay_off,
        'wrench_last_step_ratio': last_step['worst_ratio'],
        'full_force_from_s': full, 'release_s': release,
        'false_contacts_push_run': false,
        'false_contacts_held_out': held,
        'contacts_while_braked': braked,
        'brakes_fading_s': [moving, free],
        # ~/contact's changes to true as heard, and as replayed
        'contacts_heard': heard, 'contacts_replayed': replayed,
        'contact_heard_s': (episodes(push['contact'], onset) or [None])[0],
        'max_speed_rad_s': float(np.abs(push['qd']).max()),
        'wall_s': time.monotonic() - started,
        'targets': {
            'onset_delay': bool(delay <= TARGET_DELAY),
            'wrench': bool(result['compared'] > 0
                           and result['worst_ratio'] <= 1.0
                           and replay_off < 1e-9),
            'no_false_contact': not false and not held
            and heard == replayed}}


def table(s):
    """Return the printed table of a summary."""
    w = s['wrench']
    held = ('-' if s['false_contacts_held_out'] is None
            else str(len(s['false_contacts_held_out'])))
    ok = {True: 'met', False: 'MISSED'}
    t = s['targets']
    rows = [
        ('contact onset delay', f'{1e3 * s["onset_delay_s"]:.1f} ms',
         '<= 50 ms', ok[t['onset_delay']]),
        ('wrench error / (10 % + 1 N)', f'{w["worst_ratio"]:.2f} '
         f'(worst {w["worst_error_n"]:.2f} N at up to '
         f'{w["lagged_force_peak_n"]:.1f} N; {w["worst_at"]["axis"]} at '
         f't = {w["worst_at"]["t"]:.3f} s)', '<= 1', ok[t['wrench']]),
        ('false contacts, free motion', f'{len(s["false_contacts_push_run"])}'
         f' in the push run, {held} held out', '0',
         ok[t['no_false_contact']])]
    width = [max(len(r[i]) for r in rows) for i in range(4)]
    lines = [f'{s["scene"]} over DDS: node observer (gain {s["gain"]:g} '
             f'1/s) at {s["link"]}, onset at t = {s["onset_s"]:.3f} s, '
             f'joint speeds up to {s["max_speed_rad_s"]:.2f} rad/s']
    lines += ['  '.join(c.ljust(width[i]) for i, c in enumerate(r))
              for r in rows]
    return '\n'.join(lines)


def main(argv=None):
    """Run the measurement; return the exit status."""
    parser = argparse.ArgumentParser(
        prog='python -m newton_euler_tools.mujoco_observer',
        description="The node's momentum observer against MuJoCo's "
                    'contact wrenches, over DDS.')
    parser.add_argument('--quick', action='store_true',
                        help=f'{QUICK_DURATION:g} s runs, no held-out run')
    parser.add_argument('--out', default=os.path.join('out',
                                                      'mujoco_observer'),
                        help='output folder (default out/mujoco_observer)')
    parser.add_argument('--real-time-factor', type=float, default=RTF,
                        help="the plant's pace, simulated s per wall-clock "
                             f's (default {RTF:g})')
    args = parser.parse_args(argv)
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    from newton_euler_ros.core.robot_file import read_yaml
    try:
        base = first_domain(1 + os.getpid() % 100, 3)
    except ValueError as exc:
        print(f'mujoco_observer: {exc}', file=sys.stderr)
        return 2
    data = read_yaml(data_path())
    out, log_dir, _ = start_runs(args.out)
    try:
        summary = measure(data, out, log_dir, base, args.quick,
                          args.real_time_factor)
    except DemoError as exc:
        print(f'mujoco_observer: {exc}', file=sys.stderr)
        return 1
    print(table(summary), flush=True)
    with open(os.path.join(out, 'summary.json'), 'w') as fh:
        json.dump(summary, fh, indent=1)
    print(f'wrote {os.path.join(out, "summary.json")}', flush=True)
    return 0 if all(summary['targets'].values()) else 1


if __name__ == '__main__':
    sys.exit(main())
