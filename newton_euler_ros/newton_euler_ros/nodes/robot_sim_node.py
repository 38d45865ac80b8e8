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
robot_sim_node: a scene's robot simulated in (scaled) real time.

The plant of the closed-loop demo.  Every timer tick advances the scene
by one control period (1 / rate of simulated time) in sub-steps of the
scene's integrator step, holding the last torque command (zero-order
hold), then publishes the state.  Simulated time t maps onto the
wall-clock stamp ``start + t``; ``~/start`` (latched) carries ``start``
so that controllers can align their reference.  Once a publisher on
``~/commands`` or ``~/joint_trajectory`` is matched
(``wait_for_controller``) and joint_states has ``wait_for_subscribers``
matched subscribers (tracking_controller_node subscribes only once its
own peers are matched: then every node has discovered its peers), and
GRACE seconds later, ``start`` is announced LEAD seconds ahead, so
that the controller and the inverse-dynamics node have the reference
(and the wrench) before t = 0; and t = 0 is held until the first
command arrives (at most FIRST_COMMAND seconds: the
first message over a fresh connection is slow), so the robot does not
start with a period at zero torque.  Stamps then run that much behind the
wall clock.  The simulation stops advancing after the scene's duration,
still publishing.  Parameters: ``robot_sim_parameters.yaml``.  On exit
the node logs how many commands it received (``commands received: N``).

