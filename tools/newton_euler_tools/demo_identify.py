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
The identification loop end to end, over DDS.

Excite, record, identify, track again, pick up a payload and estimate it.

    python -m newton_euler_tools.demo_identify [--out DIR] [--quick]

The plant (robot_sim_node) is a Franka Panda whose links differ from the
published URDF (example-robot-data) as real arms do (masses +-15 %,
centres of mass +-15 mm, inertias +-25 %: ``ident_example.perturb_urdf``),
with joint friction (viscous + Coulomb) and rotor inertia the URDF does
not have.  inverse_dynamics_node is given the published URDF.

1. ``newton-euler excite`` writes an excitation trajectory (one period
   of 8 s, 4 harmonics, 5 s of optimisation; ``--quick``: 5 s, 3, 4 s).
2. It runs through the node (``~/trajectory_in`` -> ``~/trajectory_out``,
   efforts filled) into the simulator's ``~/joint_trajectory`` (PD + the
   points' effort, as joint_trajectory_controller); ``/joint_states`` is
   recorded by a subscriber and written to a rosbag2 (MCAP) with
   ``ident.bag``'s writer.
3. ``newton-euler identify`` writes the corrected URDF.
4. Two runs at once, each node given the identified URDF on
   ``robot_description`` with ``drives.compensate:=true``: the same
   trajectory as is, and with the plant holding a payload (its
   ``payload.*`` parameters) the node is not told of, recorded.
5. ``newton-euler payload --json`` estimates the payload from that
   recording.
6. A last run: the estimate goes to the node's ``payload.*`` in one
   ``set_parameters_atomically`` call, and the trajectory runs again.

