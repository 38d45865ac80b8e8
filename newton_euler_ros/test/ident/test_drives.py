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

"""Drive terms: read back from URDF, used by the feedforward and the node."""
import os
import warnings

from descriptions import as_published
from newton_euler_ros.core import inverse_dynamics, load_robot, RobotFileError
from newton_euler_ros.core.drives import Drives, DRIVES_NS, model_drives
from newton_euler_ros.core.urdf import load_urdf, model_to_urdf
from newton_euler_ros.feedforward import FeedforwardComputer
from newton_euler_ros.joint_inputs import JointOrder
from newton_euler_ros.wrenches import WrenchInput
import numpy as np
import pytest

VIS = [0.3, 0.2, 0.1, 0.05, 0.04, 0.03]
COUL = [1.0, 0.8, 0.6, 0.2, 0.1, 0.05]
ARM = [0.2, 0.3, 0.1, 0.01, 0.01, 0.005]
OFF = [0.1, -0.2, 0.0, 0.05, 0.0, -0.01]
WIDTH = 0.05


def puma_urdf(drives=True, bad=None):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot('puma560')
    text = model_to_urdf(model)
    text = text.replace('<robot ', f'<robot xmlns:ne="{DRIVES_NS}" ', 1)
    if not drives:
        return model, text
    for j, name in enumerate(model.joint_names):
        extra = (f'<dynamics damping="{VIS[j]}" friction="{COUL[j]}"/>'
                 f'<ne:drive armature="{ARM[j]}" offset="{OFF[j]}" '
                 f'coulomb_width="{WIDTH}"/>')
        if bad and j == 2:
            extra = bad
        i = text.index(f'<joint name="{name}"')
        k = text.index('</joint>', i)
        text = text[:k] + extra + text[k:]
    return model, text


def quiet_urdf(text):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_urdf(text, tip='tool0')


def test_read_back_from_urdf():
    _, text = puma_urdf()
    d = model_drives(quiet_urdf(text))
    np.testing.assert_array_equal(d.viscous, VIS)
    np.testing.assert_array_equal(d.coulomb, COUL)
    np.testing.assert_array_equal(d.armature, ARM)
    np.testing.assert_array_equal(d.offset, OFF)
    np.testing.assert_array_equal(d.coulomb_width, WIDTH)
    assert model_drives(quiet_urdf(puma_urdf(drives=False)[1])) is None


@pytest.mark.parametrize('bad, text', [
    ('<dynamics damping="-1"/>',
     r"joint 'joint3' <dynamics> damping: must be >= 0"),
    ('<dynamics friction="nan"/>', '<dynamics> friction: must be a finite'),
    ('<ne:drive armature="-0.1"/>', '<ne:drive> armature: must be >= 0'),
    ('<ne:drive coulomb_width="0"/>', 'coulomb_width: must be > 0'),
    # a mistyped attribute is not dropped (armature 0 would be read)
    ('<ne:drive armatur="0.3"/>',
     r"joint 'joint3' <ne:drive>: unknown attribute 'armatur' \(it takes "
     'armature, offset, coulomb_width, torque_constant'),
    ('<ne:drive armature="0.3"/><ne:drive armature="0.1"/>',
     r"joint 'joint3': <ne:drive> given 2 times \(once at most\)"),
    ('<dynamics damping="1"/><dynamics damping="2"/>',
     r"joint 'joint3': <dynamics> given 2 times"),
])
def test_bad_drive_values_are_one_line(bad, text):
    _, urdf = puma_urdf(bad=bad)
    with pytest.raises(RobotFileError, match=text) as info:
        quiet_urdf(urdf)
    assert '\n' not in str(info.value)


@pytest.mark.parametrize('where, path', [
    ('<ros2_control name="arm" type="system"><joint name="joint2">{}'
     '</joint></ros2_control>',
     "<robot name='puma560'> <ros2_control name='arm'> <joint "
     "name='joint2'>"),
    ('{}', "<robot name='puma560'>"),
])
def test_a_drive_element_where_it_is_not_read_is_refused(where, path):
    # ignored there, a user's torque constants would silently be lost
    _, urdf = puma_urdf()
    placed = where.format('<ne:drive torque_constant="9"/>')
    urdf = urdf.replace('</robot>', placed + '</robot>')
    with pytest.raises(RobotFileError) as info:
        quiet_urdf(urdf)
    assert str(info.value) == (
        f'robot_description: <ne:drive> inside {path}: it is read only as a '
        f"child of the <robot> element's own <joint>")


def test_a_drive_namespace_of_another_version_is_refused():
    _, urdf = puma_urdf()
    other = DRIVES_NS[:-1] + '2'
    with pytest.raises(RobotFileError) as info:
        quiet_urdf(urdf.replace(DRIVES_NS, other))
    assert str(info.value) == (
        f"robot_description: <drive> of namespace '{other}': not one this "
        f'version reads ({DRIVES_NS})')


