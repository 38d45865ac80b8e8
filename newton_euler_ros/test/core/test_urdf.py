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
URDF robots, checked against references that do not use our loader.

- DH -> URDF -> model round trip for every bundled robot, both
  conventions: the same tau, D, C, g and J (the DH path is itself checked
  against Euler-Lagrange and Pinocchio elsewhere).
- Fixed-joint merging and inertial-origin rotation worked out by hand.
- The Euler-Lagrange oracle (``reference_dynamics``, its own rotation
  about an arbitrary axis) on URDF chains with tilted axes, prismatic and
  continuous joints.
- Pinocchio's own URDF reader on published URDFs (``make peers``).
- Every error names the source, the element and the attribute.
"""
import json
import math
import subprocess
import sys
import warnings

from newton_euler_ros.core import (bundled_robots, coriolis_matrix,
                                   gravity_torques, inverse_dynamics,
                                   jacobian, load_robot, mass_matrix,
                                   RobotFileError)
from newton_euler_ros.core.highprec import HighPrecisionModel, relative_error
from newton_euler_ros.core.model import convert_convention
from newton_euler_ros.core.robot_file import RobotFileWarning
from newton_euler_ros.core.urdf import (inspect_urdf, load_urdf, matrix_rpy,
                                        model_to_urdf)
import numpy as np
import pytest
import reference_dynamics as ref
from cli_harness import newton_euler  # noqa: E402, I100

EPS = np.finfo(float).eps

INERTIAL = ('<inertial><origin xyz="{xyz}" rpy="{rpy}"/><mass value="{m}"/>'
            '<inertia ixx="{ixx}" ixy="{ixy}" ixz="0" iyy="{iyy}" iyz="0" '
            'izz="{izz}"/></inertial>')


def inertial(m, xyz='0 0 0', rpy='0 0 0', ixx=0.01, iyy=0.02, izz=0.03,
             ixy=0.0):
    return INERTIAL.format(m=m, xyz=xyz, rpy=rpy, ixx=ixx, iyy=iyy, izz=izz,
                           ixy=ixy)


# A chain with everything the loader must handle: a fixed root joint, an
# off-axis revolute joint, a prismatic joint with a rotated origin, a
# continuous joint about -z, an off-chain (locked) finger and a fixed tool.
ARM = f"""<?xml version="1.0"?>
<robot name="testarm">
  <link name="world"/>
  <link name="base_link">{inertial(5.0)}</link>
  <joint name="mount" type="fixed"><parent link="world"/>
    <child link="base_link"/><origin xyz="0 0 0.1"/></joint>
  <link name="l1">{inertial(2.0, '0.2 0 0', '0.1 0.2 0.3', ixy=0.004)}</link>
  <joint name="j1" type="revolute"><parent link="base_link"/>
    <child link="l1"/><origin xyz="0 0 0.3" rpy="0 0.5 0"/>
    <axis xyz="0 1 1"/>
    <limit lower="-1" upper="1" effort="40" velocity="2"/></joint>
  <link name="l2">{inertial(1.5, '0.1 0.05 0', '0 0 0', 0.05, 0.06, 0.07)}
  </link>
  <joint name="j2" type="prismatic"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.4 0 0" rpy="0.3 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-0.5" upper="0.5" effort="100" velocity="1"/></joint>
  <link name="l3">{inertial(0.5, '0 0.02 0.03', '0.4 -0.2 0.1')}</link>
  <joint name="j3" type="continuous"><parent link="l2"/><child link="l3"/>
    <origin xyz="0 0.2 0" rpy="0 0 1.0"/><axis xyz="0 0 -1"/>
    <limit effort="5" velocity="3"/></joint>
  <link name="finger">{inertial(0.2, '0 0 0.05')}</link>
  <joint name="grip" type="prismatic"><parent link="l2"/>
    <child link="finger"/><origin xyz="0 0.1 0"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="10" velocity="1"/></joint>
  <link name="tool0"/>
  <joint name="flange" type="fixed"><parent link="l3"/><child link="tool0"/>
    <origin xyz="0 0 0.1" rpy="0 1.5707963267948966 0"/></joint>
