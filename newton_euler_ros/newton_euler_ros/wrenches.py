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
Wrenches in, as the dynamics take them, free of ROS.

- :class:`WrenchInput` keeps the latest end-effector wrench of a chain
  with its frame, sign convention and age (``rigid_frames`` lists the
  URDF frames fixed to its base or tip).
- :class:`LinkWrenches` holds, on a whole robot (a URDF tree, no tip
  link), the last wrench of each sensor (told apart by
  ``header.frame_id``), each with its own expiry, acting at the link its
  frame names.
- :func:`wrench_input` picks one of them for a node's ``wrench.*``
  parameters.

Both check their settings and every wrench by the same rules
(:func:`convention_sign`, :func:`checked_wrench`); a rejection raises
:class:`~newton_euler_ros.joint_inputs.InputRejected`.
"""
import math

import numpy as np

from .core.text import clip
from .joint_inputs import InputRejected
from .safety import wrench_bounds

EXERTED_BY_ROBOT = 'exerted_by_robot'
APPLIED_TO_ROBOT = 'applied_to_robot'


def convention_sign(base_frames, end_effector_frames, convention, timeout):
    """
    Check the wrench settings; return the sign the convention applies.

    ``'exerted_by_robot'`` (the library's F_e) keeps a wrench,
    ``'applied_to_robot'`` (what a force-torque sensor reports: the
    wrench the environment applies) negates it.  ValueError names a frame
    listed on both sides, an unknown convention or a bad timeout.
    """
    both = set(base_frames) & set(end_effector_frames)
    if both:
        raise ValueError(f'frame {sorted(both)[0]!r} is listed as both a '
                         f'base and an end-effector frame')
    if convention not in (EXERTED_BY_ROBOT, APPLIED_TO_ROBOT):
        raise ValueError(f"wrench convention must be '{EXERTED_BY_ROBOT}'"
                         f" or '{APPLIED_TO_ROBOT}', got {convention!r}")
    if not (timeout >= 0.0 and math.isfinite(timeout)):
        raise ValueError(f'wrench timeout must be >= 0 s, got {timeout}')
    return 1.0 if convention == EXERTED_BY_ROBOT else -1.0


def checked_wrench(values, max_force, max_moment):
    """
    Return [fx, fy, fz, tx, ty, tz] as float64, or InputRejected.

    ``non_finite`` for a NaN or infinite entry, ``implausible`` for a
    force or moment component beyond the plausible bounds.
    """
    w = np.asarray(values, dtype=np.float64)
    if not np.isfinite(w).all():
        raise InputRejected('non_finite', f'wrench has a non-finite '
                            f'entry: {w.tolist()}')
    # component-wise (a norm of 1e200 would overflow)
    force, moment = np.abs(w[:3]).max(), np.abs(w[3:]).max()
    if force > max_force or moment > max_moment:
        raise InputRejected(
            'implausible', f'wrench with a force of {force:.4g} N or a '
            f'moment of {moment:.4g} N m along an axis is beyond the '
            f'plausible {max_force:.4g} N, {max_moment:.4g} '
            f'N m')
    return w


def wrench_input(params, model, bounds, whole):
    """
    Return the wrench input a node's ``wrench.*`` parameters ask for.

    ``bounds`` are the torque bounds (model order) the plausible wrench
    is derived from; ``whole``: a whole robot's :class:`LinkWrenches`,
    else a chain's :class:`WrenchInput`.
    """
    p = params
    if whole:
        return LinkWrenches(model, p['wrench.base_frames'],
                            p['wrench.end_effector_frames'],
                            p['wrench.link'], p['wrench.convention'],
                            p['wrench.timeout'], wrench_bounds(bounds))
    return WrenchInput(p['wrench.base_frames'],
                       p['wrench.end_effector_frames'],
                       p['wrench.convention'], p['wrench.timeout'],
                       rigid_frames(model), wrench_bounds(bounds))


class WrenchInput:
    """
    The latest end-effector wrench, as the dynamics expect it.

    Parameters
    ----------
    base_frames, end_effector_frames : ``header.frame_id`` values taken as
        base-frame or end-effector-frame axes.
    convention : ``'exerted_by_robot'`` (the library's F_e) or
        ``'applied_to_robot'`` (what a wrist force/torque sensor reports:
        the wrench the environment applies; it is negated).
    timeout : seconds after which a wrench is stale (0 disables).
    rigid_frames : optional ``{frame_id: (kind, T)}`` of frames rigidly
        attached to the base (``kind`` ``'base'``) or to the end effector
        (``'end_effector'``), with T the 4x4 pose of the frame in that one
        (from a URDF).  A wrench in such a frame (moment about its origin)
        is rotated into base or end-effector axes, and an end-effector
        one also moved to the end-effector origin: n_ee = R n + p x R f.
        A frame listed in ``base_frames`` / ``end_effector_frames`` uses
        its transform when it is attached to that same side.

    """

    def __init__(self, base_frames, end_effector_frames,
                 convention=EXERTED_BY_ROBOT, timeout=0.5, rigid_frames=None,
                 bounds=(np.inf, np.inf)):
        sign = convention_sign(base_frames, end_effector_frames, convention,
                               timeout)
        self.frames = dict.fromkeys(base_frames, 'base')
        self.frames.update(dict.fromkeys(end_effector_frames, 'end_effector'))
        self.transforms = {}
        for frame_id, (kind, T) in (rigid_frames or {}).items():
            if self.frames.setdefault(frame_id, kind) != kind:
                continue        # listed for the other side: taken as axes
            T = np.asarray(T, dtype=np.float64)
            if np.array_equal(T, np.eye(4)):
                continue
            self.transforms[frame_id] = (T[:3, :3].copy(), T[:3, 3].copy())
        self.sign = sign
        self.max_force, self.max_moment = bounds
        self.timeout = timeout
        self.wrench = None
        self.frame = 'base'
        self.stamp = None
        self.expired = 0

    def update(self, frame_id, values, stamp, now):
        """Accept a wrench [fx, fy, fz, tx, ty, tz] stamped ``stamp`` (s)."""
        frame = self.frames.get(frame_id)
        if frame is None:
            raise InputRejected(
                'unknown_frame', f'wrench frame_id {clip(frame_id, 80)!r} '
                f'is not one of {clip(sorted(self.frames), 200)}')
        w = checked_wrench(values, self.max_force, self.max_moment)
        if stamp == 0.0:          # unstamped: take it as of now
            stamp = now
        if self.timeout and now - stamp > self.timeout:
            raise InputRejected(
                'stale', f'wrench is {now - stamp:.3f} s old (timeout '
                f'{self.timeout} s)')
        if self.timeout and stamp - now > self.timeout:
            # a clock running ahead would otherwise keep it applied forever
            raise InputRejected(
                'stale', f'wrench is stamped {stamp - now:.3f} s in the '
                f'future (timeout {self.timeout} s)')
        moved = self.transforms.get(frame_id)
        if moved is not None:
            R, p = moved
            f = R @ w[:3]
            n = R @ w[3:]
            if frame == 'end_effector':
                n = n + np.cross(p, f)
            w = np.concatenate([f, n])
        self.wrench = self.sign * w
        self.frame = frame
        self.stamp = stamp

    def current(self, now):
        """
        (wrench or None, frame) at ``now``; reading changes nothing.

        A wrench older than the timeout is not returned (the torques are
        then computed without it); :meth:`expire` drops and counts it.
        """
        if self.wrench is None or self._too_old(now):
            return None, self.frame
        return self.wrench, self.frame

    def expire(self, now):
        """
        Drop the wrench if it is older than the timeout at ``now``.

        Return True when it expired by this call (``expired`` counts each
        such event once), False otherwise.
        """
        if self.wrench is None or not self._too_old(now):
            return False
        self.wrench = None
        self.expired += 1
        return True

    def _too_old(self, now):
        return bool(self.timeout) and now - self.stamp > self.timeout


def rigid_frames(model):
    """
    Frames rigidly attached to a URDF model's base or tip, for wrenches.

    Returns ``{link: (kind, T)}`` for :class:`WrenchInput` (empty for a DH
    model): every link fixed to the end effector (T its pose in the
    end-effector frame) and to the base (T its pose in the base frame).
    """
    report = model.info.get('urdf') or {}
    out = {name: ('base', T)
           for name, T in report.get('base_frames', {}).items()}
    out.update((name, ('end_effector', T))
               for name, T in report.get('tip_frames', {}).items())
    return out


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
        sign = convention_sign(base_frames, end_effector_frames, convention,
                               timeout)
        links = model.link_frames or {}
        if link and link not in links:
            raise ValueError(f'wrench.link: {link!r} is not a link of '
                             f'{model.name}')
        self.links = links
        self.at = link or ('end_effector' if model.tool_body is not None
                           else None)
        self.base_frames = tuple(base_frames)
        self.end_effector_frames = tuple(end_effector_frames)
        self.sign = sign
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
        w = checked_wrench(values, self.max_force, self.max_moment)
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
