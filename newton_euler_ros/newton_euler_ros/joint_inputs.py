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
Named joint inputs in the model's order, free of ROS.

A JointState or a JointTrajectory names its joints in any order, with
joints of other robots among them; the dynamics take vectors in the
model's joint order:

- :class:`JointOrder` maps named joint vectors (any order, extra joints)
  onto the model's joint order and back to the output order.
- :class:`ReferenceTrajectory` samples desired accelerations from a joint
  trajectory.
- :func:`name_positions` and :func:`other_joints`: the checks of a name
  list that the whole robot's merger (``whole_robot``) shares.

Every rejection of an input message, here and in ``wrenches``,
``whole_robot``, ``feedforward`` and the linearize service, raises
:class:`InputRejected` with a one-line reason and a short ``kind``, one
of :data:`REJECTIONS`: the node's counters (``/diagnostics``) are made
from that list, so a kind cannot be raised without being counted.
"""
import numpy as np

from .core.text import clip


#: why an input message is not used: each a counter in /diagnostics
REJECTIONS = ('missing_joints', 'non_finite', 'malformed', 'unknown_frame',
              'stale', 'no_state', 'implausible', 'oversized', 'bad_stamp',
              'other_joints', 'mimic_mismatch')


class InputRejected(Exception):
    """An input message cannot be used; ``kind`` names the counter."""

    def __init__(self, kind, message):
        if kind not in REJECTIONS:      # a programming error, not input's
            raise ValueError(f'InputRejected: unknown kind {kind!r} (not '
                             f'in joint_inputs.REJECTIONS)')
        super().__init__(message)
        self.kind = kind


def name_positions(names):
    """
    Return {name: index in the message} of a message's joint names.

    A name with control characters or named twice makes the message
    ``malformed``.
    """
    where = {}
    for i, name in enumerate(names):
        if not name.isprintable():
            raise InputRejected('malformed',
                                f'joint name {clip(name, 60)!r} has '
                                f'control characters')
        if name in where:
            raise InputRejected('malformed',
                                f'joint {clip(name, 60)!r} appears '
                                f'twice')
        where[name] = i
    return where


def other_joints(names):
    """Return the rejection of a message naming none of the robot's joints."""
    return InputRejected(
        'other_joints', f"none of the robot's joints (it names "
        f'{clip([clip(x, 60) for x in list(names)[:8]], 300)})')


