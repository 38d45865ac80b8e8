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
Feedforward torques for one message, free of ROS.

The node converts messages to plain Python/numpy values and calls into
:class:`FeedforwardComputer`, which holds the model, its workspace, the
joint order (``joint_inputs``), the wrench input (``wrenches``), the
reference and, on a whole robot, the joint-state merger
(``whole_robot``): tau = D qdd + C qd + g + J^T F_e for a joint state,
the terms for a service request, the efforts of a planned trajectory.
It is built for a node's parameters, payload included, by
``feedforward_build``.  Everything here is testable without a ROS graph;
every rejection raises ``InputRejected`` with a one-line reason and a
short ``kind`` used for counters.
"""
import dataclasses

import numpy as np

from .core import (coriolis_matrix, DynamicsInputError, gravity_torques,
                   inverse_dynamics, mass_matrix, NewtonEulerError)
from .core.drives import model_drives
from .core.effects import EffectDynamics, RIGID_BODY
from .core.trajectory import trajectory_efforts
from .joint_inputs import InputRejected
from .safety import joint_units, TorqueGuard, velocity_bounds
from .wrenches import WrenchInput

MODES = ('gravity', 'gravity_coriolis', 'full')


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
                                   params['limits.action'],
                                   order.output_joints,
                                   order.to_output_order(np.array(
                                       joint_units(model), dtype=object))),
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

    def request_state(self, names, position, velocity):
        """
        (q, qd) of a service request, model order, or InputRejected.

        An empty position means the latest measured state (its velocities
        too when velocity is empty); with a position given, an empty
        velocity means zeros.
        """
        if len(position) == 0:
            if self.last_q is None:
                raise InputRejected('no_state', 'no position given and no '
                                    'joint state received yet')
            q = self.last_q
        else:
            q = self.order.gather(names, 'position', position)
        if len(velocity) == 0:
            qd = self.last_qd if (len(position) == 0 and self.last_qd
                                  is not None) else np.zeros(self.model.n)
        else:
            qd = self.order.gather(names, 'velocity', velocity)
        return q, qd

    def terms(self, names, position, velocity, acceleration, now):
        """
        D, C, g, tau in output order for a service request.

        Empty position/velocity mean the latest measured state; empty
        acceleration means zeros.
        """
        n = self.model.n
        q, qd = self.request_state(names, position, velocity)
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

    def trajectory(self, names, points, now, include_wrench=True):
        """
        Guarded efforts of a planned trajectory, or InputRejected.

        ``points`` are dicts of ``time_from_start``, ``positions``,
        ``velocities``, ``accelerations``
        (:func:`~newton_euler_ros.core.trajectory.trajectory_efforts`);
        the wrench held at ``now`` acts along it with ``include_wrench``.
        On a whole robot the joints it leaves out are held at the last
        joint state, at rest.  Return (efforts, a row per point in the
        order of ``names``, or None when the guard drops them; whether a
        point exceeded the torque bounds: ``{joint: (largest torque asked,
        bound, unit)}`` of the joints over, empty within them).
        """
        w, frame = (self.wrench.current(now) if include_wrench
                    else (None, 'base'))
        hold = self._hold(names)
        try:
            efforts = trajectory_efforts(
                self.model, names, points, w, frame, 'trajectory: ',
                self.ws, drives=self.drives,
                gravity=not self.robot_compensates_gravity, hold=hold)
        except NewtonEulerError as exc:
            raise InputRejected('malformed', str(exc)) from None
        if self.guard is None:
            return efforts, {}
        out = efforts.copy()
        # the bounds of the trajectory's joints, in its order
        guard = self.guard.sub(names)
        # the joints over, each with the largest torque asked at a point
        peak = (efforts[np.abs(efforts).argmax(axis=0),
                        np.arange(len(names))]
                if efforts.shape[0] else np.zeros(len(names)))
        exceeded = guard.over(peak)
        if not exceeded:
            return out, exceeded
        for k in range(out.shape[0]):
            row, _ = guard.check(efforts[k])
            if row is None:
                return None, exceeded
            out[k] = row
        return out, exceeded

    def _hold(self, names):
        """Return where a whole robot's joints a trajectory leaves out are."""
        if self.merger is None or set(self.model.joint_names) <= set(names):
            return None
        if self.last_q is None:
            raise InputRejected(
                'no_state', f'the trajectory names {len(names)} of the '
                f'{self.model.n} joints, and no joint state has arrived '
                f'yet to hold the others at')
        return self.last_q
