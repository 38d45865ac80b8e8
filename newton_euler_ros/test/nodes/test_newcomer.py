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

Missing joints are all named, with the names the input has: in a bag
(identify, replay, observe, payload) and in a JointState or a service
request to the node (also through examples/compute_dynamics_client.py,
which takes the robot's joint names and state).  replay says why its
low-passed error can exceed the raw one.
"""
import os
import shutil
import subprocess
import sys
import time

from newton_euler_ros.ident.bag_write import write_joint_states
from newton_euler_tools.ident_example import BASE, make_example, TIP
import numpy as np
import pytest

from ros_harness import (domain_id, id_node_cmd, joint_state,  # noqa: I100
                         NodeProcess, Probe, ros_env)

DOMAIN = domain_id(67)
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))))
PUMA = [f'joint{k}' for k in range(1, 7)]
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
    ['excite', '{xacro}', '--base', 'a', '--tip', 'b', '--start', '0',
     '-o', 'x.json'],
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


# ---------------------------------------------------------------------------
# missing joints, all named with the names the input has
# ---------------------------------------------------------------------------
CHAIN = ['--base', BASE, '--tip', TIP]
ARM = [f'panda_joint{k}' for k in range(1, 8)]
# a recording of another arm's driver: four of the joints, and a gripper
RECORDED = ARM[:4] + ['gripper_left', 'gripper_right']
BAG_LINE = ('chain joint(s) panda_joint5, panda_joint6, panda_joint7 not in '
            "the JointState messages on '/joint_states'; they name 6 "
            'joint(s): panda_joint1, panda_joint2, panda_joint3, '
            'panda_joint4, gripper_left, gripper_right')


@pytest.fixture(scope='module')
def loop(tmp_path_factory):
    root = tmp_path_factory.mktemp('loop')
    example = make_example(str(root / 'example'), seconds=8.0, rate=100.0,
                           seed=7, validation=False)
    m = 300
    stamps = 10 ** 9 + np.arange(m, dtype=np.int64) * 10 ** 7
    values = np.zeros((m, len(RECORDED)))
    bag = root / 'other_names'
    write_joint_states(str(bag), stamps, RECORDED, values, values, values)
    return {**example, 'other': str(bag), 'root': root}


@pytest.mark.parametrize('command, extra', [
    ('identify', ['-o', '{root}/out.urdf']),
    ('replay', ['--csv', '{root}/out.csv']),
    ('observe', ['--csv', '{root}/out.csv']),
    ('payload', []),
])
def test_bag_missing_joints_are_all_named(command, extra, loop):
    proc = cli(command, loop['urdf'], loop['other'], *CHAIN,
               *[a.format(**loop) for a in extra])
    assert proc.returncode == 2, proc.stderr
    lines = [x for x in proc.stderr.splitlines()
             if not x.startswith(('warning:', 'note:'))]
    assert len(lines) == 1 and lines[0].endswith(BAG_LINE), proc.stderr
    assert loop['other'] in lines[0]


def test_replay_says_why_filtered_can_exceed_raw(loop, tmp_path):
    proc = cli('replay', loop['urdf'], loop['recording'], *CHAIN, '--csv',
               tmp_path / 'replay.csv')
    assert proc.returncode == 0, proc.stderr
    words = ' '.join(proc.stdout.split())
    assert 'rel % raw' in words
    assert ('(the 10 Hz column compares with the effort low-passed like the '
            'state: free of noise, but smoothed where a joint reverses, '
            "while the model's friction still switches sharply there, so on "
            'a joint with friction and little noise it can exceed the raw '
            'one; docs/identification.md)') in words, proc.stdout


def test_node_names_every_missing_joint(tmp_path):
    from newton_euler_interfaces.srv import ComputeDynamics
    from sensor_msgs.msg import JointState
    probe = Probe(DOMAIN)
    node = NodeProcess(id_node_cmd('puma560.yaml'), DOMAIN,
                       str(tmp_path / 'node.log'))
    names = ['joint1', 'joint2', 'joint3', 'gripper_finger']
    expected = ("missing joints ['joint4', 'joint5', 'joint6']; the message "
                "names 4: ['joint1', 'joint2', 'joint3', 'gripper_finger']")
    try:
        js = probe.publisher(JointState, 'joint_states')
        assert probe.spin_until(lambda: js.get_subscription_count() > 0
                                and 'puma560 (' in node.log(), 90.0), \
            node.log()
        js.publish(joint_state(names, [0.1] * 4, [0.0] * 4,
                               probe.keyed_stamp(1)))
        assert probe.spin_until(lambda: 'missing joints' in node.log(),
                                10.0), node.log()
        assert f'dropped joint state: {expected} (missing_joints: 1 so ' \
            'far)' in node.log(), node.log()
        reply = probe.call(ComputeDynamics,
                           '/inverse_dynamics_node/compute_dynamics',
                           ComputeDynamics.Request(name=names,
                                                   position=[0.1] * 4))
        assert not reply.success and reply.message == expected, \
            reply.message
        # the example client, with the robot's joints and state
        client = [sys.executable, os.path.join(ROOT, 'examples',
                                               'compute_dynamics_client.py')]
        proc = subprocess.run(
            client + ['--joints', *reversed(PUMA), '--q', *'0.3 0.2 0.1 '
                      '-0.3 0.5 0'.split(), '--qd', *['0.1'] * 6],
            capture_output=True, text=True, timeout=120, env=ros_env(DOMAIN))
        assert proc.returncode == 0, proc.stderr
        assert f'joints {PUMA}' in proc.stdout and 'tau = ' in proc.stdout
        proc = subprocess.run(client + ['--joints', *names, '--q',
                                        *['0.1'] * 4],
                              capture_output=True, text=True, timeout=120,
                              env=ros_env(DOMAIN))
        assert proc.returncode == 1 and proc.stderr.strip() == \
            f'/inverse_dynamics_node/compute_dynamics: {expected}', \
            proc.stderr
        proc = subprocess.run(client + ['--joints', 'a', 'b', '--q', '1'],
                              capture_output=True, text=True, timeout=60)
        assert proc.returncode == 2 and proc.stderr.strip().endswith(
            'error: --q: 1 values for 2 joints'), proc.stderr
    finally:
        code = node.stop()
        probe.close()
    assert code == 0, node.log()
