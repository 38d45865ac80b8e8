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
A whole robot's joint state from several drivers, free of ROS.

On a dual-arm robot or an arm with its gripper (a URDF tree, no tip
link), ``/joint_states`` is often published by several drivers, each
naming part of the joints (an arm driver, a gripper driver).
:class:`JointStateMerger` keeps the latest value of every joint and turns
a partial JointState into the whole robot's state: a message is computed
when it names at least one of the *trigger* joints (the ones commanded on
``~/torque_command``), with every joint it does not name taken from the
latest message that did, if that arrived within ``hold`` seconds; mimic
followers it names are checked against their leaders.  (The wrenches of
several sensors at links: ``wrenches.LinkWrenches``.)

Every rejection raises :class:`~newton_euler_ros.joint_inputs.InputRejected`
with a one-line reason and the counter's ``kind``.
"""
import numpy as np

from .core.text import clip
from .joint_inputs import InputRejected, name_positions, other_joints

#: name lists remembered (each driver publishes its own, over and over)
CACHED_NAME_LISTS = 8


def followers_of(model):
    """Return {mimic joint: (leader joint, multiplier, offset)} of a model."""
    out = {}
    for b, m in enumerate(model.mimic or ()):
        if m is not None:
            out[model.moving_joints[b]] = (model.moving_joints[m[0]], m[1],
                                           m[2])
    return out


def needed_coordinates(model, trigger):
    """
    Return which coordinates the torques of the ``trigger`` ones depend on.

    A joint's torque depends on the joints above it (they move its
    subtree) and below it (their bodies are what it carries), not on a
    sibling branch: commanding one arm of a mobile manipulator needs its
    torso and its own joints, never the wheels or the other arm.  Bodies
    are mapped to coordinates through their leaders (a mimic follower's
    leader counts where the follower's body does).
    """
    from .core.tree import coordinates, support
    _, coord = coordinates(model.mimic)
    parents = model.parents
    nb = len(parents)
    children = [[] for _ in range(nb)]
    for b, p in enumerate(parents):
        if p >= 0:
            children[p].append(b)
    marked = np.zeros(nb, dtype=bool)
    for b in range(nb):
        if not trigger[coord[b]] or marked[b]:
            continue
        marked[support(parents, b)] = True
        stack = [b]
        while stack:
            c = stack.pop()
            marked[c] = True
            stack.extend(children[c])
    needed = np.zeros(len(trigger), dtype=bool)
    needed[[coord[b] for b in np.flatnonzero(marked)]] = True
    return needed


class _Names:
    """Where a name list's joints go: coordinates, followers, the rest."""

    def __init__(self, names, index, followers):
        where = name_positions(names)
        own = [(i, index[name]) for name, i in where.items() if name in index]
        #: message index and coordinate of each joint of the model named
        self.take = np.array([i for i, _ in own], dtype=np.intp)
        self.into = np.array([k for _, k in own], dtype=np.intp)
        #: (message index, name, leader's coordinate, leader's message
        #: index or -1, multiplier, offset) of each mimic joint named
        self.mimic = []
        for name, (leader, mult, offset) in followers.items():
            if name in where:
                self.mimic.append((where[name], name, index[leader],
                                   where.get(leader, -1), mult, offset))
        self.mimic_take = np.array([m[0] for m in self.mimic],
                                   dtype=np.intp)


class JointStateMerger:
    """
    The whole robot's joint state from JointStates that each name part of it.

    Parameters
    ----------
    model : the robot model; its independent joints (``joint_names``) are
        the state, its mimic joints are accepted and checked.
    trigger : names of the joints whose arrival computes the torques
        (the commanded joints); a message naming none of them only updates
        the held values.
    hold : seconds (node clock) a joint's latest value stands in for it
        in a message that does not name it.
    tolerance : largest |q_f - (multiplier q_leader + offset)| accepted
        for a mimic joint (rad or m); 0 turns the check off.
    max_names : longer name lists are refused at once.
    locked : {joint: position} held whatever the messages say (velocity
        0); the joints neither commanded nor locked are required only if
        the commanded ones' torques depend on them
        (:func:`needed_coordinates`), else they take their latest value
        (0 until one arrives).

    """

    def __init__(self, model, trigger, hold=0.5, tolerance=0.005,
                 max_names=0, locked=None):
        self.names = tuple(model.joint_names)
        n = len(self.names)
        self.index = {name: k for k, name in enumerate(self.names)}
        self.followers = followers_of(model)
        self.hold = float(hold)
        self.tolerance = float(tolerance)
        self.max_names = max_names or 4 * (n + len(self.followers)) + 16
        self.trigger = np.zeros(n, dtype=bool)
        self.trigger[[self.index[name] for name in trigger]] = True
        self.q = np.zeros(n)
        self.qd = np.zeros(n)
        #: latest effort of each joint; NaN where its message had none
        self.effort = np.full(n, np.nan)
        #: whether each joint's latest message had its velocity
        self.rated = np.zeros(n, dtype=bool)
        #: node-clock time each joint was last received (-inf: never)
        self.seen = np.full(n, -np.inf)
        self._cache = {}
        #: the joints the commanded ones' torques depend on: only these
        #: must be received (a mobile base's wheels need not be)
        self.needed = needed_coordinates(model, self.trigger)
        #: joints held at given positions whatever the messages say
        self.locked = np.zeros(n, dtype=bool)
        self.locked_q = np.zeros(n)
        for name, value in (locked or {}).items():
            k = self.index[name]
            self.locked[k], self.locked_q[k] = True, float(value)
        self.needed &= ~self.locked
        self.q[self.locked] = self.locked_q[self.locked]

    def _names(self, names):
        key = tuple(names)
        found = self._cache.get(key)
        if found is None:
            found = _Names(key, self.index, self.followers)
            if len(self._cache) >= CACHED_NAME_LISTS:
                self._cache.pop(next(iter(self._cache)))
            self._cache[key] = found
        return found

    def _values(self, field, values, count, required):
        if len(values) == 0 and not required:
            return None
        if len(values) != count:
            raise InputRejected('malformed', f'{field} has {len(values)} '
                                f'entries for {count} names')
        return np.asarray(values, dtype=np.float64)

    def merge(self, names, position, velocity, effort, now):
        """
        Take one JointState; return (q, qd) to compute with, or None.

        None: the message named no trigger joint (its values are held).
        Raises InputRejected: ``other_joints`` (none of the robot's
        joints), ``malformed``, ``oversized``, ``non_finite``,
        ``mimic_mismatch`` (nothing of the message is kept) or
        ``missing_joints`` (a joint neither in the message nor held; the
        message's values are kept).
        """
        count = len(names)
        if max(count, len(position), len(velocity), len(effort)) > \
                self.max_names:
            raise InputRejected(
                'oversized', f'{max(count, len(position), len(velocity))} '
                f'names or values, more than the {self.max_names} accepted')
        where = self._names(names)
        if not where.take.size and not where.mimic:
            raise other_joints(names)
        q = self._values('position', position, count, True)
        qd = self._values('velocity', velocity, count, False)
        eff = self._values('effort', effort, count, False)
        for field, x in (('position', q), ('velocity', qd)):
            if x is None:
                continue
            bad = ~np.isfinite(x[where.take])
            if bad.any():
                k = int(where.into[np.argmax(bad)])
                raise InputRejected('non_finite', f'{field} of '
                                    f'{self.names[k]!r} is '
                                    f'{float(x[where.take][np.argmax(bad)])!r}')
        if where.mimic:
            self._check_mimic(where, q)
        into = where.into
        self.q[into] = q[where.take]
        self.qd[into] = 0.0 if qd is None else qd[where.take]
        self.rated[into] = qd is not None
        if eff is None:
            self.effort[into] = np.nan
        else:       # a non-finite effort is no effort
            e = eff[where.take]
            self.effort[into] = np.where(np.isfinite(e), e, np.nan)
        self.seen[into] = now
        if self.locked.any():
            self.q[self.locked] = self.locked_q[self.locked]
            self.qd[self.locked] = 0.0
        if not self.trigger[into].any():
            return None
        old = (self.seen < now - self.hold) & self.needed
        if old.any():
            raise self._missing(np.flatnonzero(old), names, now)
        return self.q.copy(), self.qd.copy()

    def efforts(self):
        """Return the latest effort of every joint, or the joints without one."""
        missing = np.isnan(self.effort)
        if missing.any():
            return None, [self.names[k] for k in np.flatnonzero(missing)]
        return self.effort.copy(), []

    def unrated(self):
        """Return the joints whose latest message had no velocity."""
        return [self.names[k] for k in np.flatnonzero(~self.rated)]

    def _check_mimic(self, where, q):
        x = q[where.mimic_take]
        bad = ~np.isfinite(x)
        if bad.any():
            i = int(np.argmax(bad))
            raise InputRejected('non_finite', f'position of '
                                f'{where.mimic[i][1]!r} is {float(x[i])!r}')
        if not self.tolerance:
            return
        for (_, name, k, at, mult, offset), value in zip(where.mimic, x):
            if at >= 0:
                lead = float(q[at])
            elif self.seen[k] > -np.inf:
                lead = float(self.q[k])
            else:
                continue        # its leader not known yet
            expected = mult * lead + offset
            if not abs(value - expected) <= self.tolerance:
                raise InputRejected(
                    'mimic_mismatch',
                    f'mimic joint {name!r} is at {value:.6g} but its leader '
                    f'{self.names[k]!r} at {lead:.6g} puts it at '
                    f'{expected:.6g} (multiplier {mult:g}, offset '
                    f'{offset:g}; joint_states.mimic_tolerance '
                    f'{self.tolerance:g})')

    def _missing(self, old, names, now):
        never = [self.names[k] for k in old if self.seen[k] == -np.inf]
        late = [f'{self.names[k]} ({now - self.seen[k]:.3g} s ago)'
                for k in old if self.seen[k] > -np.inf]
        parts = []
        if never:
            parts.append(f'never received: {clip(never, 400)}')
        if late:
            parts.append(f'older than joint_states.hold ({self.hold:g} s): '
                         f'{clip(late, 400)}')
        return InputRejected(
            'missing_joints', f'missing joints ({"; ".join(parts)}); the '
            f'message names {len(names)}: '
            f'{clip([clip(x, 60) for x in names], 400)}')
