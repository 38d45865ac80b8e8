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

- ``torque_constant`` K (N m, or N, per effort unit): for a robot whose
  ``JointState.effort`` is not a torque (UR's driver reports motor current
  in A by default), the joint torque is K times the effort.  Also an
  attribute of ``<ne:drive>``; absent on every joint when the efforts are
  torques (``Drives.torque_constant`` is then None).  Every term above is
  a joint torque, in N m, whatever the effort's unit.

Only the ``<joint>`` elements that are children of ``<robot>`` are read:
a ros2_control description also has ``<joint name=...>`` elements inside
``<ros2_control>`` and ``<transmission>`` blocks, which are not joints of
the kinematic tree.

Coulomb friction near rest.  sign(qd) jumps at qd = 0, where a real joint
sticks with any friction torque between -F_c and F_c.  The smooth sign
tanh(qd / eps) is 0 at rest, 76 % of F_c at |qd| = eps and within 0.01 %
of F_c from |qd| = 5 eps: compensating it adds no torque to a joint at
rest, so velocity noise of a standing arm (well below eps) does not
chatter the feedforward, and its full value from a few eps on.
"""
from dataclasses import dataclass
import math

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
    torque_constant: np.ndarray = None

    @classmethod
    def zeros(cls, n, coulomb_width=DEFAULT_COULOMB_WIDTH,
              torque_constant=None):
        """Return drives that add nothing."""
        z = np.zeros(n)
        return cls(z, z.copy(), z.copy(), z.copy(),
                   np.full(n, float(coulomb_width)),
                   _constants(torque_constant, n))

    @classmethod
    def from_parameters(cls, p, coulomb_width=DEFAULT_COULOMB_WIDTH,
                        torque_constant=None):
        """From the 4n drive parameters in the regressor's order."""
        p = np.asarray(p, dtype=np.float64).reshape(-1, 4)
        n = p.shape[0]
        width = np.broadcast_to(np.asarray(coulomb_width, dtype=float),
                                (n,)).copy()
        return cls(p[:, 0].copy(), p[:, 1].copy(), p[:, 2].copy(),
                   p[:, 3].copy(), width, _constants(torque_constant, n))

    def with_torque_constant(self, torque_constant):
        """Return a copy with these torque constants (None: torques)."""
        return Drives(self.viscous, self.coulomb, self.offset,
                      self.armature, self.coulomb_width,
                      _constants(torque_constant, self.n))

    def effort_to_torque(self, effort):
        """Joint torques of (..., n) efforts: K effort (as is without K)."""
        effort = np.asarray(effort, dtype=np.float64)
        if self.torque_constant is None:
            return effort
        return effort * self.torque_constant

    def torque_to_effort(self, tau):
        """Efforts of (..., n) joint torques: tau / K (as is without K)."""
        tau = np.asarray(tau, dtype=np.float64)
        if self.torque_constant is None:
            return tau
        return tau / self.torque_constant

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


def _constants(k, n):
    if k is None:
        return None
    k = np.broadcast_to(np.asarray(k, dtype=np.float64), (n,)).copy()
    if not np.all(np.isfinite(k)) or not np.all(k > 0):
        raise ValueError(f'torque constants must be finite and > 0, got '
                         f'{k.tolist()}')
    return k


def describe_drives(drives, names):
    """Return lines saying the drive terms read, a joint a line (check)."""
    if drives is None:
        return ['drive terms: none (no <dynamics> or <ne:drive>)']
    k = drives.torque_constant
    lines = ['drive terms (viscous N m s/rad, Coulomb N m, its width rad/s, '
             'armature kg m^2, offset N m'
             + (', torque constant N m per effort unit):' if k is not None
                else '; no torque constants: efforts are torques):')]
    for j, name in enumerate(names):
        lines.append(
            f'  {name}: {drives.viscous[j]:.6g}, {drives.coulomb[j]:.6g}, '
            f'{drives.coulomb_width[j]:.6g}, {drives.armature[j]:.6g}, '
            f'{drives.offset[j]:.6g}' + ('' if k is None else f', {k[j]:.6g}'))
    return lines


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


#: the attributes of <ne:drive>
DRIVE_ATTRIBUTES = ('armature', 'offset', 'coulomb_width', 'torque_constant')


def _one(el, tag, where, label):
    """Return the joint's element ``tag`` or None; refuse it twice."""
    found = el.findall(tag)
    if len(found) > 1:
        shown = tag.replace(f'{{{DRIVES_NS}}}', f'{DRIVES_PREFIX}:')
        raise RobotFileError(f'{label}: {where}: <{shown}> given '
                             f'{len(found)} times (once at most)')
    return found[0] if found else None


