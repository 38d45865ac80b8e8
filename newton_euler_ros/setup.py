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
Build script for the newton_euler_ros ament_python package.

Used both by colcon (ROS 2 workspace) and by `pip install -e` (the
project's virtualenv, see scripts/setup_env.sh).
"""
from glob import glob
import os

from setuptools import find_packages, setup

package_name = 'newton_euler_ros'
here = os.path.dirname(os.path.abspath(__file__))


def tree(subdir):
    """
    Return data_files entries installing every file below ``subdir``.

    Files are globbed at build time, so robots, params, scenes or launch
    files added later are installed without touching this script.  Each
    directory keeps its relative place under share/<package>/.
    """
    entries = {}
    for path in sorted(glob(os.path.join(here, subdir, '**', '*'), recursive=True)):
        if not os.path.isfile(path) or '__pycache__' in path:
            continue
        rel = os.path.relpath(path, here)
        dest = os.path.join('share', package_name, os.path.dirname(rel))
        entries.setdefault(dest, []).append(rel)
    return sorted(entries.items())


setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test', 'test.*']),
    # Data read from beside the modules (e.g. the parameter schema): needed
    # in non-editable installs such as colcon's.
    package_data={package_name: ['*.yaml']},
    data_files=[
        # ament index marker: lets ament_index_python find the package.
        ('share/ament_index/resource_index/packages',
            ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        *tree('config'),
        *tree('launch'),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='newton_euler_ros maintainers',
    maintainer_email='maintainer@example.com',
    description='Recursive Newton-Euler inverse dynamics with a ROS 2 node.',
    license='Apache-2.0',
    extras_require={'test': ['pytest']},
    entry_points={
        'console_scripts': [
            'newton-euler = newton_euler_ros.cli:main',
            'inverse_dynamics_node = '
            'newton_euler_ros.nodes.entry:inverse_dynamics_node',
            'robot_sim_node = newton_euler_ros.nodes.entry:robot_sim_node',
            'mujoco_sim_node = newton_euler_ros.nodes.entry:mujoco_sim_node',
            'tracking_controller_node = '
            'newton_euler_ros.nodes.entry:tracking_controller_node',
        ],
    },
)