def test_check_says_the_drive_terms_it_read(tmp_path):
    import subprocess
    import sys
    _, urdf = puma_urdf()
    path = tmp_path / 'drives.urdf'
    path.write_text(urdf)
    proc = subprocess.run([sys.executable, '-m', 'newton_euler_ros.cli',
                           'check', str(path), '--tip', 'tool0'],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    i = next(k for k, x in enumerate(lines) if 'drive terms (' in x)
    assert 'no torque constants' in lines[i]
    for j in range(6):
        name, values = lines[i + 1 + j].strip().split(': ')
        assert name == f'joint{j + 1}'
        np.testing.assert_array_equal(
            [float(v) for v in values.split(', ')],
            [VIS[j], COUL[j], WIDTH, ARM[j], OFF[j]])


def test_a_byte_order_mark_is_not_part_of_the_urdf(tmp_path):
    _, urdf = puma_urdf()
    want = model_drives(quiet_urdf(urdf))
    path = tmp_path / 'bom.urdf'
    path.write_text('\ufeff' + urdf, encoding='utf-8')
    for given in ('\ufeff' + urdf, str(path)):
        got = model_drives(quiet_urdf(given))
        np.testing.assert_array_equal(got.viscous, want.viscous)
        np.testing.assert_array_equal(got.armature, want.armature)


def test_drive_torques_and_coulomb_near_rest():
    d = Drives(np.array([0.5]), np.array([2.0]), np.array([0.1]),
               np.array([0.3]), np.array([0.02]))
    assert d.torques([0.0], [0.0])[0] == pytest.approx(0.1)    # at rest
    assert d.torques([0.02], [0.0])[0] == pytest.approx(
        0.5 * 0.02 + 2.0 * np.tanh(1.0) + 0.1)
    assert d.torques([0.1], [1.0])[0] == pytest.approx(
        0.05 + 2.0 * np.tanh(5.0) + 0.1 + 0.3, rel=1e-12)
    assert d.torques([-1.0], [0.0])[0] == pytest.approx(-0.5 - 2.0 + 0.1)


def test_feedforward_adds_the_drives_when_given():
    _, text = puma_urdf()
    model = quiet_urdf(text)
    drives = model_drives(model)
    order = JointOrder(model.joint_names)
    rng = np.random.default_rng(0)
    q, qd = rng.normal(size=(2, model.n))
    for mode in ('gravity_coriolis', 'gravity'):
        ff = FeedforwardComputer(model, order, WrenchInput([], []),
                                 mode=mode)
        rigid = ff.torques(model.joint_names, q, qd, 0.0, 0.0).copy()
        ff.drives = drives
        tau = ff.torques(model.joint_names, q, qd, 0.0, 0.0)
        used = qd if mode != 'gravity' else np.zeros(model.n)
        np.testing.assert_allclose(
            tau, rigid + drives.torques(used, np.zeros(model.n)),
            rtol=1e-13, atol=1e-13)


@pytest.mark.ros
def test_node_compensates_only_when_asked(tmp_path):
    pytest.importorskip('rclpy')
    from ros_harness import (domain_id, id_node_cmd, joint_state,
                             NodeProcess, Probe)
    from sensor_msgs.msg import JointState
    _, text = puma_urdf()
    # as a ros2_control robot publishes it: every joint name also appears
    # in <ros2_control> and <transmission> blocks after the tree
    path = tmp_path / 'puma_drives.urdf'
    path.write_text(as_published(text, 'franka'))
    model = quiet_urdf(text)
    drives = model_drives(model)
    domain = domain_id(61)
    common = ['-p', f'robot_file:={path}', '-p', 'tip_link:=tool0']
    nodes = {
        'on': NodeProcess(id_node_cmd(None, *common, '-p',
                                      'drives.compensate:=true', '-r',
                                      '__node:=ff_on'), domain,
                          os.path.join(tmp_path, 'on.log')),
        'off': NodeProcess(id_node_cmd(None, *common, '-r',
                                       '__node:=ff_off'), domain,
                           os.path.join(tmp_path, 'off.log')),
    }
    probe = Probe(domain)
    try:
        boxes = {k: probe.collect(JointState, f'/ff_{k}/torques')
                 for k in nodes}
        js = probe.publisher(JointState, 'joint_states')
        assert probe.spin_until(lambda: js.get_subscription_count() >= 2,
                                120.0), (js.get_subscription_count(),
                                         nodes['on'].log(),
                                         nodes['off'].log())
        # a node may drop what arrives before it is matched and warm:
        # send until both answer (as test_urdf_node.py's graph does)
        for seq in range(100, 220):
            stamp = probe.keyed_stamp(seq)
            js.publish(joint_state(model.joint_names, np.zeros(model.n),
                                   np.zeros(model.n), stamp))
            if (probe.answer(boxes['on'], stamp, 0.5) is not None
                    and probe.answer(boxes['off'], stamp, 0.5) is not None):
                break
        rng = np.random.default_rng(1)
        for seq in range(1, 4):
            q, qd = rng.uniform(-1, 1, (2, model.n))
            stamp = probe.keyed_stamp(seq)
            js.publish(joint_state(model.joint_names, q, qd, stamp))
            rigid = inverse_dynamics(model, q, qd)
            on = probe.answer(boxes['on'], stamp, 10.0)
            off = probe.answer(boxes['off'], stamp, 10.0)
            assert on is not None, nodes['on'].log()
            assert off is not None, nodes['off'].log()
            np.testing.assert_allclose(off.effort, rigid, rtol=1e-12,
                                       atol=1e-12)
            np.testing.assert_allclose(
                on.effort, rigid + drives.torques(qd, np.zeros(model.n)),
                rtol=1e-12, atol=1e-12)
        assert (f'drive terms compensated (largest Coulomb friction '
                f'{max(COUL):.3g}, rotor inertia {max(ARM):.3g}; '
                f'newton-euler check lists them)') in nodes['on'].log()
    finally:
        for node in nodes.values():
            node.stop()
        probe.close()
