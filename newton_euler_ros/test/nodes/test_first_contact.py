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
What a new user meets first: --help, typos in parameters, quiet start-up.

Every node's console script answers ``--help`` with what it does, every
topic it publishes or subscribes to (read here from its source) and its
parameters, without starting ROS.  A parameter override that no parameter
matches (``-p robot:=puma560``, ``-p robot_flie:=…``, a ``joint:`` key in
a params file) stops the node with one line naming the closest real
parameter, exit status 2; a params file without a section for the node's
name is a warning naming the sections it has (the node then runs without
those parameters: inverse_dynamics_node waits for robot_description).
The section rules of ROS 2 (leading ``/``, ``*``, ``**``) are checked
against rclpy's own choice.  A mistyped ``tip_link`` names the closest
links.  The bundled Puma's published oddities (notes) and the massless
frames of a URDF written by ``newton-euler urdf`` stay out of the log.
"""
import ast
import os
import subprocess
import sys
import time

from newton_euler_ros.parameters import load_specs, NODES
import pytest
import yaml

rclpy = pytest.importorskip('rclpy')
Node = pytest.importorskip('rclpy.node').Node

from newton_euler_ros.nodes.common import (  # noqa: E402, I100
    params_file_sections, params_files, section_matches)
from ros_harness import (domain_id, id_node_cmd, NodeProcess,  # noqa: E402
                         PARAMS_DIR, ros_env)

pytestmark = pytest.mark.ros

DOMAIN = domain_id(17)
SRC = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), 'newton_euler_ros', 'nodes')
PUMA_PARAMS = os.path.join(PARAMS_DIR, 'puma560.yaml')
SCENE = ['-p', 'scene:=puma_payload_press']


def script(node):
    return os.path.join(os.path.dirname(sys.executable), node)


def run(cmd, env=None, timeout=120):
    return subprocess.run(cmd, env={**ros_env(DOMAIN), **(env or {})},
                          capture_output=True, text=True, timeout=timeout)


def topics_in_source(node):
    """Topic and service names a node's source creates (string literals)."""
    with open(os.path.join(SRC, f'{node}.py'), encoding='utf-8') as fh:
        tree = ast.parse(fh.read())
    names = set()
    for call in ast.walk(tree):
        if isinstance(call, ast.Call) and isinstance(call.func,
                                                     ast.Attribute) \
                and call.func.attr in ('create_publisher',
                                       'create_subscription',
                                       'create_service') \
                and len(call.args) > 1 \
                and isinstance(call.args[1], ast.Constant):
            names.add(call.args[1].value)
    return names


# ---------------------------------------------------------------------------
# --help
# ---------------------------------------------------------------------------
@pytest.mark.parametrize('node', NODES)
@pytest.mark.parametrize('flag', ['--help', '-h'])
def test_help_describes_the_node_and_does_not_start_ros(node, flag,
                                                        tmp_path):
    logs = tmp_path / 'ros_log'
    logs.mkdir()
    proc = run([script(node), flag], env={'ROS_LOG_DIR': str(logs)})
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ''
    assert list(logs.iterdir()) == []           # rclpy.init never ran
    out = proc.stdout
    assert out.startswith(f'usage: {node} ')
    assert f'{node}: ' in out                   # what it does
    assert 'Subscribes' in out and 'Publishes' in out
    topics = topics_in_source(node)
    assert len(topics) >= 4, topics
    words = ' '.join(out.split())
    for topic in topics:
        assert f'{topic} (' in words, topic      # every topic, with type
    for spec in load_specs(node):
        assert f'\n  {spec.name} ({spec.type}, default ' in out, spec.name


def test_help_through_python_m_too():
    proc = run([sys.executable, '-m',
                'newton_euler_ros.nodes.tracking_controller_node', '--help'])
    assert proc.returncode == 0, proc.stderr
    assert 'feedforward (bool, default true' in proc.stdout


