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
Recordings of a "real" Panda, for identification examples and tests.

    python -m newton_euler_tools.ident_example OUT_DIR [--seconds 40]
        [--rate 500] [--seed 0]

writes into OUT_DIR:

- ``panda.urdf``: the published Panda URDF (example-robot-data), the
  nominal model a user starts from;
- ``recording/`` and ``validation/``: rosbag2 (MCAP) recordings of
  /joint_states of an arm that differs from it as real ones do: masses
  +-15 %, centres of mass +-15 mm, inertias +-25 % (principal moments,
  kept physical), viscous and Coulomb friction, torque offsets and rotor
  inertia per joint.  The efforts come from Pinocchio's RNEA on that
  perturbed URDF (an independent implementation) plus the drive terms.
  The recordings have what real ones have: effort and velocity noise,
  quantised positions, irregular sample times (stamped exactly), lost
  messages, repeated messages, the finger joints in the message and the
  joints in another order.  Two different excitation trajectories
  (finite Fourier series, Swevers et al. 1997).
- ``truth.json``: the perturbed parameters (for checking, not used by the
  commands).
"""
import argparse
import json
import math
import os
import shutil
import tempfile
import xml.etree.ElementTree as ET

import numpy as np

PANDA = 'panda_description/urdf/panda.urdf'
BASE, TIP = 'panda_link0', 'panda_link8'
EXTRA = ('panda_finger_joint1', 'panda_finger_joint2')


def panda_path():
    """Return the published Panda URDF's path (example-robot-data)."""
    from .peers import example_robot_urdf
    return example_robot_urdf(PANDA)


def _triangle_ok(eig):
    a, b, c = eig
    return a + b >= c and a + c >= b and b + c >= a and min(eig) > 0


def perturb_urdf(text, links, rng, mass=0.15, com=0.015, inertia=0.25):
    """
    Return URDF text with the named links' inertials perturbed.

    Masses by a factor in 1 +- ``mass``, centres of mass by up to ``com``
    metres per axis, principal moments by factors in 1 +- ``inertia``
    (redrawn until the triangle inequality holds).
    """
    root = ET.fromstring(text)
    for el in root.iter('link'):
        if el.get('name') not in links:
            continue
        inertial = el.find('inertial')
        m_el = inertial.find('mass')
        m_el.set('value', repr(float(m_el.get('value'))
                               * rng.uniform(1 - mass, 1 + mass)))
        origin = inertial.find('origin')
        if origin is None:
            origin = ET.SubElement(inertial, 'origin', xyz='0 0 0',
                                   rpy='0 0 0')
        xyz = np.array([float(v) for v in origin.get('xyz', '0 0 0')
                        .split()]) + rng.uniform(-com, com, 3)
        origin.set('xyz', ' '.join(repr(float(v)) for v in xyz))
        i_el = inertial.find('inertia')
        keys = ('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz')
        v = {k: float(i_el.get(k, '0')) for k in keys}
        I = np.array([[v['ixx'], v['ixy'], v['ixz']],  # noqa: E741
                      [v['ixy'], v['iyy'], v['iyz']],
                      [v['ixz'], v['iyz'], v['izz']]])
        eig, V = np.linalg.eigh(I)
        for _ in range(1000):
            new = eig * rng.uniform(1 - inertia, 1 + inertia, 3)
            if _triangle_ok(new):
                break
        else:
            new = eig
        In = (V * new) @ V.T
        for k, (a, b) in zip(keys, ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2),
                                    (2, 2))):
            i_el.set(k, repr(float(In[a, b])))
    return ET.tostring(root, encoding='unicode')


def random_drives(rng, n):
    """Return true drive parameters of a Panda-like arm."""
    return {'viscous': rng.uniform(0.05, 0.4, n),
            'coulomb': rng.uniform(0.2, 1.2, n),
            'offset': rng.uniform(-0.4, 0.4, n),
            'armature': rng.uniform(0.02, 0.12, n),
            'coulomb_width': 0.02}


