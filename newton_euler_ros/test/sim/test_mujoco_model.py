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
MuJoCo as a second truth: its own URDF reader and dynamics against ours.

The library's tau, D and g against MuJoCo's ``mj_inverse`` and full mass
matrix on every bundled robot and published URDF without mimic joints
(beside the Pinocchio cross-checks of test_urdf.py); mimic joints through
the coordinates' map; and what the conversion maps (drive terms, limits,
effort ranges, meshes), drops (with a note) or refuses (in one line).
"""
import os
import struct
import warnings

from descriptions import as_published
import mujoco
from newton_euler_ros.core import (bundled_robots, gravity_torques,
                                   inverse_dynamics, load_robot,
                                   mass_matrix, RobotFileError,
                                   RobotFileWarning)
from newton_euler_ros.sim.mujoco_model import load_mujoco, resolve_mesh
from newton_euler_ros.sim.mujoco_plant import MujocoPlant
import numpy as np
import pytest

# MuJoCo refuses these bundled robots' published inertias, naming the link
REFUSED = {'puma560': 'link1', 'stanford': 'link5'}
PUBLISHED = [
    'ur_description/urdf/ur5_robot.urdf',
    'kinova_description/robots/kinova.urdf',
    'xarm_description/urdf/xarm7.urdf',
    'z1_description/urdf/z1.urdf',
    'so_arm_description/urdf/so100.urdf',
    'so_arm_description/urdf/so101.urdf',
    'centauro_description/urdf/centauro.urdf',
]


def published(relative):
    from newton_euler_tools.peers import example_robot_urdf
    return example_robot_urdf(relative)


def quiet(fn, *args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        return fn(*args, **kw)


def rel(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return np.abs(a - b).max() / max(np.abs(b).max(), 1e-300)


def rigid(robot):
    """Return the MuJoCo model without constraints and drive terms."""
    m = robot.model
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    m.dof_damping[:] = 0.0
    m.dof_frictionloss[:] = 0.0
    m.dof_armature[:] = 0.0
    return m


def mujoco_terms(robot, order, q, qd, qdd):
    """Return MuJoCo's tau, D and g at a state given in ``order``."""
    m = rigid(robot)
    d = mujoco.MjData(m)
    idx = [robot.joints.index(j) for j in order]
    qm, vm, am = (np.zeros(robot.n) for _ in range(3))
    qm[idx], vm[idx], am[idx] = q, qd, qdd
    robot.set_state(d, qm, vm)
    d.qacc[:] = 0.0
    d.qacc[robot.dof] = am
    mujoco.mj_inverse(m, d)
    dofs = robot.dof[idx]
    tau = d.qfrc_inverse[dofs].copy()
    M = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, M)
    d.qvel[:] = 0.0
    d.qacc[:] = 0.0
    mujoco.mj_inverse(m, d)
    return tau, M[np.ix_(dofs, dofs)], d.qfrc_inverse[dofs].copy()


def check_against_mujoco(source, seed):
    model = quiet(load_robot, source)
    robot = quiet(load_mujoco, source)
    assert set(model.joint_names) == set(robot.joints)
    rng = np.random.default_rng(seed)
    for _ in range(3):
        q, qd, qdd = rng.uniform(-1.5, 1.5, size=(3, model.n))
        tau, D, g = mujoco_terms(robot, model.joint_names, q, qd, qdd)
        assert rel(inverse_dynamics(model, q, qd, qdd), tau) <= 1e-12
        assert rel(mass_matrix(model, q), D) <= 1e-12
        assert rel(gravity_torques(model, q), g) <= 1e-12


@pytest.mark.parametrize('name', sorted(set(bundled_robots()) - set(REFUSED)))
def test_bundled_robot_matches_mujoco(name):
    check_against_mujoco(name, sum(map(ord, name)))


@pytest.mark.parametrize('relative', PUBLISHED)
def test_published_urdf_matches_mujoco(relative):
    check_against_mujoco(published(relative), sum(map(ord, relative)))


