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
Recordings of a "real" dual-arm robot (a Baxter), for whole-robot examples.

    python -m newton_euler_tools.dual_arm_example OUT_DIR [--seed N]
        [--seconds S] [--rate HZ] [--effort torque|current]
        [--robot baxter|pr2]

A model of what a Baxter's ``/joint_states`` gives (no real robot was
recorded): the whole tree below its base link, two 7-joint arms, the
head's pan joint and a gripper per arm whose second finger is a mimic
joint of the first, so 17 coordinates and 19 moving bodies.

- **A robot that is not its URDF.**  The published Baxter of
  example-robot-data (``baxter.urdf``, the nominal model) with every
  moving link's mass +-15 %, centre of mass +-15 mm and principal moments
  +-25 % (``ident_example.perturb_urdf``).  Rigid-body torques from
  Pinocchio's RNEA on that robot, read with ``mimic=True`` (an
  independent implementation of the tree and its mimic fingers).
- **Drives.**  Per coordinate: viscous and Coulomb friction (smooth sign
  of width 0.01 rad/s), a torque offset and reflected rotor inertia,
  drawn around typical values per kind of joint (shoulder and elbow,
  wrist, head, gripper finger in N).  At a stop (qd exactly 0) a joint's
  friction keeps a fraction in [-0.3, 1] of what it was (static
  friction holding the last correction), which no model predicts.
- **Motions.**  Every coordinate at once (both arms, the head and the
  grippers): a finite Fourier series per coordinate about the middle of
  its limits, within 55 % of its half range and a peak speed per kind of
  joint (the fingers open and close faster, period 1 s), slowed to
  exact stops: at rest at both ends (1 s) and twice in between (0.5-1 s).
  ``excitation`` (``--seconds``, default 60 s) and ``validation`` (30 s,
  another series) differ.  ``payload``: another motion with a 1.5 kg
  tool on ``left_gripper`` (for ``newton-euler payload --link``).
- **A driver's messages.**  100 Hz (Baxter's rate), stamps jittering by
  +-20 % of a period, 1 % lost, 1 % repeated, a gap of 0.3-0.6 s every
  20 s, velocity noise (2e-3), quantised positions, effort noise, every
  joint named in sorted order: the mimic fingers too (position, velocity
  and effort mirrored from their leader) and the fixed ``torso_t0`` that
  Baxter reports.
- ``--effort current``: efforts are currents, torque / K with a constant
  K per coordinate (:data:`TORQUE_CONSTANTS` by kind), and a
  ``known_mass`` recording with :data:`KNOWN_MASS` kg on
  ``left_gripper`` (``identify --effort current --known-mass ...
  --known-mass-link left_gripper``).

``--robot pr2``: the same of example-robot-data's PR2 below
``base_link``: a prismatic torso lift (0.013 m/s) carrying both arms and
the head, a laser tilt joint, grippers of five mimic joints each (20
coordinates, 30 bodies); the payload and known mass on
``l_gripper_palm_link``.

