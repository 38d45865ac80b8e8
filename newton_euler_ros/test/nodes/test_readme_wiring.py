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

"""The README's effort-controller wiring, run as written through bash."""
import os
import re

import pytest

pytest.importorskip('rclpy')

from ros_harness import domain_id, NodeProcess, Probe  # noqa: E402, I100
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import Float64MultiArray  # noqa: E402

pytestmark = pytest.mark.ros

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))))


def readme_line(prefix):
    with open(os.path.join(ROOT, 'README.md'), encoding='utf-8') as fh:
        for line in fh:
            if line.startswith(prefix):
                return line.strip()
    raise AssertionError(f'no README line starts with {prefix!r}')


def test_readme_wiring_command_publishes_on_the_controller_topic(tmp_path):
    line = readme_line('.venv/bin/inverse_dynamics_node --ros-args '
                       '--params-file newton_euler_ros/config/params/'
                       'puma560_gravity_coriolis.yaml -r')
    assert re.search(r"'~/torque_command:=/effort_controller/commands'",
                     line), 'the ~ remap must be quoted'
    domain = domain_id(59)
    # as pasted into bash, from the repository root
    node = NodeProcess(['bash', '-c', f'cd {ROOT} && exec {line}'], domain,
                       str(tmp_path / 'node.log'))
    probe = Probe(domain)
    try:
        commands = probe.collect(Float64MultiArray,
                                 '/effort_controller/commands')
        js = probe.publisher(JointState, '/joint_states')
        assert probe.spin_until(
            lambda: js.get_subscription_count() > 0
            and probe.node.count_publishers('/effort_controller/commands')
            > 0, 90.0), node.log()
        msg = JointState()
        msg.name = [f'joint{i}' for i in range(1, 7)]
        msg.position = [0.0, 0.5, -0.3, 0.1, 0.2, 0.3]
        msg.velocity = [0.0] * 6
        for _ in range(20):
            msg.header.stamp = probe.node.get_clock().now().to_msg()
            js.publish(msg)
            if probe.spin_until(lambda: commands, 0.5):
                break
        assert commands and len(commands[-1].data) == 6
        # and nothing on the default name
        assert probe.node.count_publishers(
            '/inverse_dynamics_node/torque_command') == 0
    finally:
        assert node.stop() == 0
        probe.close()
