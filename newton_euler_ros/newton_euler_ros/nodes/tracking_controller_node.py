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
tracking_controller_node: PD on a scene's reference plus feedforward.

Once the simulator's start time t0 is known (latched ``~/start``, remapped
to ``/robot_sim_node/start``), the node publishes the scene's reference on
``~/reference`` (remap it to ``/inverse_dynamics_node/reference``) and,
for every joint state, commands

    tau = kp (q_d - q) + kd (qd_d - qd) + ff

on ``~/commands`` (remap it to ``/robot_sim_node/commands``), with
(q_d, qd_d) the reference at t = stamp - t0 and ff the inverse-dynamics
node's torques for the same stamp, read from ``~/feedforward`` (remap it
to ``/inverse_dynamics_node/torques``; the node waits for them).  With
``feedforward`` false, ff = 0 and every state is answered at once.
``joint_states`` is subscribed only once the peers are matched
(``wait_for_subscribers``).  On a stop it waits up to ACK_WAIT
seconds for every command to be acknowledged, then logs ``commands
sent: N``.  The remaps of the closed loop are
:data:`..graph.CONTROLLER_REMAPS` (used by launch/closed_loop.launch.py
and the demo).

Subscribes
    joint_states (sensor_msgs/JointState), ~/start (std_msgs/Header,
    transient local), ~/feedforward (sensor_msgs/JointState, only with
    feedforward)
Publishes
    ~/commands (std_msgs/Float64MultiArray), ~/reference
    (trajectory_msgs/JointTrajectory)
"""
from collections import OrderedDict
import sys

from builtin_interfaces.msg import Duration
import numpy as np
from rclpy.clock import Clock, ClockType
from rclpy.duration import Duration as Span
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray, Header
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from .common import qos_profile, run_node, seconds, SharedGraphNode
from .robot_sim_node import declare_scene_parameters
from ..sim.simulate import pd_torque

SAMPLE = 0.01           # reference sampling period, seconds
PENDING = 32            # joint states / feedforward kept for matching
ACK_WAIT = 5.0          # seconds a stop waits for the last commands' acks
REPUBLISH = 0.1         # seconds between checks to republish the reference


def _key(stamp):
    return (stamp.sec, stamp.nanosec)


def _keep(pending, key, value):
    """Keep ``value`` for matching by stamp; the oldest beyond PENDING go."""
    pending[key] = value
    while len(pending) > PENDING:
        pending.popitem(last=False)


def reference_message(scene, names, t0_stamp, sample=SAMPLE):
    """Return the scene's reference as a JointTrajectory starting at t0."""
    msg = JointTrajectory()
    msg.header.stamp = t0_stamp
    msg.joint_names = list(names)
    steps = int(round(scene.duration / sample))
    for k in range(steps + 1):
        t = k * sample
        q, qd, qdd = scene.reference.at(t)
        sec = int(t)
        msg.points.append(JointTrajectoryPoint(
            positions=[float(x) for x in q],
            velocities=[float(x) for x in qd],
            accelerations=[float(x) for x in qdd],
            time_from_start=Duration(sec=sec,
                                     nanosec=int(round((t - sec) * 1e9)))))
    return msg


