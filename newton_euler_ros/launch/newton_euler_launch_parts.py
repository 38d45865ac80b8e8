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
What this package's launch files share; installed beside them.

Not a launch file itself: each ``*.launch.py`` here puts its own folder
on ``sys.path`` and imports this module, so it works from the source
tree and from an install (``share/newton_euler_ros/launch``) alike.
"""
import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from newton_euler_ros.graph import URDF_TOPICS

PACKAGE = 'newton_euler_ros'


def package_node(executable, **kwargs):
    """Return a node of this package named as its executable, on screen."""
    return Node(package=PACKAGE, executable=executable, name=executable,
                output='screen', **kwargs)


def params_path(*name):
    """Return the path of a bundled parameter file (config/params/...)."""
    return os.path.join(get_package_share_directory(PACKAGE), 'config',
                        'params', *name)


def topic_arguments(topics):
    """Return a launch argument per (topic, argument, default, text)."""
    return [DeclareLaunchArgument(name, default_value=default,
                                  description=text)
            for _, name, default, text in topics]


def urdf_description(base_text, arguments, params_file, parameters,
                     remappings):
    """
    Return inverse_dynamics_node on the URDF of ``robot_description``.

    The launch arguments: ``base_link`` (described by ``base_text``), then
    ``arguments``, ``params_file`` (a bundled file and its description,
    ``params_file``'s pair) and the topics of ``URDF_TOPICS``.  The node
    takes the parameter file, then ``parameters`` (a dict), and
    ``remappings``.
    """
    default, text = params_file
    return LaunchDescription([
        DeclareLaunchArgument('base_link', default_value='base_link',
                              description=base_text),
        *arguments,
        DeclareLaunchArgument('params_file',
                              default_value=params_path(default),
                              description=text),
        *topic_arguments(URDF_TOPICS),
        package_node('inverse_dynamics_node',
                     parameters=[LaunchConfiguration('params_file'),
                                 parameters],
                     remappings=remappings),
    ])