# ---------------------------------------------------------------------------
# unknown parameters
# ---------------------------------------------------------------------------
def refused(cmd, node):
    proc = run(cmd)
    assert proc.returncode == 2, proc.stderr + proc.stdout
    assert 'Traceback' not in proc.stderr
    lines = [line for line in proc.stderr.splitlines()
             if not line.startswith('[')]
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith(f'{node}: invalid configuration: ')
    return lines[0]


@pytest.mark.parametrize('args, message', [
    (['-p', 'robot:=puma560'],
     "unknown parameter 'robot' (did you mean 'robot_file'?)"),
    (['-p', 'robot_flie:=puma560'],
     "unknown parameter 'robot_flie' (did you mean 'robot_file'?)"),
    (['-p', 'robot_file:=puma560', '-p', 'qos.dept:=3'],
     "unknown parameter 'qos.dept' (did you mean 'qos.depth'?)"),
])
def test_unknown_parameter_names_the_closest(args, message):
    line = refused(id_node_cmd(None, *args), 'inverse_dynamics_node')
    assert line.endswith(message), line


def test_unknown_key_in_a_params_file(tmp_path):
    path = tmp_path / 'params.yaml'
    path.write_text(yaml.safe_dump({'inverse_dynamics_node': {
        'ros__parameters': {'robot_file': 'puma560',
                            'joint': ['joint1', 'joint2']}}}))
    line = refused(id_node_cmd(None, '--params-file', str(path)),
                   'inverse_dynamics_node')
    assert line.endswith(
        "unknown parameter 'joint' (did you mean 'joints'?)"), line


@pytest.mark.parametrize('node, args, message', [
    ('robot_sim_node', [*SCENE, '-p', 'real_time_factr:=2.0'],
     "unknown parameter 'real_time_factr' (did you mean "
     "'real_time_factor'?)"),
    ('tracking_controller_node', [*SCENE, '-p', 'feed_forward:=false',
                                  '-p', 'zzz:=1'],
     "unknown parameter 'feed_forward' (did you mean 'feedforward'?); "
     "unknown parameter 'zzz' (tracking_controller_node --help lists the "
     'parameters)'),
])
def test_every_node_refuses_unknown_parameters(node, args, message):
    line = refused([script(node), '--ros-args', *args], node)
    assert line.endswith(message), line


