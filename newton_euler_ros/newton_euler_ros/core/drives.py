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
Drive terms per joint: friction, torque offset and rotor inertia.

The torque a joint's drive needs on top of the rigid-body torque::

    tau_drive = F_v qd + F_c tanh(qd / eps) + offset + I_a qdd

- ``viscous`` F_v (N m s/rad, or N s/m): URDF ``<dynamics damping=>``.
- ``coulomb`` F_c (N m, or N): URDF ``<dynamics friction=>``.
- ``offset`` (N m, or N): a constant torque (torque-sensor or current
  offset); ``armature`` I_a (kg m^2, or kg): the reflected rotor inertia
  (G^2 J_m); ``coulomb_width`` eps (rad/s, or m/s): the smooth sign's
  width.  URDF has no tag for these three: they live in the extension
  element ``<ne:drive>`` of the namespace :data:`DRIVES_NS`, inside the
  ``<joint>``, which other URDF parsers ignore::

      <robot xmlns:ne="https://newton-euler-ros.github.io/ns/drives/1" ...>
        <joint name="joint1" type="revolute"> ...
          <dynamics damping="0.21" friction="0.8"/>
          <ne:drive armature="0.12" offset="-0.05" coulomb_width="0.02"/>
        </joint>

Coulomb friction near rest.  sign(qd) jumps at qd = 0, where a real joint
sticks with any friction torque between -F_c and F_c.  The smooth sign
tanh(qd / eps) is 0 at rest, 76 % of F_c at |qd| = eps and within 0.01 %
of F_c from |qd| = 5 eps: compensating it adds no torque to a joint at
rest, so velocity noise of a standing arm (well below eps) does not
chatter the feedforward, and its full value from a few eps on.
"""
from dataclasses import dataclass
import math
import xml.etree.ElementTree as ET

import numpy as np

from .errors import RobotFileError

DRIVES_NS = 'https://newton-euler-ros.github.io/ns/drives/1'
DRIVES_PREFIX = 'ne'
DEFAULT_COULOMB_WIDTH = 0.02
FIELDS = ('viscous', 'coulomb', 'offset', 'armature')


@dataclass(frozen=True, eq=False)
class Drives:
    """Per-joint drive parameters, arrays of n (see the module docstring)."""

    viscous: np.ndarray
    coulomb: np.ndarray
    offset: np.ndarray
    armature: np.ndarray
    coulomb_width: np.ndarray

    @classmethod
    def zeros(cls, n, coulomb_width=DEFAULT_COULOMB_WIDTH):
        """Return drives that add nothing."""
        z = np.zeros(n)
        return cls(z, z.copy(), z.copy(), z.copy(),
                   np.full(n, float(coulomb_width)))

    @classmethod
    def from_parameters(cls, p, coulomb_width=DEFAULT_COULOMB_WIDTH):
        """From the 4n drive parameters in the regressor's order."""
        p = np.asarray(p, dtype=np.float64).reshape(-1, 4)
        n = p.shape[0]
        width = np.broadcast_to(np.asarray(coulomb_width, dtype=float),
                                (n,)).copy()
        return cls(p[:, 0].copy(), p[:, 1].copy(), p[:, 2].copy(),
                   p[:, 3].copy(), width)

    @property
    def n(self):
        """Return the number of joints."""
        return len(self.viscous)

    def parameters(self):
        """Return the 4n drive parameters in the regressor's order."""
        return np.stack([self.viscous, self.coulomb, self.offset,
                         self.armature], axis=1).ravel()

    def is_zero(self):
        """Return True when the drives add no torque."""
        return not any(np.any(getattr(self, k)) for k in FIELDS)

    def torques(self, qd, qdd, out=None):
        """Drive torques at (..., n) velocities and accelerations."""
        qd = np.asarray(qd, dtype=np.float64)
        qdd = np.asarray(qdd, dtype=np.float64)
        tau = (self.viscous * qd + self.coulomb * np.tanh(
            qd / self.coulomb_width) + self.offset + self.armature * qdd)
        if out is not None:
            out[...] = tau
            return out
        return tau


def model_drives(model):
    """Return the model's :class:`Drives`, or None when it has none."""
    info = getattr(model, 'info', None) or {}
    return info.get('drives')


def _number(el, attr, where, label, minimum=None):
    text = el.get(attr)
    if text is None:
        return None
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise RobotFileError(f'{label}: {where} {attr}: must be a finite '
                             f'number, got {text[:40]!r}')
    if minimum is not None and value < minimum:
        raise RobotFileError(f'{label}: {where} {attr}: must be >= '
                             f'{minimum:g}, got {value:g}')
    return value


def read_drives(root, joint_names, label='robot_description'):
    """
    Drives of ``joint_names`` from a parsed URDF (an ElementTree root).

    Returns None when no joint of the chain has ``<dynamics>`` or
    ``<ne:drive>``; raises RobotFileError on a bad value (one line naming
    the joint and the attribute).
    """
    joints = {el.get('name'): el for el in root.iter('joint')}
    n = len(joint_names)
    vals = {k: np.zeros(n) for k in FIELDS}
    width = np.full(n, DEFAULT_COULOMB_WIDTH)
    found = False
    for j, name in enumerate(joint_names):
        el = joints.get(name)
        if el is None:
            continue
        dyn = el.find('dynamics')
        if dyn is not None:
            where = f'joint {name!r} <dynamics>'
            for attr, key in (('damping', 'viscous'),
                              ('friction', 'coulomb')):
                v = _number(dyn, attr, where, label, minimum=0.0)
                if v is not None:
                    vals[key][j] = v
                    found = True
        ext = el.find(f'{{{DRIVES_NS}}}drive')
        if ext is not None:
            where = f'joint {name!r} <{DRIVES_PREFIX}:drive>'
            for attr, minimum in (('armature', 0.0), ('offset', None)):
                v = _number(ext, attr, where, label, minimum=minimum)
                if v is not None:
                    vals[attr][j] = v
                    found = True
            v = _number(ext, 'coulomb_width', where, label)
            if v is not None:
                if not v > 0:
                    raise RobotFileError(
                        f'{label}: {where} coulomb_width: must be > 0, got '
                        f'{v:g}')
                width[j] = v
    if not found:
        return None
    return Drives(vals['viscous'], vals['coulomb'], vals['offset'],
                  vals['armature'], width)


def read_drives_text(text, joint_names, label='robot_description'):
    """:func:`read_drives` from URDF text."""
    return read_drives(ET.fromstring(text), joint_names, label)
