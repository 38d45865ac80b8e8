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
import os
import subprocess
import sys

import import_graph as ig
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


PACKAGE = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), 'newton_euler_ros')
# per module of core/ and of the ROS adapters (docs/how-it-is-computed.md)
MAX_LINES = 600


def _long(paths):
    """{path: lines} of the files longer than MAX_LINES."""
    return {path: n for path in paths
            if (n := sum(1 for _ in open(path, encoding='utf-8')))
            > MAX_LINES}


def _adapter_modules():
    """
    Paths of the ROS adapter modules: nodes/ and the package's own modules.

    The modules beside core/, sim/ and ident/ (feedforward*, safety,
    parameters, cli*, joint_inputs, wrenches, whole_robot, graph...).
    """
    top = [os.path.join(PACKAGE, name) for name in os.listdir(PACKAGE)
           if name.endswith('.py')]
    nodes = os.path.join(PACKAGE, 'nodes')
    return sorted(top + [os.path.join(nodes, name)
                         for name in os.listdir(nodes)
                         if name.endswith('.py')])


def test_core_modules_are_short():
    long = _long(ig.modules('core').values())
    assert not long, f'core modules over {MAX_LINES} lines: {long}'


def test_ros_adapter_modules_are_short():
    paths = _adapter_modules()
    names = {os.path.relpath(path, PACKAGE) for path in paths}
    # the walk sees the modules it is meant to hold
    assert {'feedforward.py', 'safety.py', 'parameters.py', 'cli.py',
            'nodes/inverse_dynamics_node.py'} <= names, names
    long = {os.path.relpath(path, PACKAGE): n
            for path, n in _long(paths).items()}
    assert not long, (f'ROS adapter modules over {MAX_LINES} lines (split '
                      f'them along what they do): {long}')


def test_simulation_and_identification_modules_are_short():
    paths = [os.path.join(PACKAGE, part, name)
             for part in ('sim', 'ident')
             for name in os.listdir(os.path.join(PACKAGE, part))
             if name.endswith('.py')]
    names = {os.path.relpath(path, PACKAGE) for path in paths}
    assert {'sim/simulate.py', 'ident/fit.py', 'ident/bag.py'} <= names
    long = {os.path.relpath(path, PACKAGE): n
            for path, n in _long(paths).items()}
    assert not long, (f'sim/ and ident/ modules over {MAX_LINES} lines '
                      f'(split them along what they do): {long}')


def test_the_size_check_sees_a_long_module(tmp_path):
    short, long = tmp_path / 'short.py', tmp_path / 'long.py'
    short.write_text('x = 1\n' * MAX_LINES)
    long.write_text('x = 1\n' * (MAX_LINES + 1))
    assert _long([str(short), str(long)]) == {str(long): MAX_LINES + 1}