def wait_for(node, text, timeout=90.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if text in node.log():
            return node.log()
        assert node.alive(), node.tail()
        time.sleep(0.2)
    raise AssertionError(f'no {text!r} in:\n{node.tail()}')


def test_params_file_for_another_node_name_warns(tmp_path):
    node = NodeProcess(id_node_cmd('puma560.yaml', '-r', '__node:=arm'),
                       DOMAIN, str(tmp_path / 'node.log'))
    try:
        log = wait_for(node, 'waiting for the robot_description topic')
    finally:
        assert node.stop() == 0
    assert (f'params file {PUMA_PARAMS}: no section for this node (/arm); '
            f'its sections: inverse_dynamics_node; none of its parameters '
            f'apply (name a section arm: or /**:)') in log, log


# ---------------------------------------------------------------------------
# params-file sections: our reading of the ROS 2 rules against rclpy's
# ---------------------------------------------------------------------------
SECTIONS = ['inverse_dynamics_node', '/inverse_dynamics_node', '/**',
            'other_node', '/ns/inverse_dynamics_node', '/ns/*', '/*',
            '/**/inverse_dynamics_node', '/ns/**', '/*/arm', '/ns/*/arm',
            'ns/deep/arm', '/ns/**/arm', '/**/deep/arm', '*',
            ('ns', 'deep', 'arm'), ('ns', 'inverse_dynamics_node'),
            ('/**', 'arm')]
NAMES = [('inverse_dynamics_node', '/'), ('inverse_dynamics_node', '/ns'),
         ('arm', '/ns/deep'), ('arm', '/other')]


@pytest.mark.parametrize('section', SECTIONS)
def test_section_rules_agree_with_rclpy(section, tmp_path):
    # a tuple: nested keys (ns: node: ros__parameters:)
    keys = section if isinstance(section, tuple) else (section,)
    tree = {'ros__parameters': {'robot_file': 'puma560'}}
    for key in reversed(keys):
        tree = {key: tree}
    path = tmp_path / 'params.yaml'
    path.write_text(yaml.safe_dump(tree))
    section = '/'.join(keys)
    assert params_file_sections(yaml.safe_load(path.read_text())) == \
        [section]
    context = rclpy.Context()
    rclpy.init(args=['x', '--ros-args', '--params-file', str(path)],
               context=context)
    try:
        for name, namespace in NAMES:
            node = Node(name, namespace=namespace, context=context)
            try:
                fqn = node.get_fully_qualified_name()
                applied = 'robot_file' in node._parameter_overrides
                assert section_matches(section, fqn) == applied, \
                    (section, fqn, applied)
            finally:
                node.destroy_node()
    finally:
        rclpy.shutdown(context=context)


def test_nested_sections_and_params_file_arguments():
    data = {'ns': {'arm': {'ros__parameters': {'a': 1}},
                   'hand': {'ros__parameters': {'b': 2}}},
            '/**': {'ros__parameters': {'c': 3}}}
    assert sorted(params_file_sections(data)) == ['/**', 'ns/arm',
                                                  'ns/hand']
    assert params_files(['node', '--params-file', 'not_ros.yaml',
                         '--ros-args', '-p', 'x:=--params-file',
                         '--params-file', 'a.yaml', '--', '--params-file',
                         'b.yaml', '--ros-args', '--params-file',
                         'c.yaml']) == ['a.yaml', 'c.yaml']


# ---------------------------------------------------------------------------
# links, and a quiet start
# ---------------------------------------------------------------------------
@pytest.fixture(scope='module')
def puma_urdf(tmp_path_factory):
    path = tmp_path_factory.mktemp('urdf') / 'puma560.urdf'
    proc = subprocess.run([script('newton-euler'), 'urdf', 'puma560', '-o',
                           str(path)], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ''
    return str(path)


def test_mistyped_tip_link_names_the_closest_links(puma_urdf):
    line = refused(id_node_cmd(None, '-p', f'robot_file:={puma_urdf}',
                               '-p', 'tip_link:=tol0'),
                   'inverse_dynamics_node')
    assert "tip link 'tol0' is not in the URDF (closest: 'tool0')" in line
    proc = subprocess.run([script('newton-euler'), 'check', puma_urdf,
                           '--base', 'bse_link'], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.count('\n') == 1
    assert "base link 'bse_link' is not in the URDF (closest: " \
        "'base_link'" in proc.stderr


def test_urdf_written_by_the_cli_reads_back_without_a_warning(puma_urdf):
    proc = subprocess.run([script('newton-euler'), 'dynamics', puma_urdf,
                           '--q', *['0.1'] * 6], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ''                    # tool0 is a frame
    assert 'puma560: 6 joints' in proc.stdout


def test_library_first_example_prints_no_warning():
    code = ('import numpy as np\n'
            'from newton_euler_ros.core import load_robot, Workspace, '
            'inverse_dynamics\n'
            "arm = load_robot('puma560')\n"
            'ws = Workspace(arm)\n'
            'tau = inverse_dynamics(arm, np.zeros(6), np.ones(6), '
            'np.zeros(6), [0.0, 0.0, 10.0, 0.0, 0.0, 0.0], ws=ws)\n'
            'print(len(tau))\n')
    proc = run([sys.executable, '-c', code])
    assert proc.returncode == 0 and proc.stdout == '6\n', proc.stderr
    assert proc.stderr == ''


@pytest.mark.parametrize('source', ['bundled', 'urdf'])
def test_node_start_prints_no_warning(source, puma_urdf, tmp_path):
    args = (['--params-file', PUMA_PARAMS] if source == 'bundled' else
            ['-p', f'robot_file:={puma_urdf}', '-p', 'tip_link:=tool0'])
    node = NodeProcess(id_node_cmd(None, *args), DOMAIN,
                       str(tmp_path / 'node.log'))
    try:
        log = wait_for(node, '6 joints [joint1')
    finally:
        assert node.stop() == 0
    assert 'WARN' not in log and 'triangle' not in log, log
    assert 'massless' not in log, log
