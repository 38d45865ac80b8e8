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

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration, PythonExpression
from launch_ros.actions import Node
from newton_euler_ros.graph import INVERSE_DYNAMICS_TOPICS


def generate_launch_description():
    share = get_package_share_directory('newton_euler_ros')
    robot = LaunchConfiguration('robot')
    params = PythonExpression([
        "'", os.path.join(share, 'config', 'params', ''), "' + '", robot,
        "' + '.yaml'"])
    return LaunchDescription([
        DeclareLaunchArgument('robot', default_value='puma560',
                              description='bundled robot whose parameter '
                                          'file to load'),
        DeclareLaunchArgument('params_file', default_value=params,
                              description='parameter file (overrides robot)'),
        *(DeclareLaunchArgument(arg, default_value=default,
                                description=text)
          for _, arg, default, text in INVERSE_DYNAMICS_TOPICS),
        Node(
            package='newton_euler_ros',
            executable='inverse_dynamics_node',
            name='inverse_dynamics_node',
            output='screen',
            parameters=[LaunchConfiguration('params_file')],
            remappings=[(name, LaunchConfiguration(arg))
                        for name, arg, _, _ in INVERSE_DYNAMICS_TOPICS],
        ),
    ])
