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
A whole robot's inputs without ROS: partial joint states, sensors at links.

On published URDFs (Baxter: two arms, a head, a mimic finger in each
gripper; Unitree's Z1, a tree with a single tip): the rules of
``whole_robot.JointStateMerger`` and ``wrenches.LinkWrenches`` one by
one, and the wrenches the sensors give against sum J_link^T F from the
Jacobians of the links.
"""
import warnings

from newton_euler_ros.core import (frame_pose, inverse_dynamics, jacobian,
                                   load_urdf)
from newton_euler_ros.joint_inputs import InputRejected
from newton_euler_ros.whole_robot import JointStateMerger
from newton_euler_ros.wrenches import LinkWrenches
import numpy as np
import pytest

BAXTER = 'baxter_description/urdf/baxter.urdf'
Z1 = 'z1_description/urdf/z1.urdf'


def robot(relative):
    from newton_euler_tools.peers import example_robot_urdf
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_urdf(example_robot_urdf(relative))


@pytest.fixture(scope='module')
def baxter():
    return robot(BAXTER)


def rejected(kind, call, *args):
    with pytest.raises(InputRejected) as info:
        call(*args)
    assert info.value.kind == kind, str(info.value)
    return str(info.value)


def test_mimic_joints_are_checked_against_the_latest_leader(baxter):
    merger = JointStateMerger(baxter, ['left_s0'], hold=0.5, tolerance=0.005)
    arm = [j for j in baxter.joint_names if 'finger' not in j]
    # the leader in one message, its follower in the next: checked
    # against the held leader
    merger.merge(['l_gripper_l_finger_joint'], [0.015], [], [], 0.0)
    line = rejected('mimic_mismatch', merger.merge,
                    ['l_gripper_r_finger_joint'], [0.015], [], [], 0.1)
    assert line.startswith("mimic joint 'l_gripper_r_finger_joint' is at "
                           "0.015 but its leader 'l_gripper_l_finger_joint' "
                           'at 0.015 puts it at -0.015')
    merger.merge(['l_gripper_r_finger_joint'], [-0.017], [], [], 0.1)
    # a refused message changes nothing held: the right finger's leader
    # has never been received, so its follower is not checked
    merger.merge(['r_gripper_r_finger_joint'], [0.3], [], [], 0.1)
    q, _ = merger.merge(arm + ['r_gripper_l_finger_joint'],
                        np.zeros(len(arm) + 1), [], [], 0.2)
    assert q[baxter.joint_names.index('l_gripper_l_finger_joint')] == 0.015
    # tolerance 0: no check
    free = JointStateMerger(baxter, ['left_s0'], hold=0.5, tolerance=0.0)
    free.merge(['l_gripper_l_finger_joint', 'l_gripper_r_finger_joint'],
               [0.01, 0.01], [], [], 0.0)


def test_partial_messages_alternate_and_expire(baxter):
    left = [j for j in baxter.joint_names if j.startswith('left')]
    rest = [j for j in baxter.joint_names if j not in left]
    merger = JointStateMerger(baxter, left, hold=0.5)
    assert 'never received' in rejected('missing_joints', merger.merge, left,
                                        np.ones(7), np.ones(7), [], 0.0)
    for t in np.arange(1.0, 2.0, 0.1):          # two drivers, 10 Hz each
        assert merger.merge(rest, np.full(10, t), [], [], t) is None
        q, qd = merger.merge(left, np.full(7, -t), np.ones(7), [], t + 0.05)
        assert np.array_equal(q, np.where(np.isin(baxter.joint_names, left),
                                          -t, t))
        assert np.array_equal(qd, np.isin(baxter.joint_names, left) * 1.0)
    assert len(merger._cache) == 2
    line = rejected('missing_joints', merger.merge, left, np.ones(7), [], [],
                    2.5)
    assert 'older than joint_states.hold (0.5 s): [' in line
    # the left gripper (carried by the left arm) is needed; the head and
    # the right arm (other branches) are not
    assert "'l_gripper_l_finger_joint (0.6 s ago)'" in line
    assert 'head_pan' not in line and 'right_' not in line


def test_bad_messages_are_refused_with_the_joint_named(baxter):
    merger = JointStateMerger(baxter, baxter.joint_names)
    names = list(baxter.moving_joints)
    n = len(names)
    assert rejected('other_joints', merger.merge, ['wheel'], [0.0], [], [],
                    0.0).startswith("none of the robot's joints")
    rejected('malformed', merger.merge, names, np.zeros(n - 1), [], [], 0.0)
    rejected('malformed', merger.merge, names, np.zeros(n), [1.0], [], 0.0)
    rejected('malformed', merger.merge, names[:2] + names[:1],
             np.zeros(3), [], [], 0.0)
    q = np.zeros(n)
    q[names.index('left_e1')] = np.nan
    assert "position of 'left_e1' is nan" in rejected(
        'non_finite', merger.merge, names, q, [], [], 0.0)
    rejected('oversized', merger.merge, ['x'] * 1000, [0.0] * 1000, [], [],
             0.0)
    # efforts: all of them, or the joints without one
    q = np.zeros(n)
    merger.merge(names, q, [], np.ones(n), 0.0)
    assert merger.efforts()[0] is not None
    merger.merge(names[:3], q[:3], [], [], 0.1)
    assert merger.efforts() == (None, list(names[:3]))


def test_sensors_at_links_are_sum_of_jacobian_transposes(baxter):
    wrenches = LinkWrenches(baxter, ['base_link'], ['end_effector'],
                            link='left_gripper',
                            convention='applied_to_robot', timeout=1.0)
    F = np.array([3.0, -4.0, 12.0, 0.3, -0.2, 0.5])
    wrenches.update('right_hand_camera_link', F, 10.0, 10.0)  # link axes
    wrenches.update('base_link', 2 * F, 10.2, 10.2)  # base axes, at the link
    w, axes = wrenches.current(10.5)
    assert axes == {'right_hand_camera_link': 'link', 'left_gripper': 'base'}
    q = np.random.default_rng(2).uniform(-1, 1, baxter.n)
    z = np.zeros(baxter.n)
    expected = (inverse_dynamics(baxter, q)
                - jacobian(baxter, q, 'right_hand_camera_link',
                           axes='link').T @ F
                - jacobian(baxter, q, 'left_gripper', axes='base').T @ (2 * F))
    np.testing.assert_allclose(inverse_dynamics(baxter, q, z, z, w, axes),
                               expected, rtol=1e-12, atol=1e-12)
    # each expires alone
    assert wrenches.expire(11.1) and wrenches.last_expired == [
        'right_hand_camera_link']
    assert list(wrenches.current(11.1)[0]) == ['left_gripper']
    assert wrenches.current(11.3) == (None, 'base')
    # two sensors on one link add up; in other axes one is refused
    wrenches.update('left_gripper', F, 20.0, 20.0)
    assert 'one sensor per link' in rejected(
        'malformed', wrenches.update, 'base_link', F, 20.0, 20.0)
    wrenches.update('end_effector', F, 20.0, 20.0)      # link axes too
    assert np.array_equal(wrenches.current(20.0)[0]['left_gripper'], -2 * F)


def test_frames_without_a_link_to_act_at(baxter):
    wrenches = LinkWrenches(baxter, ['base_link'], ['tool0'])
    assert 'needs wrench.link' in rejected('unknown_frame', wrenches.update,
                                           'base_link', np.ones(6), 0.0, 0.0)
    rejected('unknown_frame', wrenches.update, 'ft_sensor', np.ones(6), 0.0,
             0.0)
    rejected('stale', wrenches.update, 'head', np.ones(6), 1.0, 2.0)
    rejected('stale', wrenches.update, 'head', np.ones(6), 3.0, 2.0)
    rejected('non_finite', wrenches.update, 'head', [np.nan] * 6, 0.0, 0.0)
    with pytest.raises(ValueError, match="'hand' is not a link of baxter"):
        LinkWrenches(baxter, [], [], link='hand')


def test_a_tree_with_one_tip_takes_base_frames_at_its_end_effector():
    z1 = robot(Z1)
    assert z1.tool_body is not None
    wrenches = LinkWrenches(z1, ['link00'], ['tool0'])
    F = np.array([1.0, 2.0, -3.0, 0.1, 0.0, 0.2])
    wrenches.update('link00', F, 0.0, 0.0)
    w, axes = wrenches.current(0.0)
    assert axes == {'end_effector': 'base'}
    q = np.random.default_rng(3).uniform(-1, 1, z1.n)
    np.testing.assert_allclose(
        inverse_dynamics(z1, q, wrench=w, wrench_frame=axes)
        - inverse_dynamics(z1, q),
        jacobian(z1, q, z1.info['urdf']['tip'], axes='base').T @ F,
        rtol=1e-12, atol=1e-12)
    # the end effector is the leaf link of the tree
    assert np.allclose(frame_pose(z1, q, 'end_effector'),
                       frame_pose(z1, q, z1.info['urdf']['tip']))


def test_a_trajectory_of_one_arm_holds_the_others_where_they_are(baxter):
    """The node's computer of a whole robot, built as the node builds it."""
    from newton_euler_ros.feedforward_build import build_computer, PAYLOAD
    from newton_euler_ros.parameters import load_specs
    params = {s.name: s.default for s in load_specs()}
    left = [j for j in baxter.joint_names if j.startswith('left')]
    params['joints'] = left
    ff = build_computer(params, 'gravity_coriolis', baxter,
                        tuple(params[k] for k in PAYLOAD))
    assert ff.merger is not None and ff.order.command == len(left)
    rng = np.random.default_rng(7)
    Q, QD, QDD = rng.uniform(-1, 1, (3, 2, len(left)))
    points = [{'time_from_start': float(k), 'positions': Q[k],
               'velocities': QD[k], 'accelerations': QDD[k]}
              for k in range(2)]
    # nothing to hold the head and the other arm at yet
    assert 'no joint state has arrived' in rejected(
        'no_state', ff.trajectory, left, points, 0.0)
    # a whole joint state, then the trajectory of the left arm: the
    # others stay at its positions, at rest
    q = rng.uniform(-0.5, 0.5, baxter.n)
    state = ff.merger.merge(baxter.joint_names, q, np.ones(baxter.n), [],
                            0.0)
    ff.state_torques(*state, 0.0, 0.0)
    efforts, exceeded = ff.trajectory(left, points, 0.0)
    at = [baxter.joint_names.index(j) for j in left]
    for k in range(2):
        qk, qdk, qddk = q.copy(), np.zeros(baxter.n), np.zeros(baxter.n)
        qk[at], qdk[at], qddk[at] = Q[k], QD[k], QDD[k]
        expected = inverse_dynamics(baxter, qk, qdk, qddk)[at]
        np.testing.assert_allclose(efforts[k], expected, rtol=0,
                                   atol=1e-9 * (1 + np.abs(expected).max()))
    assert not exceeded


TIAGO_PRO = 'tiago_pro_description/robots/tiago_pro.urdf'


def test_only_the_joints_the_commanded_torques_depend_on_are_required():
    """
    The right arm of TIAGo Pro needs its torso and gripper only.

    Its torques do not depend on the wheels, the head or the left arm,
    and those need never be published.
    """
    from newton_euler_ros.whole_robot import needed_coordinates
    model = robot(TIAGO_PRO)
    names = list(model.joint_names)
    arm = [j for j in names if j.startswith('arm_right')]
    trigger = np.isin(names, arm)
    needed = {names[k] for k in np.flatnonzero(
        needed_coordinates(model, trigger))}
    assert needed == set(arm) | {'torso_lift_joint',
                                 'gripper_right_finger_joint'}
    # the physics behind it: the right arm's torques are the same
    # whatever the joints not needed do
    rng = np.random.default_rng(4)
    q, qd, qdd = rng.uniform(-1, 1, (3, model.n))
    other = ~np.isin(names, sorted(needed))
    q2, qd2, qdd2 = q.copy(), qd.copy(), qdd.copy()
    for x in (q2, qd2, qdd2):
        x[other] = rng.uniform(-1, 1, other.sum())
    tau = inverse_dynamics(model, q, qd, qdd)
    tau2 = inverse_dynamics(model, q2, qd2, qdd2)
    np.testing.assert_allclose(tau2[trigger], tau[trigger], rtol=0,
                               atol=1e-12 * np.abs(tau).max())
    assert not np.allclose(tau2[other], tau[other])     # they did change
    # the merger: states of the arm, torso and right gripper compute; the
    # left gripper locked at 0.02; wheels, head and left arm never sent
    merger = JointStateMerger(model, arm, hold=0.5, tolerance=0.005,
                              locked={'gripper_left_finger_joint': 0.02})
    sent = arm + ['torso_lift_joint', 'gripper_right_finger_joint']
    got, _ = merger.merge(sent, np.full(len(sent), 0.1), [], [], 0.0)
    assert got[names.index('gripper_left_finger_joint')] == 0.02
    # a message moving the locked joint changes nothing
    merger.merge(['gripper_left_finger_joint'], [0.5], [], [], 0.1)
    got, _ = merger.merge(sent, np.full(len(sent), 0.1), [], [], 0.2)
    assert got[names.index('gripper_left_finger_joint')] == 0.02
    # a needed joint missing is still refused, by name
    line = rejected('missing_joints', merger.merge, arm,
                    np.zeros(len(arm)), [], [], 1.0)
    assert 'torso_lift_joint' in line and 'wheel' not in line