Every run is a fresh pair of processes in a ROS domain of its own
(``ROS_DOMAIN_ID`` and the next three ids if it is set, else from
1 + pid % 100), discovery limited to this host.  A run's processes start
while an earlier step works (the first run's during ``excite``, the
next two during the first run, the last during ``identify``); the
simulator starts its clock only when the demo subscribes to its
``/joint_states``, once the node has its model.  The commands run
in this process through the console script's entry point, their output
saved.  Writes ``summary.md`` (one table: feedforward torque error
against the plant's true torque along the plan, and the tracking error,
per run), ``summary.json`` (the figures and the wall time of each step),
``tracking.png``, ``torques.png``, the files of every step (URDFs,
trajectory, bags, the commands' output) and the nodes' logs to DIR
(default out/demo_identify).
"""
import argparse
import contextlib
import io
import json
import os
import shutil
import sys
import time
import warnings
import xml.etree.ElementTree as ET

import numpy as np

from .demo import base_domain, DemoError
from .demo_identify_runs import drive, LoopRun, wait_until
from .ident_example import BASE, panda_path, perturb_urdf, TIP

# what the plant has and the URDF does not
VISCOUS = [0.25, 0.3, 0.2, 0.25, 0.1, 0.1, 0.05]
COULOMB = [0.8, 0.9, 0.6, 0.7, 0.3, 0.3, 0.2]
ARMATURE = [0.08, 0.08, 0.06, 0.06, 0.03, 0.03, 0.02]
# the payload picked up (node parameter forms)
PAYLOAD = {'mass': 2.0, 'com': [0.0, 0.02, 0.08],
           'inertia': [0.006, 0.005, 0.003, 0.0, 0.0, 0.0]}
# joint_trajectory_controller-like PD: stiff enough to follow, soft
# enough that the feedforward matters
KP = [300.0, 300.0, 250.0, 250.0, 60.0, 60.0, 20.0]
KD = [30.0, 30.0, 25.0, 25.0, 6.0, 6.0, 2.0]
RATE = 250.0
START = [0.0, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8]
# excitation: period (s), periods, harmonics, optimisation budget (s)
FULL = (8.0, 1, 4, 5.0)
QUICK = (4.0, 1, 3, 2.0)


def keep_bytecode(out):
    """
    Keep the bytecode this process and its children compile, in a cache.

    The demo and each of its 8 nodes import numba, scipy and rclpy (some
    1500 modules).  With PYTHONDONTWRITEBYTECODE set (and no
    PYTHONPYCACHEPREFIX), every process would compile them from source
    again, 1.5 to 2 s of CPU apiece (twice that for the commands' scipy
    parts).  The bytecode then goes to ``pycache`` beside NUMBA_CACHE_DIR
    (else beside ``out``), never next to the sources.
    """
    if not os.environ.get('PYTHONDONTWRITEBYTECODE') or \
            os.environ.get('PYTHONPYCACHEPREFIX'):
        return
    beside = os.environ.get('NUMBA_CACHE_DIR') or out
    prefix = os.path.join(os.path.dirname(os.path.abspath(beside)),
                          'pycache')
    os.environ['PYTHONPYCACHEPREFIX'] = prefix
    del os.environ['PYTHONDONTWRITEBYTECODE']
    sys.pycache_prefix = prefix
    sys.dont_write_bytecode = False


def warm_excite(model):
    """
    Load (or, the first time, compile) what ``excite`` evaluates.

    Its time budget counts from its start: with numba's cache still
    empty, compiling the regressor would take all of it, and the
    trajectory would be the unoptimised series.
    """
    import scipy.optimize  # noqa: F401
    from newton_euler_ros.core.regressor import regressor_batch
    from newton_euler_ros.ident.base import random_states
    regressor_batch(model, *random_states(model, 2), drives=True)


class Steps:
    """The wall time of each step of the demo, printed as it goes."""

    def __init__(self, started):
        self.started = started
        self.times = {}
        self._step = None

    def begin(self, key, text):
        """Start step ``key``, printing ``text`` and the time so far."""
        self._step = (key, time.monotonic())
        print(f'{text} (at {time.monotonic() - self.started:.1f} s)',
              flush=True)

    def end(self):
        """End the current step."""
        key, begun = self._step
        self.times[key] = round(time.monotonic() - begun, 2)


def newton_euler(*args, log):
    """
    Run ``newton-euler ARGS``; write its output to ``log``, return stdout.

    The console script's entry point (``newton_euler_ros.cli.main``) runs
    in this process, which has imported numba, scipy and the kernels
    already: a process of its own would spend 2 to 4 s starting up.
    DemoError when it fails.
    """
    from newton_euler_ros import cli
    args = [str(a) for a in args]
    out, err = io.StringIO(), io.StringIO()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = cli.main(args)
    except SystemExit as exc:       # argparse on bad arguments
        code = exc.code
    stdout, stderr = out.getvalue(), err.getvalue()
    with open(log, 'w', encoding='utf-8') as f:
        f.write('$ newton-euler ' + ' '.join(args) + '\n')
        f.write(stdout + stderr)
    if code != 0:
        raise DemoError(f'newton-euler {args[0]} failed: '
                        f'{stderr.strip()[-400:]}')
    return stdout


def real_plant_urdf(text, links, seed):
    """
    Return the plant's URDF: perturbed inertials, ending at the tip link.

    The hand and fingers (fixed at zero, as the node lumps them) become one
    inertial of ``panda_link8``, so that the simulator's scene, which takes
    a URDF with one leaf, has the same bodies and end-effector frame.
    """
    from newton_euler_ros.core.regressor import link_inertials, N_INERTIAL
    from newton_euler_ros.ident.fit import fixed_parts
    rng = np.random.default_rng(seed)
    out = perturb_urdf(text, links, rng)
    model = _chain_of_text(out)
    attached = fixed_parts(model, out)[-1]
    m, c, Ic = link_inertials(attached[:N_INERTIAL])
    R, p = model.tool[:3, :3], model.tool[:3, 3]
    c8, I8 = R.T @ (c - p), R.T @ Ic @ R
    c8, I8, m = c8.tolist(), I8.tolist(), float(m)
    root = ET.fromstring(out)
    drop = set()
    for joint in list(root.findall('joint')):
        if joint.find('parent').get('link') in drop | {TIP}:
            drop.add(joint.find('child').get('link'))
            root.remove(joint)
    for joint in list(root.findall('joint')):      # grandchildren
        if joint.find('parent').get('link') in drop:
            drop.add(joint.find('child').get('link'))
            root.remove(joint)
    for link in list(root.findall('link')):
        if link.get('name') in drop:
            root.remove(link)
        elif link.get('name') == TIP:
            for el in link.findall('inertial'):
                link.remove(el)
            inertial = ET.SubElement(link, 'inertial')
            ET.SubElement(inertial, 'origin', xyz=' '.join(map(repr, c8)),
                          rpy='0 0 0')
            ET.SubElement(inertial, 'mass', value=repr(m))
            ET.SubElement(inertial, 'inertia', ixx=repr(I8[0][0]),
                          ixy=repr(I8[0][1]), ixz=repr(I8[0][2]),
                          iyy=repr(I8[1][1]), iyz=repr(I8[1][2]),
                          izz=repr(I8[2][2]))
    return ET.tostring(root, encoding='unicode')


def _chain_of_text(text):
    from newton_euler_ros.core.urdf import urdf_model
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return urdf_model(text, 'plant', base=BASE, tip=TIP)[0]


def write_scene(path, robot_file, duration):
    """Write the plant's scene: the real URDF, friction, rotor inertia."""
    lines = [
        '# written by newton_euler_tools.demo_identify: the "real" Panda',
        'name: panda_real',
        'description: a Panda whose inertials, friction and rotor inertia '
        'differ from its URDF',
        f'robot: {os.path.basename(robot_file)}',
        'effects:',
        '  gravity: true',
        '  velocity_products: true',
        f'  friction: {{viscous: {VISCOUS}, coulomb: {COULOMB}}}',
        f'  armature: {ARMATURE}',
        f'initial: {{q: {START}, qd: {[0.0] * 7}}}',
        f'reference: {{type: quintic, goal: {START}, duration: 1.0}}',
        f'controller: {{kp: {KP}, kd: {KD}, feedforward: true}}',
        f'integrator: {{method: rk4, step: 1.0e-3, duration: {duration}, '
        f'rate: {RATE}}}', '']
    with open(path, 'w', encoding='utf-8') as f:
        f.write('\n'.join(lines))


def plan_at(times, segment):
    """Planned positions at the given times."""
    ts, Q = segment[0], segment[1]
    return np.column_stack([np.interp(times, ts, Q[:, j])
                            for j in range(Q.shape[1])])


def load_segment(path):
    """(t, Q, QD, QDD) of a trajectory JSON."""
    with open(path, encoding='utf-8') as f:
        traj = json.load(f)
    pts = traj['points']
    return (np.array([p['time_from_start'] for p in pts]),
            np.array([p['positions'] for p in pts]),
            np.array([p['velocities'] for p in pts]),
            np.array([p['accelerations'] for p in pts]))


def true_torques(truth_model, segment, payload=None):
    """Return the plant's torque along the plan (body, friction, rotor)."""
    from newton_euler_ros.core import inverse_dynamics_batch
    from newton_euler_ros.core.model import inertia_matrix, with_payload
    model = truth_model
    if payload:
        model = with_payload(model, payload['mass'], payload['com'],
                             inertia_matrix(*payload['inertia']))
    _, Q, QD, QDD = segment
    return (inverse_dynamics_batch(model, Q, QD, QDD)
            + np.asarray(VISCOUS) * QD + np.asarray(COULOMB) * np.sign(QD)
            + np.asarray(ARMATURE) * QDD)


def quiet_load(path):
    """Load the Panda chain of a URDF without its notes."""
    from newton_euler_ros.core import load_robot
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot(path, base=BASE, tip=TIP)


def prepare_plots():
    """Import matplotlib (Agg), a second or two, ahead of :func:`plot`."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot  # noqa: F401


def plot(runs, segment, truth, out):
    """Tracking error and feedforward torque error per run."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(9, 4))
    for label, r in runs.items():
        err = np.linalg.norm(r['q'] - plan_at(r['t'], segment), axis=1)
        ax.semilogy(r['t'], err + 1e-9, label=label, lw=0.9)
    ax.set_xlabel('simulated time (s)')
    ax.set_ylabel('|q - q_plan| (rad)')
    ax.set_title('Panda: tracking error along the excitation trajectory')
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, 'tracking.png'), dpi=100)
    plt.close(fig)
    fig, axes = plt.subplots(7, 1, sharex=True, figsize=(9, 12))
    t = segment[0]
    for j, ax in enumerate(axes):
        for label, r in runs.items():
            ax.plot(t, r['ff'][:, j] - truth[label][:, j], lw=0.8,
                    label=label)
        ax.set_ylabel(f'joint {j + 1}\nN m', fontsize=8)
    axes[0].set_title('feedforward effort minus the true torque')
    axes[0].legend(fontsize=7, ncol=2)
    axes[-1].set_xlabel('time along the plan (s)')
    fig.tight_layout()
    fig.savefig(os.path.join(out, 'torques.png'), dpi=90)
    plt.close(fig)