@pytest.mark.parametrize('name,link', sorted(REFUSED.items()))
def test_a_link_mujoco_refuses_is_named_in_one_line(name, link):
    with pytest.raises(RobotFileError) as err:
        quiet(load_mujoco, name)
    text = str(err.value)
    assert text.startswith(f'{name}: MuJoCo refuses link {link!r}: ')
    assert '\n' not in text


def one_joint(inertia='ixx="0.01" iyy="0.02" izz="0.03"', mass=1.0,
              dynamics='', drive='', limit='effort="7" velocity="2"',
              collision='', extra=''):
    return (
        '<robot name="one" xmlns:ne="https://newton-euler-ros.github.io/'
        'ns/drives/1"><link name="base"/>'
        f'<link name="arm"><inertial><origin xyz="0.1 0 0"/>'
        f'<mass value="{mass}"/><inertia {inertia} ixy="0" ixz="0" '
        f'iyz="0"/></inertial>{collision}</link>'
        '<joint name="j1" type="revolute"><parent link="base"/>'
        '<child link="arm"/><axis xyz="0 0 1"/>'
        f'<limit lower="-1.5" upper="2" {limit}/>{dynamics}{drive}'
        f'</joint>{extra}</robot>')


def test_drive_terms_limits_and_effort_reach_the_plant():
    text = one_joint(dynamics='<dynamics damping="0.7" friction="1.3"/>',
                     drive='<ne:drive armature="0.25" offset="0.1"/>')
    robot = load_mujoco(text)
    m = robot.model
    dof = robot.dof[0]
    assert m.dof_damping[dof] == 0.7
    assert m.dof_frictionloss[dof] == 1.3
    assert m.dof_armature[dof] == 0.25
    j = m.dof_jntid[dof]
    assert m.jnt_limited[j] and list(m.jnt_range[j]) == [-1.5, 2.0]
    a = robot.actuator[0]
    assert m.actuator_forcelimited[a]
    assert list(m.actuator_forcerange[a]) == [-7.0, 7.0]
    assert m.actuator_gear[a, 0] == 1.0
    # what has no MuJoCo counterpart is said
    assert any('offsets' in note and 'Coulomb width' in note
               for note in robot.notes)


def test_the_motor_applies_the_commanded_torque_within_its_effort_limit():
    # no gravity about a vertical axis: the arm's acceleration is tau / I
    plant = MujocoPlant(load_mujoco(one_joint(), timestep=1e-4))
    plant.release()
    inertia = 0.03 + 1.0 * 0.1 ** 2
    plant.advance([2.0], 1e-4)
    assert plant.applied()[0] == pytest.approx(2.0)
    assert plant.data.qacc[plant.robot.dof[0]] == pytest.approx(
        2.0 / inertia, rel=1e-9)
    plant.advance([50.0], 1e-4)
    assert plant.applied()[0] == pytest.approx(7.0)     # the effort limit


def test_brakes_hold_the_pose_until_released():
    text = one_joint().replace('xyz="0 0 1"', 'xyz="0 1 0"')
    plant = MujocoPlant(load_mujoco(text), q0=[0.3])
    plant.advance([0.0], 0.5)
    assert plant.state()[0][0] == 0.3 and plant.time == pytest.approx(0.5)
    plant.release()
    plant.advance([0.0], 0.05)
    assert plant.state()[1][0] != 0.0       # gravity about y now moves it


