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
from .demo_identify_report import prepare_plots, write_report
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


# the runs, as the report names them
PUBLISHED = 'published URDF'
IDENTIFIED = 'identified URDF + drive compensation'
UNTOLD = f'{PAYLOAD["mass"]:g} kg payload, node not told'
TOLD = f'{PAYLOAD["mass"]:g} kg payload, estimate applied'


class PayloadSteps:
    """
    The identified runs' start and steps 5 and 6, the same on either plant.

    A loop has ``steps``, ``identified``, ``bag2`` (the payload
    recording), ``last`` (the run the estimate is applied to), ``segment``,
    ``live``, ``out`` and ``args``; the steps 1 to 4, ``all_runs()``,
    ``last_seconds()`` and ``keep_told(run)`` are the plant's own.
    """

    def __init__(self, args, out, base, started, count):
        """Make ``out``'s logs folder; ``count`` domains from ``base``."""
        self.args, self.out = args, out
        self.log_dir = os.path.join(out, 'logs')
        os.makedirs(self.log_dir, exist_ok=True)
        self.steps = Steps(started)
        self.domains = iter(range(base, base + count))
        self.live = []
        self.runs, self.truth = {}, {}

    def run(self):
        """All six steps; DemoError if one fails (every run stopped)."""
        try:
            self.excite()
            self.record_published()
            self.identify()
            self.record_identified()
            self.estimate_payload()
            self.apply_estimate()
            for r in self.all_runs():
                r.close()
        finally:
            for item in reversed(self.live):
                item.abort()

    def path(self, name):
        """Return the path of a file in the demo's output folder."""
        return os.path.join(self.out, name)

    def plant_files(self, plant_urdf):
        """
        Copy the published URDF and write the plant's.

        ``plant_urdf(text, links, seed)`` makes the plant's text; returns
        (published model, plant model, plant URDF path).
        """
        self.published = self.path('panda_published.urdf')
        shutil.copyfile(panda_path(), self.published)
        nominal = quiet_load(self.published)
        with open(self.published, encoding='utf-8') as f:
            text = f.read()
        real = self.path('panda_real.urdf')
        with open(real, 'w', encoding='utf-8') as f:
            f.write(plant_urdf(text, set(nominal.info['urdf']['links']),
                               self.args.seed))
        return nominal, quiet_load(real), real

    def start_identified(self, runs, plans, which):
        """
        Start ``runs`` (on ``plans``) with the identified URDF.

        The last run is described too, to be ready when step 6 comes.
        """
        with open(self.identified, encoding='utf-8') as f:
            identified_text = f.read()
        for r in (*runs, self.last):
            r.describe(identified_text)
        wait_until(runs, lambda: all(r.ready() for r in runs),
                   f'the nodes of the {which} runs')
        for r, plan in zip(runs, plans):
            r.go(plan)
        wait_until(runs, lambda: all(r.begun() for r in runs),
                   'the simulation start')

    def estimate_payload(self):
        """5: ``payload --json`` on the payload recording."""
        self.steps.begin('payload', '[5/6] newton-euler payload --json')
        found = json.loads(newton_euler(
            'payload', self.identified, self.bag2, '--base', BASE, '--tip',
            TIP, '--json', log=self.path('payload.json')))
        # what the motion does not determine is null: the node keeps its
        # value of those parameters
        self.estimate = {k: v for k, v in found.items()
                         if k.startswith('payload.') and v is not None
                         and not (isinstance(v, list) and None in v)}
        self.steps.end()

    def apply_estimate(self):
        """6: the estimate set on the node in one call, the plan again."""
        last = self.last
        self.steps.begin('estimate applied', '[6/6] the estimate set on the '
                         'node (set_parameters_atomically), run again')
        wait_until([last], last.ready, 'the nodes of the last run')
        last.rec.set_payload(self.estimate)
        last.go(self.segment)
        wait_until([last], last.begun, 'the simulation start')
        prepare_plots()         # while the last run runs
        drive([last], self.last_seconds())
        self.keep_told(last)
        self.steps.end()


