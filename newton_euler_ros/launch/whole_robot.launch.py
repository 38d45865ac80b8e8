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
Launch inverse_dynamics_node on a whole robot's URDF (apt ROS).

    ros2 launch newton_euler_ros whole_robot.launch.py base_link:=base

Beside robot_state_publisher: the node reads the URDF from the
``robot_description`` topic (reliable, transient local) and, with a base
link and no tip link, serves the whole tree below it: every joint of a
dual-arm robot, a torso with arms or an arm with its fingers, mimic
joints following their leaders, joint states from several drivers
merged (docs/node.md, "Whole robots").  ``params_file`` holds the rest
(the joints an effort controller commands, wrench sensors, observer end
effectors; config/params/baxter.yaml is an example).  Remap
``robot_description``, ``joint_states``, ``wrench`` and the torque
command as your graph needs, e.g.
``torque_command:=/effort_controller/commands``.
"""
import os
import sys

from launch.substitutions import LaunchConfiguration
from newton_euler_ros.graph import URDF_TOPICS

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from newton_euler_launch_parts import urdf_description  # noqa: E402, I100


def generate_launch_description():
    arg = LaunchConfiguration
    return urdf_description(
        'base link of the robot: the whole tree below it is served', [],
        ('whole_robot.yaml', 'parameter file (commanded joints, wrench '
                             'sensors, observer end effectors, QoS, ...)'),
        # no tip link: the whole robot, whatever the file says
        {'robot_file': '', 'base_link': arg('base_link'), 'tip_link': ''},
        remappings=[(topic, arg(name))
                    for topic, name, _, _ in URDF_TOPICS])