class JointOrder:
    """
    Map named joint values onto a model's joints, and out again.

    Parameters
    ----------
    model_joints : names in the model's order (the dynamics' order).
    output_joints : names in the order results are published, a
        permutation of ``model_joints``; with ``subset`` some of them
        (the commanded joints), the others following in model order.
    followers : {mimic joint: (leader, ...)}: named in the output, one is
        refused with its leader's name.

    """

    def __init__(self, model_joints, output_joints=None, max_names=0,
                 subset=False, followers=None):
        self.model_joints = tuple(model_joints)
        #: longer name lists are rejected before any per-name work
        self.max_names = max_names or 4 * len(self.model_joints) + 16
        output = tuple(output_joints) if output_joints else self.model_joints
        if len(set(output)) != len(output):
            dup = next(j for j in output if output.count(j) > 1)
            raise ValueError(f'joints: {dup!r} is listed twice')
        mimic = [j for j in output if j in (followers or {})]
        if mimic:
            raise ValueError(f'joints: {mimic[0]!r} is a mimic joint (it '
                             f'follows {followers[mimic[0]][0]!r}): its '
                             f'torque acts through its leader')
        missing = sorted(set(self.model_joints) - set(output))
        extra = sorted(set(output) - set(self.model_joints))
        if extra or (missing and not subset):
            raise ValueError(
                ('joints: must name every joint of the robot exactly once'
                 if not subset else 'joints: must name joints of the robot')
                + (f'; missing {missing}' if missing and not subset else '')
                + (f'; not in the robot: {extra}' if extra else ''))
        #: ~/torque_command carries the first ``command`` joints of the
        #: output: those named (a subset on a whole robot), then the rest
        self.command = len(output)
        output += tuple(j for j in self.model_joints if j not in output)
        self.output_joints = output
        index = {name: i for i, name in enumerate(self.model_joints)}
        #: out[k] = model_vector[self.to_output[k]]
        self.to_output = np.array([index[j] for j in output], dtype=np.intp)
        self._cache_names = None
        self._cache_take = None
        #: the last name list that held none of the model's joints
        self._other_names = None

    @property
    def n(self):
        return len(self.model_joints)

    def _take(self, names):
        """
        Return the indices into a message's arrays that give the model's order.

        A message that names none of the model's joints (another
        publisher's on the same topic, e.g. a gripper driver's) raises
        InputRejected of kind ``other_joints``.
        """
        if names == self._cache_names:
            return self._cache_take
        if names == self._other_names:
            raise other_joints(names)
        where = name_positions(names)
        missing = [j for j in self.model_joints if j not in where]
        if names and len(missing) == len(self.model_joints):
            self._other_names = list(names)
            raise other_joints(names)
        if missing:
            # all of them, and what the message does name
            raise InputRejected(
                'missing_joints', f'missing joints {clip(missing, 600)}; '
                f'the message names {len(names)}: '
                f'{clip([clip(x, 60) for x in names], 600)}')
        take = np.array([where[j] for j in self.model_joints], dtype=np.intp)
        self._cache_names = list(names)
        self._cache_take = take
        return take

    def gather(self, names, field, values, required=True):
        """
        Model-ordered float64 vector of one field (position, ...).

        An empty ``values`` gives None when not ``required``.
        """
        if len(names) > self.max_names or len(values) > self.max_names:
            raise InputRejected(
                'oversized', f'{max(len(names), len(values))} names or '
                f'values, more than the {self.max_names} accepted')
        names = list(names)
        if len(values) == 0 and not required:
            return None
        if len(values) != len(names):
            raise InputRejected(
                'malformed', f'{field} has {len(values)} entries for '
                f'{len(names)} names')
        take = self._take(names)
        x = np.asarray(values, dtype=np.float64)[take]
        if not np.isfinite(x).all():
            k = int(np.argmin(np.isfinite(x)))
            raise InputRejected(
                'non_finite', f'{field} of {self.model_joints[k]!r} is '
                f'{float(x[k])!r}')
        return x

    def to_output_order(self, x):
        return x[self.to_output]

    def matrix_to_output_order(self, M):
        return M[np.ix_(self.to_output, self.to_output)]


class ReferenceTrajectory:
    """
    Desired joint accelerations sampled from a joint trajectory.

    Accelerations are interpolated linearly in time between points; before
    the first point the first is used, after the last the last.  Points
    without accelerations count as zero.
    """

    def __init__(self, order):
        self.order = order
        self.times = None
        self.accelerations = None
        self.start = 0.0

    def set(self, names, start, points, now):  # noqa: A003 (public API name)
        """``points``: list of (time_from_start s, accelerations list)."""
        if not points:
            self.times = None
            return
        times = np.array([p[0] for p in points], dtype=np.float64)
        if not np.isfinite(times).all() or np.any(np.diff(times) < 0.0):
            raise InputRejected('malformed', 'reference trajectory times '
                                'must be finite and non-decreasing')
        acc = np.zeros((len(points), self.order.n))
        for k, (_, values) in enumerate(points):
            if len(values):
                acc[k] = self.order.gather(names, f'point {k} accelerations',
                                           values)
        self.times = times
        self.accelerations = acc
        self.start = now if start == 0.0 else start

    def acceleration(self, t):
        if self.times is None:
            return None
        s = t - self.start
        times, acc = self.times, self.accelerations
        if s <= times[0]:
            return acc[0].copy()
        if s >= times[-1]:
            return acc[-1].copy()
        k = int(np.searchsorted(times, s, side='right'))
        t0, t1 = times[k - 1], times[k]
        w = (s - t0) / (t1 - t0) if t1 > t0 else 1.0
        return (1.0 - w) * acc[k - 1] + w * acc[k]