class Loop(PayloadSteps):
    """
    The demo's six steps, one method each, in the order they run.

    A run's nodes start while an earlier step works, so the methods hand
    runs on through attributes: ``first`` (the published URDF),
    ``second`` and ``third`` (the identified URDF, without and with the
    payload), ``last`` (the estimate applied).  ``live`` lists what to
    stop if anything fails.
    """

    def __init__(self, args, out, base, started):
        super().__init__(args, out, base, started, 4)
        self.period, self.periods, self.harmonics, self.budget = (
            QUICK if args.quick else FULL)
        self.duration = self.period * self.periods + 0.5

    def start_run(self, label, **kw):
        """Start a run's nodes in the next ROS domain."""
        run = LoopRun(label, self.scene, next(self.domains), self.log_dir,
                      **kw)
        self.live.append(run)
        return run

    def excite(self):
        """1: the plant's files, the first run's nodes, ``excite``."""
        self.steps.begin('excite', '[1/6] newton-euler excite; the nodes '
                         'of the first run start meanwhile')
        nominal, truth_model, real = self.plant_files(real_plant_urdf)
        self.scene = self.path('panda_real.yaml')
        write_scene(self.scene, real, self.duration)
        self.first = self.start_run('published', urdf=self.published)
        warm_excite(nominal)
        traj = self.path('excitation.json')
        newton_euler('excite', self.published, '--base', BASE, '--tip', TIP,
                     '-o', traj, '--period', self.period, '--harmonics',
                     self.harmonics, '--seconds', self.period * self.periods,
                     '--budget', self.budget, '--start', *START,
                     log=self.path('excite.txt'))
        self.steps.end()
        self.segment = load_segment(traj)
        # the plant's torque along the plan; computed now, it also puts the
        # batch kernel the node fills the plan with in numba's cache
        bare = true_torques(truth_model, self.segment)
        held = true_torques(truth_model, self.segment, PAYLOAD)
        self.truth = {PUBLISHED: bare, IDENTIFIED: bare, UNTOLD: held,
                      TOLD: held}

    def record_published(self):
        """2: the plan through the node with the published URDF, recorded."""
        first = self.first
        self.steps.begin('published', '[2/6] run with the published URDF, '
                         'recording /joint_states')
        wait_until([first], first.ready, 'the nodes of the first run')
        first.go(self.segment)
        wait_until([first], first.begun, 'the simulation start')
        # the next two runs' nodes start now; their URDF comes later
        self.second = self.start_run('identified', compensate=True)
        self.third = self.start_run('payload_untold', compensate=True,
                                    plant_payload=PAYLOAD)
        drive([first], self.duration)
        self.bag1 = self.path('recording')
        self.runs[PUBLISHED] = first.finish(self.duration, bag=self.bag1)
        self.steps.end()

    def identify(self):
        """3: ``identify`` on the recording; the last run's nodes start."""
        self.steps.begin('identify', '[3/6] newton-euler identify; the '
                         'nodes of the last run start meanwhile')
        self.last = self.start_run('payload_told', compensate=True,
                                   plant_payload=PAYLOAD)
        self.identified = self.path('panda_identified.urdf')
        newton_euler('identify', self.published, self.bag1, '--base', BASE,
                     '--tip', TIP, '-o', self.identified,
                     log=self.path('identify.txt'))
        self.steps.end()

    def record_identified(self):
        """4: the identified URDF, without and with the untold payload."""
        second, third = self.second, self.third
        self.steps.begin(
            'identified + untold', '[4/6] two runs at once, the node given '
            'the identified URDF (robot_description) + drive compensation: '
            f'as is, and with {PAYLOAD["mass"]:g} kg picked up (node not '
            'told), recorded')
        self.start_identified((second, third), (self.segment, self.segment),
                              'second and third')
        drive([second, third], self.duration)
        self.bag2 = self.path('payload_recording')
        self.runs[IDENTIFIED] = second.finish(self.duration)
        self.runs[UNTOLD] = third.finish(self.duration, bag=self.bag2)
        self.steps.end()

    def last_seconds(self):
        """Return how long the last run drives (simulated s)."""
        return self.duration

    def keep_told(self, last):
        """Keep the last run's figures (the estimate applied)."""
        self.runs[TOLD] = last.finish(self.duration)

    def all_runs(self):
        """Return every run, in the order they started."""
        return (self.first, self.second, self.third, self.last)


def loop_parser(name, doc, quick):
    """
    Return an identification loop's parser: ``--out`` and ``--quick``.

    ``name`` is the module (prog ``python -m newton_euler_tools.NAME``,
    default ``--out`` out/NAME), ``doc`` its docstring (the description:
    its first line) and ``quick`` what ``--quick`` shortens.
    """
    parser = argparse.ArgumentParser(
        prog=f'python -m newton_euler_tools.{name}',
        description=doc.strip().split('\n')[0])
    parser.add_argument('--out', default=os.path.join('out', name))
    parser.add_argument('--quick', action='store_true', help=quick)
    return parser


def parse_args(argv):
    """Parse the demo's command line."""
    parser = loop_parser('demo_identify', __doc__,
                         'a short trajectory and optimisation (tests)')
    parser.add_argument('--seed', type=int, default=7)
    parser.add_argument('--plant', choices=('mujoco', 'builtin'),
                        default='mujoco',
                        help='the robot: mujoco (mujoco_sim_node, a plant '
                        'that is not the model; default) or builtin '
                        "(robot_sim_node, the library's own dynamics)")
    return parser.parse_args(argv)


def main(argv=None):
    """Run the loop; return the exit status."""
    args = parse_args(argv)
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    started = time.monotonic()
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    keep_bytecode(out)
    try:
        base = base_domain(5 if args.plant == 'mujoco' else 4)
    except ValueError as exc:
        print(f'demo_identify: {exc}', file=sys.stderr)
        return 2
    if args.plant == 'mujoco':
        from .demo_identify_mujoco import MujocoLoop
        loop = MujocoLoop(args, out, base, started)
    else:
        loop = Loop(args, out, base, started)
    try:
        loop.run()
    except DemoError as exc:
        print(f'demo_identify: {exc}', file=sys.stderr)
        return 1
    write_report(loop, PAYLOAD, started)
    return 0


if __name__ == '__main__':
    sys.exit(main())