def fourier_trajectory(model, rng, period=10.0, harmonics=5, speed=1.2):
    """
    Return f(t) -> (q, qd, qdd) at times t (finite Fourier series).

    Each joint oscillates about the middle of its limits, within 60 % of
    its half range, with a peak velocity near ``speed`` rad/s.
    """
    n = model.n
    w0 = 2 * math.pi / period
    k = np.arange(1, harmonics + 1)
    a = rng.normal(size=(n, harmonics)) / k
    b = rng.normal(size=(n, harmonics)) / k
    mid = np.zeros(n)
    half = np.full(n, 1.5)
    for j, lim in enumerate(model.limits):
        if 'lower' in lim and 'upper' in lim:
            mid[j] = 0.5 * (lim['lower'] + lim['upper'])
            half[j] = 0.5 * (lim['upper'] - lim['lower'])
    # scale: position amplitude and peak speed within bounds
    t = np.linspace(0, period, 2000, endpoint=False)
    arg = w0 * np.outer(t, k)
    s, c = np.sin(arg), np.cos(arg)
    pos = s @ a.T + c @ b.T
    vel = w0 * (c * k) @ a.T - w0 * (s * k) @ b.T
    amp = np.minimum(0.6 * half / np.abs(pos).max(axis=0),
                     speed / np.abs(vel).max(axis=0))
    a *= amp[:, None]
    b *= amp[:, None]
    # start from the middle: subtract the value at t = 0
    offset = mid - b.sum(axis=1)

    def f(times):
        arg = w0 * np.outer(times, k)
        s, c = np.sin(arg), np.cos(arg)
        q = s @ a.T + c @ b.T + offset
        qd = w0 * ((c * k) @ a.T - (s * k) @ b.T)
        qdd = -w0 ** 2 * ((s * k * k) @ a.T + (c * k * k) @ b.T)
        return q, qd, qdd
    return f


def measured_efforts(peer, q, qd, qdd, drives, effort_noise, rng):
    """
    Return what the drives of a Pinocchio arm would measure along a path.

    Pinocchio's RNEA (``peer``, a ``peers.PinocchioUrdf``) plus the drive
    terms (``drives``: viscous, coulomb, coulomb_width, offset, armature)
    and white effort noise of ``effort_noise`` N m.
    """
    import pinocchio as pin
    tau = np.empty_like(q)
    for i in range(len(q)):
        tau[i] = pin.rnea(peer.model, peer.data, peer.config(q[i]), qd[i],
                          qdd[i])
    tau += (drives['viscous'] * qd + drives['coulomb'] * np.tanh(
        qd / drives['coulomb_width']) + drives['offset']
        + drives['armature'] * qdd)
    return tau + rng.normal(0, effort_noise, tau.shape)


def simulate(truth_urdf_path, model, drives, trajectory, seconds, rate,
             rng, effort_noise=0.05, velocity_noise=2e-3, quantum=2e-6,
             lost=0.02, repeated=0.01, jitter=0.2):
    """
    Return (stamps_ns, names, q, qd, effort) of a JointState recording.

    Sample times are irregular (+-``jitter`` of a period) and stamped
    exactly; ``lost`` of the messages are dropped and ``repeated`` sent
    twice (same values, a later stamp); positions are quantised.
    """
    from .peers import PinocchioUrdf
    peer = PinocchioUrdf(truth_urdf_path, model.joint_names, TIP)
    count = int(seconds * rate)
    t = (np.arange(count) + rng.uniform(-jitter, jitter, count)) / rate
    t[0] = 0.0
    q, qd, qdd = trajectory(t)
    tau = measured_efforts(peer, q, qd, qdd, drives, effort_noise, rng)
    qm = np.round(q / quantum) * quantum
    qdm = qd + rng.normal(0, velocity_noise, qd.shape)
    keep = rng.random(count) >= lost
    keep[0] = keep[-1] = True
    idx = np.flatnonzero(keep)
    stamps = np.round((1_000_000_000 + t[idx]) * 1e9).astype(np.int64)
    rows = [qm[idx], qdm[idx], tau[idx]]
    # repeated messages: the same values, stamped a little later
    rep = np.flatnonzero(rng.random(len(idx) - 1) < repeated)
    if rep.size:
        stamps, rows = repeat_messages(stamps, rows, rep)
    # the message lists the fingers too, and in another order
    names = list(reversed(model.joint_names)) + list(EXTRA)
    perm = [model.joint_names.index(x) for x in reversed(model.joint_names)]
    extra = np.zeros((len(stamps), len(EXTRA)))
    q_out, qd_out, e_out = (np.hstack([r[:, perm], extra]) for r in rows)
    return stamps, names, q_out, qd_out, e_out


