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

1. ``newton-euler excite`` writes an excitation trajectory.
2. It runs through the node (``~/trajectory_in`` -> ``~/trajectory_out``,
   efforts filled) into the simulator's ``~/joint_trajectory`` (PD + the
   points' effort, as joint_trajectory_controller); ``/joint_states`` is
   recorded by a subscriber and written to a rosbag2 (MCAP) with
   ``ident.bag``'s writer.
3. ``newton-euler identify`` writes the corrected URDF.
4. The same trajectory runs again, the node on the identified URDF with
   ``drives.compensate:=true``.
5. The plant picks up a payload (its ``payload.*`` parameters); a run
   with the node not told is recorded, ``newton-euler payload --json``
   estimates the payload from it, and a last run gives the estimate to
   the node (its ``payload.*`` parameters).

Every run is a fresh pair of processes in a ROS domain of its own
(``ROS_DOMAIN_ID`` from the environment as the first, if set), discovery
limited to this host.  Writes ``summary.md`` (one table: feedforward
torque error against the plant's true torque along the plan, and the
tracking error, per run), ``tracking.png``, ``torques.png``, the files of
every step (URDFs, trajectory, bags, the commands' output) and the nodes'
logs to DIR (default out/demo_identify).
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time
import warnings
import xml.etree.ElementTree as ET

from newton_euler_ros.graph import ID, SIM
import numpy as np

from .demo import (base_domain, check_exits, Child, DemoError, Recorder,
                   stop_children, wait_for)
from .demo_pick import trajectory_message
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


def newton_euler(*args, log=None):
    """Run ``newton-euler ARGS``; return its stdout (fail on error)."""
    cmd = [sys.executable, '-m', 'newton_euler_ros.cli', *map(str, args)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if log is not None:
        with open(log, 'w', encoding='utf-8') as f:
            f.write('$ newton-euler ' + ' '.join(map(str, args)) + '\n')
            f.write(proc.stdout + proc.stderr)
    if proc.returncode != 0:
        raise DemoError(f'newton-euler {args[0]} failed: '
                        f'{proc.stderr.strip()[-400:]}')
    return proc.stdout


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


class LoopRecorder(Recorder):
    """The demo recorder, plus the filled trajectory and ns stamps."""

    def __init__(self, domain):
        super().__init__(domain)
        from trajectory_msgs.msg import JointTrajectory
        self.filled = []
        self.stamps_ns = []
        self.names = None
        self.node.create_subscription(JointTrajectory,
                                      f'{SIM}/joint_trajectory',
                                      self.filled.append, 10)
        self.plan = self.node.create_publisher(JointTrajectory,
                                               f'{ID}/trajectory_in', 10)

    def _on_state(self, msg):
        super()._on_state(msg)
        self.stamps_ns.append(msg.header.stamp.sec * 1_000_000_000
                              + msg.header.stamp.nanosec)
        if self.names is None:
            self.names = list(msg.name)


def _array(values):
    return '[' + ','.join(repr(float(v)) for v in values) + ']'


def run(label, scene_path, node_urdf, segment, duration, domain, log_dir,
        compensate=False, plant_payload=None, node_payload=None, bag=None):
    """Run simulator + node once; return the recorded arrays."""
    children = []
    rec = LoopRecorder(domain)
    status = {}
    sim_args = ['-p', f'scene:={scene_path}', '-p', 'wait_for_subscribers:=2']
    if plant_payload:
        sim_args += ['-p', f'payload.mass:={plant_payload["mass"]}',
                     '-p', f'payload.com:={_array(plant_payload["com"])}',
                     '-p',
                     f'payload.inertia:={_array(plant_payload["inertia"])}']
    id_args = ['-p', f'robot_file:={node_urdf}', '-p',
               f'base_link:={BASE}', '-p', f'tip_link:={TIP}',
               '-p', 'mode:=gravity',
               '-p', f'drives.compensate:={"true" if compensate else "false"}',
               '-r', f'~/trajectory_out:={SIM}/joint_trajectory']
    if node_payload:
        id_args += ['-p', f'payload.mass:={node_payload["payload.mass"]}',
                    '-p',
                    f'payload.com:={_array(node_payload["payload.com"])}',
                    '-p', 'payload.inertia:='
                    f'{_array(node_payload["payload.inertia"])}']
    try:
        children.append(Child(f'{label}_robot_sim_node',
                              'newton_euler_ros.nodes.robot_sim_node',
                              sim_args, domain, log_dir))
        wait_for(rec, children,
                 lambda: rec.subscribers(f'{SIM}/joint_trajectory') >= 1,
                 'robot_sim_node')
        children.append(Child(f'{label}_inverse_dynamics_node',
                              'newton_euler_ros.nodes.inverse_dynamics_node',
                              id_args, domain, log_dir))
        wait_for(rec, children,
                 lambda: rec.plan.get_subscription_count() >= 1
                 and rec.publishers(f'{SIM}/joint_trajectory') >= 1
                 and rec.t0 is not None, 'the simulation start')
        rec.plan.publish(trajectory_message(rec_names(), rec.t0, segment))
        wait_for(rec, children, lambda: len(rec.filled) >= 1,
                 'the trajectory with efforts')
        end = time.monotonic() + 60.0 + 5.0 * duration
        while True:
            rec.spin_once()
            for child in children:
                child.check_alive()
            t = rec.last_time()
            if t is not None and t >= duration - 1e-9:
                break
            if time.monotonic() > end:
                raise DemoError(f'[{label}] did not reach t = {duration} s')
    finally:
        stop_children(children, rec, status)
    check_exits(label, status)
    ns = np.array(rec.stamps_ns, dtype=np.int64)
    t = np.array([s[0] for s in rec.states]) - rec.t0
    keep = (t >= -1e-9) & (t <= duration + 1e-9)
    order = np.argsort(t[keep], kind='stable')
    idx = np.flatnonzero(keep)[order]
    q = np.array([rec.states[i][1] for i in idx])
    qd = np.array([rec.states[i][2] for i in idx])
    effort = np.array([rec.states[i][3] for i in idx])
    if bag is not None:
        from newton_euler_ros.ident.bag import write_joint_states
        if os.path.exists(bag):
            shutil.rmtree(bag)
        write_joint_states(bag, ns[idx], rec.names, q, qd, effort)
    filled = rec.filled[0]
    return {'t': t[idx], 'q': q, 'qd': qd, 'effort': effort,
            'ff': np.array([p.effort for p in filled.points])}


_NAMES = [f'panda_joint{k}' for k in range(1, 8)]


def rec_names():
    """Joint names of the Panda chain."""
    return _NAMES


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
    period, periods, harmonics, budget = ((5.0, 1, 3, 4.0) if args.quick
                                          else (6.0, 2, 4, 10.0))
    try:
        published = os.path.join(out, 'panda_published.urdf')
        shutil.copyfile(panda_path(), published)
        nominal = quiet_load(published)
        with open(published, encoding='utf-8') as f:
            text = f.read()
        real = os.path.join(out, 'panda_real.urdf')
        with open(real, 'w', encoding='utf-8') as f:
            f.write(real_plant_urdf(text, set(nominal.info['urdf']['links']),
                                    args.seed))
        truth_model = quiet_load(real)
        duration = period * periods + 0.5
        scene = os.path.join(out, 'panda_real.yaml')
        write_scene(scene, real, duration)
        traj = os.path.join(out, 'excitation.json')
        print('[1/6] newton-euler excite', flush=True)
        newton_euler('excite', published, '--base', BASE, '--tip', TIP,
                     '-o', traj, '--period', period, '--harmonics',
                     harmonics, '--seconds', period * periods, '--budget',
                     budget, '--start', *START,
                     log=os.path.join(out, 'excite.txt'))
        segment = load_segment(traj)
        base = base_domain()
        domains = iter(1 + (base - 1 + k) % 100 for k in range(10))
        runs, truth = {}, {}
        bag1 = os.path.join(out, 'recording')
        print('[2/6] run with the published URDF, recording', flush=True)
        runs['published URDF'] = run('published', scene, published, segment,
                                     duration, next(domains), log_dir,
                                     bag=bag1)
        truth['published URDF'] = true_torques(truth_model, segment)
        identified = os.path.join(out, 'panda_identified.urdf')
        print('[3/6] newton-euler identify', flush=True)
        newton_euler('identify', published, bag1, '--base', BASE, '--tip',
                     TIP, '-o', identified,
                     log=os.path.join(out, 'identify.txt'))
        print('[4/6] run with the identified URDF + drive compensation',
              flush=True)
        key = 'identified URDF + drive compensation'
        runs[key] = run('identified', scene, identified, segment, duration,
                        next(domains), log_dir, compensate=True)
        truth[key] = truth['published URDF']
        bag2 = os.path.join(out, 'payload_recording')
        print(f'[5/6] payload {PAYLOAD["mass"]} kg picked up, node not told;'
              f' newton-euler payload', flush=True)
        key = f'{PAYLOAD["mass"]:g} kg payload, node not told'
        runs[key] = run('payload_untold', scene, identified, segment,
                        duration, next(domains), log_dir, compensate=True,
                        plant_payload=PAYLOAD, bag=bag2)
        truth[key] = true_torques(truth_model, segment, PAYLOAD)
        estimate = json.loads(newton_euler(
            'payload', identified, bag2, '--base', BASE, '--tip', TIP,
            '--json', log=os.path.join(out, 'payload.json')))
        print('[6/6] payload estimate given to the node', flush=True)
        key = f'{PAYLOAD["mass"]:g} kg payload, estimate applied'
        runs[key] = run('payload_told', scene, identified, segment, duration,
                        next(domains), log_dir, compensate=True,
                        plant_payload=PAYLOAD, node_payload=estimate)
        truth[key] = truth[f'{PAYLOAD["mass"]:g} kg payload, node not told']
    except DemoError as exc:
        print(f'demo_identify: {exc}', file=sys.stderr)
        return 1
    plot(runs, segment, truth, out)
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
        f'trajectory runs with the identified URDF and '
        f'`drives.compensate:=true`; then the plant picks up '
        f'{PAYLOAD["mass"]:g} kg, `newton-euler payload` estimates it from '
        f'a recording, and the estimate goes to the `payload.*` of the node.',
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
                   'payload_true': PAYLOAD, 'wall_s': wall}, f, indent=1)
    print('\n'.join(lines[4:6 + len(rows)]))
    print(f'wrote {out} ({wall:.0f} s)', flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
