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
A Panda carrying a known payload, recorded to a rosbag2 (for ``payload``).

Writes into OUT_DIR:

- ``arm.urdf``: the published Panda URDF (example-robot-data) with drive
  terms (friction, offset, rotor inertia) in ``<dynamics>`` and
  ``<ne:drive>``: the arm's identified model, as ``identify`` writes it.
- ``payload/``: a rosbag2 (MCAP) of /joint_states of that arm moving with
  a rigid payload fixed to ``panda_link8``; torques from Pinocchio's RNEA
  (the payload added to the last joint's inertia by Pinocchio), the
  drive terms, noise, lost messages and stamp jitter.
- ``truth.json``: the payload (the node's ``payload.*`` parameters).

    python -m newton_euler_tools.payload_example OUT_DIR [--mass KG]
           [--com X Y Z] [--seconds S] [--seed N] [--only-base]
"""
import os
import shutil
import warnings

import numpy as np

from .ident_example import (BASE, example_parser, EXTRA,
                            fourier_trajectory, measured_efforts,
                            panda_path, print_paths, random_drives, TIP,
                            write_truth)

MASS = 1.5
COM = (0.01, -0.02, 0.06)
# inertia about the com, tip frame: a 1.5 kg box 8 x 6 x 12 cm, tilted
INERTIA_C = ((2.3e-3, 1e-4, 0.0), (1e-4, 2.6e-3, 2e-4), (0.0, 2e-4, 1.25e-3))


def arm_urdf(drives):
    """Return the published Panda URDF text with ``drives`` written in."""
    from newton_euler_ros.core import load_robot
    from newton_euler_ros.core.drives import Drives
    from newton_euler_ros.ident.fit import fixed_parts, nominal_theta
    from newton_euler_ros.ident.urdf_out import identified_urdf
    with open(panda_path(), encoding='utf-8') as f:
        text = f.read()
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot(panda_path(), base=BASE, tip=TIP)
    d = Drives(np.asarray(drives['viscous']), np.asarray(drives['coulomb']),
               np.asarray(drives['offset']), np.asarray(drives['armature']),
               np.full(model.n, float(drives['coulomb_width'])))
    return identified_urdf(text, model, nominal_theta(model),
                           fixed_parts(model, text), d), model


def record(path, model, drives, mass, com, inertia_c, seconds=30.0,
           rate=500.0, seed=0, only_base=False, effort_noise=0.05,
           storage='mcap'):
    """Write a recording of the Panda with the payload; return its path."""
    import pinocchio as pin
    from newton_euler_ros.ident.bag_write import write_joint_states
    from .peers import PinocchioUrdf
    peer = PinocchioUrdf(panda_path(), model.joint_names, TIP)
    if mass > 0:
        frame = peer.model.frames[peer.frame]
        body = pin.Inertia(float(mass), np.asarray(com, dtype=float),
                           np.asarray(inertia_c, dtype=float))
        peer.model.inertias[frame.parentJoint] = (
            peer.model.inertias[frame.parentJoint]
            + frame.placement.act(body))
        peer.data = peer.model.createData()
    rng = np.random.default_rng(seed)
    traj = fourier_trajectory(model, np.random.default_rng([seed, 1]),
                              period=10.0)
    count = int(seconds * rate)
    t = (np.arange(count) + rng.uniform(-0.2, 0.2, count)) / rate
    t[0] = 0.0
    q, qd, qdd = traj(t)
    if only_base:
        # a poor motion: only the first joint turns (about the vertical),
        # the payload never tilts
        for X, v in ((q, q[0, 1:]), (qd, 0.0), (qdd, 0.0)):
            X[:, 1:] = v
    tau = measured_efforts(peer, q, qd, qdd, drives, effort_noise, rng)
    keep = rng.random(count) >= 0.02
    keep[0] = keep[-1] = True
    stamps = np.round((1_000_000_000 + t[keep]) * 1e9).astype(np.int64)
    names = list(model.joint_names) + list(EXTRA)
    extra = np.zeros((int(keep.sum()), len(EXTRA)))
    write_joint_states(path, stamps, names, np.hstack([q[keep], extra]),
                       np.hstack([qd[keep], extra]),
                       np.hstack([tau[keep], extra]), storage=storage)
    return path


def make_example(out_dir, mass=MASS, com=COM, inertia_c=INERTIA_C,
                 seconds=30.0, seed=0, only_base=False):
    """Write the files the module docstring lists; return their paths."""
    os.makedirs(out_dir, exist_ok=True)
    drives = random_drives(np.random.default_rng(seed), 7)
    text, model = arm_urdf(drives)
    arm = os.path.join(out_dir, 'arm.urdf')
    with open(arm, 'w', encoding='utf-8') as f:
        f.write(text)
    bag = os.path.join(out_dir, 'payload')
    if os.path.exists(bag):
        shutil.rmtree(bag)
    record(bag, model, drives, mass, com, inertia_c, seconds=seconds,
           seed=seed, only_base=only_base)
    Ic = np.asarray(inertia_c, dtype=float)
    truth = {'payload.mass': float(mass),
             'payload.com': [float(x) for x in com],
             'payload.inertia': [float(Ic[a, b]) for a, b in
                                 ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2),
                                  (0, 2))]}
    return {'urdf': arm, 'bag': bag, 'truth': write_truth(out_dir, truth)}


def main(argv=None):
    """Write the example files."""
    parser = example_parser(__doc__)
    parser.add_argument('--mass', type=float, default=MASS)
    parser.add_argument('--com', type=float, nargs=3, default=COM)
    parser.add_argument('--seconds', type=float, default=30.0)
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--only-base', action='store_true',
                        help='only the first joint moves (a poor motion)')
    args = parser.parse_args(argv)
    paths = make_example(args.out_dir, args.mass, args.com,
                         seconds=args.seconds, seed=args.seed,
                         only_base=args.only_base)
    return print_paths(paths)


if __name__ == '__main__':
    raise SystemExit(main())
