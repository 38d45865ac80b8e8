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


"""The folder tree is the architecture: core, then sim, then ROS."""
import subprocess
import sys

import pytest

ROS_MODULES = ('rclpy', 'rcl_interfaces', 'sensor_msgs', 'geometry_msgs',
               'std_msgs', 'diagnostic_msgs', 'trajectory_msgs',
               'newton_euler_interfaces', 'newton_euler_tools')


@pytest.mark.parametrize('package, forbidden', [
    ('newton_euler_ros.core', ROS_MODULES + ('newton_euler_ros.sim',
                                             'newton_euler_ros.nodes')),
    ('newton_euler_ros.sim', ROS_MODULES + ('newton_euler_ros.nodes',)),
])
def test_lower_layers_import_nothing_above_them(package, forbidden):
    """Import every module of ``package`` in a fresh interpreter."""
    code = f"""
import importlib, pkgutil, sys
import {package} as root
for info in pkgutil.iter_modules(root.__path__):
    importlib.import_module('{package}.' + info.name)
print(sorted(m for m in sys.modules
             if m.split('.')[0] in {forbidden!r}
             or any(m.startswith(f) for f in {forbidden!r})))
"""
    out = subprocess.run([sys.executable, '-c', code], capture_output=True,
                         text=True, timeout=120, check=True).stdout
    assert out.strip() == '[]', f'{package} imports {out.strip()}'