</robot>
"""


def arm(**kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        return load_urdf(ARM, **kw)


def quiet_load(*args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        return load_robot(*args, **kw)


def rel(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return np.abs(a - b).max() / max(np.abs(b).max(), 1e-300)


# ---------------------------------------------------------------------------
# round trip DH -> URDF -> model
# ---------------------------------------------------------------------------
@pytest.mark.parametrize('convention', ['standard', 'modified'])
@pytest.mark.parametrize('name', bundled_robots())
def test_dh_to_urdf_round_trip_gives_the_same_dynamics(name, convention):
    dh = convert_convention(quiet_load(name), convention)
    text = model_to_urdf(dh)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        urdf = load_urdf(text, gravity=dh.gravity)
    assert urdf.joint_names == dh.joint_names
    assert urdf.joint_types == dh.joint_types
    assert urdf.total_mass == pytest.approx(dh.total_mass, rel=1e-15)
    rng = np.random.default_rng(sum(map(ord, name)))
    for _ in range(5):
        q, qd, qdd = rng.uniform(-2, 2, size=(3, dh.n))
        w = rng.normal(size=6) * 10
        for frame in ('base', 'end_effector'):
            assert rel(inverse_dynamics(urdf, q, qd, qdd, w, frame),
                       inverse_dynamics(dh, q, qd, qdd, w, frame)) < 1e-13
            assert rel(jacobian(urdf, q, frame), jacobian(dh, q, frame)) \
                < 1e-13
        assert rel(mass_matrix(urdf, q), mass_matrix(dh, q)) < 1e-13
        assert rel(coriolis_matrix(urdf, q, qd),
                   coriolis_matrix(dh, q, qd)) < 1e-13
        assert rel(gravity_torques(urdf, q), gravity_torques(dh, q)) < 1e-13
    # limits survive (revolute joints without position limits become
    # continuous, which has none)
    for a, b in zip(urdf.limits, dh.limits):
        assert {k: v for k, v in b.items() if k in a} == a


def test_cli_urdf_writes_a_loadable_file(tmp_path):
    out = tmp_path / 'puma.urdf'
    proc = subprocess.run([sys.executable, '-m', 'newton_euler_ros.cli',
                           'urdf', 'puma560', '-o', str(out)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    model = quiet_load(str(out), base='base_link', tip='tool0')
    assert model.n == 6 and model.info['urdf']['merged_fixed'] == [
        'tool0_joint']


def test_matrix_rpy_inverts_rpy_including_gimbal_lock():
    from newton_euler_ros.core.model import rpy_matrix
    rng = np.random.default_rng(3)
    for angles in list(rng.uniform(-3, 3, size=(50, 3))) + [
            (0.3, math.pi / 2, -0.2), (0.1, -math.pi / 2, 0.4)]:
        R = rpy_matrix(*angles)
        np.testing.assert_allclose(rpy_matrix(*matrix_rpy(R)), R,
                                   atol=1e-15)


# ---------------------------------------------------------------------------
# by hand
# ---------------------------------------------------------------------------
def test_inertial_origin_rotates_the_tensor_but_not_the_centre_of_mass():
    # yaw 90 deg swaps x and y: diag(1, 2, 3) about the com becomes
    # diag(2, 1, 3) in link axes; the com stays at the origin's xyz.
    text = f"""<robot name="r"><link name="b"/>
      <link name="a">{inertial(3.0, '0.1 0.2 0.3', '0 0 1.5707963267948966',
                               1.0, 2.0, 3.0)}</link>
      <joint name="j" type="revolute"><parent link="b"/><child link="a"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1"
        velocity="1"/></joint></robot>"""
    model = load_urdf(text)
    np.testing.assert_allclose(model.com[0], [0.1, 0.2, 0.3], atol=0)
    np.testing.assert_allclose(model.inertia[0], np.diag([2.0, 1.0, 3.0]),
                               atol=1e-15)


def test_fixed_joints_merge_by_the_parallel_axis_theorem():
    # link a (2 kg at its origin, I = diag(1, 1, 1)) carries b (1 kg point
    # mass, I = 0) through a fixed joint 0.3 m along x: 3 kg with the com at
    # x = 0.1; about it, Iyy = Izz = 1 + 2 (0.1)^2 + 1 (0.2)^2 = 1.06.
    text = f"""<robot name="r"><link name="base"/>
      <link name="a">{inertial(2.0, ixx=1.0, iyy=1.0, izz=1.0)}</link>
      <link name="b">{inertial(1.0, ixx=0.0, iyy=0.0, izz=0.0)}</link>
      <joint name="j" type="revolute"><parent link="base"/>
        <child link="a"/><axis xyz="0 1 0"/><origin xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="50" velocity="1"/></joint>
      <joint name="weld" type="fixed"><parent link="a"/><child link="b"/>
        <origin xyz="0.3 0 0"/></joint></robot>"""
    model = load_urdf(text)
    assert model.mass[0] == 3.0
    np.testing.assert_allclose(model.com[0], [0.1, 0.0, 0.0], atol=1e-16)
    np.testing.assert_allclose(model.inertia[0],
                               np.diag([1.0, 1.06, 1.06]), atol=1e-15)
    # the tool is the tip link b, 0.3 m out; holding the arm horizontal
    # takes m g x_com about the y axis, and D is I_yy about the axis
    assert model.info['urdf']['tip'] == 'b'
    np.testing.assert_allclose(model.tool[:3, 3], [0.3, 0.0, 0.0])
    # rotating about +y by q = 0 with gravity -z: torque = -(m g x) (the
    # weight pulls the +x arm down, i.e. a negative rotation about +y)
    assert gravity_torques(model, [0.0])[0] == pytest.approx(
        -3.0 * 9.81 * 0.1, rel=1e-15)
    assert mass_matrix(model, [0.7])[0, 0] == pytest.approx(
        1.0 + 2.0 * 0.0 + 1.0 * 0.09, rel=1e-15)


def test_rotated_fixed_joint_rotates_the_merged_inertia():
    # link a (massless, no inertial) carries b through a fixed joint with
    # a 90 deg yaw and no translation: b's anisotropic diag(1, 2, 3) about
    # its com at its origin becomes diag(2, 1, 3) in a's axes (a yaw of
    # 90 deg maps b's x axis onto a's y axis, so Ixx and Iyy swap).  An
    # off-axis com (0.1, 0, 0) in b turns into (0, 0.1, 0) in a.
    text = f"""<robot name="r"><link name="base"/><link name="a"/>
      <link name="b">{inertial(2.0, '0.1 0 0', ixx=1.0, iyy=2.0,
                                izz=3.0)}</link>
      <joint name="j" type="revolute"><parent link="base"/>
        <child link="a"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="50" velocity="1"/></joint>
      <joint name="weld" type="fixed"><parent link="a"/><child link="b"/>
        <origin rpy="0 0 1.5707963267948966"/></joint></robot>"""
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        model = load_urdf(text)
    assert model.info['urdf']['merged_fixed'] == ['weld']
    assert model.mass[0] == 2.0
    np.testing.assert_allclose(model.com[0], [0.0, 0.1, 0.0], atol=1e-16)
    np.testing.assert_allclose(model.inertia[0], np.diag([2.0, 1.0, 3.0]),
                               atol=1e-15)
    # about the vertical joint axis: Izz + m r^2 = 3 + 2 (0.1)^2
    assert mass_matrix(model, [0.4])[0, 0] == pytest.approx(3.02, rel=1e-15)


TILTED = ('<robot name="r"><link name="base"/>{links}'
          '<joint name="j1" type="revolute"><parent link="base"/>'
          '<child link="a"/><axis xyz="0 0 1"/><origin xyz="0 0 0.2"/>'
          '<limit lower="-3" upper="3" effort="50" velocity="1"/></joint>'
          '<joint name="j2" type="revolute"><parent link="a"/>'
          '<child link="b"/><axis xyz="0 1 0"/><origin xyz="0.3 0 0"/>'
          '<limit lower="-3" upper="3" effort="50" velocity="1"/></joint>'
          '{extra}</robot>')


def test_a_body_through_an_extra_rotated_fixed_joint_has_the_same_dynamics():
    # The same body of link b written twice: directly in b, and in a link
    # c welded to b by a fixed joint with a general rotation and offset,
    # its inertial re-expressed in c's axes by hand (c's pose in b is
    # (R, p): com_c = R^T (com_b - p), I_c = R^T I_b R).  The dynamics
    # must not tell them apart.
    from newton_euler_ros.core.model import pose_matrix
    com_b = np.array([0.05, -0.02, 0.1])
    I_b = np.array([[0.02, 0.003, -0.001], [0.003, 0.05, 0.002],
                    [-0.001, 0.002, 0.07]])
    xyz, rpy = (0.1, 0.2, -0.05), (0.4, -0.7, 1.1)
    T = pose_matrix(xyz, rpy)
    R, p = T[:3, :3], T[:3, 3]
    com_c = R.T @ (com_b - p)
    I_c = R.T @ I_b @ R

    def body(name, m, com, inertia):
        i = inertia
        return (f'<link name="{name}"><inertial><origin xyz="'
                f'{" ".join(repr(float(x)) for x in com)}"/>'
                f'<mass value="{m}"/><inertia ixx="{float(i[0, 0])!r}" '
                f'ixy="{float(i[0, 1])!r}" ixz="{float(i[0, 2])!r}" '
                f'iyy="{float(i[1, 1])!r}" iyz="{float(i[1, 2])!r}" '
                f'izz="{float(i[2, 2])!r}"/></inertial></link>')

    a = body('a', 1.0, [0.1, 0.0, 0.0], np.diag([0.01, 0.02, 0.03]))
    direct = TILTED.format(links=a + body('b', 1.5, com_b, I_b), extra='')
    welded = TILTED.format(
        links=a + '<link name="b"/>' + body('c', 1.5, com_c, I_c),
        extra=('<joint name="weld" type="fixed"><parent link="b"/>'
               f'<child link="c"/><origin xyz="{" ".join(map(str, xyz))}" '
               f'rpy="{" ".join(map(str, rpy))}"/></joint>'))
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        one = load_urdf(direct)
        two = load_urdf(welded)
    assert two.info['urdf']['merged_fixed'] == ['weld']
    assert two.mass.tolist() == one.mass.tolist()
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, qd, qdd = rng.uniform(-2, 2, (3, 2))
        assert rel(inverse_dynamics(two, q, qd, qdd),
                   inverse_dynamics(one, q, qd, qdd)) < 50 * EPS
        assert rel(mass_matrix(two, q), mass_matrix(one, q)) < 50 * EPS
        assert rel(coriolis_matrix(two, q, qd),
                   coriolis_matrix(one, q, qd)) < 50 * EPS
        assert rel(gravity_torques(two, q), gravity_torques(one, q)) \
            < 50 * EPS


def test_total_mass_is_every_link_that_rides_on_the_chain():
    model = arm(base='world', tip='tool0')
    # base_link (5 kg) is fixed to the world; l1, l2 + finger, l3 move
    assert model.mass.tolist() == [2.0, 1.7, 0.5]
    assert model.info['urdf']['lumped'] == ['grip']
    assert model.info['urdf']['merged_fixed'] == ['mount', 'flange']
    assert model.info['urdf']['continuous'] == ['j3']
    assert model.limits[0] == {'lower': -1.0, 'upper': 1.0, 'effort': 40.0,
                               'velocity': 2.0}
    assert model.limits[2] == {'effort': 5.0, 'velocity': 3.0}


def test_without_a_tip_the_whole_tree_loads():
    # base_link carries l1 (j1); l2 (j2) carries l3 (j3) and the finger
    # (grip): depth first in document order, grip after j3's subtree
    tree = arm(base='world')
    assert tree.joint_names == ('j1', 'j2', 'j3', 'grip')
    assert tree.parents == (-1, 0, 1, 1)
    assert tree.tool_body is None          # two tips: finger and tool0
    assert tree.info['urdf']['tip'] is None
    assert tree.info['urdf']['lumped'] == []
    assert tree.link_frames['tool0'][0] == 2
    assert tree.link_frames['base_link'][0] == -1
    # the total mass is the same as the chain's, which lumps the finger
    assert tree.total_mass == pytest.approx(
        arm(base='world', tip='tool0').total_mass)
    assert arm(tip='l3').info['urdf']['lumped'] == ['grip', 'flange']


def test_mimic_joint_is_lumped_at_its_offset():
    base = f"""<robot name="r"><link name="b"/>
      <link name="a">{inertial(1.0)}</link>
      <link name="f">{inertial(1.0, ixx=0, iyy=0, izz=0)}</link>
      <joint name="j" type="revolute"><parent link="b"/><child link="a"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1"
        velocity="1"/></joint>
      <joint name="s" type="prismatic"><parent link="a"/><child link="f"/>
        <axis xyz="1 0 0"/>MIMIC<limit lower="0" upper="1" effort="1"
        velocity="1"/></joint></robot>"""
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        plain = load_urdf(base.replace('MIMIC', ''), tip='a')
        mimic = load_urdf(base.replace(
            'MIMIC', '<mimic joint="j" multiplier="2" offset="0.4"/>'),
            tip='a')
    assert plain.com[0][0] == 0.0
    assert mimic.com[0][0] == pytest.approx(0.2)       # (0 + 0.4) / 2


# ---------------------------------------------------------------------------
# against the Euler-Lagrange oracle and the 50-digit reference
# ---------------------------------------------------------------------------
@pytest.mark.parametrize('tip', ['tool0', 'l3', 'l2'])
def test_urdf_chain_matches_euler_lagrange(tip):
    model = arm(base='world', tip=tip)
    rng = np.random.default_rng(11)
    for _ in range(4):
        q, qd, qdd = rng.uniform(-1.5, 1.5, size=(3, model.n))
        w = rng.normal(size=6) * 5
        for frame in ('base', 'end_effector'):
            np.testing.assert_allclose(
                inverse_dynamics(model, q, qd, qdd, w, frame),
                ref.inverse_dynamics(model, q, qd, qdd, w, frame),
                rtol=1e-11, atol=1e-11)
            np.testing.assert_allclose(jacobian(model, q, frame),
                                       ref.ee_jacobian(model, q, frame),
                                       atol=1e-14)
        np.testing.assert_allclose(mass_matrix(model, q),
                                   ref.mass_matrix(model, q), atol=1e-14)
        np.testing.assert_allclose(coriolis_matrix(model, q, qd),
                                   ref.christoffel_coriolis(model, q, qd),
                                   atol=1e-12)
        np.testing.assert_allclose(gravity_torques(model, q),
                                   ref.gravity_vector(model, q), atol=1e-12)


def test_continuous_joint_takes_any_angle():
    model = arm(base='world', tip='tool0')
    q = np.array([0.2, 0.1, 1e4])
    q_wrapped = np.array([0.2, 0.1, math.remainder(1e4, 2 * math.pi)])
    # the same pose: only the rounding of 1e4 mod 2 pi differs (|q| eps)
    assert rel(gravity_torques(model, q), gravity_torques(model, q_wrapped)) \
        < 1e4 * EPS * 10


def test_urdf_model_agrees_with_its_50_digit_evaluation():
    model = arm(base='world', tip='tool0')
    hp = HighPrecisionModel(model)
    rng = np.random.default_rng(5)
    for _ in range(3):
        q, qd, qdd = rng.uniform(-1.5, 1.5, size=(3, model.n))
        assert relative_error(inverse_dynamics(model, q, qd, qdd),
                              hp.inverse_dynamics(q, qd, qdd)) < 20 * EPS
        assert relative_error(mass_matrix(model, q),
                              hp.mass_matrix(q, 'crba')) < 20 * EPS


# ---------------------------------------------------------------------------
# Pinocchio's own URDF reader on published robots (make peers)
# ---------------------------------------------------------------------------
PUBLISHED = [
    ('ur_description/urdf/ur5_robot.urdf', 'tool0'),
    ('panda_description/urdf/panda.urdf', 'panda_hand_tcp'),
    ('kinova_description/robots/kinova.urdf', 'j2s6s200_end_effector'),
    ('xarm_description/urdf/xarm7.urdf', None),
    ('z1_description/urdf/z1.urdf', None),
    ('so_arm_description/urdf/so100.urdf', None),
    ('so_arm_description/urdf/so101.urdf', 'gripper_frame_link'),
    ('baxter_description/urdf/baxter.urdf', 'left_gripper'),
    ('talos_data/robots/talos_full_v2.urdf', 'arm_left_7_link'),
]


@pytest.mark.parametrize('relative,tip', PUBLISHED)
def test_published_urdf_matches_pinocchio(relative, tip):
    import pinocchio  # noqa: F401 (a test dependency: make setup installs it)
    from newton_euler_tools.peers import example_robot_urdf, PinocchioUrdf
    try:
        path = example_robot_urdf(relative)
    except ImportError:
        pytest.skip('example-robot-data is not installed (make peers)')
    model = quiet_load(path, tip=tip)
    peer = PinocchioUrdf(path, model.joint_names, model.info['urdf']['tip'])
    rng = np.random.default_rng(sum(map(ord, relative)))
    for _ in range(5):
        q, qd, qdd = rng.uniform(-1.5, 1.5, size=(3, model.n))
        w = rng.normal(size=6) * 10
        theirs = peer.terms(q, qd, qdd, w)
        ours = {'tau': inverse_dynamics(model, q, qd, qdd),
                'D': mass_matrix(model, q),
                'C': coriolis_matrix(model, q, qd),
                'g': gravity_torques(model, q), 'J': jacobian(model, q),
                'tau_wrench': inverse_dynamics(model, q, qd, qdd, w)}
        for key, value in ours.items():
            assert rel(value, theirs[key]) <= 1e-12, key


# ---------------------------------------------------------------------------
# errors: one line, naming the source, the element and the attribute
# ---------------------------------------------------------------------------
def one_link(joint='type="revolute"', axis='<axis xyz="0 0 1"/>',
             inert=inertial(1.0), extra=''):
    return (f'<robot name="r"><link name="b"/><link name="a">{inert}</link>'
            f'<joint name="j" {joint}><parent link="b"/><child link="a"/>'
            f'{axis}<limit lower="-1" upper="1" effort="1" velocity="1"/>'
            f'</joint>{extra}</robot>')


BAD = [
    (one_link(axis='<axis xyz="0 0 0"/>'),
     r"robot_description: joint 'j' <axis> xyz: must be a nonzero vector"),
    (one_link(axis='<axis xyz="0 nan 1"/>'),
     r"joint 'j' <axis> xyz: must be finite, got nan"),
    (one_link(axis='<axis xyz="0 1"/>'),
     r"joint 'j' <axis> xyz: must be 3 numbers, got '0 1'"),
    (one_link(inert=inertial(-1.0)),
     r"link 'a' <inertial><mass> value: must be >= 0, got -1.0"),
    (one_link(inert=inertial(1.0, ixx=-1.0)),
     r"link 'a' <inertial><inertia>: not positive semi-definite"),
    (one_link(inert=inertial(1.0, ixx=0.01, iyy=0.01, ixy=0.5)),
     r"link 'a' <inertial><inertia>: not positive semi-definite"),
    (one_link(inert=inertial(1.0, xyz='0 0 inf')),
     r"link 'a' <inertial><origin> xyz: must be finite, got inf"),
    (one_link(joint='type="floating"'),
     r"joint 'j' type: a floating joint is on the chain"),
    (one_link(joint='type="planar"'),
     r"joint 'j' type: a planar joint is on the chain"),
    (one_link(joint='type="hinge"'),
     r"joint 'j' type: must be one of revolute, continuous"),
    (one_link(extra='<link name="a"/>'),
     r"link 'a': the name is used twice"),
    (one_link(extra='<link name="c"/><joint name="j" type="fixed">'
                    '<parent link="a"/><child link="c"/></joint>'),
     r"joint 'j': the name is used twice"),
    (one_link(extra='<joint name="k" type="fixed"><parent link="a"/>'
                    '<child link="nowhere"/></joint>'),
     r"joint 'k' <child> link: no link named 'nowhere'"),
    (one_link(extra='<joint name="k" type="fixed"><parent link="ghost"/>'
                    '<child link="b"/></joint>'),
     r"joint 'k' <parent> link: no link named 'ghost'"),
    (one_link(extra='<joint name="k" type="fixed"><parent link="a"/>'
                    '<child link="b"/></joint>'),
     r'the links form a cycle'),
    (one_link(extra='<link name="c"/><link name="d"/><joint name="k" '
                    'type="fixed"><parent link="c"/><child link="d"/>'
                    '</joint><joint name="m" type="fixed"><parent link="d"/>'
                    '<child link="c"/></joint>'),
     r'more than one root link|links on a cycle'),
    (one_link(extra='<link name="c"/>'), r'more than one root link'),
    ('<robot name="r"><link name="b"/><link name="a"/></robot>',
     r'more than one root link'),
    ('<robot name="r"/>', r'<robot> has no <link>'),
    ('<robt/>', r'the root element is <robt>, not <robot>'),
    ('<robot name="r"><link name="b">', r'not well-formed XML \(line 1'),
    ('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaa">'
     '<!ENTITY b "&a;&a;&a;&a;">]><robot name="r">&b;</robot>',
     r'refused: a <!DOCTYPE> declaration \(DTDs and entities are not '
     r'accepted in URDF\)$'),
    ('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY x SYSTEM '
     '"file:///etc/passwd">]><robot name="r">&x;</robot>',
     r'refused'),
    ('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
     '<xacro:property name="a" value="1"/><link name="b"/></robot>',
     r'xacro, not URDF \(<xacro:property>\): expand it with xacro first$'),
    ('<robot name="r" xmlns:xacro="http://ros.org/wiki/xacro"><link '
     'name="b"/><link name="a"/><joint name="j" type="fixed"><parent '
     'link="b"/><child link="a"/><origin xyz="0 0 ${h}"/></joint></robot>',
     r'xacro, not URDF \(<origin xyz="0 0 \$\{h\}">\): expand it with '
     r'xacro first$'),
    ('<robot name="r"><link name="b"><visual><geometry><mesh filename='
     '"$(find arm)/base.stl"/></geometry></visual></link></robot>',
     r'xacro, not URDF \(<mesh filename="\$\(find arm\)/base.stl">\)'),
]


@pytest.mark.parametrize('text,message', BAD)
def test_bad_urdf_is_one_clear_error(text, message):
    with pytest.raises(RobotFileError, match=message) as info:
        load_urdf(text, tip='a')
    assert '\n' not in str(info.value)
    assert str(info.value).startswith('robot_description: ')


def test_xacro_namespace_alone_is_not_xacro():
    """Load a URDF with xmlns:xacro: xacro leaves it in what it writes."""
    text = ('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
            + one_link()[len('<robot name="r">'):])
    assert load_urdf(text, tip='a').n == 1


def test_urdf_and_xacro_are_recognised_by_content(tmp_path):
    """A URDF under another name loads; a xacro file is one line."""
    xml = tmp_path / 'arm.xml'
    xml.write_text('\ufeff\n  ' + one_link())
    assert load_robot(str(xml), tip='a').n == 1
    xacro = tmp_path / 'arm.urdf.xacro'
    xacro.write_text('<?xml version="1.0"?>\n<robot name="r" xmlns:xacro='
                     '"http://www.ros.org/wiki/xacro"><xacro:include '
                     'filename="arm.xacro"/></robot>')
    with pytest.raises(RobotFileError) as info:
        load_robot(str(xacro))
    assert str(info.value) == ('arm.urdf.xacro: xacro, not URDF '
                               '(<xacro:include>): expand it with xacro '
                               'first')


def test_chain_errors_name_the_links():
    with pytest.raises(RobotFileError, match=r"tip link 'nope' is not in"):
        arm(tip='nope')
    with pytest.raises(RobotFileError,
                       match=r"base link 'l3' is not an ancestor of tip "
                             r"link 'l1'"):
        arm(base='l3', tip='l1')
    with pytest.raises(RobotFileError, match=r'no revolute, continuous or '
                                             r'prismatic joint between'):
        arm(base='l3', tip='tool0')


def test_file_errors_name_the_file(tmp_path):
    empty = tmp_path / 'empty.urdf'
    empty.write_text('')
    binary = tmp_path / 'binary.urdf'
    binary.write_bytes(b'\xff\xfe<robot>\x00\x81')
    folder = tmp_path / 'folder.urdf'
    folder.mkdir()
    for path, message in ((empty, 'empty.urdf: the file is empty'),
                          (binary, r'binary.urdf: not UTF-8 text'),
                          (folder, r'folder.urdf: is a directory'),
                          (tmp_path / 'missing.urdf',
                           r'missing.urdf: cannot read')):
        with pytest.raises(RobotFileError, match=message):
            load_robot(str(path))
    with pytest.raises(RobotFileError, match=r'characters, more than the'):
        load_urdf('<robot>' + ' ' * (16 * 1024 * 1024) + '</robot>')
    # a small file can still describe an absurd robot: bounded too
    many = ''.join(f'<link name="l{i}"/>' for i in range(4001))
    with pytest.raises(RobotFileError, match=r'^robot_description: 4001 '
                       r'links and 0 joints, more than the 4000 accepted$'):
        load_urdf(f'<robot name="r">{many}</robot>')


def test_base_and_tip_apply_to_urdf_only():
    with pytest.raises(RobotFileError, match='URDF robots'):
        load_robot('puma560', tip='tool0')


def test_warnings_name_massless_links_and_lumped_subtrees():
    _, found, _ = inspect_urdf(ARM, base='world', tip='tool0')
    # tool0 is a massless frame on a fixed joint: nothing to say about it
    assert not any('massless' in w for w in found), found
    assert any('moving joints off the chain locked at zero' in w
               and w.endswith(': grip (prismatic)') for w in found), found
    # a link a joint moves, without <inertial>, is worth a warning
    l3 = inertial(0.5, '0 0.02 0.03', '0.4 -0.2 0.1')
    bare = ARM.replace(f'<link name="l3">{l3}</link>', '<link name="l3"/>')
    assert bare != ARM
    _, found, _ = inspect_urdf(bare, base='world', tip='tool0')
    assert any('massless: l3' in w for w in found), found


# what a real robot_description carries beside links and joints
ROS2_CONTROL = """
  <ros2_control name="arm" type="system">
    <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
    <joint name="{joint}"><command_interface name="effort"/>
      <state_interface name="position"/><state_interface name="velocity"/>
    </joint>
  </ros2_control>
  <transmission name="{joint}_trans">
    <type>transmission_interface/SimpleTransmission</type>
    <joint name="{joint}">
      <hardwareInterface>hardware_interface/EffortJointInterface
      </hardwareInterface></joint>
    <actuator name="{joint}_motor">
      <mechanicalReduction>1</mechanicalReduction></actuator>
  </transmission>
  <gazebo reference="{link}"><material>Gazebo/Grey</material></gazebo>
  <gazebo><plugin filename="libgazebo_ros2_control.so"
    name="gazebo_ros2_control"><parameters>/tmp/controllers.yaml</parameters>
  </plugin></gazebo>