def main(argv=None):
    """Run the loop; return the exit status."""
    parser = argparse.ArgumentParser(
        prog='python -m newton_euler_tools.demo_identify',
        description=__doc__.strip().split('\n')[0])
    parser.add_argument('--out', default=os.path.join('out',
                                                      'demo_identify'))
    parser.add_argument('--quick', action='store_true',
                        help='a short trajectory and optimisation (tests)')
    parser.add_argument('--seed', type=int, default=7)
    args = parser.parse_args(argv)
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    started = time.monotonic()
    out = os.path.abspath(args.out)
    log_dir = os.path.join(out, 'logs')
    os.makedirs(log_dir, exist_ok=True)
    keep_bytecode(out)
    period, periods, harmonics, budget = QUICK if args.quick else FULL
    try:
        base = base_domain(4)
    except ValueError as exc:
        print(f'demo_identify: {exc}', file=sys.stderr)
        return 2
    steps = Steps(started)
    live = []           # the runs to stop if anything fails
    try:
        domains = iter(range(base, base + 4))
        published = os.path.join(out, 'panda_published.urdf')
        shutil.copyfile(panda_path(), published)
        duration = period * periods + 0.5
        traj = os.path.join(out, 'excitation.json')
        steps.begin('excite', '[1/6] newton-euler excite; the nodes of the '
                    'first run start meanwhile')
        nominal = quiet_load(published)
        with open(published, encoding='utf-8') as f:
            text = f.read()
        real = os.path.join(out, 'panda_real.urdf')
        with open(real, 'w', encoding='utf-8') as f:
            f.write(real_plant_urdf(text, set(nominal.info['urdf']['links']),
                                    args.seed))
        truth_model = quiet_load(real)
        scene = os.path.join(out, 'panda_real.yaml')
        write_scene(scene, real, duration)
        first = LoopRun('published', scene, next(domains), log_dir,
                        urdf=published)
        live.append(first)
        warm_excite(nominal)
        newton_euler('excite', published, '--base', BASE, '--tip', TIP, '-o',
                     traj, '--period', period, '--harmonics', harmonics,
                     '--seconds', period * periods, '--budget', budget,
                     '--start', *START, log=os.path.join(out, 'excite.txt'))
        steps.end()
        segment = load_segment(traj)
        # the plant's torque along the plan; computed now, it also puts the
        # batch kernel the node fills the plan with in numba's cache
        bare = true_torques(truth_model, segment)
        held = true_torques(truth_model, segment, PAYLOAD)
        published_key = 'published URDF'
        identified_key = 'identified URDF + drive compensation'
        untold = f'{PAYLOAD["mass"]:g} kg payload, node not told'
        told = f'{PAYLOAD["mass"]:g} kg payload, estimate applied'
        truth = {published_key: bare, identified_key: bare, untold: held,
                 told: held}
        runs = {}
        steps.begin('published', '[2/6] run with the published URDF, '
                    'recording /joint_states')
        wait_until([first], first.ready, 'the nodes of the first run')
        first.go(segment)
        wait_until([first], first.begun, 'the simulation start')
        # the next two runs' nodes start now; their URDF comes later
        second = LoopRun('identified', scene, next(domains), log_dir,
                         compensate=True)
        third = LoopRun('payload_untold', scene, next(domains), log_dir,
                        compensate=True, plant_payload=PAYLOAD)
        live += [second, third]
        drive([first], duration)
        bag1 = os.path.join(out, 'recording')
        runs[published_key] = first.finish(duration, bag=bag1)
        steps.end()
        identified = os.path.join(out, 'panda_identified.urdf')
        steps.begin('identify', '[3/6] newton-euler identify; the nodes of '
                    'the last run start meanwhile')
        last = LoopRun('payload_told', scene, next(domains), log_dir,
                       compensate=True, plant_payload=PAYLOAD)
        live.append(last)
        newton_euler('identify', published, bag1, '--base', BASE, '--tip',
                     TIP, '-o', identified,
                     log=os.path.join(out, 'identify.txt'))
        with open(identified, encoding='utf-8') as f:
            identified_text = f.read()
        steps.end()
        steps.begin('identified + untold', '[4/6] two runs at once, the '
                    'node given the identified URDF (robot_description) + '
                    f'drive compensation: as is, and with {PAYLOAD["mass"]:g}'
                    ' kg picked up (node not told), recorded')
        for r in (second, third, last):
            r.describe(identified_text)
        wait_until([second, third], lambda: second.ready() and third.ready(),
                   'the nodes of the second and third runs')
        second.go(segment)
        third.go(segment)
        wait_until([second, third],
                   lambda: all([second.begun(), third.begun()]),
                   'the simulation start')
        drive([second, third], duration)
        bag2 = os.path.join(out, 'payload_recording')
        runs[identified_key] = second.finish(duration)
        runs[untold] = third.finish(duration, bag=bag2)
        steps.end()
        steps.begin('payload', '[5/6] newton-euler payload --json')
        estimate = json.loads(newton_euler(
            'payload', identified, bag2, '--base', BASE, '--tip', TIP,
            '--json', log=os.path.join(out, 'payload.json')))
        steps.end()
        steps.begin('estimate applied', '[6/6] the estimate set on the node '
                    '(set_parameters_atomically), run again')
        wait_until([last], last.ready, 'the nodes of the last run')
        last.rec.set_payload(estimate)
        last.go(segment)
        wait_until([last], last.begun, 'the simulation start')
        prepare_plots()         # while the last run runs
        drive([last], duration)
        runs[told] = last.finish(duration)
        steps.end()
        plot(runs, segment, truth, out)
        for r in (first, second, third, last):
            r.close()
    except DemoError as exc:
        print(f'demo_identify: {exc}', file=sys.stderr)
        return 1
    finally:
        for item in reversed(live):
            item.abort()
    rows = []
    figures = {}
    for label, r in runs.items():
        ff = r['ff'] - truth[label]
        ff_rms = float(np.sqrt(np.mean(ff ** 2)))
        ff_rel = ff_rms / float(np.sqrt(np.mean(truth[label] ** 2)))
        err = r['q'] - plan_at(r['t'], segment)
        tr_rms = float(np.sqrt(np.mean(err ** 2)))
        tr_max = float(np.abs(err).max())
        figures[label] = {'ff_rms': ff_rms, 'ff_rel': ff_rel,
                          'tracking_rms': tr_rms, 'tracking_max': tr_max}
        rows.append(f'| {label} | {ff_rms:.3f} | {100 * ff_rel:.1f} % | '
                    f'{1000 * tr_rms:.2f} | {1000 * tr_max:.2f} |')
    wall = time.monotonic() - started
    with open(os.path.join(out, 'excite.txt'), encoding='utf-8') as f:
        excite_lines = [x for x in f.read().splitlines()
                        if 'condition number' in x]
    with open(os.path.join(out, 'identify.txt'), encoding='utf-8') as f:
        ident_lines = [x for x in f.read().splitlines()
                       if x.startswith(('rank', 'identified in'))]
    m, c = estimate['payload.mass'], estimate['payload.com']
    lines = [
        '# The identification loop, end to end',
        '',
        f'`make demo-identify` ({"quick, " if args.quick else ""}'
        f'{wall:.0f} s wall). The plant (robot_sim_node) is a Panda whose '
        f'links differ from the published URDF (masses +-15 %, centres of '
        f'mass +-15 mm, inertias +-25 %) with joint friction and rotor '
        f'inertia; inverse_dynamics_node starts with the published URDF. '
        f'An excitation trajectory ({periods} x {period:g} s, {harmonics} '
        f'harmonics) runs through the node (`~/trajectory_in` -> '
        f'`~/trajectory_out`) into the simulator (PD + the efforts, as '
        f'joint_trajectory_controller); `/joint_states` is recorded to a '
        f'rosbag2; `newton-euler identify` corrects the URDF; the same '
        f'trajectory runs with the identified URDF (on `robot_description`)'
        f' and `drives.compensate:=true`, and at the same time, in another '
        f'ROS domain, with the plant holding {PAYLOAD["mass"]:g} kg the node '
        f'is not told of; `newton-euler payload` estimates the payload from '
        "that recording, and a last run has the estimate in the node's "
        f'`payload.*` (one `set_parameters_atomically` call).',
        '',
        '| run | feedforward torque error, RMS (N m) | relative to the true '
        'torque | tracking error, RMS (mrad) | max (mrad) |',
        '|---|---|---|---|---|',
        *rows,
        '',
        'Feedforward torque error: the efforts the node filled in, against '
        'the true torque of the plant along the plan (its real inertials, '
        'friction and rotor inertia, the payload when held). Tracking error: '
        'the joint positions against the plan.',
        '',
        f'- excite: {excite_lines[0].strip() if excite_lines else ""}',
        *[f'- identify: {x}' for x in ident_lines],
        f'- payload estimate: {m:.3f} kg (true {PAYLOAD["mass"]:g}), com '
        f'[{", ".join(f"{1000 * v:.1f}" for v in c)}] mm (true '
        f'[{", ".join(f"{1000 * v:.1f}" for v in PAYLOAD["com"])}])',
        '- wall time per step (s; the nodes of a run start while an earlier '
        'step works): ' + ', '.join(f'{k} {v:.1f}'
                                    for k, v in steps.times.items()),
        '',
        'Files: `excitation.json`, `recording/` and `payload_recording/` '
        '(rosbag2), `panda_identified.urdf`, the output of the commands '
        '(`excite.txt`, `identify.txt`, `payload.json`), the logs of the '
        'nodes in `logs/`.',
        '',
        '![tracking error](tracking.png)',
        '',
        '![feedforward torque error](torques.png)', '']
    with open(os.path.join(out, 'summary.md'), 'w', encoding='utf-8') as f:
        f.write('\n'.join(lines))
    with open(os.path.join(out, 'summary.json'), 'w', encoding='utf-8') as f:
        json.dump({'runs': figures, 'payload_estimate': estimate,
                   'payload_true': PAYLOAD, 'wall_s': wall,
                   'steps_s': steps.times,
                   'runs_timing_s': {r.label: r.timing(started) for r in (
                       first, second, third, last)}}, f, indent=1)
    print('\n'.join(lines[4:6 + len(rows)]))
    print(f'wrote {out} ({wall:.0f} s)', flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
