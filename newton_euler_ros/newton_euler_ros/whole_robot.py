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
The inputs of a whole robot (a URDF tree, no tip link), free of ROS.

On a dual-arm robot or an arm with its gripper, ``/joint_states`` is
often published by several drivers, each naming part of the joints (an
arm driver, a gripper driver), and wrenches come from several sensors (a
force-torque sensor at each wrist).

- :class:`JointStateMerger` keeps the latest value of every joint and
  turns a partial JointState into the whole robot's state: a message is
  computed when it names at least one of the *trigger* joints (the ones
  commanded on ``~/torque_command``), with every joint it does not name
  taken from the latest message that did, if that arrived within
  ``hold`` seconds; mimic followers it names are checked against their
  leaders.
- :class:`LinkWrenches` holds the last wrench of each sensor (told apart
  by ``header.frame_id``), each with its own expiry, acting at the link
  its frame names.

Every rejection raises :class:`~newton_euler_ros.feedforward.InputRejected`
with a one-line reason and the counter's ``kind``.
"""
import math

import numpy as np

from .core.text import clip
from .feedforward import APPLIED_TO_ROBOT, EXERTED_BY_ROBOT, InputRejected

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


class _Names:
    """Where a name list's joints go: coordinates, followers, the rest."""

    def __init__(self, names, index, followers):
        where = {}
        for i, name in enumerate(names):
            if not name.isprintable():
                raise InputRejected('malformed', f'joint name '
                                    f'{clip(name, 60)!r} has control '
                                    f'characters')
            if name in where:
                raise InputRejected('malformed', f'joint {clip(name, 60)!r}'
                                    f' appears twice')
            where[name] = i
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

    """

    def __init__(self, model, trigger, hold=0.5, tolerance=0.005,
                 max_names=0):
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
            raise InputRejected(
                'other_joints', f"none of the robot's joints (it names "
                f'{clip([clip(x, 60) for x in list(names)[:8]], 300)})')
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
        if not self.trigger[into].any():
            return None
        old = self.seen < now - self.hold
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


class LinkWrenches:
    """
    The last wrench of each sensor, at the link its frame names.

    A ``WrenchStamped`` whose ``frame_id`` names a link of the model acts
    at that link, in its axes, the moment about its origin (a force-torque
    sensor's own frame).  A frame_id of ``base_frames`` is in base axes,
    one of ``end_effector_frames`` in the axes of the link it acts at;
    both act at ``link``, or the end effector when ``link`` is empty (a
    tree with several tips has none: they are then unknown frames, even
    one that is a link: the lists come first).
    Sensors are told apart by frame_id; each one's last wrench applies
    until it is older than ``timeout`` (0: forever).

    ``current(now)`` returns the wrenches the dynamics take,
    ``({frame: [f; n]}, {frame: 'base' | 'link'})``, or ``(None, 'base')``.
    """

    def __init__(self, model, base_frames, end_effector_frames, link='',
                 convention=EXERTED_BY_ROBOT, timeout=0.5,
                 bounds=(np.inf, np.inf)):
        both = set(base_frames) & set(end_effector_frames)
        if both:
            raise ValueError(f'frame {sorted(both)[0]!r} is listed as both a '
                             f'base and an end-effector frame')
        if convention not in (EXERTED_BY_ROBOT, APPLIED_TO_ROBOT):
            raise ValueError(f"wrench convention must be '{EXERTED_BY_ROBOT}'"
                             f" or '{APPLIED_TO_ROBOT}', got {convention!r}")
        if not (timeout >= 0.0 and math.isfinite(timeout)):
            raise ValueError(f'wrench timeout must be >= 0 s, got {timeout}')
        links = model.link_frames or {}
        if link and link not in links:
            raise ValueError(f'wrench.link: {link!r} is not a link of '
                             f'{model.name}')
        self.links = links
        self.at = link or ('end_effector' if model.tool_body is not None
                           else None)
        self.base_frames = tuple(base_frames)
        self.end_effector_frames = tuple(end_effector_frames)
        self.sign = 1.0 if convention == EXERTED_BY_ROBOT else -1.0
        self.max_force, self.max_moment = bounds
        self.timeout = timeout
        #: frame_id -> (target frame, axes, wrench, stamp)
        self.held = {}
        self.expired = 0
        self.last_expired = []

    @property
    def frames(self):
        """Return what a frame_id may be (for the log): the lists, any link."""
        return ([*self.base_frames, *self.end_effector_frames]
                if self.at is not None else []) + ['<any link>']

    def target(self, frame_id):
        """Return (frame the wrench acts at, axes) of a frame_id."""
        listed = (frame_id in self.base_frames
                  or frame_id in self.end_effector_frames)
        if listed and self.at is not None:
            return self.at, ('base' if frame_id in self.base_frames
                             else 'link')
        if listed:
            raise InputRejected(
                'unknown_frame', f'wrench frame_id {clip(frame_id, 80)!r} '
                f'of wrench.base_frames or end_effector_frames needs '
                f'wrench.link to act at: the robot has several tips')
        if frame_id in self.links:
            return frame_id, 'link'
        raise InputRejected(
            'unknown_frame', f'wrench frame_id {clip(frame_id, 80)!r} is '
            f'not a link of the robot nor one of wrench.base_frames, '
            f'end_effector_frames')

    def update(self, frame_id, values, stamp, now):
        """Accept a sensor's wrench [fx, fy, fz, tx, ty, tz] stamped ``stamp``."""
        at, axes = self.target(frame_id)
        w = np.asarray(values, dtype=np.float64)
        if not np.isfinite(w).all():
            raise InputRejected('non_finite', f'wrench has a non-finite '
                                f'entry: {w.tolist()}')
        force, moment = np.abs(w[:3]).max(), np.abs(w[3:]).max()
        if force > self.max_force or moment > self.max_moment:
            raise InputRejected(
                'implausible', f'wrench with a force of {force:.4g} N or a '
                f'moment of {moment:.4g} N m along an axis is beyond the '
                f'plausible {self.max_force:.4g} N, {self.max_moment:.4g} '
                f'N m')
        if stamp == 0.0:          # unstamped: take it as of now
            stamp = now
        if self.timeout and abs(now - stamp) > self.timeout:
            ahead = stamp > now
            raise InputRejected(
                'stale', f'wrench in {clip(frame_id, 80)!r} is '
                + (f'stamped {stamp - now:.3f} s in the future' if ahead
                   else f'{now - stamp:.3f} s old')
                + f' (timeout {self.timeout} s)')
        for other, (o_at, o_axes, _, o_stamp) in self.held.items():
            if self.timeout and now - o_stamp > self.timeout:
                continue            # expired: no longer applies
            if other != frame_id and o_at == at and o_axes != axes:
                raise InputRejected(
                    'malformed', f'wrench in {clip(frame_id, 80)!r} acts at '
                    f'{at!r} in {axes} axes, where the one in {other!r} '
                    f'acts in {o_axes} axes: one sensor per link')
        self.held[frame_id] = (at, axes, self.sign * w, stamp)

    def current(self, now):
        """({frame: wrench}, {frame: axes}) of the unexpired wrenches."""
        wrenches, axes = {}, {}
        for at, frame, w, stamp in self.held.values():
            if self.timeout and now - stamp > self.timeout:
                continue
            if at in wrenches:          # two sensors on one link: the sum
                wrenches[at] = wrenches[at] + w
            else:
                wrenches[at], axes[at] = w, frame
        if not wrenches:
            return None, 'base'
        return wrenches, axes

    def expire(self, now):
        """Drop the wrenches older than the timeout; True if any was."""
        if not self.timeout:
            return False
        old = [k for k, (_, _, _, stamp) in self.held.items()
               if now - stamp > self.timeout]
        for k in old:
            del self.held[k]
        self.expired += len(old)
        self.last_expired = old
        return bool(old)
