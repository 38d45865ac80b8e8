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
echo_node: the inverse-dynamics node's message work without the dynamics.

The latency floor for :mod:`newton_euler_tools.latency_bench`.  It takes the
same inputs and produces the same outputs as ``inverse_dynamics_node``, with
the same QoS and the same executor (``common.run_node``), but computes
nothing: the "torques" are a copy of the positions.

Subscribes
    joint_states (sensor_msgs/JointState)
Publishes
    ~/torques (sensor_msgs/JointState: the input's header.stamp and names,
    effort = position), ~/torque_command (std_msgs/Float64MultiArray, the
    same values)

Parameters ``qos.depth`` (10) and ``qos.reliability`` (``reliable`` or
``best_effort``) are the real node's: declared from its schema, with its
descriptions and validation (a bad value refuses to start, exit
status 2).

    python -m newton_euler_tools.echo_node
"""
import sys

from newton_euler_ros.nodes.common import (declare_parameters, qos_profile,
                                           run_node)
from newton_euler_ros.parameters import load_specs
from rclpy.node import Node
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray


class EchoNode(Node):
    """Republish each joint state as torques = positions."""

    def __init__(self, **kwargs):
        super().__init__('echo_node', **kwargs)
        p = declare_parameters(self, [
            spec for spec in load_specs('inverse_dynamics_node')
            if spec.name in ('qos.depth', 'qos.reliability')])
        qos = qos_profile(p['qos.depth'], p['qos.reliability'])
        self.cmd_pub = self.create_publisher(Float64MultiArray,
                                             '~/torque_command', qos)
        self.torque_pub = self.create_publisher(JointState, '~/torques', qos)
        self.create_subscription(JointState, 'joint_states',
                                 self._on_joint_state, qos)
        # reused messages, as in the real node
        self._cmd = Float64MultiArray()
        self._torques = JointState()
        self.published = 0

    def _on_joint_state(self, msg):
        # the real node converts the message's arrays to Python lists
        # (tau.tolist()) and publishes both messages; do the same work
        values = list(msg.position)
        self._cmd.data = values
        self.cmd_pub.publish(self._cmd)
        self._torques.header.stamp = msg.header.stamp
        self._torques.name = msg.name
        self._torques.effort = values
        self.torque_pub.publish(self._torques)
        self.published += 1


def main(args=None):
    """Entry point: ``python -m newton_euler_tools.echo_node``."""
    return run_node(EchoNode, 'echo_node', args)


if __name__ == '__main__':
    sys.exit(main())
