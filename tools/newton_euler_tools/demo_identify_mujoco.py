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
``make demo-identify`` on MuJoCo: the plant is not the model, over DDS.

The plant is mujoco_sim_node simulating the true Panda of
:mod:`.mujoco_identify_plant` (the published URDF with perturbed
inertials, viscous and Coulomb friction and rotor inertia, compiled by
MuJoCo's reader; MuJoCo's friction is its ``frictionloss`` constraint),
1 kHz physics, ``/joint_states`` at a driver's 500 Hz (``--quick``: 250 Hz)
with sensor noise (its ``noise.*``), real time.  Each run is three processes in a ROS
domain of its own: mujoco_sim_node, inverse_dynamics_node (fills the
plan's efforts: ``~/trajectory_in`` -> ``~/trajectory_out``) and
:mod:`.trajectory_controller` (joint_trajectory_controller with an
effort interface: PD on the plan plus its efforts, one command per joint
state, into ``/effort_controller/commands``).

1. ``newton-euler excite`` twice: the identification trajectory and a
   held-out one (another seed and period).
2. Both run at once with the published URDF; ``/joint_states`` of each
   recorded into a rosbag2.
3. ``newton-euler identify --validate`` on the held-out recording: the
   held-out torque error of both URDFs.
4. The held-out trajectory again with the identified URDF and
   ``drives.compensate``; at the same time the identification
   trajectory with the plant holding a payload (in its scene) the node
   is not told of, recorded.
5. ``newton-euler payload --json`` on that recording.
6. The estimate set on the node (``set_parameters_atomically``), run
   again.
"""
import os

from .demo_identify import (ARMATURE, COULOMB, IDENTIFIED, KD, KP,
                            load_segment, newton_euler, PAYLOAD,
                            PayloadSteps, PUBLISHED, START, TOLD,
                            true_torques, UNTOLD, VISCOUS, warm_excite)
from .demo_identify_report import payload_line
from .demo_identify_runs import drive, LoopRun, wait_until
from .ident_example import BASE, TIP
from .mujoco_identify import held_out_error
from .mujoco_identify_plant import NOISE, PHYSICS_STEP, plant_urdf

DRIVER_RATE = 500.0     # Hz: mujoco_sim_node's joint_states
# --quick: half as many lockstep round trips (the figures move by a few
# per cent, the wall time falls by a quarter)
QUICK_RATE = 250.0
POINTS_RATE = 250.0     # Hz: the plan's points
# (period s, periods, harmonics, optimisation budget s, seed): the
# identification trajectory and the held-out one
FULL = ((8.0, 1, 4, 5.0, 0), (6.0, 1, 4, 2.0, 1))
QUICK = ((4.0, 1, 3, 2.0, 0), (4.0, 1, 3, 1.0, 1))
# the runs, as the report names them (PUBLISHED ... TOLD: demo_identify's)
HELDOUT_PUBLISHED = 'published URDF, held-out trajectory'
HELDOUT_IDENTIFIED = ('identified URDF + drive compensation, held-out '
                      'trajectory')


def write_mujoco_scene(path, robot_file, payload=None, rate=DRIVER_RATE):
    """
    Write mujoco_sim_node's scene: the true URDF, friction, rotor inertia.

    The scene's effects give MuJoCo the same friction and armature as
    the URDF's ``<dynamics>`` and ``<ne:drive>`` (a MuJoCo scene sets
    them from its effects); ``payload`` (node parameter forms) is a body
    fixed to the tip link; ``rate`` the joint states' (Hz).
    """
    held = ''
    if payload:
        held = (f'  payload: {{mass: {payload["mass"]}, com: '
                f'{payload["com"]}, inertia: {payload["inertia"]}, '
                f'link: {TIP}}}\n')
    text = (
        '# written by newton_euler_tools.demo_identify: the true Panda\n'
        f'name: panda_true{"_payload" if payload else ""}\n'
        'description: a Panda whose inertials, friction and rotor inertia '
        'differ from its URDF\n'
        f'robot: {os.path.basename(robot_file)}\n'
        'engine: mujoco\n'
        'effects:\n'
        '  gravity: true\n'
        '  velocity_products: true\n'
        f'{held}'
        f'  friction: {{viscous: {VISCOUS}, coulomb: {COULOMB}}}\n'
        f'  armature: {ARMATURE}\n'
        f'initial: {{q: {START}, qd: {[0.0] * 7}}}\n'
        f'reference: {{type: quintic, goal: {START}, duration: 1.0}}\n'
        f'controller: {{kp: {KP}, kd: {KD}, feedforward: true}}\n'
        f'integrator: {{method: semi_implicit_euler, step: {PHYSICS_STEP},'
        f' duration: 60.0, rate: {rate}}}\n')
    with open(path, 'w', encoding='utf-8') as f:
        f.write(text)


class MujocoLoop(PayloadSteps):
    """
    The six steps on MuJoCo, one method each, in the order they run.

    Runs: ``pub`` and ``pub_held`` (the published URDF on the two
    trajectories), ``ident`` (identified, held-out trajectory),
    ``untold`` and ``last`` (the payload, not told and told).  ``live``
    lists what to stop if anything fails; ``runs``, ``segments`` and
    ``truth`` hold each run's recording, plan and the plant's torque
    along it.
    """

    def __init__(self, args, out, base, started):
        super().__init__(args, out, base, started, 5)
        self.excitations = QUICK if args.quick else FULL
        self.rate = QUICK_RATE if args.quick else DRIVER_RATE
        self.period, self.periods, self.harmonics = self.excitations[0][:3]
        self.segments = {}
        self.noise = dict(NOISE, seed=args.seed)

    def start_run(self, label, scene, **kw):
        """Start a run's nodes in the next ROS domain."""
        run = LoopRun(label, scene, next(self.domains), self.log_dir,
                      plant='mujoco', noise=self.noise, gains=(KP, KD), **kw)
        self.live.append(run)
        return run

    def excite(self):
        """1: the plant's files, the first runs' nodes, ``excite`` twice."""
        self.steps.begin('excite', '[1/6] newton-euler excite (twice: '
                         'identification, held out); the nodes of the '
                         'first two runs start meanwhile')
        nominal, truth_model, real = self.plant_files(plant_urdf)
        self.scene = self.path('panda_real.yaml')
        write_mujoco_scene(self.scene, real, rate=self.rate)
        self.payload_scene = self.path('panda_real_payload.yaml')
        write_mujoco_scene(self.payload_scene, real, PAYLOAD, self.rate)
        self.pub = self.start_run('published', self.scene,
                                  urdf=self.published)
        self.pub_held = self.start_run('published_heldout', self.scene,
                                       urdf=self.published)
        warm_excite(nominal)
        segments = []
        for name, (period, periods, harmonics, budget, seed) in zip(
                ('excitation', 'heldout'), self.excitations):
            traj = self.path(f'{name}.json')
            newton_euler('excite', self.published, '--base', BASE, '--tip',
                         TIP, '-o', traj, '--period', period, '--harmonics',
                         harmonics, '--seconds', period * periods, '--budget',
                         budget, '--seed', seed, '--rate', POINTS_RATE,
                         '--start', *START, log=self.path(f'excite_{name}.txt'))
            segments.append(load_segment(traj))
        self.steps.end()
        self.segment, self.heldout = segments
        # the plant's torque along the plans (and numba's cache of the
        # batch kernel the node fills them with)
        bare = true_torques(truth_model, self.segment)
        self.truth_of = {
            'excitation': bare,
            'heldout': true_torques(truth_model, self.heldout),
            'payload': true_torques(truth_model, self.segment, PAYLOAD)}

    def duration(self, segment):
        """Return a run's simulated seconds: the plan and 0.5 s at rest."""
        return float(segment[0][-1]) + 0.5

    def _keep(self, label, run, segment, truth, **kw):
        self.runs[label] = run.finish(self.duration(segment), **kw)
        self.segments[label] = segment
        self.truth[label] = self.truth_of[truth]

    def record_published(self):
        """2: both plans with the published URDF, recorded."""
        pub, held = self.pub, self.pub_held
        self.steps.begin('published', '[2/6] two runs at once with the '
                         'published URDF (identification and held-out '
                         'trajectories), recording /joint_states')
        wait_until([pub, held], lambda: pub.ready() and held.ready(),
                   'the nodes of the first two runs')
        pub.go(self.segment)
        held.go(self.heldout)
        wait_until([pub, held], lambda: all([pub.begun(), held.begun()]),
                   'the simulation start')
        self.ident = self.start_run('identified_heldout', self.scene,
                                    compensate=True)
        self.untold = self.start_run('payload_untold', self.payload_scene,
                                     compensate=True)
        drive([pub], self.duration(self.segment))
        drive([held], self.duration(self.heldout))
        self.bag1 = self.path('recording')
        self.bag_held = self.path('heldout_recording')
        self._keep(PUBLISHED, pub, self.segment, 'excitation', bag=self.bag1)
        self._keep(HELDOUT_PUBLISHED, held, self.heldout, 'heldout',
                   bag=self.bag_held)
        self.steps.end()

    def identify(self):
        """3: ``identify --validate``; the last run's nodes start."""
        self.steps.begin('identify', '[3/6] newton-euler identify '
                         '--validate (held-out recording); the nodes of '
                         'the last run start meanwhile')
        self.last = self.start_run('payload_told', self.payload_scene,
                                   compensate=True)
        self.identified = self.path('panda_identified.urdf')
        stdout = newton_euler(
            'identify', self.published, self.bag1, '--base', BASE, '--tip',
            TIP, '-o', self.identified, '--validate', self.bag_held,
            '--overwrite', log=self.path('identify.txt'))
        self.held_out = held_out_error(stdout, self.bag_held)
        self.steps.end()

    def record_identified(self):
        """4: the identified URDF on the held-out plan; the payload untold."""
        ident, untold = self.ident, self.untold
        self.steps.begin(
            'identified + untold', '[4/6] two runs at once, the node given '
            'the identified URDF (robot_description) + drive compensation: '
            f'the held-out trajectory, and with {PAYLOAD["mass"]:g} kg held '
            '(node not told), recorded')
        self.start_identified((ident, untold), (self.heldout, self.segment),
                              'third and fourth')
        drive([ident], self.duration(self.heldout))
        drive([untold], self.duration(self.segment))
        self.bag2 = self.path('payload_recording')
        self._keep(HELDOUT_IDENTIFIED, ident, self.heldout, 'heldout')
        self._keep(UNTOLD, untold, self.segment, 'payload', bag=self.bag2)
        self.steps.end()

    def last_seconds(self):
        """Return how long the last run drives (simulated s)."""
        return self.duration(self.segment)

    def keep_told(self, last):
        """Keep the last run's figures (the estimate applied)."""
        self._keep(TOLD, last, self.segment, 'payload')

    def figures(self, table):
        """Return the held-out torque error and the two ratios."""
        h = self.held_out
        return {
            'held_out_torque_error': h,
            'held_out_ratio': h['nominal_rms'] / h['identified_rms'],
            'tracking_ratio': (table[HELDOUT_PUBLISHED]['tracking_rms']
                               / table[HELDOUT_IDENTIFIED]['tracking_rms']),
            'recording': {'rate': self.rate, 'noise': self.noise,
                          'physics_step': PHYSICS_STEP},
            'excitations': [dict(zip(('period', 'periods', 'harmonics',
                                      'budget', 'seed'), e))
                            for e in self.excitations]}

    def summary_lines(self, payload, wall, rows, table):
        """Return the lines of summary.md and the two headline lines."""
        f = self.figures(table)
        h = f['held_out_torque_error']
        pub = table[HELDOUT_PUBLISHED]['tracking_rms']
        ident = table[HELDOUT_IDENTIFIED]['tracking_rms']
        headline = [
            f'held-out torque error (identify --validate, mean over the '
            f'joints): published URDF {h["nominal_rms"]:.3f} N m '
            f'({h["nominal_rel"]:.1f} %), identified {h["identified_rms"]:.3f}'
            f' N m ({h["identified_rel"]:.1f} %): '
            f'{f["held_out_ratio"]:.1f} times smaller',
            f'tracking RMS on the held-out trajectory: published URDF '
            f'{1000 * pub:.2f} mrad, identified + drive compensation '
            f'{1000 * ident:.2f} mrad: {f["tracking_ratio"]:.1f} times '
            'better']
        n = self.noise
        lines = [
            '# The identification loop on MuJoCo, end to end over DDS', '',
            f'`make demo-identify` ({"quick, " if self.args.quick else ""}'
            f'{wall:.0f} s wall). The plant (mujoco_sim_node) is a Panda '
            'whose links differ from the published URDF (masses +-15 %, '
            'centres of mass +-15 mm, inertias +-25 %), with viscous and '
            "Coulomb friction (MuJoCo's frictionloss) and rotor inertia; "
            f'joint states at {self.rate:g} Hz with noise (position '
            f'{n["position"]:g} rad, velocity {n["velocity"]:g} rad/s, '
            f'effort {n["effort"]:g} N m). Each plan goes through '
            'inverse_dynamics_node (efforts filled) to trajectory_controller '
            '(PD + the efforts) into the plant.', '',
            '| run | feedforward torque error, RMS (N m) | relative to the '
            'true torque | tracking error, RMS (mrad) | max (mrad) |',
            '|---|---|---|---|---|', *rows, '',
            *[f'- {x}' for x in headline],
            payload_line(self.estimate, payload),
            '- wall time per step (s): ' + ', '.join(
                f'{k} {v:.1f}' for k, v in self.steps.times.items()), '',
            'Files: `excitation.json`, `heldout.json`, `recording/`, '
            '`heldout_recording/`, `payload_recording/` (rosbag2), '
            '`panda_real.urdf`, `panda_identified.urdf`, the scenes, the '
            "commands' output, the nodes' logs in `logs/`.", '',
            '![tracking error](tracking.png)', '',
            '![feedforward torque error](torques.png)', '']
        return lines, headline

    def all_runs(self):
        """Return every run, in the order they started."""
        return (self.pub, self.pub_held, self.ident, self.untold, self.last)


__all__ = ['HELDOUT_IDENTIFIED', 'HELDOUT_PUBLISHED', 'IDENTIFIED',
           'MujocoLoop', 'write_mujoco_scene']