</robot>"""
# a wrist camera on a fixed joint off the chain, with mass
CAMERA = """
  <link name="wrist_camera"><inertial><origin xyz="0 0 0.02"/>
    <mass value="0.3"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0"
    ixz="0" iyz="0"/></inertial></link>
  <joint name="wrist_camera_joint" type="fixed"><parent link="{link}"/>
    <child link="wrist_camera"/><origin xyz="0.05 0 0"/></joint>"""
# (file, base, tip, a joint for the blocks, the link the camera is on)
CORRECT = [
    ('ur_description/urdf/ur5_robot.urdf', 'base_link', 'tool0',
     'shoulder_pan_joint', 'wrist_3_link'),
    ('kinova_description/robots/kinova.urdf', None,
     'j2s6s200_end_effector', 'j2s6s200_joint_1', 'j2s6s200_link_6'),
    ('xarm_description/urdf/xarm7.urdf', None, 'link_eef', 'joint1', 'link5'),
    ('z1_description/urdf/z1.urdf', None, 'gripperMover', 'joint1', 'link05'),
]


@pytest.mark.parametrize('relative,base,tip,joint,link', CORRECT)
def test_published_urdf_with_fixed_off_chain_parts_loads_quietly(
        relative, base, tip, joint, link):
    """
    Load a correct model, as a bringup publishes it, without a warning.

    ros2_control, transmission and gazebo blocks are ignored; a fixed
    joint off the chain (the robot's own frames, a wrist camera with
    mass) is merged without a word, and its mass is in the model.
    """
    from newton_euler_tools.peers import example_robot_urdf
    with open(example_robot_urdf(relative), encoding='utf-8') as fh:
        text = fh.read()
    described = text.replace('</robot>', CAMERA.format(link=link)
                             + ROS2_CONTROL.format(joint=joint, link=link))
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        plain = load_urdf(text, base=base, tip=tip)
        model, found, report = inspect_urdf(described, base=base, tip=tip)
    assert found == [] and report['locked'] == [], found
    assert 'wrist_camera_joint' in report['lumped']
    assert model.total_mass == pytest.approx(plain.total_mass + 0.3)


def test_only_locked_moving_joints_are_warned_about():
    """Merge the Panda's hand quietly (fixed); name its moving fingers."""
    from newton_euler_tools.peers import example_robot_urdf
    path = example_robot_urdf('panda_description/urdf/panda.urdf')
    for tip in ('panda_link8', 'panda_hand_tcp'):
        _, found, report = inspect_urdf(path, base='panda_link0', tip=tip)
        assert report['locked'] == ['panda_finger_joint1',
                                    'panda_finger_joint2']
        assert found == [
            'panda.urdf: moving joints off the chain locked at zero (their '
            'motion is not modelled; their links are lumped rigidly into '
            'the chain): panda_finger_joint1 (prismatic), '
            'panda_finger_joint2 (prismatic, mimic of panda_finger_joint1, '
            'at 0)'], found
        assert not any('panda_hand_joint' in w for w in found)