def make_example(out_dir, seconds=40.0, rate=500.0, seed=0,
                 storage='mcap', validation=True, validation_seconds=20.0,
                 validation_storage=None):
    """Write the files the module docstring lists; return their paths."""
    import warnings
    from newton_euler_ros.core import load_robot
    from newton_euler_ros.ident.bag_write import write_joint_states
    os.makedirs(out_dir, exist_ok=True)
    rng = np.random.default_rng(seed)
    nominal_path = os.path.join(out_dir, 'panda.urdf')
    shutil.copyfile(panda_path(), nominal_path)
    with open(nominal_path, encoding='utf-8') as f:
        text = f.read()
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot(nominal_path, base=BASE, tip=TIP)
    truth_text = perturb_urdf(text, set(model.info['urdf']['links']), rng)
    drives = random_drives(rng, model.n)
    paths = {'urdf': nominal_path}
    with tempfile.TemporaryDirectory() as tmp:
        truth_path = os.path.join(tmp, 'truth.urdf')
        with open(truth_path, 'w', encoding='utf-8') as f:
            f.write(truth_text)
        runs = [('recording', seconds, 1, storage)]
        if validation:
            runs.append(('validation', validation_seconds, 2,
                         validation_storage or storage))
        for label, secs, k, fmt in runs:
            traj = fourier_trajectory(model, np.random.default_rng(
                [seed, k]), period=10.0 if k == 1 else 8.0)
            stamps, names, q, qd, e = simulate(
                truth_path, model, drives, traj, secs, rate,
                np.random.default_rng([seed, k, 1]))
            path = os.path.join(out_dir, label)
            if os.path.exists(path):
                shutil.rmtree(path)
            write_joint_states(path, stamps, names, q, qd, e,
                               storage=fmt)
            paths[label] = path
    paths['truth'] = write_truth(out_dir, {
        'urdf': truth_text, 'base': BASE, 'tip': TIP,
        'drives': jsonable(drives)})
    return paths


def repeat_messages(stamps, rows, again):
    """
    Return ``stamps`` and ``rows`` with the messages ``again`` sent twice.

    A repeat carries the same values, stamped halfway to the next message.
    """
    order = np.argsort(np.concatenate([np.arange(len(stamps)), again + 0.5]),
                       kind='stable')
    later = stamps[again] + (stamps[again + 1] - stamps[again]) // 2
    return (np.concatenate([stamps, later])[order],
            [np.concatenate([r, r[again]])[order] for r in rows])


def jsonable(values):
    """Return a dict of arrays and numbers as JSON takes it (lists)."""
    return {k: (v.tolist() if isinstance(v, np.ndarray) else v)
            for k, v in values.items()}


def write_truth(out_dir, truth):
    """Write an example's ``truth.json`` (for checking); return its path."""
    path = os.path.join(out_dir, 'truth.json')
    with open(path, 'w', encoding='utf-8') as f:
        json.dump(truth, f)
    return path


def example_parser(doc, seconds=None, rate=None):
    """
    Return an example writer's parser: ``doc``'s first line, ``out_dir``.

    With ``seconds`` and ``rate``, also the options of a recording:
    ``--seed`` (default 0), ``--seconds`` and ``--rate`` with these
    defaults.
    """
    parser = argparse.ArgumentParser(description=doc.strip().split('\n')[0])
    parser.add_argument('out_dir')
    if seconds is not None:
        parser.add_argument('--seed', type=int, default=0)
        parser.add_argument('--seconds', type=float, default=seconds)
        parser.add_argument('--rate', type=float, default=rate)
    return parser


def print_paths(paths, leave_out=()):
    """Print ``name: path`` for each file an example wrote; return 0."""
    for key, value in paths.items():
        if key not in leave_out:
            print(f'{key}: {value}')
    return 0


def main(argv=None):
    """Write the example files."""
    parser = example_parser(__doc__, seconds=40.0, rate=500.0)
    parser.add_argument('--storage', choices=('mcap', 'sqlite3'),
                        default='mcap')
    args = parser.parse_args(argv)
    paths = make_example(args.out_dir, args.seconds, args.rate, args.seed,
                         args.storage)
    return print_paths(paths, leave_out=('truth',))


if __name__ == '__main__':
    raise SystemExit(main())
