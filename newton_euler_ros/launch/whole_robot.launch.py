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

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from newton_euler_ros.graph import URDF_TOPICS


def generate_launch_description():
    share = get_package_share_directory('newton_euler_ros')
    arg = LaunchConfiguration
    return LaunchDescription([
        DeclareLaunchArgument('base_link', default_value='base_link',
                              description='base link of the robot: the '
                                          'whole tree below it is served'),
        DeclareLaunchArgument(
            'params_file',
            default_value=os.path.join(share, 'config', 'params',
                                       'whole_robot.yaml'),
            description='parameter file (commanded joints, wrench '
                        'sensors, observer end effectors, QoS, ...)'),
        *(DeclareLaunchArgument(name, default_value=default,
                                description=text)
          for _, name, default, text in URDF_TOPICS),
        Node(
            package='newton_euler_ros',
            executable='inverse_dynamics_node',
            name='inverse_dynamics_node',
            output='screen',
            # no tip link: the whole robot, whatever the file says
            parameters=[arg('params_file'),
                        {'robot_file': '', 'base_link': arg('base_link'),
                         'tip_link': ''}],
            remappings=[(topic, arg(name))
                        for topic, name, _, _ in URDF_TOPICS],
        ),
    ])