def test_massless_frames_lumped_or_written_back_do_not_warn():
    # an ee_link frame (zero-mass <inertial>) off the chain is lumped
    # without a warning; a moving off-chain joint still gets one
    frame = ('  <link name="ee_link"><inertial><mass value="0"/>'
             '<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>'
             '</inertial></link>\n  <joint name="ee_fixed" type="fixed">'
             '<parent link="l3"/><child link="ee_link"/>'
             '<origin xyz="0 0 0.05"/></joint>\n</robot>')
    text = ARM.replace('</robot>', frame)
    _, found, report = inspect_urdf(text, base='world', tip='tool0')
    assert 'ee_fixed' in report['lumped']
    assert not any('ee_fixed' in w or 'ee_link' in w for w in found), found
    # what `newton-euler urdf` writes reads back without a word
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        load_urdf(model_to_urdf(quiet_load('panda')))
        load_urdf(model_to_urdf(quiet_load('puma560')), tip='tool0')


def test_mistyped_links_name_the_closest():
    with pytest.raises(RobotFileError, match=r"tip link 'tol0' is not in "
                       r"the URDF \(closest: 'tool0'"):
        inspect_urdf(ARM, tip='tol0')
    with pytest.raises(RobotFileError, match=r"base link 'wrld'.*closest: "
                       r"'world'"):
        inspect_urdf(ARM, base='wrld', tip='tool0')
    with pytest.raises(RobotFileError, match=r'\(links: world, base_link, '):
        inspect_urdf(ARM, tip='xyzzy')


