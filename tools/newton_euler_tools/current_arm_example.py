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
Recordings of a "real" current-sensing arm (a UR5), as its driver reports.

    python -m newton_euler_tools.current_arm_example OUT_DIR [--seed N]
        [--effort current|torque] [--seconds S] [--free N] [--pushes N]
        [--rate HZ] [--unmodelled S]

A model of the recordings a UR5 gives through its ROS 2 driver with the
default settings (``/joint_states`` effort = motor current, A), for the
identification and observer examples and tests.  It is a model: no real
arm was recorded.  What it has of a real recording:

- **An arm that is not its URDF.**  The published UR5 of
  example-robot-data (``ur5.urdf``, the nominal model) with masses
  +-15 %, centres of mass +-15 mm and inertias +-25 %; that file's wrist
  links carry 0.11-0.22 kg m^2 (far too much for 1.2 kg bodies), the
  "real" arm has inertias of a body of that mass and size.  Rigid-body
  torques from Pinocchio's RNEA on that arm (an independent
  implementation).
- **Drives as on a geared, current-sensed arm.**  Reflected rotor
  inertia (0.3-0.5 kg m^2 on the big joints), viscous friction, torque
  offsets, Coulomb friction F_c (about 12 N m on the shoulder) with a
  Stribeck peak at low speed, and static friction F_s = 1.2-1.5 F_c.
  Friction is a stick-slip (Dahl) state: while the joint moves it
  follows sign(qd) (F_c + (F_s - F_c) exp(-(qd / 0.01 rad/s)^2)) within
  about a milliradian of travel; when the joint stops it keeps that value,
  scaled by a draw in [-0.3, 1] (the position loop's last correction),
  then drifts slowly, always within +-F_s: what a resting joint's current
  is, no model of (q, qd, qdd) can predict.  Torque ripple locked to the
  joint angle (202 periods per turn).
- **Current, not torque.**  effort = joint torque / K per joint
  (:data:`TORQUE_CONSTANTS`, plausible values for a UR5, not UR's), plus
  current noise (0.03 A RMS).  ``--effort torque`` writes K times that
  current instead: a torque output as on newer UR software.
- **A driver's messages.**  100 Hz, stamps jittering by +-20 % of a
  period, 1 % of messages lost, a gap of 0.3-0.6 s every 20 s, 1 %
  repeated (same values, a later stamp), joints in the driver's order
  (shoulder_pan last), velocity noise (2e-3 rad/s), quantised positions.
- **Motions a user records.**  ``excitation``: a windowed Fourier series,
  2 s at rest at both ends (about a minute); ``validation``:
  point-to-point moves with short stops (0.1-0.4 s), every joint
  reversing at every move; ``known_mass``: another excitation with
  :data:`KNOWN_MASS` kg at ``tool0`` (its centre of mass and inertia are
  not told); ``free_1`` ...: free motion with longer stops (0.3-2.5 s),
  some moves of one to three joints, joints that creep (for observer
  thresholds); ``rest``: the arm holding five poses for 4-8 s each;
  ``pushed`` (with ``--pushes N``): holding poses then moving, with N
  pushes of 20-100 N on the tool (a half-sine of 0.4-1.2 s; the position
  controller holds the path, so the drives apply -J^T F on top).

Files in OUT_DIR: ``ur5.urdf`` (nominal), the rosbag2 (MCAP) recordings
above, and ``truth.json`` (the arm: URDF text, drives, torque constants,
the known payload, each recording's pushes; for checking, not used by
the commands).

Python API (kept stable for the tests that use it):

- :func:`real_arm` (seed) -> :class:`RealArm`, the truth;
- :func:`excitation`, :func:`point_to_point`, :func:`holding`,
  :func:`concatenate`, :func:`held_then_moving` (``current_arm_motions``):
  motions, callables ``f(t) -> (q, qd, qdd)`` with a ``seconds``
  attribute;
- :func:`record` (arm, path, motion, ...): one recording, with an
  optional payload and pushes (:func:`random_pushes`); returns the true
  signals at the messages (torque, friction, external torque);
- :func:`make_example` (out_dir, ...): every file above; returns paths.
"""
import math
import os
import shutil
import tempfile
import warnings
import xml.etree.ElementTree as ET

import numpy as np

from .current_arm_motions import (CENTRE, concatenate, excitation,  # noqa
                                  HALF_RANGE, held_then_moving, holding,
                                  point_to_point, random_pushes, SPEED)

UR5 = 'ur_description/urdf/ur5_robot.urdf'
BASE, TIP = 'base_link', 'tool0'
JOINTS = ('shoulder_pan_joint', 'shoulder_lift_joint', 'elbow_joint',
          'wrist_1_joint', 'wrist_2_joint', 'wrist_3_joint')
# the order of the driver's JointState (shoulder_pan last)
DRIVER_ORDER = JOINTS[1:] + JOINTS[:1]
# N m per A, per joint (plausible for a UR5; not UR's published values)
TORQUE_CONSTANTS = (12.6, 13.2, 10.4, 7.6, 7.5, 7.3)
# typical drive terms; each arm draws its own around them (+-20 %)
COULOMB = (10.5, 12.0, 8.5, 2.6, 2.4, 2.2)          # N m
STATIC_RATIO = (1.2, 1.5)                            # F_s / F_c
VISCOUS = (6.0, 6.5, 4.0, 1.2, 1.1, 1.0)             # N m s / rad
ARMATURE = (0.45, 0.45, 0.30, 0.06, 0.06, 0.06)      # kg m^2
RIPPLE = (0.25, 0.25, 0.2, 0.05, 0.05, 0.05)         # N m
STRIBECK_SPEED = 0.01     # rad/s
BRISTLE = 5e-4            # rad of travel for friction to follow the motion
REST_DRIFT = 0.05         # of F_s per sqrt(s), at rest
CURRENT_NOISE = 0.03      # A RMS
KNOWN_MASS = 2.8          # kg
# what an identified model may lack, for ``unmodelled`` > 0 (times it):
# friction growing with the square of the speed (a lubricant's churning,
# stiffer when the arm is cold), N m s^2 / rad^2, and rotor and gear
# inertia beyond the identified one, kg m^2
QUADRATIC = (16.0, 18.0, 10.0, 1.6, 1.5, 1.2)
HIDDEN_ARMATURE = (1.2, 1.2, 0.6, 0.08, 0.08, 0.08)
PAYLOAD_COM = (0.004, -0.012, 0.045)                 # m, tool0 frame
PAYLOAD_INERTIA = ((4.2e-3, 0.0, 0.0), (0.0, 4.6e-3, 0.0),
                   (0.0, 0.0, 3.1e-3))               # kg m^2 about the com


def ur5_path():
    """Return the published UR5 URDF's path (example-robot-data)."""
    from .peers import example_robot_urdf
    return example_robot_urdf(UR5)


def nominal_model():
    """Return the published UR5 as our chain model (base_link -> tool0)."""
    from newton_euler_ros.core import load_robot
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot(ur5_path(), base=BASE, tip=TIP)


class RealArm:
    """The truth: URDF text of the real arm, drives, torque constants."""

    def __init__(self, urdf, drives, constants, seed):
        self.urdf = urdf
        self.drives = drives          # dict of (6,) arrays
        self.constants = np.asarray(constants, dtype=np.float64)
        self.seed = seed

    def to_json(self):
        """Return the truth as a JSON-ready dict."""
        from .ident_example import jsonable
        return {'urdf': self.urdf, 'base': BASE, 'tip': TIP,
                'joints': list(JOINTS), 'seed': self.seed,
                'torque_constant': self.constants.tolist(),
                'drives': jsonable(self.drives)}


def _realistic_wrists(root, rng):
    """Inertias of a 1.2 kg wrist body (a cylinder r 6 cm, h 12 cm)."""
    for el in root.iter('link'):
        if el.get('name') not in ('wrist_1_link', 'wrist_2_link',
                                  'wrist_3_link'):
            continue
        inertial = el.find('inertial')
        m = float(inertial.find('mass').get('value'))
        r, h = rng.uniform(0.05, 0.065), rng.uniform(0.09, 0.12)
        side = m * (3 * r * r + h * h) / 12.0
        axial = 0.5 * m * r * r
        i_el = inertial.find('inertia')
        for k, v in (('ixx', side), ('iyy', side), ('izz', axial),
                     ('ixy', 0.0), ('ixz', 0.0), ('iyz', 0.0)):
            i_el.set(k, repr(float(v)))


def real_arm(seed=0, unmodelled=0.0):
    """
    Return the :class:`RealArm` of ``seed`` (the published UR5 perturbed).

    ``unmodelled`` > 0: its drives also have ``unmodelled`` times
    :data:`QUADRATIC` friction and :data:`HIDDEN_ARMATURE`, which the
    identified model (``current_arm_model``) does not have: a model
    whose error grows with speed and acceleration.
    """
    from .ident_example import perturb_urdf
    rng = np.random.default_rng([seed, 27])
    with open(ur5_path(), encoding='utf-8') as f:
        text = f.read()
    root = ET.fromstring(text)
    _realistic_wrists(root, rng)
    links = set(nominal_model().info['urdf']['links'])
    truth = perturb_urdf(ET.tostring(root, encoding='unicode'), links, rng)

    def draw(values, spread=0.2):
        return np.asarray(values) * rng.uniform(1 - spread, 1 + spread, 6)
    coulomb = draw(COULOMB)
    drives = {'coulomb': coulomb,
              'static': coulomb * rng.uniform(*STATIC_RATIO, 6),
              'viscous': draw(VISCOUS), 'armature': draw(ARMATURE),
              'offset': rng.uniform(-0.6, 0.6, 6),
              'ripple': draw(RIPPLE), 'ripple_phase': rng.uniform(0, 6.3, 6),
              'stribeck_speed': STRIBECK_SPEED, 'bristle': BRISTLE}
    constants = draw(TORQUE_CONSTANTS, 0.03)
    if unmodelled:
        drives['quadratic'] = unmodelled * np.asarray(QUADRATIC)
        drives['hidden_armature'] = unmodelled * np.asarray(HIDDEN_ARMATURE)
    return RealArm(truth, drives, constants, seed)


# ---------------------------------------------------------------------------
# the drives and the driver

def friction(arm, qd, dt, rng):
    """
    Friction torque (m, 6) along velocities ``qd`` sampled every ``dt``.

    A Dahl state per joint: while moving it approaches the Stribeck curve
    sign(qd) (F_c + (F_s - F_c) exp(-(qd / v_s)^2)) exponentially with
    the travel (constant ``bristle`` rad); at rest (qd exactly 0) it
    keeps its value: scaled by a draw in [-0.3, 1] when the joint stops
    (the position loop's last correction), then a slow random walk,
    always within +-F_s.
    """
    d = arm.drives
    fc, fs = np.asarray(d['coulomb']), np.asarray(d['static'])
    vs, delta = d['stribeck_speed'], d['bristle']
    settle = rng.uniform(-0.3, 1.0, qd.shape)
    walk = rng.normal(0.0, REST_DRIFT * math.sqrt(dt), qd.shape) * fs
    # everything but the state, for every sample at once; the state
    # recursion then runs per joint on plain floats
    moving = qd != 0.0
    fss = np.sign(qd) * (fc + (fs - fc) * np.exp(-(qd / vs) ** 2))
    a = np.exp(-np.abs(qd) * dt / delta)
    stopped = ~moving
    stopped[1:] &= moving[:-1]
    stopped[0] = False
    out = np.empty_like(qd)
    for j in range(qd.shape[1]):
        f, hi, lo = 0.0, float(fs[j]), -float(fs[j])
        column = zip(moving[:, j].tolist(), fss[:, j].tolist(),
                     a[:, j].tolist(), stopped[:, j].tolist(),
                     settle[:, j].tolist(), walk[:, j].tolist())
        values = []
        for move, target, decay, stop, scale, step in column:
            if move:
                f = target + (f - target) * decay
            else:
                f = min(max((f * scale if stop else f) + step, lo), hi)
            values.append(f)
        out[:, j] = values
    return out


class _Pinocchio:
    """Pinocchio's RNEA (and tool Jacobian) on the real arm's URDF."""

    def __init__(self, urdf_text, payload=None):
        import pinocchio as pin
        from .peers import PinocchioUrdf
        self.pin = pin
        self._tmp = tempfile.TemporaryDirectory()
        path = os.path.join(self._tmp.name, 'truth.urdf')
        with open(path, 'w', encoding='utf-8') as f:
            f.write(urdf_text)
        self.peer = PinocchioUrdf(path, list(JOINTS), TIP)
        if payload is not None:
            model = self.peer.model
            frame = model.frames[self.peer.frame]
            body = pin.Inertia(float(payload['mass']),
                               np.asarray(payload['com'], dtype=float),
                               np.asarray(payload['inertia'], dtype=float))
            model.inertias[frame.parentJoint] = (
                model.inertias[frame.parentJoint]
                + frame.placement.act(body))
            self.peer.data = model.createData()

    def torques(self, q, qd, qdd):
        p = self.peer
        return np.array([self.pin.rnea(p.model, p.data, p.config(q[i]),
                                       qd[i], qdd[i]) for i in range(len(q))])

    def tool_jacobian(self, q):
        p, pin = self.peer, self.pin
        x = p.config(q)
        pin.computeJointJacobians(p.model, p.data, x)
        pin.updateFramePlacements(p.model, p.data)
        return pin.getFrameJacobian(p.model, p.data, p.frame,
                                    pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)


def _message_times(seconds, rate, rng, lost, repeated, gap_every, jitter):
    """Sample times (s) of the messages and the indices sent twice."""
    count = int(seconds * rate)
    t = (np.arange(count) + rng.uniform(-jitter, jitter, count)) / rate
    t[0] = 0.0
    keep = rng.random(count) >= lost
    if gap_every:
        for _ in range(int(seconds // gap_every)):
            g0 = rng.uniform(1.0, max(1.0, seconds - 2.0))
            keep &= ~((t > g0) & (t < g0 + rng.uniform(0.3, 0.6)))
    keep[0] = keep[-1] = True
    t = t[keep]
    twice = np.flatnonzero(rng.random(len(t) - 1) < repeated)
    return t, twice


def push_torques(sim, q, t, pushes):
    """J^T F of the pushes (force on the tool, base axes) at times t."""
    out = np.zeros((len(t), 6))
    for p in pushes:
        s = (t - p['start']) / p['duration']
        on = np.flatnonzero((s > 0) & (s < 1))
        F = np.asarray(p['force'], dtype=float)
        for i in on:
            J = sim.tool_jacobian(q[i])[:3]
            out[i] = J.T @ F * math.sin(math.pi * s[i])
    return out


def record(arm, path, motion, rate=100.0, effort='current', payload=None,
           pushes=(), seed=0, storage='mcap', lost=0.01, repeated=0.01,
           gap_every=20.0, jitter=0.2, sim_rate=500.0):
    """
    Write one recording of ``arm`` following ``motion``; return its truth.

    ``effort`` 'current' (A) or 'torque' (N m: K times the current);
    ``payload`` None or {'mass', 'com', 'inertia'} at ``tool0``;
    ``pushes`` [{'start', 'duration', 'force'}] (s, s, N on the tool in
    base axes, a half-sine).  Returns a dict of arrays at the messages
    (chain order, before repeats): 't' (s from the start), 'q', 'qd',
    'torque' (what the drives apply, N m), 'friction', 'external'
    (J^T F of the pushes) and 'current' (A, noiseless).
    """
    from newton_euler_ros.ident.bag_write import write_joint_states
    if effort not in ('current', 'torque'):
        raise ValueError(f"effort must be 'current' or 'torque', not "
                         f'{effort!r}')
    rng = np.random.default_rng([seed, 5])
    d = arm.drives
    dt = 1.0 / sim_rate
    fine = np.arange(0.0, motion.seconds + dt, dt)
    _, qd_f, _ = motion(fine)
    fric_f = friction(arm, qd_f, dt, rng)
    t, twice = _message_times(motion.seconds, rate, rng, lost, repeated,
                              gap_every, jitter)
    q, qd, qdd = motion(t)
    idx = np.clip(np.round(t / dt).astype(int), 0, len(fine) - 1)
    fric = fric_f[idx]
    sim = _Pinocchio(arm.urdf, payload)
    external = push_torques(sim, q, t, pushes)
    ripple = np.asarray(d['ripple']) * np.sin(202.0 * q + d['ripple_phase'])
    torque = (sim.torques(q, qd, qdd) + np.asarray(d['armature']) * qdd
              + np.asarray(d['viscous']) * qd + fric + np.asarray(d['offset'])
              + ripple - external)
    if 'quadratic' in d:            # what the identified model lacks
        torque += (np.asarray(d['quadratic']) * qd * np.abs(qd)
                   + np.asarray(d['hidden_armature']) * qdd)
    current = torque / arm.constants
    measured = current + rng.normal(0.0, CURRENT_NOISE, current.shape)
    if effort == 'torque':
        measured = measured * arm.constants
    qm = np.round(q / 2e-5) * 2e-5
    qdm = qd + rng.normal(0.0, 2e-3, qd.shape)
    stamps = 1_700_000_000 * 10**9 + np.round(t * 1e9).astype(np.int64)
    rows = [qm, qdm, measured]
    if twice.size:
        from .ident_example import repeat_messages
        stamps, rows = repeat_messages(stamps, rows, twice)
    perm = [JOINTS.index(x) for x in DRIVER_ORDER]
    if os.path.exists(path):
        shutil.rmtree(path)
    write_joint_states(path, stamps, list(DRIVER_ORDER),
                       *(np.ascontiguousarray(r[:, perm]) for r in rows),
                       storage=storage)
    return {'t': t, 'q': q, 'qd': qd, 'torque': torque, 'friction': fric,
            'external': external, 'current': current}


def known_payload():
    """Return the known-mass payload at tool0 (only its mass is told)."""
    return {'mass': KNOWN_MASS, 'com': list(PAYLOAD_COM),
            'inertia': [list(r) for r in PAYLOAD_INERTIA]}


RUNS = ('excitation', 'validation', 'known_mass', 'free', 'rest', 'pushed')


def make_example(out_dir, seed=0, effort='current', seconds=60.0,
                 validation_seconds=40.0, known_mass_seconds=None, free=3,
                 free_seconds=30.0, pushes=0, rate=100.0, storage='mcap',
                 runs=RUNS, unmodelled=0.0):
    """
    Write the files the module docstring lists; return their paths.

    ``runs`` selects the recordings (names of :data:`RUNS`; 'free'
    writes ``free_1`` ... ``free_<free>``, 'pushed' a recording with
    ``pushes`` pushes of 20-100 N on the tool when ``pushes`` > 0;
    ``unmodelled``: as :func:`real_arm`).
    The paths dict has 'urdf', 'truth' and one key per recording.
    """
    os.makedirs(out_dir, exist_ok=True)
    arm = real_arm(seed, unmodelled)
    paths = {'urdf': os.path.join(out_dir, 'ur5.urdf')}
    shutil.copyfile(ur5_path(), paths['urdf'])
    truth = arm.to_json()
    truth['effort'] = effort
    truth['runs'] = {}
    plan = []
    if 'excitation' in runs:
        plan.append(('excitation', excitation(seed, seconds), None, ()))
    if 'validation' in runs:
        plan.append(('validation', point_to_point(seed, validation_seconds),
                     None, ()))
    if 'known_mass' in runs:
        plan.append(('known_mass', excitation(seed + 1000, known_mass_seconds
                                              or seconds), known_payload(),
                     ()))
    if 'free' in runs:
        for k in range(1, free + 1):
            plan.append((f'free_{k}', point_to_point(
                seed + 100 * k, free_seconds, dwell=(0.3, 2.5), few=0.3,
                reverse=0.7),
                None, ()))
    if 'rest' in runs:
        plan.append(('rest', holding(seed), None, ()))
    if 'pushed' in runs and pushes > 0:
        motion = held_then_moving(seed + 7)
        plan.append(('pushed', motion, None,
                     random_pushes(seed, motion.seconds, pushes)))
    for k, (name, motion, payload, push) in enumerate(plan):
        path = os.path.join(out_dir, name)
        record(arm, path, motion, rate=rate, effort=effort, payload=payload,
               pushes=push, seed=seed * 1000 + k, storage=storage)
        paths[name] = path
        truth['runs'][name] = {'seconds': motion.seconds, 'payload': payload,
                               'pushes': list(push)}
    from .ident_example import write_truth
    paths['truth'] = write_truth(out_dir, truth)
    return paths


def main(argv=None):
    """Write the example files."""
    from .ident_example import example_parser, print_paths
    parser = example_parser(__doc__)
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--effort', choices=('current', 'torque'),
                        default='current')
    parser.add_argument('--seconds', type=float, default=60.0,
                        help='excitation length, s (default 60)')
    parser.add_argument('--free', type=int, default=3, metavar='N',
                        help='free-motion recordings (default 3)')
    parser.add_argument('--pushes', type=int, default=0, metavar='N',
                        help='also a recording with N pushes on the tool')
    parser.add_argument('--rate', type=float, default=100.0)
    parser.add_argument('--unmodelled', type=float, default=0.0,
                        metavar='S', help='S x friction in speed squared '
                        'and rotor inertia the identified model lacks '
                        '(default 0)')
    args = parser.parse_args(argv)
    paths = make_example(args.out_dir, seed=args.seed, effort=args.effort,
                         seconds=args.seconds, free=args.free,
                         pushes=args.pushes, rate=args.rate,
                         unmodelled=args.unmodelled)
    return print_paths(paths)


if __name__ == '__main__':
    raise SystemExit(main())