Files in OUT_DIR: ``ROBOT.urdf`` (nominal), the rosbag2 (MCAP)
recordings above, and ``truth.json`` (the perturbed URDF, the drives, the
constants and payloads; for checking, not used by the commands).
"""
import math
import os
import shutil
import tempfile
import warnings

import numpy as np

BAXTER = 'baxter_description/urdf/baxter.urdf'
BASE = 'base'
TOOL_LINK = 'left_gripper'
EXTRA = ('torso_t0',)       # a fixed joint Baxter's driver reports
# the robots: example-robot-data file, base link, the link a tool is
# fixed to, fixed joints the driver reports
ROBOTS = {
    'baxter': {'urdf': BAXTER, 'base': BASE, 'tool': TOOL_LINK,
               'extra': EXTRA},
    # a torso lift joint (prismatic, 0.013 m/s) carrying both arms and the
    # head; grippers of five mimic joints each
    'pr2': {'urdf': 'pr2_description/urdf/pr2.urdf', 'base': 'base_link',
            'tool': 'l_gripper_palm_link', 'extra': ()},
}
# per kind of coordinate: peak speed (rad/s, m/s), viscous, Coulomb,
# offset, armature, effort noise, torque constant (N m/A or N/A)
KINDS = {
    'big': (1.0, (0.3, 1.0), (0.5, 2.0), 0.3, (0.05, 0.2), 0.05, 4.5),
    'wrist': (1.4, (0.05, 0.3), (0.2, 0.8), 0.15, (0.01, 0.05), 0.02, 1.6),
    'head': (0.8, (0.02, 0.1), (0.1, 0.3), 0.05, (0.005, 0.02), 0.01, 0.8),
    'finger': (0.06, (2.0, 5.0), (0.5, 1.5), 0.2, (0.05, 0.2), 0.05, 6.0),
    'torso': (0.05, (500.0, 1500.0), (20.0, 60.0), 10.0, (5.0, 20.0), 2.0,
              60.0),
}
COULOMB_WIDTH = 0.01
FINGER_PERIOD = 1.2        # s: a gripper opens and closes quickly
FINGER_HARMONICS = 2
KNOWN_MASS = 2.0
PAYLOAD = {'mass': 1.5, 'com': [0.01, -0.02, 0.06],
           'inertia': [[4e-3, 0.0, 0.0], [0.0, 5e-3, 0.0], [0.0, 0.0, 3e-3]]}
KNOWN = {'mass': KNOWN_MASS, 'com': [-0.01, 0.015, 0.05],
         'inertia': [[3e-3, 0.0, 0.0], [0.0, 3.5e-3, 0.0],
                     [0.0, 0.0, 2e-3]]}


def baxter_path(robot='baxter'):
    """Return the published URDF's path (example-robot-data)."""
    from .peers import example_robot_urdf
    return example_robot_urdf(ROBOTS[robot]['urdf'])


def nominal_model(path, base=BASE):
    """Load the whole tree below ``base`` (warnings off)."""
    from newton_euler_ros.core import load_robot
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot(path, base=base)


def kind(model, j):
    """Return the kind of coordinate j (a key of :data:`KINDS`)."""
    name = model.joint_names[j]
    if 'finger' in name:
        return 'finger'
    if 'torso' in name:
        return 'torso'
    if name.startswith(('head', 'laser')):
        return 'head'
    return 'wrist' if ('_w' in name or 'wrist' in name) else 'big'


def random_drives(model, rng):
    """Return the true drive terms per coordinate (dict of arrays)."""
    out = {k: np.zeros(model.n) for k in ('viscous', 'coulomb', 'offset',
                                          'armature', 'noise', 'constant')}
    for j in range(model.n):
        _, vis, cou, off, arm, noise, k_const = KINDS[kind(model, j)]
        out['viscous'][j] = rng.uniform(*vis)
        out['coulomb'][j] = rng.uniform(*cou)
        out['offset'][j] = rng.uniform(-off, off)
        out['armature'][j] = rng.uniform(*arm)
        out['noise'][j] = noise
        out['constant'][j] = k_const * rng.uniform(0.85, 1.15)
    out['coulomb_width'] = COULOMB_WIDTH
    return out


def _ranges(model):
    """Middle, half range and peak speed of each coordinate."""
    mid, half, speed = (np.zeros(model.n) for _ in range(3))
    for j, b in enumerate(model.independent):
        lim = model.limits[b]
        if 'lower' in lim and 'upper' in lim:
            mid[j] = 0.5 * (lim['lower'] + lim['upper'])
            half[j] = 0.5 * (lim['upper'] - lim['lower'])
        else:                   # continuous: a quarter turn each way
            half[j] = 0.5 * math.pi
        speed[j] = min(KINDS[kind(model, j)][0],
                       0.9 * lim.get('velocity', np.inf))
    return mid, half, speed