# ---------------------------------------------------------------------------
# the CLI on URDF
# ---------------------------------------------------------------------------
def run_cli(*args):
    return newton_euler(*args)


def test_cli_dynamics_on_urdf_prints_the_dh_json(tmp_path):
    urdf = tmp_path / 'puma.urdf'
    urdf.write_text(model_to_urdf(quiet_load('puma560')))
    states = tmp_path / 'states.json'
    states.write_text(json.dumps([
        {'q': [0.1, 0.5, -0.3, 0.2, 0.4, 0.6], 'qd': [1, 2, 3, 4, 5, 6],
         'qdd': [1, 1, 1, 1, 1, 1], 'wrench': [1, 2, 3, 0.1, 0.2, 0.3]}]))
    code, out_u, err = run_cli('dynamics', str(urdf), '--base', 'base_link',
                               '--tip', 'tool0', '--states', str(states),
                               '--json')
    assert code == 0, err
    code, out_d, err = run_cli('dynamics', 'puma560', '--states',
                               str(states), '--json')
    assert code == 0, err
    (u,), (d,) = json.loads(out_u), json.loads(out_d)
    assert set(u) == set(d) and u['joint_names'] == d['joint_names']
    for key in d:
        if key != 'joint_names':
            assert rel(u[key], d[key]) < 1e-13, key


