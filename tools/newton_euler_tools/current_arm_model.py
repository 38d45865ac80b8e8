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
An identified model of the current-sensing example arm, for the observer.

    python -m newton_euler_tools.current_arm_model TRUTH.json OUT.urdf
        [--seed N]

``TRUTH.json`` is what ``current_arm_example`` writes beside its
recordings.  Writes the URDF an identification of that arm would give:
its inertials within a few per cent (masses +-8 %, centres of mass
+-8 mm, inertias +-20 %), its viscous and Coulomb friction, rotor inertia
and offsets within 10 %, its torque constants within 3 % (N m per A),
written as ``identify`` writes them (``<dynamics damping friction>``,
``<ne:drive armature offset coulomb_width torque_constant>``).  What no
identification gives is left out: the static friction above the Coulomb
level, the stick-slip state at rest and the ripple.
"""
import argparse
import json
import sys
import xml.etree.ElementTree as ET

import numpy as np

#: identification errors: relative spread per drive term
SPREAD = {'coulomb': 0.1, 'viscous': 0.1, 'armature': 0.1, 'offset': 0.1,
          'torque_constant': 0.03}
WIDTH = 0.02            # rad/s, the Coulomb tanh width identify writes


def identified_urdf(truth, seed=0):
    """Return the URDF text of the identified arm (``truth``: a dict)."""
    from newton_euler_ros.core.drives import (DRIVES_NS, DRIVES_PREFIX,
                                              Drives)
    from newton_euler_ros.ident.urdf_out import _set_drive
    from .current_arm_example import JOINTS, nominal_model
    from .ident_example import perturb_urdf
    rng = np.random.default_rng([seed, 31])
    links = set(nominal_model().info['urdf']['links'])
    text = perturb_urdf(truth['urdf'], links, rng, mass=0.08, com=0.008,
                        inertia=0.2)
    true = dict(truth['drives'], torque_constant=truth['torque_constant'])
    d = {k: np.asarray(true[k], dtype=float) * rng.uniform(
        1 - s, 1 + s, 6) for k, s in SPREAD.items()}
    drives = Drives(d['viscous'], d['coulomb'], d['offset'], d['armature'],
                    np.full(6, WIDTH), d['torque_constant'])
    ET.register_namespace(DRIVES_PREFIX, DRIVES_NS)
    root = ET.fromstring(text)
    joints = {el.get('name'): el for el in root.findall('joint')}
    for j, name in enumerate(JOINTS):
        _set_drive(joints[name], drives, j)
    return ET.tostring(root, encoding='unicode')


def write_identified(path, arm, seed=0):
    """Write the identified URDF of ``arm`` (a ``RealArm``); return path."""
    with open(path, 'w', encoding='utf-8') as fh:
        fh.write(identified_urdf(arm.to_json(), seed))
    return str(path)


def main(argv=None):
    """Write the identified URDF; 0, or 2 with one line on bad input."""
    parser = argparse.ArgumentParser(
        prog='current_arm_model', description=__doc__.strip().split('\n')[0])
    parser.add_argument('truth', metavar='TRUTH.json')
    parser.add_argument('out', metavar='OUT.urdf')
    parser.add_argument('--seed', type=int, default=0)
    args = parser.parse_args(argv)
    try:
        with open(args.truth, encoding='utf-8') as f:
            truth = json.load(f)
        text = identified_urdf(truth, args.seed)
    except (OSError, ValueError, KeyError) as exc:
        print(f'current_arm_model: {args.truth}: not a current_arm_example '
              f'truth file ({exc})', file=sys.stderr)
        return 2
    with open(args.out, 'w', encoding='utf-8') as f:
        f.write(text)
    print(f'wrote {args.out}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
