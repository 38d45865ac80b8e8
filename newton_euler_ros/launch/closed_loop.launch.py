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
Launch the closed loop of the demo: simulator, feedforward, controller.

    ros2 launch newton_euler_ros closed_loop.launch.py \
        scene:=puma_payload_press feedforward:=true

robot_sim_node simulates the scene; inverse_dynamics_node computes the
feedforward from the controller's reference; tracking_controller_node
commands PD plus that feedforward.  The nodes use relative or private
names; the controller's remaps come from ``newton_euler_ros.graph``
(the demo, ``python -m newton_euler_tools.demo``, uses the same).
"""
import os
import sys

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from newton_euler_ros.graph import CONTROLLER_REMAPS

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from newton_euler_launch_parts import package_node  # noqa: E402, I100


def generate_launch_description():
    scene = LaunchConfiguration('scene')
    return LaunchDescription([
        DeclareLaunchArgument('scene', default_value='puma_payload_press',
                              description='bundled scene name or scene '
                                          'file'),
        DeclareLaunchArgument('feedforward', default_value='true',
                              description='false: PD alone'),
        package_node(
            'robot_sim_node',
            # the controller and the inverse-dynamics node
            parameters=[{'scene': scene, 'wait_for_subscribers': 2}],
        ),
        package_node(
            'inverse_dynamics_node',
            parameters=[{'scene': scene,
                         'acceleration_source': 'reference'}],
        ),
        package_node(
            'tracking_controller_node',
            parameters=[{'scene': scene,
                         'feedforward': LaunchConfiguration('feedforward')}],
            remappings=list(CONTROLLER_REMAPS),
        ),
    ])