def test_cli_check_prints_chain_merges_and_lumps(tmp_path):
    path = tmp_path / 'arm.urdf'
    path.write_text(ARM)
    code, out, err = run_cli('check', str(path), '--tip', 'tool0')
    assert code == 0, err
    assert ('chain: world -[mount]-> base_link -[j1]-> l1 -[j2]-> l2 '
            '-[j3]-> l3 -[flange]-> tool0') in out
    assert 'merged fixed joints: mount, flange' in out
    assert 'lumped off-chain subtrees (at zero position): grip' in out
    assert 'locked off-chain moving joints: grip' in out
    assert 'massless' not in out          # tool0 is a frame
    code, out, err = run_cli('check', str(path))     # the whole tree
    assert code == 0, err
    # one joint a line, indented by depth, with its type
    assert ('    world\n'
            '      mount (fixed, merged) -> base_link\n'
            '        j1 (revolute) -> l1\n'
            '          j2 (prismatic) -> l2\n'
            '            j3 (continuous) -> l3\n'
            '              flange (fixed, merged) -> tool0\n'
            '            grip (prismatic) -> finger\n') in out
    # a continuous joint is listed as continuous, not revolute
    assert 'joints: 4 (RPCP)' in out
    assert ('total mass: ' in out and '(the links the joints move; world '
            'and the links fixed to it not counted)' in out)
    code, out, err = run_cli('dynamics', str(path), '--q', '0', '0', '0',
                             '0')
    assert code == 0, err
    assert [line.split()[1] for line in out.splitlines()[3:7]] == [
        'revolute', 'prismatic', 'continuous', 'prismatic']


def test_float32_runs_the_same_kernels_on_a_urdf_model():
    from newton_euler_ros.core.float32 import Float32Dynamics
    model = arm(base='world', tip='tool0')
    f32 = Float32Dynamics(model)
    rng = np.random.default_rng(9)
    q, qd, qdd = rng.uniform(-1.5, 1.5, size=(3, model.n))
    tau = f32.inverse_dynamics(q, qd, qdd)
    assert tau.dtype == np.float32
    # a few float32 ulp of the float64 torques
    assert rel(tau, inverse_dynamics(model, q, qd, qdd)) < 100 * model.n * \
        np.finfo(np.float32).eps
