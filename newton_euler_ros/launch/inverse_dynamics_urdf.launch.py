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
Launch inverse_dynamics_node on the robot's own URDF (apt ROS).

    ros2 launch newton_euler_ros inverse_dynamics_urdf.launch.py \
        base_link:=base_link tip_link:=tool0

Beside robot_state_publisher: the node reads the URDF from the
``robot_description`` topic (reliable, transient local), so no robot file
is written by hand.  Remap ``robot_description``, ``joint_states``,
``wrench`` and the torque command as your graph needs, e.g.
``torque_command:=/effort_controller/commands``.
"""
import os
import sys

from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from newton_euler_ros.graph import URDF_TOPICS

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from newton_euler_launch_parts import urdf_description  # noqa: E402, I100


def generate_launch_description():
    arg = LaunchConfiguration
    tip = DeclareLaunchArgument('tip_link', default_value='tool0',
                                description='last link: the end effector')
    return urdf_description(
        'first link of the chain', [tip],
        ('urdf.yaml', 'parameter file (wrench frames, QoS, ...)'),
        {'base_link': arg('base_link'), 'tip_link': arg('tip_link')},
        remappings=[(topic, arg(name))
                    for topic, name, _, _ in URDF_TOPICS])