def fourier(model, rng, period=10.0, harmonics=5, fill=0.55):
    """
    Return x(tau) -> (x, x', x''): a Fourier series per coordinate.

    About the middle of each joint's limits, within ``fill`` of its half
    range and its kind's peak speed; fingers with period
    FINGER_PERIOD and FINGER_HARMONICS harmonics.
    """
    mid, half, speed = _ranges(model)
    n = model.n
    fingers = np.array([kind(model, j) == 'finger' for j in range(n)])
    w0 = np.where(fingers, 2 * math.pi / FINGER_PERIOD,
                  2 * math.pi / period)
    k = np.arange(1, harmonics + 1)
    a = rng.normal(size=(n, harmonics)) / k
    b = rng.normal(size=(n, harmonics)) / k
    # a gripper opens and closes: its first harmonics only
    a[fingers, FINGER_HARMONICS:] = b[fingers, FINGER_HARMONICS:] = 0.0
    grid = np.linspace(0.0, 1.0, 2000, endpoint=False)

    def series(tau, a, b):
        arg = (tau[:, None, None] * w0[None, :, None]) * k
        s, c = np.sin(arg), np.cos(arg)
        x = np.einsum('tjk,jk->tj', s, a) + np.einsum('tjk,jk->tj', c, b)
        xd = w0 * (np.einsum('tjk,jk->tj', c * k, a)
                   - np.einsum('tjk,jk->tj', s * k, b))
        xdd = -w0 ** 2 * (np.einsum('tjk,jk->tj', s * k * k, a)
                          + np.einsum('tjk,jk->tj', c * k * k, b))
        return x, xd, xdd
    # a series without a constant term has zero mean over its period:
    # about the middle, scaled to the range and the speed
    x, xd, _ = series(grid * 2 * math.pi / w0.min(), a, b)
    amp = np.minimum(fill * half / np.abs(x).max(axis=0),
                     speed / np.abs(xd).max(axis=0))
    a, b = a * amp[:, None], b * amp[:, None]

    def f(tau):
        x, xd, xdd = series(np.asarray(tau, dtype=np.float64), a, b)
        return mid + x, xd, xdd
    return f


def _ramp(x):
    """Smoothstep S, its integral P and derivative on [0, 1]."""
    x = np.clip(x, 0.0, 1.0)
    return (x ** 3 * (10 - 15 * x + 6 * x * x),
            2.5 * x ** 4 - 3 * x ** 5 + x ** 6,
            30 * x * x * (1 - x) ** 2)


def with_stops(series, stops, ramp=0.6):
    """
    Return f(t) -> (q, qd, qdd): ``series`` slowed to exact stops.

    Time runs as tau(t) = t - sum of each stop's deficit: over ``ramp``
    seconds from t0 the series slows to rest (d tau/dt = 1 - S), stays
    still ``hold`` seconds (qd = qdd = 0 exactly), and speeds up again.
    ``stops``: [(t0, hold)].
    """
    def warp(t):
        D = np.zeros_like(t)
        Dd = np.zeros_like(t)
        Ddd = np.zeros_like(t)
        for t0, hold in stops:
            t1 = t0 + ramp + hold
            x1 = (t - t0) / ramp
            x2 = (t - t1) / ramp
            S1, P1, dS1 = _ramp(x1)
            S2, P2, dS2 = _ramp(x2)
            down = (t > t0) & (t <= t0 + ramp)
            still = (t > t0 + ramp) & (t <= t1)
            up = (t > t1) & (t <= t1 + ramp)
            after = t > t1 + ramp
            D += np.where(down, ramp * P1, 0.0)
            D += np.where(still, 0.5 * ramp + (t - t0 - ramp), 0.0)
            D += np.where(up, 0.5 * ramp + hold + ramp * (
                np.clip(x2, 0, 1) - P2), 0.0)
            D += np.where(after, ramp + hold, 0.0)
            Dd += np.where(down, S1, 0.0) + np.where(still, 1.0, 0.0) \
                + np.where(up, 1.0 - S2, 0.0)
            Ddd += np.where(down, dS1 / ramp, 0.0) \
                - np.where(up, dS2 / ramp, 0.0)
        return t - D, 1.0 - Dd, -Ddd

    def f(t):
        t = np.asarray(t, dtype=np.float64)
        tau, v, a = warp(t)
        x, xd, xdd = series(tau)
        v, a = v[:, None], a[:, None]
        return x, xd * v, xdd * v * v + xd * a
    return f


