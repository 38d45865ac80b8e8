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
The identification loop measured on MuJoCo, offline.

    python -m newton_euler_tools.mujoco_identify [--out DIR] [--quick]
        [--seed N]

The true robot is a Franka Panda simulated by MuJoCo, physics nobody
here wrote (:mod:`.mujoco_identify_plant`): the published URDF
(example-robot-data) with perturbed inertials (masses +-15 %, centres of
mass +-15 mm, inertias +-25 %), viscous and Coulomb friction (MuJoCo's
damping and ``frictionloss`` constraint) and rotor inertia (armature)
the published URDF lacks.  The controller's model is the published URDF.

1. ``newton-euler excite`` on the published URDF writes the excitation
   trajectory, and a second one (another seed and period) held out for
   validation (``--quick``: shorter ones, less optimisation).
2. Both run on the plant: PD (``demo_identify``'s gains) plus the
   published model's feedforward along the plan, computed every 1 ms
   physics step and held over it; the joint states are recorded at
   500 Hz with sensor noise, the effort being the torque the motors
   applied, standing still before and after the motion; written as
   rosbag2 (MCAP) recordings.
3. ``newton-euler identify published.urdf recording --validate heldout``
   writes the identified URDF; its held-out torque error is read from
   what it prints, and ``newton-euler replay`` of both URDFs on the
   held-out recording gives the RMS torque error of each.
4. The held-out trajectory runs again on the plant with the identified
   URDF's feedforward, its drive terms compensated (as the node's
   ``drives.compensate``), and once without them; their tracking error
   against the published URDF's run of step 2.

