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
One way to read a URDF: only ``<robot>``'s own links and joints count.

A published ros2_control description repeats every joint name inside
``<ros2_control>`` and ``<transmission>`` blocks.  The model, its limits,
its drive terms (friction, rotor inertia, offsets, torque constants) and
the identified-URDF writer must read and write the tree's joints only:
reading the last element of a name lost the drive terms of every
identified URDF that had such blocks.
"""
import warnings
import xml.etree.ElementTree as ET

from descriptions import as_published
from newton_euler_ros.core import load_urdf, RobotFileError
from newton_euler_ros.core.drives import Drives, DRIVES_NS, model_drives
from newton_euler_ros.core.regressor import inertial_parameters
from newton_euler_ros.ident.fit import fixed_parts
from newton_euler_ros.ident.urdf_out import identified_urdf
from newton_euler_tools.peers import example_robot_urdf
import numpy as np
import pytest

# (style, file under example-robot-data's robots/, base, tip)
CASES = [
    ('ur', 'ur_description/urdf/ur5_robot.urdf', 'base_link', 'tool0'),
    ('franka', 'panda_description/urdf/panda.urdf', 'panda_link0',
     'panda_link8'),
    ('kinova', 'kinova_description/robots/kinova.urdf', 'base',
     'j2s6s200_end_effector'),
]


def _text(rel):
    with open(example_robot_urdf(rel), encoding='utf-8') as f:
        return f.read()


def _load(text, base, tip):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_urdf(text, base=base, tip=tip)


def _arrays(model):
    return (model.links_array, model.frames_array)


@pytest.mark.parametrize('style, rel, base, tip', CASES)
def test_published_blocks_change_nothing(style, rel, base, tip):
    plain = _text(rel)
    shaped = as_published(plain, style, tip=None)
    a = _load(plain, base, tip)
    b = _load(shaped, base, tip)
    assert a.joint_names == b.joint_names
    for x, y in zip(_arrays(a), _arrays(b)):
        np.testing.assert_array_equal(x, y)
    assert a.limits == b.limits
    da, db = model_drives(a), model_drives(b)
    assert (da is None) == (db is None)
    if da is not None:      # the UR5's <dynamics damping="0.0" ...>
        np.testing.assert_array_equal(da.parameters(), db.parameters())


@pytest.mark.parametrize('style, rel, base, tip', CASES)
def test_a_mimic_gripper_is_carried_by_the_tip(style, rel, base, tip):
    plain = _text(rel)
    a = _load(plain, base, tip)
    b = _load(as_published(plain, style, tip=tip), base, tip)
    # the gripper (0.3 kg base, two 0.05 kg fingers) rides on the tip link
    assert b.total_mass == pytest.approx(a.total_mass + 0.4, rel=1e-12)
    np.testing.assert_array_equal(a.mass[:-1], b.mass[:-1])


def _drives(n, rng, constants):
    return Drives(rng.uniform(0.1, 1, n), rng.uniform(0.5, 5, n),
                  rng.uniform(-1, 1, n), rng.uniform(0.01, 0.5, n),
                  np.full(n, 0.03),
                  rng.uniform(5, 15, n) if constants else None)


@pytest.mark.parametrize('constants', [False, True])
@pytest.mark.parametrize('style, rel, base, tip', CASES)
def test_identified_urdf_reads_back_its_drives(style, rel, base, tip,
                                               constants):
    rng = np.random.default_rng(len(rel))
    shaped = as_published(_text(rel), style, tip=tip)
    model = _load(shaped, base, tip)
    drives = _drives(model.n, rng, constants)
    # one factor >= 1 per link keeps every link's own part (what remains
    # after the parts it carries are taken off) physically consistent
    theta = inertial_parameters(model) * np.repeat(
        rng.uniform(1.0, 1.2, model.n), 10)
    out = identified_urdf(shaped, model, theta, fixed_parts(model, shaped),
                          drives)
    back = _load(out, base, tip)
    got = model_drives(back)
    assert got is not None, 'the drive terms were lost on reading back'
    for key in ('viscous', 'coulomb', 'offset', 'armature',
                'coulomb_width'):
        np.testing.assert_array_equal(getattr(got, key),
                                      getattr(drives, key), err_msg=key)
    if constants:
        np.testing.assert_array_equal(got.torque_constant,
                                      drives.torque_constant)
    else:
        assert got.torque_constant is None
    np.testing.assert_allclose(inertial_parameters(back), theta, rtol=1e-9,
                               atol=1e-12)
    # the writer touched only the tree's joints: the ros2_control and
    # transmission blocks still have no <dynamics> or <ne:drive>
    root = ET.fromstring(out)
    blocks = root.findall('ros2_control') + root.findall('transmission')
    assert len(blocks) >= 1 + model.n
    for block in blocks:
        for el in block.iter():
            assert el.tag not in ('dynamics', f'{{{DRIVES_NS}}}drive'), \
                block.get('name')


def _with_drive(text, joint, attrs):
    el = f'<ne:drive {attrs}/>'
    i = text.index(f'<joint name="{joint}"')
    k = text.index('</joint>', i)
    return text[:k] + el + text[k:]


def test_torque_constants_all_or_none_and_positive():
    style, rel, base, tip = CASES[0]
    shaped = as_published(_text(rel), style)
    shaped = shaped.replace('<robot ', f'<robot xmlns:ne="{DRIVES_NS}" ', 1)
    model = _load(shaped, base, tip)
    one = _with_drive(shaped, model.joint_names[0], 'torque_constant="9.5"')
    with pytest.raises(RobotFileError,
                       match='torque_constant is given for some joints but '
                             "not for 'shoulder_lift_joint'") as info:
        _load(one, base, tip)
    assert '\n' not in str(info.value)
    bad = _with_drive(shaped, model.joint_names[1], 'torque_constant="-2"')
    with pytest.raises(RobotFileError,
                       match=r"joint 'shoulder_lift_joint' <ne:drive> "
                             'torque_constant: must be > 0'):
        _load(bad, base, tip)


def test_efforts_and_torques_convert_through_the_constants():
    d = Drives.zeros(3, torque_constant=[2.0, 4.0, 0.5])
    effort = np.array([[1.0, -2.0, 3.0], [0.5, 0.25, -4.0]])
    np.testing.assert_array_equal(d.effort_to_torque(effort),
                                  effort * [2.0, 4.0, 0.5])
    np.testing.assert_allclose(d.torque_to_effort(d.effort_to_torque(effort)),
                               effort, rtol=1e-15)
    plain = Drives.zeros(3)
    assert plain.torque_constant is None
    np.testing.assert_array_equal(plain.effort_to_torque(effort), effort)
    with pytest.raises(ValueError, match='torque constants'):
        Drives.zeros(2, torque_constant=[1.0, 0.0])
