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
Kinematic trees and mimic joints: the whole robot in one model.

- Published branched robots (example-robot-data: Baxter, PR2, TIAGo Pro,
  the Allegro hand, the Panda with its fingers, Centauro) and seeded
  random trees (revolute, continuous, prismatic, fixed and mimic joints)
  against Pinocchio's own reading of the same URDF
  (``buildModelFromUrdf(path, mimic=True)``): tau, D, C, g, forward
  dynamics, the Jacobians of several links in both axes.
- The identities that hold on chains hold on trees: D symmetric positive
  definite, Ddot - 2C skew, C qd the velocity-product torques, CRBA and
  the composite C equal to the n recursions, the articulated-body
  algorithm equal to the Cholesky solve, D_ij = 0 across branches, and
  everything equal to the independent Euler-Lagrange reference.
- The URDF reading: joint order, parents, mimic resolution, named frames,
  the chain with ``tip=``, and one-line errors for bad trees.
"""
import math
import warnings

from newton_euler_ros.core import (coriolis_matrix, forward_dynamics,
                                   gravity_torques, inverse_dynamics,
                                   jacobian, load_robot, load_urdf,
                                   mass_matrix, RobotFileError,
                                   velocity_products)
from newton_euler_ros.core.errors import DynamicsInputError
from newton_euler_ros.core.highprec import HighPrecisionModel, relative_error
from newton_euler_ros.core.robot_file import RobotFileWarning
import numpy as np
import pytest
from random_tree import random_tree_urdf
import reference_dynamics as ref

EPS = float(np.finfo(np.float64).eps)

# (URDF below example-robot-data's robots/, links whose Jacobians are
# compared): every branched robot of the issue
BRANCHED = [
    ('baxter_description/urdf/baxter.urdf',
     ('left_gripper', 'r_gripper_r_finger', 'head')),
    ('pr2_description/urdf/pr2.urdf',
     ('l_gripper_r_finger_tip_link', 'r_gripper_palm_link',
      'head_tilt_link')),
    ('tiago_pro_description/robots/tiago_pro.urdf',
     ('gripper_right_fingertip_right_link', 'arm_left_7_link',
      'head_2_link')),
    ('allegro_hand_description/urdf/allegro_right_hand.urdf',
     ('link_3.0_tip', 'link_15.0_tip', 'link_9.0')),
    ('panda_description/urdf/panda.urdf',
     ('panda_rightfinger', 'panda_hand_tcp', 'panda_link4')),
    ('centauro_description/urdf/centauro.urdf',
     ('arm1_8', 'wheel_3', 'torso_2')),
]


def quiet(load, *args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        return load(*args, **kw)


def rel(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


def robot_path(relative):
    from newton_euler_tools.peers import example_robot_urdf
    return example_robot_urdf(relative)


def urdf_path(source, tmp_path, **kw):
    """Return a published URDF's path, or a random tree's (seed ``source``)."""
    if isinstance(source, int):
        path = tmp_path / 'tree.urdf'
        path.write_text(random_tree_urdf(source, **kw)[0])
        return str(path)
    return robot_path(source)


def ours(model, q, qd, qdd, tau, links):
    out = {'tau': inverse_dynamics(model, q, qd, qdd),
           'D': mass_matrix(model, q), 'C': coriolis_matrix(model, q, qd),
           'g': gravity_torques(model, q),
           'fd': forward_dynamics(model, q, qd, tau)}
    for link in links:
        for axes in ('base', 'link'):
            out[f'J {link} {axes}'] = jacobian(model, q, link, axes=axes)
    return out


def check_against_pinocchio(path, links, seed, states=3):
    from newton_euler_tools.peers import PinocchioTree
    model = quiet(load_urdf, path)
    peer = PinocchioTree(path, model)
    rng = np.random.default_rng(seed)
    for _ in range(states):
        q, qd, qdd = rng.uniform(-1.2, 1.2, (3, model.n))
        theirs = peer.terms(q, qd, qdd, links)
        got = ours(model, q, qd, qdd, theirs['tau'], links)
        cond = np.linalg.cond(theirs['D'])
        # C of joints on the base alone is zero but for round-off: on the
        # scale of D qd
        scale = {'C': np.abs(theirs['D']).max() * np.abs(qd).max()}
        for key, value in got.items():
            bound = 1e-12 if key != 'fd' else 1000 * EPS * cond
            error = np.abs(value - theirs[key]).max() / max(
                np.abs(theirs[key]).max(), scale.get(key, 1e-300))
            assert error <= bound, (key, error)
    return model, peer


@pytest.mark.parametrize('relative,links', BRANCHED)
def test_branched_robot_matches_pinocchio(relative, links):
    model, peer = check_against_pinocchio(robot_path(relative), links,
                                          sum(map(ord, relative)))
    assert model.nb != model.n or 'allegro' in relative \
        or 'centauro' in relative                   # mimic joints loaded
    assert any(p != j - 1 for j, p in enumerate(model.parents))
    # Pinocchio's own mimic crba agrees on these robots too
    q = np.random.default_rng(3).uniform(-1, 1, model.n)
    theirs = peer.terms(q, q, q)
    assert rel(mass_matrix(model, q), theirs['D mimic']) <= 1e-12


@pytest.mark.parametrize('seed', range(12))
def test_random_tree_matches_pinocchio(seed, tmp_path):
    text, names = random_tree_urdf(seed, links=5 + seed % 7)
    path = tmp_path / 'tree.urdf'
    path.write_text(text)
    links = [f'l{k:02d}' for k in (1, len(names) // 2 + 1, len(names))]
    check_against_pinocchio(str(path), links, seed)


def test_centauro_whole_body_is_39_joints_on_5_branches():
    model = quiet(load_urdf, robot_path(
        'centauro_description/urdf/centauro.urdf'))
    assert (model.n, model.nb) == (39, 39)
    assert model.parents.count(-1) == 5     # torso and four legs
    assert model.tool_body is None and model.info['urdf']['tip'] is None


# ---------------------------------------------------------------------------
# identities, on random trees with mimic joints
# ---------------------------------------------------------------------------
def random_tree(seed, **kw):
    text, _ = random_tree_urdf(seed, **kw)
    return quiet(load_urdf, text)


@pytest.mark.parametrize('seed', range(100, 106))
def test_tree_identities(seed):
    model = random_tree(seed, links=9)
    rng = np.random.default_rng(seed)
    n = model.n
    for _ in range(3):
        q, qd, qdd = rng.uniform(-1.5, 1.5, (3, n))
        D = mass_matrix(model, q)
        assert np.array_equal(D, D.T)
        assert np.linalg.eigvalsh(D)[0] > 0
        assert rel(mass_matrix(model, q, method='newton_euler'), D) \
            < 50 * n * EPS
        C = coriolis_matrix(model, q, qd)
        assert rel(coriolis_matrix(model, q, qd, method='newton_euler'), C) \
            < 1e-12
        # C qd is the velocity-product torque
        assert rel(C @ qd, velocity_products(model, q, qd)) < 1e-12
        # Ddot - 2C is skew (Ddot by Richardson-extrapolated differences)
        h = 1e-3

        def cd(h):
            return (mass_matrix(model, q + h * qd)
                    - mass_matrix(model, q - h * qd)) / (2 * h)
        Ddot = (4 * cd(h / 2) - cd(h)) / 3
        S = Ddot - 2 * C
        assert np.abs(S + S.T).max() < 1e-8 * max(np.abs(Ddot).max(), 1)
        # D qdd + C qd + g is the recursion's torque
        tau = inverse_dynamics(model, q, qd, qdd)
        assert rel(D @ qdd + C @ qd + gravity_torques(model, q), tau) < 1e-12
        # forward dynamics inverts it (ABA, or Cholesky for mimic joints)
        for method in ('aba', 'cholesky'):
            assert rel(forward_dynamics(model, q, qd, tau, method=method),
                       qdd) < 1e-13 * np.linalg.cond(D)


@pytest.mark.parametrize('seed', range(200, 204))
def test_tree_matches_euler_lagrange(seed):
    model = random_tree(seed, links=7)
    rng = np.random.default_rng(seed)
    for _ in range(2):
        q, qd, qdd = rng.uniform(-1.5, 1.5, (3, model.n))
        np.testing.assert_allclose(mass_matrix(model, q),
                                   ref.mass_matrix(model, q), rtol=1e-12,
                                   atol=1e-13)
        np.testing.assert_allclose(coriolis_matrix(model, q, qd),
                                   ref.christoffel_coriolis(model, q, qd),
                                   rtol=1e-10, atol=1e-11)
        np.testing.assert_allclose(gravity_torques(model, q),
                                   ref.gravity_vector(model, q), rtol=1e-11,
                                   atol=1e-11)
        np.testing.assert_allclose(inverse_dynamics(model, q, qd, qdd),
                                   ref.inverse_dynamics(model, q, qd, qdd),
                                   rtol=1e-10, atol=1e-10)
        # the kinetic energy from the poses' time derivatives
        T = 0.5 * qd @ mass_matrix(model, q) @ qd
        assert abs(T - ref.kinetic_energy(model, q, qd)) < 1e-12 * max(T, 1)
        for link in ('l02', 'l05'):
            body, pose = model.link_frames[link]
            for axes in ('base', 'link'):
                np.testing.assert_allclose(
                    jacobian(model, q, link, axes=axes),
                    ref.frame_jacobian(model, q, body, pose, axes),
                    atol=1e-13)


def test_mass_matrix_is_zero_across_branches():
    model = random_tree(7, links=10, mimic=0)
    q = np.random.default_rng(1).uniform(-1, 1, model.n)
    D = mass_matrix(model, q)
    C = coriolis_matrix(model, q, np.ones(model.n))
    parents = model.parents

    def ancestors(j):
        out = set()
        while j >= 0:
            out.add(j)
            j = parents[j]
        return out
    pairs = 0
    for a in range(model.n):
        for b in range(model.n):
            if a not in ancestors(b) and b not in ancestors(a):
                assert D[a, b] == 0.0 and C[a, b] == 0.0
                pairs += 1
    assert pairs > 0


def test_tree_agrees_with_its_50_digit_evaluation():
    model = random_tree(3, links=8)
    hp = HighPrecisionModel(model)
    rng = np.random.default_rng(5)
    q, qd, qdd = rng.uniform(-1.5, 1.5, (3, model.n))
    assert relative_error(inverse_dynamics(model, q, qd, qdd),
                          hp.inverse_dynamics(q, qd, qdd)) < 50 * EPS
    assert relative_error(mass_matrix(model, q),
                          hp.mass_matrix(q, 'crba')) < 50 * EPS
    assert relative_error(coriolis_matrix(model, q, qd),
                          hp.coriolis_matrix(q, qd, 'composite')) < 100 * EPS


# ---------------------------------------------------------------------------
# reading a URDF as a tree
# ---------------------------------------------------------------------------
def inertial(m=1.0):
    return (f'<inertial><mass value="{m}"/><inertia ixx="0.01" ixy="0" '
            f'ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial>')


def joint(name, parent, child, kind='revolute', extra='', xyz='0 0 0.1'):
    limit = ('<limit lower="-1" upper="1" effort="10" velocity="1"/>'
             if kind in ('revolute', 'prismatic') else '')
    axis = '<axis xyz="0 1 0"/>' if kind != 'fixed' else ''
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{xyz}"/>{axis}{limit}'
            f'{extra}</joint>')


def torso(extra='', mimic=''):
    """Return a torso: two arms of two joints, a gripper with a mimic."""
    links = ['base', 'torso', 'la1', 'la2', 'ra1', 'ra2', 'fa', 'fb', 'cam']
    body = ''.join(f'<link name="{n}">{inertial() if n != "cam" else ""}'
                   f'</link>' for n in links)
    joints = [joint('waist', 'base', 'torso'),
              joint('l1', 'torso', 'la1'), joint('l2', 'la1', 'la2'),
              joint('cam_mount', 'torso', 'cam', 'fixed'),
              joint('r1', 'torso', 'ra1'), joint('r2', 'ra1', 'ra2'),
              joint('fa_j', 'ra2', 'fa', 'prismatic'),
              joint('fb_j', 'ra2', 'fb', 'prismatic',
                    mimic or '<mimic joint="fa_j" multiplier="-1" '
                    'offset="0.01"/>')]
    return f'<robot name="t">{body}{"".join(joints)}{extra}</robot>'


def test_joint_order_parents_and_mimic():
    model = quiet(load_urdf, torso())
    assert model.moving_joints == ('waist', 'l1', 'l2', 'r1', 'r2', 'fa_j',
                                   'fb_j')
    assert model.joint_names == ('waist', 'l1', 'l2', 'r1', 'r2', 'fa_j')
    assert model.parents == (-1, 0, 1, 0, 3, 4, 4)
    assert model.mimic[6] == (5, -1.0, 0.01)
    assert model.link_frames['cam'][0] == 0      # fixed to the torso
    assert model.info['urdf']['merged_fixed'] == ['cam_mount']
    assert model.tool_body is None              # three tips
    # the chain with a tip is today's chain: the rest locked and lumped
    chain = quiet(load_urdf, torso(), tip='la2')
    assert chain.joint_names == ('waist', 'l1', 'l2')
    assert chain.is_chain and chain.tool_body == 2
    assert chain.total_mass == pytest.approx(model.total_mass)


def test_mimic_of_a_mimic_resolves_to_the_root_leader():
    # fb follows fa (x -1, +0.01), fc follows fb (x 2, +0.1):
    # q_fc = 2 (-q_fa + 0.01) + 0.1 = -2 q_fa + 0.12
    extra = ('<link name="fc">' + inertial() + '</link>'
             + joint('fc_j', 'ra2', 'fc', 'prismatic',
                     '<mimic joint="fb_j" multiplier="2" offset="0.1"/>'))
    model = quiet(load_urdf, torso(extra))
    assert model.mimic[-1][0] == 5
    assert model.mimic[-1][1:] == pytest.approx((-2.0, 0.12))
    assert model.n == 6 and model.nb == 8


def test_dual_arm_torso_torque_carries_both_arms():
    # the waist holds both arms: a chain to one hand gets it wrong
    model = quiet(load_urdf, torso())
    q = np.array([0.3, 0.5, -0.2, -0.4, 0.6, 0.02])
    left = quiet(load_urdf, torso(), tip='la2')
    g = gravity_torques(model, q)
    assert abs(g[0] - gravity_torques(left, q[:3])[0]) > 1e-3
    # each arm's own joints see only their arm
    assert g[1:3] == pytest.approx(gravity_torques(left, q[:3])[1:3])


def test_end_effector_of_a_tree_and_jacobian_spellings():
    model = quiet(load_urdf, torso())
    q = np.zeros(model.n)
    with pytest.raises(DynamicsInputError, match='no end effector'):
        jacobian(model, q)
    with pytest.raises(DynamicsInputError, match="closest: 'la2'"):
        jacobian(model, q, 'la3', axes='base')
    with pytest.raises(DynamicsInputError, match="axes must be 'base' or"):
        jacobian(model, q, 'la2', axes='world')
    J = jacobian(model, q, 'la2')                 # axes='base' by default
    assert np.array_equal(J[:, 3:], np.zeros((6, 3)))   # the other arm
    arm = load_robot('puma560')
    qa = np.linspace(-1, 1, 6)
    assert np.array_equal(jacobian(arm, qa, 'end_effector'),
                          jacobian(arm, qa, 'end_effector', axes='link'))
    assert np.array_equal(jacobian(arm, qa),
                          jacobian(arm, qa, 'end_effector', axes='base'))


@pytest.mark.parametrize('text,message', [
    (torso(mimic='<mimic joint="nope"/>'),
     "robot_description: joint 'fb_j' <mimic> joint: no joint named "
     "'nope'"),
    (torso(mimic='<mimic joint="fb_j"/>'),
     "joint 'fb_j' <mimic> joint: mimic joints form a cycle: fb_j -> fb_j"),
    (torso(extra=joint('loop', 'la2', 'ra2', 'fixed')),
     "joint 'loop' <child> link: 'ra2' already has the parent joint 'r2'"),
    (torso(mimic='<mimic joint="cam_mount"/>'),
     "joint 'fb_j' <mimic> joint: its leader 'cam_mount' is a fixed joint"),
    (torso(extra='<link name="o"/>' + joint('free', 'la2', 'o', 'floating')),
     "joint 'free' type: a floating joint is in the tree below the base"),
])
def test_bad_trees_are_one_clear_error(text, message):
    with pytest.raises(RobotFileError) as info:
        load_urdf(text)
    assert message in str(info.value)
    assert '\n' not in str(info.value)


@pytest.mark.parametrize('kind', ['floating', 'planar'])
def test_a_floating_root_starts_the_model_below_it(kind):
    """A root 'odom' -> 'base' (floating, planar): the model starts at base."""
    from newton_euler_ros.core.urdf import urdf_model
    text = torso().replace(
        '</robot>', '<link name="odom"/>' + joint('odom_j', 'odom', 'base',
                                                  kind) + '</robot>')
    model, found, _ = urdf_model(text)
    notes = [str(m) for m in found]
    assert any(f"'odom' carries the rest through the {kind} joint "
               f"'odom_j': the model starts at 'base', fixed" in m
               for m in notes), notes
    given, _, _ = urdf_model(text, base='base')
    rng = np.random.default_rng(2)
    q, qd, qdd = rng.uniform(-1, 1, (3, model.n))
    assert model.joint_names == given.joint_names
    assert np.array_equal(inverse_dynamics(model, q, qd, qdd),
                          inverse_dynamics(given, q, qd, qdd))
    # a chain to a tip too; the base given as the root says where to start
    chain, _, _ = urdf_model(text, tip='la2')
    assert chain.n == 3
    with pytest.raises(RobotFileError,
                       match=r'start below it \(base link .base.\)'):
        urdf_model(text, base='odom')


def test_mimic_cycle_of_two_joints_names_both():
    extra = ('<link name="fc">' + inertial() + '</link>'
             + joint('fc_j', 'ra2', 'fc', 'prismatic',
                     '<mimic joint="fb_j"/>'))
    text = torso(extra, mimic='<mimic joint="fc_j"/>')
    with pytest.raises(RobotFileError, match=r'fb_j -> fc_j -> fb_j'):
        load_urdf(text)


def test_leader_above_the_base_is_an_error():
    text = torso(mimic='<mimic joint="waist"/>')
    with pytest.raises(RobotFileError,
                       match="its leader 'waist' is not below the base"):
        quiet(load_urdf, text, base='torso')


def test_continuous_leader_follower_angles():
    # a follower's angle is multiplier q + offset: at q = pi / 2 a
    # follower with multiplier -1, offset pi is at pi / 2 too
    text = torso(mimic='<mimic joint="fa_j" multiplier="1" offset="0.5"/>')
    model = quiet(load_urdf, text)
    q = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.2])
    from newton_euler_ros.core import link_poses
    T = link_poses(model, q)
    # fa slides 0.2 along y of ra2, fb 0.7 along the same axis
    ra2 = T[5]
    assert (np.linalg.inv(ra2) @ T[6])[1, 3] == pytest.approx(0.2)
    assert (np.linalg.inv(ra2) @ T[7])[1, 3] == pytest.approx(0.7)
    assert math.isfinite(float(gravity_torques(model, q)[5]))


def test_a_tree_written_as_urdf_reads_back_the_same():
    from newton_euler_ros.core import model_to_urdf
    model = random_tree(31, links=9)
    back = quiet(load_urdf, model_to_urdf(model))
    assert back.joint_names == model.joint_names
    assert back.parents == model.parents
    assert [m is None for m in back.mimic] == [m is None for m in model.mimic]
    rng = np.random.default_rng(8)
    q, qd, qdd = rng.uniform(-1, 1, (3, model.n))
    for f in (lambda m: inverse_dynamics(m, q, qd, qdd),
              lambda m: mass_matrix(m, q),
              lambda m: coriolis_matrix(m, q, qd)):
        assert rel(f(back), f(model)) < 1e-13
