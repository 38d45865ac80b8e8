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
Every node declares its parameters from a schema, and refuses bad ones.

The schemas (``<node>_parameters.yaml``) give each parameter a type,
default and description; a node started with a wrong type or an invalid
value exits with status 2 and one line saying why, as
inverse_dynamics_node does (``test_inverse_dynamics_node.py``).
"""
import os
import subprocess
import sys

from newton_euler_ros.parameters import load_specs, markdown_table, NODES
import pytest

pytest.importorskip('rclpy')

from ros_harness import domain_id, ros_env  # noqa: E402, I100

pytestmark = pytest.mark.ros


@pytest.mark.parametrize('node', NODES)
def test_every_parameter_is_described_and_documented(node):
    specs = load_specs(node)
    assert specs
    for spec in specs:
        assert len(spec.description) > 20, spec.name
        assert 'must be of type' not in spec.check(spec.default), spec.name
    assert markdown_table(specs).count('\n') == len(specs) + 1


def node_cmd(node, *args):
    script = os.path.join(os.path.dirname(sys.executable), node)
    base = [script] if os.path.exists(script) else [
        sys.executable, '-m', f'newton_euler_ros.nodes.{node}']
    return base + ['--ros-args', *args]


SCENE = ['-p', 'scene:=puma_payload_press']


@pytest.mark.parametrize('node, args, message', [
    ('robot_sim_node', [], 'scene: must not be empty'),
    ('robot_sim_node', ['-p', 'scene:=no_such_scene'],
     'scene: no_such_scene: no such file'),
    ('robot_sim_node', [*SCENE, '-p', 'real_time_factor:=0.0'],
     'real_time_factor: must be > 0'),
    ('robot_sim_node', [*SCENE, '-p', 'real_time_factor:=2'],
     'real_time_factor: wrong type'),
    ('robot_sim_node', [*SCENE, '-p', 'wait_for_subscribers:=-1'],
     'wait_for_subscribers: must be >= 0'),
    ('robot_sim_node', [*SCENE, '-p', 'limits.action:=ignore'],
     'limits.action: must be one of'),
    ('robot_sim_node', [*SCENE, '-p', 'payload.com:=[0.0, 1.0]'],
     'payload.com: must have 3 entries'),
    ('robot_sim_node', [*SCENE, '-p', 'payload.mass:=-1.0'],
     'payload.mass: must be >= 0'),
    ('tracking_controller_node', [], 'scene: must not be empty'),
    ('tracking_controller_node', ['-p', 'scene:=no_such_scene'],
     'scene: no_such_scene: no such file'),
    ('tracking_controller_node', [*SCENE, '-p', 'feedforward:=1'],
     'feedforward: wrong type'),
    ('tracking_controller_node', [*SCENE, '-p', 'wait_for_subscribers:=-2'],
     'wait_for_subscribers: must be >= 0'),
])
def test_bad_parameters_refuse_to_start(node, args, message):
    proc = subprocess.run(node_cmd(node, *args), env=ros_env(domain_id(83)),
                          capture_output=True, text=True, timeout=90)
    assert proc.returncode == 2, proc.stderr
    assert f'{node}: invalid configuration: {message}' in proc.stderr, \
        proc.stderr
    assert 'Traceback' not in proc.stderr
    # one line, after the log lines of start-up
    assert len([line for line in proc.stderr.splitlines()
                if not line.startswith('[')]) == 1, proc.stderr
