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
Launch inverse_dynamics_node with a bundled parameter file (apt ROS).

    ros2 launch newton_euler_ros inverse_dynamics.launch.py robot:=puma560

Remap ``joint_states``, ``wrench`` and the command as your graph needs,
e.g. ``ros2 launch ... joint_states:=/my_robot/joint_states
torque_command:=/effort_controller/commands``.
"""
import os
import sys

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration, PythonExpression
from newton_euler_ros.graph import INVERSE_DYNAMICS_TOPICS

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from newton_euler_launch_parts import (  # noqa: E402, I100
    package_node, params_path, topic_arguments)


def generate_launch_description():
    robot = LaunchConfiguration('robot')
    params = PythonExpression([
        "'", params_path(''), "' + '", robot, "' + '.yaml'"])
    return LaunchDescription([
        DeclareLaunchArgument('robot', default_value='puma560',
                              description='bundled robot whose parameter '
                                          'file to load'),
        DeclareLaunchArgument('params_file', default_value=params,
                              description='parameter file (overrides robot)'),
        *topic_arguments(INVERSE_DYNAMICS_TOPICS),
        package_node(
            'inverse_dynamics_node',
            parameters=[LaunchConfiguration('params_file')],
            remappings=[(name, LaunchConfiguration(arg))
                        for name, arg, _, _ in INVERSE_DYNAMICS_TOPICS],
        ),
    ])