def test_mimic_joints_are_equality_constraints_with_their_coefficients():
    model = quiet(load_robot, published('panda_description/urdf/panda.urdf'))
    robot = quiet(load_mujoco, published('panda_description/urdf/panda.urdf'))
    followers = [model.moving_joints[j]
                 for j, m in enumerate(model.mimic) if m is not None]
    assert [f[0] for f in robot.followers] == followers
    assert set(robot.joints) == set(model.joint_names)
    # with the follower moving as its leader does, MuJoCo's joint torques
    # mapped onto the coordinates are ours (tau = G^T tau_mujoco)
    m = rigid(robot)
    d = mujoco.MjData(m)
    rng = np.random.default_rng(3)
    q, qd, qdd = rng.uniform(-0.5, 0.5, size=(3, model.n))
    q[-1] = qd[-1] = 0.01
    idx = [robot.joints.index(j) for j in model.joint_names]
    qm, vm = np.zeros(robot.n), np.zeros(robot.n)
    qm[idx], vm[idx] = q, qd
    robot.set_state(d, qm, vm)
    d.qacc[:] = 0.0
    d.qacc[robot.dof[idx]] = qdd
    for k in range(m.neq):
        follower, leader = m.eq_obj1id[k], m.eq_obj2id[k]
        d.qacc[m.jnt_dofadr[follower]] = (m.eq_data[k, 1]
                                          * d.qacc[m.jnt_dofadr[leader]])
    mujoco.mj_inverse(m, d)
    tau = d.qfrc_inverse[robot.dof[idx]].copy()
    for k in range(m.neq):
        follower, leader = m.eq_obj1id[k], m.eq_obj2id[k]
        tau[idx.index(list(robot.dof).index(m.jnt_dofadr[leader]))] += (
            m.eq_data[k, 1] * d.qfrc_inverse[m.jnt_dofadr[follower]])
    assert rel(inverse_dynamics(model, q, qd, qdd), tau) <= 1e-12


def test_ros2_control_blocks_change_nothing():
    path = published('ur_description/urdf/ur5_robot.urdf')
    with open(path, encoding='utf-8') as fh:
        text = fh.read()
    plain = load_mujoco(path)
    wrapped = load_mujoco(as_published(text, 'ur', gripper=False),
                          label='ur5')
    assert plain.joints == wrapped.joints
    for key in ('body_mass', 'body_inertia', 'body_ipos', 'jnt_range',
                'actuator_forcerange'):
        assert np.array_equal(getattr(plain.model, key),
                              getattr(wrapped.model, key)), key


def test_massless_moving_link_is_refused_in_one_line():
    text = one_joint(mass=0.0, inertia='ixx="0" iyy="0" izz="0"')
    with pytest.raises(RobotFileError) as err:
        load_mujoco(text)
    assert str(err.value).startswith(
        "robot_description: MuJoCo refuses link 'arm': mass and inertia")


def test_triangle_inequality_is_refused_naming_the_link():
    text = one_joint(inertia='ixx="0.01" iyy="0.01" izz="0.5"')
    with pytest.raises(RobotFileError) as err:
        load_mujoco(text, label='bad.urdf')
    assert str(err.value).startswith(
        "bad.urdf: MuJoCo refuses link 'arm': inertia must satisfy A + B")


def stl_tetrahedron(path):
    tri = [((0, 0, 0), (0.1, 0, 0), (0, 0.1, 0)),
           ((0, 0, 0), (0, 0, 0.1), (0.1, 0, 0)),
           ((0, 0, 0), (0, 0.1, 0), (0, 0, 0.1)),
           ((0.1, 0, 0), (0, 0, 0.1), (0, 0.1, 0))]
    with open(path, 'wb') as fh:
        fh.write(b'\0' * 80 + struct.pack('<I', len(tri)))
        for t in tri:
            fh.write(struct.pack('<3f', 0, 0, 0))
            for v in t:
                fh.write(struct.pack('<3f', *v))
            fh.write(b'\0\0')


def test_meshes_resolve_from_package_or_are_dropped_with_a_note(
        tmp_path, monkeypatch):
    pkg = tmp_path / 'share' / 'my_robot' / 'meshes'
    pkg.mkdir(parents=True)
    stl_tetrahedron(pkg / 'arm.stl')
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(tmp_path))
    found = ('<collision><geometry><mesh filename="package://my_robot/'
             'meshes/arm.stl"/></geometry></collision>')
    missing = found.replace('arm.stl', 'gone.stl')
    assert resolve_mesh('package://my_robot/meshes/arm.stl') == str(
        pkg / 'arm.stl')
    robot = load_mujoco(one_joint(collision=found + missing))
    assert robot.model.ngeom == 1 and robot.model.nmesh == 1
    assert len(robot.notes) == 1
    assert "link 'arm' <collision> mesh 'package://my_robot/meshes/" \
        "gone.stl': not found; dropped" in robot.notes[0]
    # the inertia is as written, not from the mesh
    assert robot.model.body_mass[robot.model.dof_bodyid[0]] == 1.0


