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
The end effectors' wrenches of a tree estimated jointly (issue 37).

PR2 and TIAGo Pro (example-robot-data): two arms on a shared torso lift.
The residual of a push is Pinocchio's ``J^T F`` (its own URDF reading and
Jacobians), or the observer's own residual on the efforts of a resting
robot pushed (Pinocchio's gravity minus ``J^T F``, with sensor noise).
Checked: the pushed hand's wrench within 1 % of F (the part its joints
feel), the other hand's exactly zero, where estimating each hand alone
reads the push at both; both hands pushed at once recovered; the
combinations reported as not separable give no joint torque (Pinocchio's
J), none where the frames share no joint, and the estimate differs from
the truth only along them; no NaN at singular poses.
"""
import warnings

from newton_euler_ros.core import load_robot, RobotFileWarning
from newton_euler_ros.core.errors import DynamicsInputError
from newton_euler_ros.core.observer import (contact_step, external_wrench,
                                            initial_contact, initial_state,
                                            MomentumObserver, observer_step)
from newton_euler_ros.core.observer.wrenches import (external_wrenches,
                                                     own_joints,
                                                     separability)
import numpy as np
import pytest

PR2 = ('pr2_description/urdf/pr2.urdf',
       ('r_gripper_tool_frame', 'l_gripper_tool_frame'))
TIAGO = ('tiago_pro_description/robots/tiago_pro.urdf',
         ('arm_right_tool_link', 'arm_left_tool_link'))
BAXTER = ('baxter_description/urdf/baxter.urdf',
          ('right_gripper', 'left_gripper'))
F_PUSH = np.array([6.0, -4.0, -15.0, 0.8, -0.5, 0.3])
F_OTHER = np.array([-3.0, 9.0, 5.0, -0.4, 0.2, 0.6])


def _robot(source):
    """(our model, Pinocchio's reading of the same whole URDF)."""
    import pinocchio  # noqa: F401 (a test dependency: make setup installs it)
    from newton_euler_tools.peers import example_robot_urdf, PinocchioTree
    try:
        path = example_robot_urdf(source)
    except ImportError:
        pytest.skip('example-robot-data is not installed')
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        model = load_robot(path)
    return model, PinocchioTree(path, model)


@pytest.fixture(scope='module', params=[PR2, TIAGO], ids=['pr2', 'tiago'])
def two_arms(request):
    source, hands = request.param
    model, peer = _robot(source)
    return model, peer, hands


def _pose(model, seed):
    q = np.random.default_rng(seed).uniform(-0.8, 0.8, model.n)
    for k, name in enumerate(model.joint_names):
        if 'torso' in name or 'finger' in name or 'gripper' in name:
            q[k] = 0.01 * (k % 3)       # prismatic: centimetres
    return q


def _felt_part(J, F, tol=1e-6):
    """F projected on the range of J (what the frame's joints feel)."""
    U, s, _ = np.linalg.svd(J, full_matrices=False)
    U = U[:, s > tol * s[0]]
    return U @ (U.T @ F)


def _close(est, true, rel=0.01, small=1e-3):
    return np.abs(est - true).max() <= rel * np.abs(true).max() + small


def test_a_push_on_one_hand_is_read_there_and_nowhere_else(two_arms):
    model, peer, (right, left) = two_arms
    obs = MomentumObserver(model, thresholds=1.0)       # damping 0.01
    # the damping's bias is lambda^2 / s^2 of the smallest singular
    # value s: 1.2 % near PR2's wrist; within 1 % at a tenth of it
    sharp = MomentumObserver(model, thresholds=1.0, damping=1e-3)
    for seed in range(3):
        q = _pose(model, seed)
        for axes in ('base', 'link'):
            J = peer.terms(q, q, q, (right, left))
            r = J[f'J {right} {axes}'].T @ F_PUSH
            # each hand alone: the torso's share is read at the other
            alone = external_wrench(obs, q, r, frame=left, axes=axes)
            assert np.abs(alone).max() > 1.0
            got = external_wrenches(obs, q, r, (right, left), axes=axes)
            assert got.active.tolist() == [True, False]
            np.testing.assert_allclose(got.wrench[0], external_wrench(
                obs, q, r, frame=right, axes=axes), rtol=0, atol=1e-9)
            assert not got.wrench[1].any()
            assert got.ambiguous.shape[1] == 0 and got.text() == 'none'
            got = external_wrenches(sharp, q, r, (right, left), axes=axes)
            assert _close(got.wrench[0],
                          _felt_part(J[f'J {right} {axes}'], F_PUSH))
            assert not got.wrench[1].any()


def test_both_hands_pushed_at_once_are_separated(two_arms):
    model, peer, hands = two_arms
    obs = MomentumObserver(model, thresholds=1.0, damping=1e-3)
    q = _pose(model, 7)
    J = peer.terms(q, q, q, hands)
    Jr, Jl = (J[f'J {h} link'] for h in hands)
    r = Jr.T @ F_PUSH + Jl.T @ F_OTHER
    got = external_wrenches(obs, q, r, hands, axes='link')
    assert got.active.all() and got.ambiguous.shape[1] == 0
    assert _close(got.wrench[0], F_PUSH) and _close(got.wrench[1], F_OTHER)
    # the same push read on the observer's own residual
    np.testing.assert_allclose(Jr.T @ got.wrench[0] + Jl.T @ got.wrench[1],
                               r, rtol=0, atol=0.01 * np.abs(r).max())


def test_the_observer_on_a_pushed_resting_robot(two_arms):
    """Efforts of a resting robot pushed, with noise: the residual's say."""
    model, peer, (right, left) = two_arms
    obs = MomentumObserver(model, thresholds=1.0, rest_reference=False)
    q = _pose(model, 3)
    terms = peer.terms(q, 0 * q, 0 * q, (right,))
    Jr = terms[f'J {right} base']
    rng = np.random.default_rng(0)
    state, contact = initial_state(obs), initial_contact(obs)
    zero = np.zeros(model.n)
    for k in range(300):                # 1 kHz; pushed from 50 ms on
        push = F_PUSH if k >= 50 else 0.0 * F_PUSH
        tau = terms['g'] - Jr.T @ push + rng.normal(0.0, 0.02, model.n)
        r, _ = observer_step(obs, state, 1e-3 * k, q, zero, tau)
        contact_step(obs, contact, r, state.allowance, 1e-3 * k, q, zero)
        got = external_wrenches(obs, q, r, (right, left), contact=contact)
        assert not got.wrench[1].any()          # never on the other hand
        if k == 49:
            assert not got.wrench.any()         # nothing felt before
    assert contact.in_contact and got.active.tolist() == [True, False]
    assert _close(got.wrench[0], _felt_part(Jr, F_PUSH), small=0.2)


def test_not_separable_combinations_give_no_joint_torque():
    """Two shoulders on a vertical torso lift: their vertical pushes trade."""
    model, peer = _robot(PR2[0])
    obs = MomentumObserver(model, damping=0.0)
    links = ('r_upper_arm_roll_link', 'l_upper_arm_roll_link')
    q = _pose(model, 11)
    J = peer.terms(q, q, q, links)
    Jall = np.concatenate([J[f'J {x} base'] for x in links])
    layout = separability(obs, q, links)
    D = layout.ambiguous
    assert D.shape[1] >= 1 and layout.ambiguous_counts[0] >= 1
    np.testing.assert_allclose(D.T @ D, np.eye(D.shape[1]), atol=1e-9)
    assert np.abs(Jall.T @ D).max() < 1e-9
    # each part is felt by its own frame: not a direction it cannot feel
    for i, x in enumerate(links):
        assert np.abs(J[f'J {x} base'].T @ D[6 * i:6 * i + 6]).max() > 0.01
    assert 'r_upper_arm_roll_link.' in layout.text()
    # both pushed: the estimate gives the same torques, and differs from
    # the truth only along what cannot be separated or felt
    F = np.concatenate([F_PUSH, F_OTHER])
    r = Jall.T @ F
    got = external_wrenches(obs, q, r, links, felt=np.ones(model.n, bool))
    est = got.wrench.ravel()
    np.testing.assert_allclose(Jall.T @ est, r, atol=1e-8)
    N = np.concatenate([D] + [np.kron(np.eye(2)[:, [i]], u) for i, u in
                              enumerate(got.unfelt)], axis=1)
    err = F - est
    np.testing.assert_allclose(err, N @ (N.T @ err), atol=1e-8)
    assert np.abs(N.T @ est).max() < 1e-8       # the minimum-norm split


def test_frames_sharing_no_joint_have_nothing_ambiguous():
    model, peer = _robot(BAXTER[0])
    obs = MomentumObserver(model, damping=0.0)
    hands = BAXTER[1]
    # each hand owns its whole arm: no joint moves both
    assert [len(x) for x in own_joints(model, hands)] == [7, 7]
    for seed in range(3):
        q = _pose(model, seed)
        assert separability(obs, q, hands).ambiguous.shape[1] == 0
        J = peer.terms(q, q, q, hands)
        r = J[f'J {hands[0]} base'].T @ F_PUSH + \
            J[f'J {hands[1]} base'].T @ F_OTHER
        got = external_wrenches(obs, q, r, hands, felt=np.ones(model.n,
                                                               bool))
        np.testing.assert_allclose(got.wrench, [F_PUSH, F_OTHER], atol=1e-6)


def test_own_joints_follow_mimic_leaders():
    """PR2's finger tips: one coordinate moves both, so neither owns it."""
    model, _ = _robot(PR2[0])
    names = model.joint_names
    tips = ('r_gripper_l_finger_tip_link', 'r_gripper_r_finger_tip_link')
    assert own_joints(model, tips) == ((), ())
    # the right tip's finger joints follow r_gripper_l_finger_joint, on
    # the other finger's branch: that coordinate moves it, it owns it
    own = own_joints(model, (tips[1], 'l_gripper_tool_frame'))
    assert 'r_gripper_l_finger_joint' in {names[j] for j in own[0]}
    assert len(own[0]) == 8 and len(own[1]) == 7
    assert 'torso_lift_joint' not in {names[j] for j in own[0] + own[1]}
    # a frame with no joint of its own is never reported
    obs = MomentumObserver(model)
    q = _pose(model, 1)
    got = external_wrenches(obs, q, np.ones(model.n), tips,
                            felt=np.ones(model.n, bool))
    assert not got.active.any() and not got.wrench.any()


def test_no_nan_at_singular_poses(two_arms):
    model, peer, hands = two_arms
    q = np.zeros(model.n)               # wrists straight: singular
    J = peer.terms(q, q, q, hands)
    Jr = J[f'J {hands[0]} base']
    r = Jr.T @ F_PUSH
    for damping in (0.0, 0.01):
        obs = MomentumObserver(model, thresholds=1.0, damping=damping)
        got = external_wrenches(obs, q, r, hands)
        assert np.isfinite(got.wrench).all() and not got.wrench[1].any()
        if damping == 0.0:
            assert _close(got.wrench[0], _felt_part(Jr, F_PUSH))
        for r_any in (np.full(model.n, 1e6), np.full(model.n, 1e-300)):
            got = external_wrenches(obs, q, r_any, hands,
                                    felt=np.ones(model.n, bool))
            assert np.isfinite(got.wrench).all()
            assert np.isfinite(got.ambiguous).all()


def test_bad_input_is_one_line():
    model, _ = _robot(PR2[0])
    obs = MomentumObserver(model)
    q = np.zeros(model.n)
    with pytest.raises(DynamicsInputError, match='r_grip'):
        external_wrenches(obs, q, q, ('r_grip', 'l_gripper_tool_frame'))
    with pytest.raises(DynamicsInputError, match='axes'):
        external_wrenches(obs, q, q, PR2[1], axes='world')
    with pytest.raises(DynamicsInputError, match='felt'):
        external_wrenches(obs, q, q, PR2[1], felt=[True])
