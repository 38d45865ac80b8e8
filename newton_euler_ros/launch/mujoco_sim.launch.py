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
Launch mujoco_sim_node: a robot simulated by MuJoCo, driven by efforts.

    ros2 launch newton_euler_ros mujoco_sim.launch.py robot_file:=panda

The plant takes efforts on ``/effort_controller/commands`` (what
ros2_control's effort forward controller publishes; ``commands:=`` remaps
it) and publishes ``/joint_states``, ``/clock`` (simulated time: start
the other nodes with ``use_sim_time:=true``), its contact wrenches and
``/diagnostics``.  It holds the initial pose until the first command.
Doubles need a decimal point (``real_time_factor:=2.0``); docs/node.md
lists every parameter (run the node without ``robot_file`` to simulate
robot_state_publisher's ``robot_description``).
"""
import os
import sys

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from newton_euler_launch_parts import package_node  # noqa: E402, I100

ARGUMENTS = (
    ('robot_file', 'panda', 'URDF or MJCF file, robot YAML file or bundled '
                            'robot name'),
    ('real_time_factor', '1.0', 'simulated s per wall-clock s; 0.0: as '
                                'fast as it can'),
    ('rate', '500.0', 'joint_states and /clock per simulated second, Hz'),
    ('timestep', '0.001', "MuJoCo's physics step, s"),
    ('command_timeout', '0.5', 'simulated s without a command before the '
                               'efforts are zero'),
)


def generate_launch_description():
    arg = LaunchConfiguration
    return LaunchDescription([
        *(DeclareLaunchArgument(name, default_value=default,
                                description=text)
          for name, default, text in ARGUMENTS),
        DeclareLaunchArgument(
            'commands', default_value='/effort_controller/commands',
            description='topic of the effort commands'),
        package_node(
            'mujoco_sim_node',
            parameters=[{name: arg(name) for name, _, _ in ARGUMENTS}],
            remappings=[('effort_controller/commands', arg('commands'))],
        ),
    ])