Writes to DIR (default out/mujoco_identify): the URDFs (published, true,
identified), the trajectories, the recordings, each command's output,
``summary.md`` and ``summary.json`` (the figures and the wall time of
each step).  No ROS process runs: the commands run in this process.
"""
import csv
import json
import os
import shutil
import sys
import time

from newton_euler_ros.core.drives import model_drives
import numpy as np

from .demo import DemoError
from .demo_identify import (ARMATURE, COULOMB, loop_parser, newton_euler,
                            quiet_load, Steps, VISCOUS, warm_excite)
from .ident_example import BASE, panda_path, TIP
from .mujoco_identify_plant import (DRIVER_RATE, feedforward_model,
                                    load_plant, NOISE, PHYSICS_STEP,
                                    plan_points, plant_urdf, QUANTUM, run,
                                    START)

# excitation: (period s, periods, harmonics, optimisation budget s, seed)
# for identification and for the held-out validation
FULL = ((8.0, 2, 4, 8.0, 0), (6.0, 1, 4, 4.0, 1))
QUICK = ((4.0, 2, 3, 3.0, 0), (5.0, 1, 3, 1.0, 1))
REST = {False: (1.0, 1.0), True: (0.5, 0.5)}    # s standing still
TRAJECTORY_RATE = 1000.0    # Hz: the plan's points, one per physics step


def held_out_error(stdout, bag):
    """
    Read ``identify``'s validation table: the mean over the joints.

    Return {'nominal_rms', 'nominal_rel', 'identified_rms',
    'identified_rel'} (N m, and % of the RMS effort).
    """
    lines = stdout.splitlines()
    title = f'on {bag} (validation):'
    start = next(i for i, x in enumerate(lines) if x.strip() == title)
    mean = next(x for x in lines[start:] if x.split()[:1] == ['mean'])
    v = [float(x) for x in mean.split()[1:5]]
    return {'nominal_rms': v[0], 'nominal_rel': v[1],
            'identified_rms': v[2], 'identified_rel': v[3]}


def replay_error(csv_path):
    """Return the RMS of model - measured over every joint and message."""
    with open(csv_path, encoding='utf-8') as f:
        rows = list(csv.reader(f))
    data = np.array(rows[1:], dtype=float)[:, 1:]
    return float(np.sqrt(np.mean((data[:, 1::2] - data[:, 0::2]) ** 2)))


class Loop:
    """The loop's steps, one method each, in the order they run."""

    def __init__(self, args, out, started):
        self.args, self.out = args, out
        self.steps = Steps(started)
        self.excitations = QUICK if args.quick else FULL
        self.rest = REST[args.quick]
        self.rng = np.random.default_rng(args.seed)
        self.figures = {}

    def path(self, name):
        """Return the path of a file in the output folder."""
        return os.path.join(self.out, name)

    def cli(self, *args, log):
        """``newton-euler ARGS``, its output to ``log``; return stdout."""
        return newton_euler(*args, log=self.path(log))

    def setup(self):
        """Write the published URDF and the true robot's; compile the latter."""
        self.steps.begin('plant', '[1/5] the true robot: perturbed '
                         'inertials, friction and rotor inertia, in MuJoCo')
        self.published = self.path('panda_published.urdf')
        shutil.copyfile(panda_path(), self.published)
        self.nominal = quiet_load(self.published)
        with open(self.published, encoding='utf-8') as f:
            text = f.read()
        self.real = self.path('panda_real.urdf')
        with open(self.real, 'w', encoding='utf-8') as f:
            f.write(plant_urdf(text, set(self.nominal.info['urdf']['links']),
                               self.args.seed))
        self.names = list(self.nominal.joint_names)
        self.robot = load_plant(self.real, self.names)
        self.steps.end()

    def excite(self):
        """Two excitation trajectories: identification and held out."""
        self.steps.begin('excite', '[2/5] newton-euler excite (twice: '
                         'identification, held-out validation)')
        warm_excite(self.nominal)
        self.trajectories = []
        for name, (period, periods, harmonics, budget, seed) in zip(
                ('excitation', 'heldout'), self.excitations):
            path = self.path(f'{name}.json')
            self.cli('excite', self.published, '--base', BASE, '--tip', TIP,
                     '-o', path, '--period', period, '--harmonics',
                     harmonics, '--seconds', period * periods, '--budget',
                     budget, '--seed', seed, '--rate', TRAJECTORY_RATE,
                     '--start', *START, log=f'excite_{name}.txt')
            with open(path, encoding='utf-8') as f:
                self.trajectories.append(json.load(f))
        self.steps.end()

    def track(self, trajectory, urdf, compensate):
        """Run a trajectory with a URDF's feedforward; return the Run."""
        model, drives = feedforward_model(urdf, compensate)
        points = plan_points(trajectory, model, drives)
        return run(self.robot, trajectory['joint_names'], model, points,
                   self.rest, self.rng)

    def record(self):
        """Both trajectories on the plant, published feedforward."""
        self.steps.begin('record', '[3/5] both trajectories on MuJoCo (PD + '
                         'feedforward of the published URDF), recorded')
        self.bags = []
        self.runs = {}
        for name, traj in zip(('recording', 'heldout_recording'),
                              self.trajectories):
            r = self.track(traj, self.published, compensate=False)
            bag = self.path(name)
            if os.path.exists(bag):
                shutil.rmtree(bag)
            r.write_bag(bag, self.robot.joints)
            self.bags.append(bag)
            self.runs[name] = r
        self.steps.end()

    def identify(self):
        """``identify --validate``, then ``replay`` of both URDFs."""
        self.steps.begin('identify', '[4/5] newton-euler identify '
                         '--validate, replay of both URDFs on the held-out '
                         'recording')
        self.identified = self.path('panda_identified.urdf')
        bag, held = self.bags
        stdout = self.cli('identify', self.published, bag, '--base', BASE,
                          '--tip', TIP, '-o', self.identified, '--validate',
                          held, '--overwrite', log='identify.txt')
        self.figures['held_out'] = held_out_error(stdout, held)
        found = model_drives(quiet_load(self.identified))
        self.figures['drives'] = {
            'true': {'viscous': VISCOUS, 'coulomb': COULOMB,
                     'armature': ARMATURE},
            'identified': {k: getattr(found, k).tolist() for k in
                           ('viscous', 'coulomb', 'armature', 'offset',
                            'coulomb_width')}}
        replay = {}
        for label, urdf in (('published', self.published),
                            ('identified', self.identified)):
            table = self.path(f'replay_{label}.csv')
            self.cli('replay', urdf, held, '--base', BASE, '--tip', TIP,
                     '--csv', table, log=f'replay_{label}.txt')
            replay[label] = replay_error(table)
        self.figures['replay_rms'] = replay
        self.steps.end()

    def track_identified(self):
        """Run the held-out plan again: identified URDF + drive terms."""
        self.steps.begin('track', '[5/5] the held-out trajectory on MuJoCo '
                         'with feedforward of the identified URDF (drive '
                         'terms compensated)')
        ident = self.track(self.trajectories[1], self.identified,
                           compensate=True)
        # the share of the drive terms: the identified links alone
        bare = self.track(self.trajectories[1], self.identified,
                          compensate=False)
        pub = self.runs['heldout_recording']
        self.steps.end()
        rows = {}
        for label, r in (('published', pub), ('identified', ident),
                         ('identified_without_drives', bare)):
            rms, peak, per_joint = r.tracking()
            rows[label] = {'rms': rms, 'max': peak, 'per_joint': per_joint,
                           'physics_seconds': round(r.seconds, 2)}
        rows['ratio'] = rows['published']['rms'] / rows['identified']['rms']
        self.figures['tracking'] = rows

    def run(self):
        """All the steps."""
        self.setup()
        self.excite()
        self.record()
        self.identify()
        self.track_identified()