def test_mjcf_is_compiled_as_it_is(tmp_path):
    path = tmp_path / 'pendulum.xml'
    path.write_text(
        '<mujoco><option gravity="0 0 -9.81"/><worldbody>'
        '<body name="arm"><joint name="hinge" axis="0 1 0"/>'
        '<inertial pos="0.5 0 0" mass="2" diaginertia="0.01 0.01 0.01"/>'
        '</body></worldbody><actuator><motor joint="hinge"/></actuator>'
        '</mujoco>')
    robot = load_mujoco(str(path))
    assert robot.joints == ('hinge',) and robot.urdf is None
    plant = MujocoPlant(robot)
    plant.release()
    plant.advance([0.0], robot.model.opt.timestep)
    # g(0) = -m g l: gravity turns the arm along x about +y towards -z
    assert plant.data.qfrc_bias[0] == pytest.approx(-2 * 9.81 * 0.5)


def test_bad_sources_are_one_line_errors(tmp_path):
    with pytest.raises(RobotFileError, match=r'^robot_description: joints: '
                       r'no moving joint named .nope. \(joints: j1\)$'):
        load_mujoco(one_joint(), joints=['nope'])
    with pytest.raises(RobotFileError, match=r'not well-formed XML'):
        load_mujoco('<robot name="x"><link')
    bad = tmp_path / 'bad.xml'
    bad.write_text('<mujoco><worldbody><body><joint type="nonsense"/>'
                   '</body></worldbody></mujoco>')
    with pytest.raises(RobotFileError) as err:
        load_mujoco(str(bad))
    assert str(err.value).startswith('bad.xml: MuJoCo refuses')
    assert '\n' not in str(err.value)


def test_contact_wrench_of_an_arm_resting_on_a_table_holds_it_up():
    # a 1 kg horizontal arm about y, its tip on a table: the table pushes
    # up on the link, and the moment about the joint balances gravity's
    text = one_joint(
        inertia='ixx="0.001" iyy="0.001" izz="0.001"',
        collision='<collision><origin xyz="0.2 0 0"/><geometry>'
                  '<sphere radius="0.01"/></geometry></collision>',
        limit='effort="7" velocity="2"').replace(
            'lower="-1.5"', 'lower="-3"').replace('xyz="0 0 1"',
                                                  'xyz="0 1 0"')

    def table(spec, mj):
        g = spec.worldbody.add_geom()
        g.type = mj.mjtGeom.mjGEOM_BOX
        g.size = [0.05, 0.05, 0.05]
        g.pos = [0.2, 0.0, -0.06]

    plant = MujocoPlant(load_mujoco(text, extend=table, timestep=5e-4))
    plant.release()
    for _ in range(400):
        plant.advance([0.0], 5e-4)
    wrenches = plant.contact_wrenches()
    assert set(wrenches) == {'arm'}
    w = wrenches['arm']
    assert w[2] == pytest.approx(9.81 * 0.1 / 0.2, rel=0.02)
    assert abs(w[0]) < 0.05 and abs(w[1]) < 0.05
    # moment about the link origin (the joint): the tip force's
    assert w[4] == pytest.approx(-0.2 * w[2], rel=0.02)


def test_resolve_mesh_relative_to_the_file(tmp_path):
    (tmp_path / 'm').mkdir()
    stl_tetrahedron(tmp_path / 'm' / 'a.stl')
    assert resolve_mesh('m/a.stl', str(tmp_path)) == os.path.join(
        str(tmp_path), 'm', 'a.stl')
    assert resolve_mesh('m/a.stl') is None
    assert resolve_mesh('package://nowhere/a.stl') is None
