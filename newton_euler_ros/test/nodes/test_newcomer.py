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
What a newcomer meets with a real robot description, as processes.

A robot's description package ships ``arm.urdf.xacro``: the CLI and the
node's ``robot_file`` say in one line to expand it with xacro first.  A
URDF saved under another name (``ur5.xml``) is read as the URDF it is.
"""
import os
import shutil
import subprocess
import sys
import time

import pytest

from ros_harness import domain_id, id_node_cmd, NodeProcess, ros_env

DOMAIN = domain_id(67)
XACRO = """<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="prefix" default=""/>
  <xacro:include filename="$(find arm_description)/urdf/arm.ros2_control.xacro"/>
  <xacro:property name="upper_arm" value="0.42"/>
  <link name="base_link"/>
</robot>
"""
XACRO_LINE = ('arm.urdf.xacro: xacro, not URDF (<xacro:arg>): expand it '
              'with xacro first')


def cli(*args):
    exe = os.path.join(os.path.dirname(sys.executable), 'newton-euler')
    return subprocess.run([exe, *map(str, args)], capture_output=True,
                          text=True, timeout=120, env=ros_env(DOMAIN))


@pytest.fixture(scope='module')
def files(tmp_path_factory):
    from newton_euler_tools.peers import example_robot_urdf
    root = tmp_path_factory.mktemp('descriptions')
    xacro = root / 'arm.urdf.xacro'
    xacro.write_text(XACRO)
    ur5 = root / 'ur5.xml'
    shutil.copyfile(example_robot_urdf('ur_description/urdf/ur5_robot.urdf'),
                    ur5)
    return {'xacro': xacro, 'ur5': ur5}


@pytest.mark.parametrize('command', [
    ['check', '{xacro}'], ['dynamics', '{xacro}', '--q', '0'],
    ['urdf', '{xacro}'],
    ['excite', '{xacro}', '--base', 'a', '--tip', 'b', '-o', 'x.json'],
])
def test_cli_says_expand_the_xacro_first(command, files, tmp_path):
    args = [a.format(**files) for a in command]
    if 'excite' in args:
        args[-1] = str(tmp_path / 'x.json')
    proc = cli(*args)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith('newton-euler: error: ') \
        and lines[0].endswith(XACRO_LINE), proc.stderr
    assert proc.stdout == '' and not (tmp_path / 'x.json').exists()


def test_cli_reads_a_urdf_under_another_name(files):
    proc = cli('check', files['ur5'], '--base', 'base_link', '--tip', 'tool0')
    assert proc.returncode == 0, proc.stderr
    assert 'joints: 6 (RRRRRR), URDF chain base_link -> tool0' in proc.stdout


def test_node_says_expand_the_xacro_first(files):
    proc = subprocess.run(id_node_cmd(None, '-p',
                                      f'robot_file:={files["xacro"]}'),
                          capture_output=True, text=True, timeout=120,
                          env=ros_env(DOMAIN))
    assert proc.returncode == 2, proc.stderr
    lines = [x for x in proc.stderr.splitlines() if not x.startswith('[')]
    assert lines == ['inverse_dynamics_node: invalid configuration: '
                     f'robot_file: {XACRO_LINE}'], proc.stderr


def test_node_reads_a_urdf_under_another_name(files, tmp_path):
    node = NodeProcess(id_node_cmd(None, '-p', f'robot_file:={files["ur5"]}',
                                   '-p', 'base_link:=base_link',
                                   '-p', 'tip_link:=tool0'),
                       DOMAIN, str(tmp_path / 'node.log'))
    try:
        deadline = time.monotonic() + 90.0
        while 'ur5 (' not in node.log() and time.monotonic() < deadline:
            assert node.alive(), node.log()
            time.sleep(0.2)
        assert 'ur5 (' in node.log() and '6 joints' in node.log(), \
            node.log()
    finally:
        assert node.stop() == 0, node.log()