def motion(model, seed, seconds, period):
    """Return a series at rest 1 s at both ends, stopped twice between."""
    rng = np.random.default_rng([seed, 11, int(period * 10)])
    series = fourier(model, rng, period=period)
    ramp = 0.6
    stops = [(-ramp, 1.0 + ramp)]          # at rest from t = 0 to 1 s
    for frac in (0.35, 0.7):
        stops.append((frac * seconds, rng.uniform(0.5, 1.0)))
    stops.append((seconds - 1.0 - ramp, 10.0))     # at rest for the last 1 s
    f = with_stops(series, stops, ramp)
    f.seconds = float(seconds)
    return f


def _message_times(seconds, rate, rng, lost=0.01, repeated=0.01,
                   gap_every=20.0, jitter=0.2):
    count = int(seconds * rate)
    t = (np.arange(count) + rng.uniform(-jitter, jitter, count)) / rate
    t[0] = 0.0
    keep = rng.random(count) >= lost
    for _ in range(int(seconds // gap_every)):
        g0 = rng.uniform(2.0, max(2.0, seconds - 3.0))
        keep &= ~((t > g0) & (t < g0 + rng.uniform(0.3, 0.6)))
    keep[0] = keep[-1] = True
    t = t[keep]
    return t, np.flatnonzero(rng.random(len(t) - 1) < repeated)


class _Truth:
    """Pinocchio's RNEA on the real robot's URDF (mimic=True)."""

    def __init__(self, urdf_text, model, payload=None, link=TOOL_LINK):
        import pinocchio as pin
        from .peers import PinocchioTree
        self.pin = pin
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, 'truth.urdf')
            with open(path, 'w', encoding='utf-8') as f:
                f.write(urdf_text)
            self.peer = PinocchioTree(path, model)
        if payload is not None:
            m = self.peer.model
            frame = m.frames[self.peer.frame(link)]
            body = pin.Inertia(float(payload['mass']),
                               np.asarray(payload['com'], dtype=float),
                               np.asarray(payload['inertia'], dtype=float))
            m.inertias[frame.parentJoint] = (m.inertias[frame.parentJoint]
                                             + frame.placement.act(body))
            self.peer.data = m.createData()

    def torques(self, q, qd, qdd):
        p, pin = self.peer, self.pin
        return np.array([pin.rnea(p.model, p.data, p.config(q[i]),
                                  p.vector(qd[i]), p.vector(qdd[i]))[p.iv]
                         for i in range(len(q))])


def friction(drives, qd, rng):
    """Viscous + Coulomb while moving; a held fraction at exact stops."""
    moving = drives['viscous'] * qd + drives['coulomb'] * np.tanh(
        qd / drives['coulomb_width'])
    out = moving.copy()
    held = np.zeros(qd.shape[1])
    for i in range(len(qd)):
        still = qd[i] == 0.0
        if i and still.any():
            starting = still & (qd[i - 1] != 0.0)
            held = np.where(starting, out[i - 1] * rng.uniform(
                -0.3, 1.0, qd.shape[1]), held)
            out[i] = np.where(still, held, out[i])
    return out


def record(model, truth, drives, path, f, rate=100.0, payload=None,
           effort='torque', seed=0, robot='baxter'):
    """Write one recording of the robot following ``f``; return its truth."""
    from newton_euler_ros.ident.bag_write import write_joint_states
    rng = np.random.default_rng([seed, 5])
    t, twice = _message_times(f.seconds, rate, rng)
    q, qd, qdd = f(t)
    sim = _Truth(truth, model, payload, ROBOTS[robot]['tool'])
    torque = (sim.torques(q, qd, qdd) + drives['armature'] * qdd
              + friction(drives, qd, rng) + drives['offset'])
    measured = torque + rng.normal(0.0, 1.0, torque.shape) * drives['noise']
    if effort == 'current':
        measured = measured / drives['constant']
    qm = np.round(q / 2e-5) * 2e-5
    qdm = qd + rng.normal(0.0, 2e-3, qd.shape)
    # every joint, sorted as a driver lists them: followers mirror their
    # leader; the fixed joints the driver reports at 0
    coord = {b: k for k, b in enumerate(model.independent)}
    names = sorted(list(model.moving_joints) + list(ROBOTS[robot]['extra']))
    cols = []
    for name in names:
        if name not in model.moving_joints:
            cols.append((None, 0.0, 0.0))
            continue
        b = model.moving_joints.index(name)
        lead, s, o = ((b, 1.0, 0.0) if model.mimic[b] is None
                      else model.mimic[b])
        cols.append((coord[lead], s, o))
    rows = []
    for X, shift in ((qm, True), (qdm, False), (measured, False)):
        rows.append(np.column_stack([
            np.zeros(len(t)) if j is None else s * X[:, j] + (o if shift
                                                              else 0.0)
            for j, s, o in cols]))
    stamps = 1_700_000_000 * 10**9 + np.round(t * 1e9).astype(np.int64)
    if twice.size:
        from .ident_example import repeat_messages
        stamps, rows = repeat_messages(stamps, rows, twice)
    if os.path.exists(path):
        shutil.rmtree(path)
    write_joint_states(path, stamps, names, *rows)
    return {'t': t, 'q': q, 'qd': qd, 'qdd': qdd, 'torque': torque}


def make_example(out_dir, seed=0, seconds=60.0, rate=100.0,
                 effort='torque', validation_seconds=30.0, payload=True,
                 robot='baxter'):
    """Write the files the module docstring lists; return their paths."""
    from .ident_example import jsonable, perturb_urdf, write_truth
    os.makedirs(out_dir, exist_ok=True)
    rng = np.random.default_rng([seed, 1])
    spec = ROBOTS[robot]
    nominal = os.path.join(out_dir, f'{robot}.urdf')
    shutil.copyfile(baxter_path(robot), nominal)
    with open(nominal, encoding='utf-8') as f:
        text = f.read()
    model = nominal_model(nominal, spec['base'])
    truth = perturb_urdf(text, set(model.info['urdf']['links']), rng)
    drives = random_drives(model, rng)
    paths = {'urdf': nominal}
    runs = [('excitation', seconds, 10.0, None),
            ('validation', validation_seconds, 8.0, None)]
    if payload:
        runs.append(('payload', 30.0, 9.0, PAYLOAD))
    if effort == 'current':
        runs.append(('known_mass', seconds, 11.0, KNOWN))
    for k, (label, secs, period, load) in enumerate(runs):
        path = os.path.join(out_dir, label)
        record(model, truth, drives, path,
               motion(model, seed + 100 * k, secs, period), rate=rate,
               payload=load, effort=effort, seed=seed + k, robot=robot)
        paths[label] = path
    paths['truth'] = write_truth(out_dir, {
        'urdf': truth, 'robot': robot, 'base': spec['base'],
        'effort': effort, 'joints': list(model.joint_names),
        'drives': jsonable(drives),
        'payload': {'link': spec['tool'], **PAYLOAD},
        'known_mass': {'link': spec['tool'], **KNOWN}})
    return paths


def main(argv=None):
    """Write the example files."""
    from .ident_example import example_parser, print_paths
    parser = example_parser(__doc__, seconds=60.0, rate=100.0)
    parser.add_argument('--effort', choices=('torque', 'current'),
                        default='torque')
    parser.add_argument('--robot', choices=sorted(ROBOTS), default='baxter')
    args = parser.parse_args(argv)
    paths = make_example(args.out_dir, args.seed, args.seconds, args.rate,
                         args.effort, robot=args.robot)
    return print_paths(paths, leave_out=('truth',))


if __name__ == '__main__':
    raise SystemExit(main())
