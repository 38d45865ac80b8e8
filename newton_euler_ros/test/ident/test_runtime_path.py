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

"""The identification stack stays out of the nodes' runtime path."""
import subprocess
import sys

import pytest

# (numba itself imports the scipy package, so scipy is not checked)
HEAVY = ('cvxpy', 'clarabel', 'rosbags', 'matplotlib')


@pytest.mark.parametrize('module', [
    'newton_euler_ros.nodes.inverse_dynamics_node',
    'newton_euler_ros.cli',
    'newton_euler_ros.core',
])
def test_importing_loads_no_identification_package(module):
    pytest.importorskip('rclpy')
    code = (f'import sys, {module}\n'
            f'print(sorted(m for m in sys.modules if m.split(".")[0] in '
            f'{HEAVY!r} or m.startswith("newton_euler_ros.ident")))')
    out = subprocess.run([sys.executable, '-c', code], capture_output=True,
                         text=True, check=True).stdout.strip()
    assert out == '[]', out