A stand-in for joint_trajectory_controller with an effort command
interface: a ``JointTrajectory`` on ``~/joint_trajectory`` (stamped on
this node's timeline, ``start + t``; zero stamp: now) takes over from
``~/commands`` once it starts, commanding kp (q_d - q) + kd (qd_d - qd)
+ effort_d with the scene's gains at every control period.  The plant's
payload (``payload.mass``, ``payload.com``, ``payload.inertia``) can be
changed at run time: picking up an object, at once or at the simulated
time ``payload.at``.

Subscribes
    ~/commands (std_msgs/Float64MultiArray: n torques, the model's order),
    ~/joint_trajectory (trajectory_msgs/JointTrajectory), wrench
    (geometry_msgs/WrenchStamped, when the scene's wrench comes from the
    topic)
Publishes
    joint_states (sensor_msgs/JointState, effort = applied torque; a
    tree's mimic joints after the others, following their leaders),
    wrench (geometry_msgs/WrenchStamped, when the scene has a wrench),
    ~/start (std_msgs/Header, transient local)
"""
import dataclasses
import math
import sys
import time

from geometry_msgs.msg import WrenchStamped
import numpy as np
from rcl_interfaces.msg import SetParametersResult
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.time import Time
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray, Header
from trajectory_msgs.msg import JointTrajectory

from .common import (check_parameters, ConfigurationError,
                     declare_parameters, qos_profile, run_node, seconds,
                     SharedGraphNode)
from ..core import NewtonEulerError
from ..core.trajectory import TrajectoryFollower
from ..feedforward_build import PAYLOAD, payload_model
from ..parameters import load_specs
from ..safety import (effort_bounds, joint_units, over_text,
                      OverLimitLog, TorqueGuard)
from ..sim.scene import load_scene
from ..sim.simulate import integrator_step, SceneDynamics

FRAME_IDS = {'base': 'base_link', 'end_effector': 'tool0'}
FRAME_OF = {'base_link': 'base', 'base': 'base', 'tool0': 'end_effector',
            'end_effector': 'end_effector', 'ee_link': 'end_effector'}
GRACE = 1.0     # seconds between seeing a controller and starting
LEAD = 0.5      # seconds between announcing the start time and t = 0
FIRST_COMMAND = 5.0     # seconds t = 0 is held for the first command
FUTURE = 1.0    # seconds: a live wrench stamped further ahead is dropped


def advance(dyn, q, qd, tau, t, period, dt, method, wrench_at=None):
    """
    Advance (q, qd) by ``period`` of simulated time from ``t``.

    Sub-steps of at most ``dt`` with the scene's integrator, holding
    ``tau`` (zero-order hold), as :func:`..sim.run.simulate` does;
    ``wrench_at(t) -> (wrench, frame)`` as for ``integrator_step``.
    Return the new (q, qd).
    """
    steps = max(1, int(math.ceil(period / dt - 1e-9)))
    h = period / steps
    for k in range(steps):
        q, qd = integrator_step(dyn, method, q, qd, tau, t + k * h, h,
                                wrench_at)
    return q, qd


def publish_wrench(pub, msg, stamp, w):
    """Publish the WrenchStamped ``msg`` stamped ``stamp``, holding ``w``."""
    msg.header.stamp = stamp
    f, n = msg.wrench.force, msg.wrench.torque
    f.x, f.y, f.z, n.x, n.y, n.z = (float(x) for x in w)
    pub.publish(msg)


def declare_scene_parameters(node, name):
    """
    Declare the parameters of node ``name`` on ``node``; load its scene.

    Sets ``node.specs`` and ``node.scene`` and returns the parameters'
    values; a scene that does not load is a ConfigurationError naming
    ``scene`` (robot_sim_node and tracking_controller_node).
    """
    node.specs = load_specs(name)
    p = declare_parameters(node, node.specs)
    try:
        node.scene = load_scene(p['scene'])
    except NewtonEulerError as exc:
        raise ConfigurationError(f'scene: {exc}') from None
    return p


class RobotSimNode(SharedGraphNode):
    """Simulate a scene; torques in on ~/commands, joint states out."""

    def __init__(self, **kwargs):
        super().__init__('robot_sim_node', **kwargs)
        p = declare_scene_parameters(self, 'robot_sim_node')
        self.wait = p['wait_for_controller']
        self.subscribers = p['wait_for_subscribers']
        rtf = p['real_time_factor']
        scene = self.scene
        self.payload = tuple(p[k] for k in PAYLOAD)
        try:
            self.dyn = self._plant(self.payload)
        except ValueError as exc:
            raise ConfigurationError(str(exc)) from None
        self.pending = None     # (time, dynamics, payload) from payload.at
        self.follower = TrajectoryFollower(scene.model)
        self.commands = 0            # commands received on ~/commands
        self.over_limit = 0          # commands beyond the torque bounds
        # the same torque guard as inverse_dynamics_node: the robot's
        # effort limits, else bounds derived from it
        self.guard = TorqueGuard(effort_bounds(scene.model)[0],
                                 p['limits.action'], scene.model.joint_names,
                                 joint_units(scene.model))
        self.over_log = OverLimitLog()   # said once per change of joints
        n = scene.model.n
        self.q = scene.q0.astype(float).copy()
        self.qd = scene.qd0.astype(float).copy()
        self.tau = np.zeros(n)       # held command; no torque until one
        self.applied = np.zeros(n)   # torque of the step just taken
        self.period = 1.0 / scene.rate
        self.ticks = 0
        self.t = 0.0                 # simulated time of the state
        self.start_ns = None
        self.started = False
        self.commanded = False
        self.first_state_ns = None
        self.ready_since = None
        self.dropped = 0
        self._last_warn = -1e300
        # the wrench the plant feels: the scene's own, or the latest one
        # from the topic (zero until one arrives; kept across payloads)
        self.live = scene.effects.wrench and scene.wrench.kind == 'topic'
        self.live_wrench = (np.zeros(6), scene.wrench.frame
                            if scene.effects.wrench else 'base')
        # compile or load the kernels before the clock starts
        advance(self.dyn, self.q, self.qd, self.tau, 0.0, scene.step,
                scene.step, scene.integrator)

        # deep history: a slow reader (a Python recorder) loses nothing
        qos = qos_profile(100, 'reliable')
        self.state_pub = self.create_publisher(JointState, 'joint_states',
                                               qos)
        # a scheduled wrench is published; a live one is read from the topic
        self.wrench_pub = (self.create_publisher(WrenchStamped, 'wrench',
                                                 qos)
                           if scene.effects.wrench and not self.live
                           else None)
        if self.live:
            self.create_subscription(WrenchStamped, 'wrench',
                                     self._on_wrench, qos)
        latched = QoSProfile(depth=1,
                             reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.start_pub = self.create_publisher(Header, '~/start', latched)
        self.cmd_sub = self.create_subscription(
            Float64MultiArray, '~/commands', self._on_command, qos)
        self.traj_sub = self.create_subscription(
            JointTrajectory, '~/joint_trajectory', self._on_trajectory, 10)
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self._state = JointState()
        self._state.name = list(scene.model.joint_names)
        # a tree's mimic joints are published too, as a driver does:
        # multiplier x leader + offset, no effort of their own
        model = scene.model
        follow = [(name, model.independent.index(m[0]), m[1], m[2])
                  for name, m in zip(model.moving_joints, model.mimic or ())
                  if m is not None]
        self._state.name += [f[0] for f in follow]
        self._lead = np.array([f[1] for f in follow], dtype=np.intp)
        self._mult = np.array([f[2] for f in follow])
        self._offset = np.array([f[3] for f in follow])
        self._wrench = WrenchStamped()
        if scene.wrench is not None:
            self._wrench.header.frame_id = FRAME_IDS[scene.wrench.frame]
        self.create_tick_timer(self.period / rtf, self._tick)
        self.get_logger().info(
            f'{scene.name}: {scene.model.name}, {n} joints, effects '
            f'{scene.effects.names()}, {scene.integrator} step '
            f'{scene.step} s, {scene.rate} Hz, duration {scene.duration} s, '
            f'real-time factor {rtf}'
            + (', waiting for a controller on ~/commands' if self.wait
               else ''))

    def _on_command(self, msg):
        data = np.asarray(msg.data, dtype=float)
        if data.shape != self.tau.shape or not np.isfinite(data).all():
            self.dropped += 1
            now = time.monotonic()
            if now - self._last_warn >= 2.0:
                self._last_warn = now
                self.get_logger().warning(
                    f'dropped command: expected {self.tau.size} finite '
                    f'torques, got {data.size} values ({self.dropped} '
                    f'dropped so far); holding the previous command')
            return
        self.commands += 1
        data = self._guarded(data)
        if data is None:
            return
        self.tau = data
        self.commanded = True

    def _ready(self):
        if not self.wait and not self.subscribers:
            return True
        # matched publishers (this node's readers know them), not just
        # discovered ones
        controllers = (self.cmd_sub.get_publisher_count()
                       + self.traj_sub.get_publisher_count())
        if ((self.wait and controllers < 1)
                or self.state_pub.get_subscription_count()
                < self.subscribers):
            self.ready_since = None
            return False
        now = time.monotonic()
        if self.ready_since is None:
            self.ready_since = now
        return now - self.ready_since >= GRACE

    def _tick(self):
        now = self.get_clock().now().nanoseconds
        if self.start_ns is None:
            if not self._ready():
                return
            self.start_ns = now + int(LEAD * 1e9)
            start = Header(frame_id='sim_start')
            start.stamp = Time(nanoseconds=self.start_ns).to_msg()
            self.start_pub.publish(start)
            self.get_logger().info(f'simulation starts in {LEAD} s')
        if now < self.start_ns:
            self._publish_wrench(Time(nanoseconds=now).to_msg())
            self.started = False
            return
        if not self.started:
            self.started = True
            self.first_state_ns = now
            self.get_logger().info(
                'simulation started (t = 0); joint_states has '
                f'{self.state_pub.get_subscription_count()} '
                'subscribers')
        elif (self.wait and not self.commanded
              and now - self.first_state_ns < FIRST_COMMAND * 1e9):
            return      # hold t = 0 until the first command answers it
        else:
            if self.ticks == 0 and self.wait and not self.commanded:
                self.get_logger().warning(
                    f'no command within {FIRST_COMMAND:g} s of t = 0: the '
                    'simulation starts without one (last torques held)')
            self.ticks += 1
            t_next = self.ticks * self.period
            if t_next <= self.scene.duration + 1e-9:
                self._take_pending_payload()
                tau = self._trajectory_command()
                self.q, self.qd = advance(self.dyn, self.q, self.qd, tau,
                                          self.t, self.period,
                                          self.scene.step,
                                          self.scene.integrator,
                                          self._wrench_at)
                self.t = t_next
                self.applied = tau
        stamp = Time(nanoseconds=self.start_ns
                     + int(round(self.ticks * self.period * 1e9))).to_msg()
        self._publish_wrench(stamp)     # first: the torques need it
        msg = self._state
        msg.header.stamp = stamp
        if self._lead.size:
            lead = self._lead
            msg.position = np.concatenate([
                self.q, self._mult * self.q[lead] + self._offset]).tolist()
            msg.velocity = np.concatenate([
                self.qd, self._mult * self.qd[lead]]).tolist()
            msg.effort = np.concatenate([
                self.applied, np.zeros(lead.size)]).tolist()
        else:
            msg.position = self.q.tolist()
            msg.velocity = self.qd.tolist()
            msg.effort = self.applied.tolist()
        self.state_pub.publish(msg)

    def _guarded(self, tau):
        """Apply the torque guard to a command (None: keep the last one)."""
        out, exceeded = self.guard.check(tau)
        if exceeded:
            self.over_limit += 1
            over = self.guard.over(tau)
            if self.over_log.news(over):
                self.get_logger().warning(
                    f'command above the torque bound ({self.guard.action}): '
                    f'{over_text(over)} ({self.over_limit} over so far; '
                    f'said again when other joints go over)')
        return out

    def _plant(self, payload):
        """Scene dynamics with a payload on the end effector (or a link)."""
        model = payload_model(self.scene.model, *payload)
        return SceneDynamics(dataclasses.replace(self.scene, model=model))

    def _on_set_parameters(self, params):
        values, errors = check_parameters(params, self.specs)
        if errors:
            return SetParametersResult(successful=False, reason=errors)
        if not any(k in values for k in PAYLOAD):
            return SetParametersResult(successful=True)
        payload = tuple(values.get(k, old)
                        for k, old in zip(PAYLOAD, self.payload))
        try:
            dyn = self._plant(payload)
        except (ValueError, TypeError) as exc:
            return SetParametersResult(successful=False, reason=str(exc))
        at = values.get('payload.at', self.get_parameter('payload.at').value)
        self.pending = (at, dyn, payload)
        if at <= self.t + 1e-9:
            self._take_pending_payload()
        else:
            self.get_logger().info(f'plant payload {payload[0]} kg from '
                                   f't = {at:.3f} s')
        return SetParametersResult(successful=True)

    def _take_pending_payload(self):
        """Put a payload change on the plant once its time has come."""
        if self.pending is None or self.pending[0] > self.t + 1e-9:
            return
        _, self.dyn, self.payload = self.pending
        self.pending = None
        self.get_logger().info(f'plant payload now {self.payload[0]} kg at '
                               f'{list(self.payload[1])} m, t = '
                               f'{self.t:.3f} s')

    def _on_trajectory(self, msg):
        stamp = seconds(msg.header.stamp)
        if stamp == 0.0:
            stamp = self.get_clock().now().nanoseconds * 1e-9
        try:
            points = [{'time_from_start': seconds(p.time_from_start),
                       'positions': p.positions, 'velocities': p.velocities,
                       'effort': p.effort} for p in msg.points]
            self.follower.set(msg.joint_names, stamp, points)
            self.commanded = True
        except NewtonEulerError as exc:
            self.dropped += 1
            self.get_logger().warning(f'dropped trajectory: {exc}'[:400],
                                      throttle_duration_sec=2.0)

    def _trajectory_command(self):
        """JTC stand-in: PD on the active trajectory plus its effort."""
        if self.start_ns is None:
            return self.tau
        t = (self.start_ns * 1e-9) + self.t
        desired = self.follower.sample(t)
        if desired is None:
            return self.tau
        q_d, qd_d, eff = desired
        sc = self.scene
        tau = self._guarded(sc.kp * (q_d - self.q) + sc.kd * (qd_d - self.qd)
                            + eff)
        return self.tau if tau is None else tau

    def _on_wrench(self, msg):
        """
        Apply a live wrench (frame_id base_link/base or tool0/...).

        It holds until the next one; one stamped more than FUTURE seconds
        ahead of this node's clock is dropped.
        """
        frame = FRAME_OF.get(msg.header.frame_id)
        f, n = msg.wrench.force, msg.wrench.torque
        w = np.array([f.x, f.y, f.z, n.x, n.y, n.z])
        ahead = (seconds(msg.header.stamp)
                 - self.get_clock().now().nanoseconds * 1e-9)
        if frame is None or not np.isfinite(w).all() or ahead > FUTURE:
            # a clock running ahead is as wrong as a bad frame (as for
            # inverse_dynamics_node); unstamped (0) wrenches are taken
            self.dropped += 1
            self.get_logger().warning(
                f'dropped wrench in frame {msg.header.frame_id!r} '
                f'(frames: {sorted(FRAME_OF)}), non-finite or stamped more '
                f'than {FUTURE} s ahead ({ahead:.3f} s): {w.tolist()}',
                throttle_duration_sec=2.0)
            return
        self.live_wrench = (w, frame)

    def _wrench_at(self, t):
        """Return (wrench or None, frame) the plant feels at time t."""
        return self.live_wrench if self.live else self.scene.wrench_at(t)

    def _publish_wrench(self, stamp):
        if self.wrench_pub is None:
            return
        publish_wrench(self.wrench_pub, self._wrench, stamp,
                       self.scene.wrench.at(self.t))

    def destroy_node(self):
        """Log how many commands the plant received, then destroy."""
        self.get_logger().info(
            f'commands received: {self.commands} ({self.dropped} malformed '
            f'messages dropped, {self.over_limit} commands over the torque '
            f'bounds)')
        return super().destroy_node()


def main(args=None):
    """Entry point of the ``robot_sim_node`` console script."""
    return run_node(RobotSimNode, 'robot_sim_node', args)


if __name__ == '__main__':
    sys.exit(main())