class TrackingControllerNode(SharedGraphNode):
    """PD tracking of a scene's reference, with inverse-dynamics torques."""

    def __init__(self, **kwargs):
        super().__init__('tracking_controller_node', **kwargs)
        p = declare_scene_parameters(self, 'tracking_controller_node')
        self.use_ff = p['feedforward']
        self.wait_subscribers = p['wait_for_subscribers']
        self.qos = qos_profile(10, 'reliable')
        self.names = list(self.scene.model.joint_names)
        self.n = len(self.names)
        self.t0 = None
        self.t0_stamp = None
        self.states = OrderedDict()     # stamp -> (t, q, qd)
        self.ffs = OrderedDict()        # stamp -> ff
        self.published = 0
        self._index = {}
        self._ref_msg = None
        self._ref_count = 0

        # deep history on the commands: a slow reader (a Python recorder)
        # loses none of them (as robot_sim_node's joint_states)
        self.cmd_pub = self.create_publisher(Float64MultiArray, '~/commands',
                                             qos_profile(100, 'reliable'))
        self.ref_pub = self.create_publisher(JointTrajectory, '~/reference',
                                             10)
        latched = QoSProfile(depth=1,
                             reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.create_subscription(Header, '~/start', self._on_start, latched)
        self.ff_sub = (self.create_subscription(
            JointState, '~/feedforward', self._on_ff, self.qos)
            if self.use_ff else None)
        self.state_sub = None       # once the peers are matched
        # on the wall clock: with use_sim_time, ROS time stands still
        # until the plant's /clock, which waits for this node's
        # joint_states subscription, which this timer makes
        self.create_timer(REPUBLISH, self._on_timer,
                          clock=Clock(clock_type=ClockType.STEADY_TIME))
        self._cmd = Float64MultiArray()
        self.get_logger().info(
            f'{self.scene.name}: PD on {self.n} joints'
            + (' + feedforward from '
               f'{self.resolve_topic_name("~/feedforward")}'
               if self.use_ff else ' alone (no feedforward)')
            + f', commands on {self.resolve_topic_name("~/commands")}')
        self._on_timer()

    def _peers_matched(self):
        """Return True once the outputs and the feedforward are matched."""
        if self.cmd_pub.get_subscription_count() < self.wait_subscribers:
            return False
        return not self.use_ff or self.wait_subscribers == 0 or (
            self.ff_sub.get_publisher_count() >= 1
            and self.ref_pub.get_subscription_count() >= 1)

    def _on_timer(self):
        if self.state_sub is None and self._peers_matched():
            # subscribing last tells a simulator that waits for
            # joint_states subscribers that this node can be heard
            self.state_sub = self.create_subscription(
                JointState, 'joint_states', self._on_state, self.qos)
            self.get_logger().info(
                f'peers matched ({self.cmd_pub.get_subscription_count()} '
                'command subscribers); subscribed to joint_states')
        self._publish_reference()

    def _gather(self, msg, *fields):
        """Return the JointState's ``fields`` in the model's joint order."""
        names = tuple(msg.name)
        idx = None
        if names != tuple(self.names) and names:
            idx = self._index.get(names)
            if idx is None:
                idx = [names.index(j) for j in self.names]
                self._index[names] = idx
        arrays = []
        for what in fields:
            values = getattr(msg, what)
            if idx is None and len(values) != self.n:
                raise ValueError(f'{what}: expected {self.n} values')
            values = np.asarray(values, dtype=float)
            arrays.append(values if idx is None else values[idx])
        return arrays

    def _on_start(self, msg):
        t0 = seconds(msg.stamp)
        if t0 != self.t0:
            self.t0, self.t0_stamp = t0, msg.stamp
            self._ref_msg = None
            self.states.clear()
            self.ffs.clear()
            self.get_logger().info(f'simulation start t0 = {t0:.6f}')
            self._publish_reference()

    def _publish_reference(self):
        """
        Publish the reference: at t0, then to each new subscriber.

        Copies go out before t = 0 and on a new subscription only: a
        copy is large, and building and converting it stalls both nodes
        for milliseconds.
        """
        if self.t0_stamp is None or not self.context.ok():
            return
        count = self.ref_pub.get_subscription_count()
        now = self.get_clock().now().nanoseconds * 1e-9
        if self._ref_msg is None:
            self._ref_msg = reference_message(self.scene, self.names,
                                              self.t0_stamp)
        elif count <= self._ref_count and now > self.t0:
            return
        self._ref_count = count
        self.ref_pub.publish(self._ref_msg)

    def _on_state(self, msg):
        if self.t0 is None:
            return
        try:
            q, qd = self._gather(msg, 'position', 'velocity')
        except (ValueError, IndexError) as exc:
            self.get_logger().warning(f'dropped joint state: {exc}',
                                      throttle_duration_sec=2.0)
            return
        key = _key(msg.header.stamp)
        t = seconds(msg.header.stamp) - self.t0
        if not self.use_ff:
            self._command(t, q, qd, np.zeros(self.n))
            return
        ff = self.ffs.pop(key, None)
        if ff is not None:
            self._command(t, q, qd, ff)
            return
        _keep(self.states, key, (t, q, qd))

    def _on_ff(self, msg):
        try:
            ff, = self._gather(msg, 'effort')
        except (ValueError, IndexError) as exc:
            self.get_logger().warning(f'dropped feedforward: {exc}',
                                      throttle_duration_sec=2.0)
            return
        key = _key(msg.header.stamp)
        state = self.states.pop(key, None)
        if state is None:
            _keep(self.ffs, key, ff)
            return
        # states older than this one will not be answered any more
        for old in [k for k in self.states if k < key]:
            del self.states[old]
        self._command(*state, ff)

    def _command(self, t, q, qd, ff):
        q_d, qd_d, _ = self.scene.reference.at(t)
        tau = pd_torque(self.scene, q_d, qd_d, q, qd) + ff
        if not np.isfinite(tau).all():
            self.get_logger().warning('non-finite torque; not sent',
                                      throttle_duration_sec=2.0)
            return
        self._cmd.data = tau.tolist()
        try:
            self.cmd_pub.publish(self._cmd)
        except Exception:
            if self.context.ok():
                raise
            return      # shutting down (SIGINT): the context is closed
        self.published += 1

    def destroy_node(self):
        """Log how many commands were sent, then destroy the node."""
        # a command lost on its first delivery is sent again only while
        # this publisher lives: wait (bounded) until every reliable
        # subscriber has acknowledged the last one
        if self.context.ok() and not self.cmd_pub.wait_for_all_acked(
                Span(seconds=ACK_WAIT)):
            self.get_logger().warning(
                f'some commands were not acknowledged within {ACK_WAIT:g} s')
        self.get_logger().info(f'commands sent: {self.published}')
        return super().destroy_node()


def main(args=None):
    """Entry point of the ``tracking_controller_node`` console script."""
    return run_node(TrackingControllerNode, 'tracking_controller_node', args)


if __name__ == '__main__':
    sys.exit(main())