def _placed(root, label):
    """Refuse a <ne:drive> that is not a robot-level joint's child."""
    tag = f'{{{DRIVES_NS}}}drive'
    for el in root.iter():
        ns = el.tag[1:].split('}')[0] if str(el.tag).startswith('{') else ''
        if ns != DRIVES_NS and ns.startswith(DRIVES_NS.rsplit('/', 1)[0]):
            raise RobotFileError(
                f'{label}: <{el.tag.split("}")[1]}> of namespace {ns!r}: '
                f'not one this version reads ({DRIVES_NS})')
    own = sum(len(j.findall(tag)) for j in root.findall('joint'))
    if own == sum(1 for _ in root.iter(tag)):
        return
    parents = {child: el for el in root.iter() for child in el}
    for el in root.iter(tag):
        up = parents[el]
        if up.tag == 'joint' and parents.get(up) is root:
            continue
        path = []
        while up is not None:
            name = up.get('name')
            path.append(f'<{up.tag}' + (f' name={name!r}>' if name else '>'))
            up = parents.get(up)
        raise RobotFileError(
            f'{label}: <{DRIVES_PREFIX}:drive> inside '
            f'{" ".join(reversed(path))}: it is read only as a child of '
            f"the <robot> element's own <joint>")


def read_drives(root, joint_names, label='robot_description', prior=False,
                notes=None):
    """
    Drives of ``joint_names`` from a parsed URDF (an ElementTree root).

    Returns None when no joint of the chain has ``<dynamics>`` or
    ``<ne:drive>``; raises RobotFileError on a bad value (one line naming
    the joint and the attribute).  ``prior=True`` (the prior of an
    identification): negative friction is kept, listed in ``notes``.
    """
    joints = {el.get('name'): el for el in root.findall('joint')}
    _placed(root, label)
    n = len(joint_names)
    vals = {k: np.zeros(n) for k in FIELDS}
    width = np.full(n, DEFAULT_COULOMB_WIDTH)
    constant = np.full(n, np.nan)
    found = False
    for j, name in enumerate(joint_names):
        el = joints.get(name)
        if el is None:
            continue
        dyn = _one(el, 'dynamics', f'joint {name!r}', label)
        if dyn is not None:
            where = f'joint {name!r} <dynamics>'
            for attr, key in (('damping', 'viscous'),
                              ('friction', 'coulomb')):
                v = _number(dyn, attr, where, label,
                            minimum=None if prior else 0.0)
                if v is not None and v < 0 and notes is not None:
                    notes.append(f'{where} {attr}: {v:g} < 0')
                if v is not None:
                    vals[key][j] = v
                    found = True
        ext = _one(el, f'{{{DRIVES_NS}}}drive', f'joint {name!r}', label)
        if ext is not None:
            where = f'joint {name!r} <{DRIVES_PREFIX}:drive>'
            unknown = sorted(set(ext.attrib) - set(DRIVE_ATTRIBUTES))
            if unknown:
                raise RobotFileError(
                    f'{label}: {where}: unknown attribute {unknown[0]!r} '
                    f'(it takes {", ".join(DRIVE_ATTRIBUTES)})')
            for attr, minimum in (('armature', 0.0), ('offset', None)):
                v = _number(ext, attr, where, label, minimum=minimum)
                if v is not None:
                    vals[attr][j] = v
                    found = True
            # positive attributes; the width alone does not make a drive
            for attr, into, unit, makes in (
                    ('coulomb_width', width, '', False),
                    ('torque_constant', constant, ' (N m per effort unit)',
                     True)):
                v = _number(ext, attr, where, label)
                if v is not None:
                    if not v > 0:
                        raise RobotFileError(
                            f'{label}: {where} {attr}: must be > 0{unit}, '
                            f'got {v:g}')
                    into[j] = v
                    found = found or makes
    if not found:
        return None
    return Drives(vals['viscous'], vals['coulomb'], vals['offset'],
                  vals['armature'], width,
                  _all_or_none(constant, joint_names, label))


def _all_or_none(constant, joint_names, label):
    given = np.isfinite(constant)
    if not given.any():
        return None
    if not given.all():
        missing = [name for name, k in zip(joint_names, given) if not k]
        raise RobotFileError(
            f'{label}: <{DRIVES_PREFIX}:drive> torque_constant is given for '
            f'some joints but not for {", ".join(map(repr, missing))}: give '
            f'it for every joint of the chain (the efforts of one robot '
            f'share a unit)')
    return constant
