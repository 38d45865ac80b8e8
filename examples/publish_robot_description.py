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
Stand in for robot_state_publisher: publish a URDF on /robot_description.

    .venv/bin/python examples/publish_robot_description.py FILE.urdf

Publishes the file's text once as std_msgs/String with the QoS
robot_state_publisher uses (reliable, transient local, depth 1), so a
node that starts later still receives it, then stays up until SIGINT
(Ctrl-C), which exits 0.  On a robot with apt ROS 2, robot_state_publisher
does this; this script is for trying the node without it.
"""
import signal
import sys

import rclpy
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String


def main(argv=None):
    """Publish the URDF latched, then wait for SIGINT."""
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1:
        print('usage: publish_robot_description.py FILE.urdf', file=sys.stderr)
        return 2
    try:
        with open(argv[0], encoding='utf-8') as fh:
            text = fh.read()
    except OSError as exc:
        print(f'{argv[0]}: {exc.strerror}', file=sys.stderr)
        return 1
    stop = []
    signal.signal(signal.SIGINT, lambda *_: stop.append(1))
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    rclpy.init(signal_handler_options=rclpy.signals.SignalHandlerOptions.NO)
    node = Node('robot_state_publisher_stand_in')
    qos = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
    node.create_publisher(String, '/robot_description', qos).publish(
        String(data=text))
    try:
        while not stop:
            rclpy.spin_once(node, timeout_sec=0.1)
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
