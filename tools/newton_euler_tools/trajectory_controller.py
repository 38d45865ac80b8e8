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
A joint_trajectory_controller with an effort interface, as a ROS node.

    python -m newton_euler_tools.trajectory_controller --ros-args
        -p joints:=[...] -p kp:=[...] -p kd:=[...]

What ``make demo-identify`` puts between inverse_dynamics_node and
mujoco_sim_node, which takes efforts: the node's ``~/trajectory_out``
(the plan with its efforts filled) comes in on ``~/joint_trajectory``;
for every ``joint_states`` message from its start on it publishes

    tau = kp (q_d - q) + kd (qd_d - qd) + effort_d

on ``effort_controller/commands`` (``joints`` order), with the plan
sampled at the state's stamp as ``core.trajectory.TrajectoryFollower``
samples it (linear between points, the last point held, at rest, after
the end).  A plan stamped 0 starts at the first joint state after it
came (joint_trajectory_controller's "now"), else at its stamp; the
latched ``~/start`` carries that stamp.  Before the start it commands
nothing: a plant whose brakes hold until the first command (mujoco_sim_node)
stands still until then.  On a stop it logs ``commands sent: N``.
Kept light (rclpy and numpy, no model): a process of the demo's
start-up.
"""
import sys

import numpy as np
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

NAME = 'trajectory_controller'
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)


def _seconds(stamp):
    return stamp.sec + stamp.nanosec * 1e-9


class Plan:
    """A trajectory's arrays in the controller's joint order."""

    def __init__(self, msg, joints):
        names = list(msg.joint_names)
        missing = [j for j in joints if j not in names]
        if missing or not msg.points:
            raise ValueError(f'trajectory without joints {missing}'
                             if missing else 'trajectory without points')
        cols = [names.index(j) for j in joints]
        pts = msg.points
        self.times = np.array([_seconds(p.time_from_start) for p in pts])
        self.Q = np.array([p.positions for p in pts])[:, cols]
        self.QD = np.array([p.velocities for p in pts])[:, cols]
        self.EFF = np.array([p.effort if len(p.effort) else
                             [0.0] * len(names) for p in pts])[:, cols]

    def sample(self, s):
        """Return (q, qd, effort) ``s`` seconds from the start."""
        times = self.times
        if s <= times[0]:
            return self.Q[0], self.QD[0], self.EFF[0]
        if s >= times[-1]:
            return self.Q[-1], np.zeros_like(self.QD[-1]), self.EFF[-1]
        k = int(np.searchsorted(times, s, side='right'))
        w = (s - times[k - 1]) / (times[k] - times[k - 1])
        return tuple((1.0 - w) * X[k - 1] + w * X[k]
                     for X in (self.Q, self.QD, self.EFF))


def make_node():
    """Return the controller node (rclpy initialised)."""
    from rclpy.node import Node
    from sensor_msgs.msg import JointState
    from std_msgs.msg import Float64MultiArray, Header
    from trajectory_msgs.msg import JointTrajectory

    class TrajectoryController(Node):
        """PD on the plan plus its efforts, one command per state."""

        def __init__(self):
            super().__init__(NAME)
            self.joints = list(self.declare_parameter(
                'joints', ['']).value)
            self.kp = np.array(self.declare_parameter('kp', [0.0]).value)
            self.kd = np.array(self.declare_parameter('kd', [0.0]).value)
            if not (len(self.joints) == self.kp.size == self.kd.size):
                from newton_euler_ros.nodes.common import ConfigurationError
                raise ConfigurationError(
                    f'joints, kp, kd: one value per joint, got '
                    f'{len(self.joints)}, {self.kp.size}, {self.kd.size}')
            self.plan = None
            self.start = None
            self.cols = None
            self.sent = 0
            self._msg = Float64MultiArray()
            self.pub = self.create_publisher(
                Float64MultiArray, 'effort_controller/commands', 100)
            self.start_pub = self.create_publisher(Header, '~/start',
                                                   LATCHED)
            self.create_subscription(JointTrajectory, '~/joint_trajectory',
                                     self._on_plan, 10)
            # the newest state only: never a command from a stale one
            self.create_subscription(JointState, 'joint_states',
                                     self._on_state, 1)

        def _on_plan(self, msg):
            try:
                self.plan = Plan(msg, self.joints)
            except ValueError as exc:
                self.get_logger().error(f'trajectory ignored: {exc}')
                return
            t = _seconds(msg.header.stamp)
            self.start = t if t > 0.0 else None
            if self.start is not None:
                self.start_pub.publish(Header(stamp=msg.header.stamp,
                                              frame_id='plan_start'))
            self.get_logger().info(
                f'trajectory of {len(msg.points)} points, '
                f'{self.plan.times[-1]:.3f} s, '
                + (f'starting at t = {t:.3f} s' if self.start is not None
                   else 'starting at the next joint state'))

        def _on_state(self, msg):
            if self.plan is None:
                return
            if self.cols is None:
                names = list(msg.name)
                self.cols = [names.index(j) for j in self.joints]
            t = _seconds(msg.header.stamp)
            if self.start is None:
                self.start = t
                self.start_pub.publish(Header(stamp=msg.header.stamp,
                                              frame_id='plan_start'))
            if t < self.start - 1e-9:
                return
            q_d, qd_d, eff = self.plan.sample(t - self.start)
            q = np.asarray(msg.position)[self.cols]
            qd = np.asarray(msg.velocity)[self.cols]
            self._msg.data = (self.kp * (q_d - q) + self.kd * (qd_d - qd)
                              + eff).tolist()
            self.pub.publish(self._msg)
            self.sent += 1

        def destroy_node(self):
            self.get_logger().info(f'commands sent: {self.sent}')
            return super().destroy_node()

    return TrajectoryController()


def main(args=None):
    """Run the controller until SIGINT; return the exit status."""
    from newton_euler_ros.nodes.common import run_node
    return run_node(make_node, NAME, args)


if __name__ == '__main__':
    sys.exit(main())