def summary(loop, started):
    """Return the summary dict of a finished loop."""
    f = loop.figures
    return {
        'quick': loop.args.quick, 'seed': loop.args.seed,
        'plant': {'engine': 'mujoco', 'physics_step': PHYSICS_STEP,
                  'urdf': os.path.basename(loop.real)},
        'recording': {'rate': DRIVER_RATE, 'noise': NOISE,
                      'position_quantum': QUANTUM,
                      'rest_seconds': list(loop.rest)},
        'excitations': [dict(zip(('period', 'periods', 'harmonics',
                                  'budget', 'seed'), e))
                        for e in loop.excitations],
        'held_out_torque_error': f['held_out'],
        'replay_rms': f['replay_rms'],
        'tracking': f['tracking'],
        'drives': f['drives'],
        'times': loop.steps.times,
        'total_seconds': round(time.monotonic() - started, 2)}


def table(result):
    """Return the summary table's lines (markdown)."""
    h, rp, tr = (result['held_out_torque_error'], result['replay_rms'],
                 result['tracking'])
    return [
        '| model | held-out torque error, identify (N m, mean over joints) '
        '| replay RMS (N m) | tracking RMS (mrad) | tracking max (mrad) |',
        '|---|---|---|---|---|',
        f'| published URDF | {h["nominal_rms"]:.3f} ({h["nominal_rel"]:.1f} '
        f'%) | {rp["published"]:.3f} | '
        f'{1e3 * tr["published"]["rms"]:.3f} | '
        f'{1e3 * tr["published"]["max"]:.2f} |',
        f'| identified URDF + drive compensation | '
        f'{h["identified_rms"]:.3f} ({h["identified_rel"]:.1f} %) | '
        f'{rp["identified"]:.3f} | {1e3 * tr["identified"]["rms"]:.3f} | '
        f'{1e3 * tr["identified"]["max"]:.2f} |']


def _without_drives(tracking):
    bare = tracking['identified_without_drives']['rms']
    return (f'identified URDF without drive compensation: tracking RMS '
            f'{1e3 * bare:.3f} mrad ({tracking["published"]["rms"] / bare:.2f}'
            f' times better than the published URDF)')


def _fmt(values):
    return '[' + ', '.join(f'{v:.2f}' for v in values) + ']'


def write_report(loop, result):
    """Write summary.json and summary.md; print the table."""
    with open(loop.path('summary.json'), 'w', encoding='utf-8') as f:
        json.dump(result, f, indent=2)
    rows = table(result)
    ratio = result['tracking']['ratio']
    times = ', '.join(f'{k} {v:.1f} s' for k, v in result['times'].items())
    text = [
        '# The identification loop on MuJoCo', '',
        'The true robot: the published Panda URDF with perturbed inertials, '
        'viscous and Coulomb friction and rotor inertia, simulated by '
        f'MuJoCo at {1 / PHYSICS_STEP:.0f} Hz (panda_real.urdf). Recorded '
        f'at {DRIVER_RATE:.0f} Hz with noise (position '
        f'{NOISE["position"]:g} rad and counts of {QUANTUM:.3g} rad, '
        f'velocity {NOISE["velocity"]:g} rad/s, effort '
        f'{NOISE["effort"]:g} N m). Torque errors on the held-out '
        'recording; tracking along the held-out trajectory.', '',
        *rows, '',
        f'Tracking RMS ratio, published / identified: {ratio:.2f}.', '',
        _without_drives(result['tracking']), '',
        'Coulomb friction per joint, N m: frictionloss in MuJoCo '
        f'{_fmt(result["drives"]["true"]["coulomb"])}, identified '
        f'{_fmt(result["drives"]["identified"]["coulomb"])}; viscous, '
        f'N m s/rad: {_fmt(result["drives"]["true"]["viscous"])}, '
        f'identified {_fmt(result["drives"]["identified"]["viscous"])}.',
        '',
        f'Wall time: {times}; total {result["total_seconds"]:.1f} s.', '']
    with open(loop.path('summary.md'), 'w', encoding='utf-8') as f:
        f.write('\n'.join(text))
    print('\n'.join(rows))
    print(f'tracking RMS ratio, published / identified: {ratio:.2f}')
    print(_without_drives(result['tracking']))
    print(f'wrote {loop.path("summary.md")}')


def parse_args(argv):
    """Parse the command line."""
    parser = loop_parser('mujoco_identify', __doc__,
                         'shorter trajectories, less optimisation (tests)')
    parser.add_argument('--seed', type=int, default=7,
                        help='seed of the true robot (perturbation) and the '
                        'noise')
    return parser.parse_args(argv)


def main(argv=None):
    """Run the loop; return the exit status."""
    args = parse_args(argv)
    started = time.monotonic()
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    loop = Loop(args, out, started)
    try:
        loop.run()
    except DemoError as exc:
        print(f'mujoco_identify: {exc}', file=sys.stderr)
        return 1
    write_report(loop, summary(loop, started))
    return 0


if __name__ == '__main__':
    sys.exit(main())
