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
Feedforward torque computation behind the ROS node, free of ROS.

The node converts messages to plain Python/numpy values and calls into
this module; everything here is testable without a ROS graph:

- :class:`JointOrder` maps named joint vectors (any order, extra joints)
  onto the model's joint order and back to the output order.
- :class:`WrenchInput` keeps the latest end-effector wrench with its frame,
  sign convention and age.
- :class:`ReferenceTrajectory` samples desired accelerations from a joint
  trajectory.
- :class:`FeedforwardComputer` ties them to the dynamics.

Every rejection raises :class:`InputRejected` with a one-line reason and a
short ``kind`` used for counters.
"""
import dataclasses
import math

import numpy as np

from .core import (coriolis_matrix, DynamicsInputError, gravity_torques,
                   inverse_dynamics, mass_matrix)
from .core.drives import model_drives
from .core.effects import EffectDynamics, RIGID_BODY
from .core.inertia import format_moments, inertia_matrix, principal_moments
from .core.model import with_payload
from .core.text import clip
from .safety import TorqueGuard, velocity_bounds

EXERTED_BY_ROBOT = 'exerted_by_robot'
APPLIED_TO_ROBOT = 'applied_to_robot'


class InputRejected(Exception):
    """An input message cannot be used; ``kind`` names the counter."""

    def __init__(self, kind, message):
        super().__init__(message)
        self.kind = kind


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
            raise self._other_joints(names)
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
        missing = [j for j in self.model_joints if j not in where]
        if names and len(missing) == len(self.model_joints):
            self._other_names = list(names)
            raise self._other_joints(names)
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

    def _other_joints(self, names):
        return InputRejected(
            'other_joints', f"none of the robot's joints (it names "
            f'{clip([clip(x, 60) for x in names[:8]], 300)})')

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
        both = set(base_frames) & set(end_effector_frames)
        if both:
            raise ValueError(f'frame {sorted(both)[0]!r} is listed as both a '
                             f'base and an end-effector frame')
        if convention not in (EXERTED_BY_ROBOT, APPLIED_TO_ROBOT):
            raise ValueError(f"wrench convention must be '{EXERTED_BY_ROBOT}'"
                             f" or '{APPLIED_TO_ROBOT}', got {convention!r}")
        if not (timeout >= 0.0 and math.isfinite(timeout)):
            raise ValueError(f'wrench timeout must be >= 0 s, got {timeout}')
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
        self.sign = 1.0 if convention == EXERTED_BY_ROBOT else -1.0
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
        w = np.asarray(values, dtype=np.float64)
        if not np.isfinite(w).all():
            raise InputRejected('non_finite', f'wrench has a non-finite '
                                f'entry: {w.tolist()}')
        # component-wise (a norm of 1e200 would overflow)
        force, moment = np.abs(w[:3]).max(), np.abs(w[3:]).max()
        if force > self.max_force or moment > self.max_moment:
            raise InputRejected(
                'implausible', f'wrench with a force of {force:.4g} N or a '
                f'moment of {moment:.4g} N m along an axis is beyond the '
                f'plausible {self.max_force:.4g} N, {self.max_moment:.4g} '
                f'N m')
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


MODES = ('gravity', 'gravity_coriolis', 'full')


def check_payload(mass, com, inertia6):
    """
    Validate payload values; return (mass, com, 3x3 inertia) or ValueError.

    ``inertia6`` is [Ixx, Iyy, Izz, Ixy, Iyz, Ixz] about the payload's
    centre of mass ``com`` (end-effector frame).
    """
    mass = float(mass)
    com = np.asarray(com, dtype=np.float64).reshape(-1)
    values = np.asarray(inertia6, dtype=np.float64).reshape(-1)
    if not (mass >= 0.0 and math.isfinite(mass)):
        raise ValueError(f'payload.mass: must be >= 0 and finite, got {mass}')
    if com.shape != (3,) or not np.isfinite(com).all():
        raise ValueError(f'payload.com: must be 3 finite numbers, got '
                         f'{com.tolist()}')
    if values.shape != (6,) or not np.isfinite(values).all():
        raise ValueError(f'payload.inertia: must be 6 finite numbers, got '
                         f'{values.tolist()}')
    inertia = inertia_matrix(*values)
    eig, valid = principal_moments(inertia)
    if not valid:
        raise ValueError(f'payload.inertia: not positive semi-definite '
                         f'(principal moments {format_moments(eig)})')
    return mass, com, inertia


def payload_model(model, mass, com, inertia6, link=''):
    """
    Return the model with a payload on the end effector, or ValueError.

    Merged into the last link (or the body carrying ``link``, a link of a
    URDF model) by :func:`~newton_euler_ros.core.model.with_payload`, the
    scenes' code; no payload (all zeros) returns ``model`` itself.
    """
    mass, com, inertia = check_payload(mass, com, inertia6)
    if mass == 0.0 and not inertia.any():
        return model
    return with_payload(model, mass, com, inertia, link or None)


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


class FeedforwardComputer:
    """
    tau = D qdd + C qd + g + J^T F_e for named joint states.

    Holds the model, a workspace, the joint order, the wrench and the
    reference, so that a node only converts messages.
    """

    def __init__(self, model, order, wrench_input, reference=None,
                 scene=None, mode=None, *, guard=None, bound_sources=None,
                 velocity_bounds=None, max_future=1.0, max_age=0.0,
                 bare_model=None, bare_scene=None,
                 robot_compensates_gravity=False):
        self.mode = mode or ('full' if reference is not None
                             else 'gravity_coriolis')
        if self.mode not in MODES:
            raise ValueError(f'mode must be one of {", ".join(MODES)}, got '
                             f'{self.mode!r}')
        self.scene = scene
        if model is None:
            model = scene.model
        # the live torques: exactly the scene's effects, or every
        # rigid-body term and the wrench without a scene; without gravity
        # when the robot adds it itself
        effects = scene.effects if scene is not None else RIGID_BODY
        #: g(q) in the world (reported by the service's gravity field)
        self.has_gravity = effects.gravity
        #: the robot adds g(q) itself: no torque published holds it
        self.robot_compensates_gravity = bool(robot_compensates_gravity)
        if self.robot_compensates_gravity:
            effects = dataclasses.replace(effects, gravity=False)
        self.dyn = (EffectDynamics(model, effects, scene.viscous,
                                   scene.coulomb, scene.armature)
                    if scene is not None else EffectDynamics(model, effects))
        self.model = self.dyn.model
        self.order = order
        self.wrench = wrench_input
        self.reference = reference
        self.ws = self.dyn.ws
        self.tau = np.empty(self.model.n)
        self.zeros = np.zeros(self.model.n)
        self.last_q = None
        self.last_qd = None
        self.output_names = list(order.output_joints)
        #: torque bounds and what to do above them (None: unguarded)
        self.guard = guard
        self.bound_sources = bound_sources
        #: speeds above these are implausible (model order; None: off)
        self.velocity_bounds = velocity_bounds
        #: joint-state stamp policy (seconds): ahead of now, and age (0: off)
        self.max_future = max_future
        self.max_age = max_age
        self.bare_model = model if bare_model is None else bare_model
        self.bare_scene = scene if bare_scene is None else bare_scene

    @classmethod
    def from_parameters(cls, params, model, order, wrench_input, bounds,
                        bound_sources, reference=None, scene=None, mode=None,
                        bare_model=None, bare_scene=None):
        """
        Build a warm computer from a node's parameters, in one call.

        ``params`` maps parameter names to values (``limits.action``,
        ``limits.velocity_factor``, ``limits.max_velocity``,
        ``joint_states.max_future``, ``joint_states.max_age``,
        ``drives.compensate`` to add the model's drive terms and
        ``robot_compensates_gravity`` to leave g(q) out); ``bounds``
        and ``bound_sources`` are the torque bounds in model order and
        where each comes from (``safety.effort_bounds``).  The kernels are
        compiled or loaded before it returns (:meth:`warm_up`).
        """
        ff = cls(model, order, wrench_input, reference, scene, mode,
                 guard=TorqueGuard(order.to_output_order(bounds),
                                   params['limits.action']),
                 bound_sources=[bound_sources[k] for k in order.to_output],
                 velocity_bounds=velocity_bounds(
                     model, params['limits.velocity_factor'],
                     params['limits.max_velocity']),
                 max_future=params['joint_states.max_future'],
                 max_age=params['joint_states.max_age'],
                 bare_model=bare_model, bare_scene=bare_scene,
                 robot_compensates_gravity=params.get(
                     'robot_compensates_gravity', False))
        if params.get('drives.compensate'):
            ff.drives = model_drives(model if bare_model is None
                                     else bare_model)
        ff.warm_up()
        return ff

    #: ``core.drives.Drives`` to add (friction, offset, rotor inertia),
    #: or None; set by :meth:`from_parameters` with ``drives.compensate``
    drives = None
    #: a whole robot's ``whole_robot.JointStateMerger`` (partial joint
    #: states from several drivers), or None: the node sets it
    merger = None

    def _torques(self, q, qd, qdd, w, frame, out=None):
        """Inverse dynamics with the scene's effects, or all of them."""
        try:
            tau = self.dyn.torques(q, qd, qdd, w, frame, out=out)
        except DynamicsInputError as exc:   # finite input that overflows
            raise InputRejected('non_finite', str(exc)) from None
        if self.drives is not None:
            tau += self.drives.torques(qd, self.zeros if qdd is None
                                       else qdd)
        return tau

    def warm_up(self):
        """
        Run every code path once so the first message is not slow.

        The compiled kernels load from numba's cache, or compile once.
        """
        z = np.zeros(self.model.n)
        for frame in ('base', 'end_effector'):
            inverse_dynamics(self.model, z, z, z, np.zeros(6), frame,
                             ws=self.ws)
        if not isinstance(self.wrench, WrenchInput):    # at links
            link = next(iter(self.model.link_frames))
            inverse_dynamics(self.model, z, z, z, {link: np.zeros(6)},
                             'link', ws=self.ws)
        inverse_dynamics(self.model, z, z, z, ws=self.ws)
        mass_matrix(self.model, z, ws=self.ws)
        coriolis_matrix(self.model, z, z, ws=self.ws)
        gravity_torques(self.model, z, ws=self.ws)
        self._torques(z, z, z, None, 'base')

    def check_stamp(self, stamp, now):
        """Reject negative, far-future and (optionally) stale stamps."""
        if stamp == 0.0:
            return now          # unknown: taken as now
        if stamp < 0.0:
            raise InputRejected('bad_stamp', f'stamp {stamp:.3f} s is '
                                f'negative')
        if stamp - now > self.max_future:
            raise InputRejected('bad_stamp', f'stamped {stamp - now:.3f} s '
                                f'in the future (max {self.max_future} s)')
        if self.max_age and now - stamp > self.max_age:
            raise InputRejected('stale', f'{now - stamp:.3f} s old (max '
                                f'{self.max_age} s)')
        return stamp

    def torques(self, names, position, velocity, stamp, now):
        """Output-ordered torques for one joint state, or InputRejected."""
        stamp = self.check_stamp(stamp, now)
        q = self.order.gather(names, 'position', position)
        qd = self.order.gather(names, 'velocity', velocity, required=False)
        return self._state_torques(q, qd, stamp, now)

    def state_torques(self, q, qd, stamp, now):
        """Output-ordered torques at (q, qd), model order (a whole robot)."""
        return self._state_torques(q, qd, self.check_stamp(stamp, now), now)

    def _state_torques(self, q, qd, stamp, now):
        if qd is None:
            qd = np.zeros(self.model.n)
        elif self.velocity_bounds is not None:
            over = np.abs(qd) > self.velocity_bounds
            if over.any():
                k = int(np.argmax(over))
                raise InputRejected(
                    'implausible', f'velocity of '
                    f'{self.model.joint_names[k]!r} is {qd[k]:.4g}, beyond '
                    f'the plausible {self.velocity_bounds[k]:.4g}')
        qdd = (self.reference.acceleration(stamp)
               if self.mode == 'full' and self.reference is not None
               else None)
        w, frame = self.wrench.current(now)
        # gravity mode: the state's velocity takes no part in the torque
        qd_used = qd if self.mode != 'gravity' else self.zeros
        tau = self._torques(q, qd_used, qdd, w, frame, out=self.tau)
        if not np.isfinite(tau).all():   # finite input; guard the output
            raise InputRejected('non_finite', 'dynamics produced a '
                                'non-finite torque')
        self.last_q, self.last_qd = q, qd   # only usable states count
        return self.order.to_output_order(tau)

    def terms(self, names, position, velocity, acceleration, now):
        """
        D, C, g, tau in output order for a service request.

        Empty position/velocity mean the latest measured state; empty
        acceleration means zeros.
        """
        n = self.model.n
        if len(position) == 0:
            if self.last_q is None:
                raise InputRejected('no_state', 'no position given and no '
                                    'joint state received yet')
            q = self.last_q
        else:
            q = self.order.gather(names, 'position', position)
        if len(velocity) == 0:
            qd = self.last_qd if (len(position) == 0 and self.last_qd
                                  is not None) else np.zeros(n)
        else:
            qd = self.order.gather(names, 'velocity', velocity)
        qdd = (np.zeros(n) if len(acceleration) == 0 else
               self.order.gather(names, 'acceleration', acceleration))
        w, frame = self.wrench.current(now)
        D = self.dyn.mass_matrix(q)
        C = coriolis_matrix(self.model, q, qd, ws=self.ws)
        g = gravity_torques(self.model, q, ws=self.ws)
        # the terms the scene has (g is reported even when the robot
        # adds it itself; tau then leaves it out)
        if not self.dyn.effects.velocity_products:
            C[:] = 0.0
        if not self.has_gravity:
            g[:] = 0.0
        tau = self._torques(q, qd, qdd, w, frame)
        o = self.order
        out = (o.matrix_to_output_order(D), o.matrix_to_output_order(C),
               o.to_output_order(g), o.to_output_order(tau))
        if not all(np.isfinite(x).all() for x in out):
            raise InputRejected('non_finite', 'dynamics produced a '
                                'non-finite value')
        return out
