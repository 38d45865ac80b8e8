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
Publish one JointState to a running inverse_dynamics_node, print its torques.

    .venv/bin/python examples/one_joint_state.py [--joints j1 j2 ...]
        [--position x1 x2 ...] [--node inverse_dynamics_node]

Publishes on /joint_states (re-sending once a second until the node has
answered, since a new publisher is matched by DDS discovery after a
moment) and prints the first ``~/torques`` message the node publishes,
joint by joint.  Exits 0 when the torques arrived, 1 after --timeout
seconds without them.  The state defaults to the Puma 560 of
``config/params/puma560.yaml`` at rest.
"""
import argparse
import sys
import time

import rclpy
from rclpy.node import Node
from sensor_msgs.msg import JointState


def main(argv=None):
    """Publish one state, wait for the torques, print them."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--joints', nargs='+',
                        default=[f'joint{i}' for i in range(1, 7)])
    parser.add_argument('--position', nargs='+', type=float,
                        default=[0.0, 0.5, -0.3, 0.1, 0.2, 0.3])
    parser.add_argument('--node', default='inverse_dynamics_node')
    parser.add_argument('--timeout', type=float, default=60.0)
    args = parser.parse_args(argv)
    if len(args.position) != len(args.joints):
        parser.error('--position needs one value per joint')
    rclpy.init()
    node = Node('one_joint_state')
    answers = []
    node.create_subscription(JointState, f'/{args.node}/torques',
                             answers.append, 10)
    pub = node.create_publisher(JointState, '/joint_states', 10)
    deadline = time.monotonic() + args.timeout
    next_send = 0.0
    try:
        while not answers and time.monotonic() < deadline:
            if time.monotonic() >= next_send and pub.get_subscription_count():
                msg = JointState(name=args.joints, position=args.position)
                msg.header.stamp = node.get_clock().now().to_msg()
                pub.publish(msg)
                next_send = time.monotonic() + 1.0
            rclpy.spin_once(node, timeout_sec=0.05)
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    if not answers:
        print(f'no torques on /{args.node}/torques within {args.timeout} s '
              '(is the node running, with these joint names?)',
              file=sys.stderr)
        return 1
    tau = answers[0]
    width = max([12, *(len(name) for name in tau.name)])
    for name, effort in zip(tau.name, tau.effort):
        print(f'{name:>{width}s}  {effort:+.6f}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
