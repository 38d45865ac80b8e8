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

"""The torque regressor: Y pi is the inverse dynamics; Y is Pinocchio's."""
import math
import warnings

from newton_euler_ros.core import (bundled_robots, DynamicsInputError,
                                   inverse_dynamics_batch, load_robot,
                                   RobotFileWarning)
from newton_euler_ros.core.model import make_chain, pose_matrix
from newton_euler_ros.core.regressor import (drive_regressor,
                                             inertial_parameters,
                                             link_inertials, link_parameters,
                                             pseudo_inertia, regressor,
                                             regressor_batch,
                                             with_parameters)
from newton_euler_tools.accuracy.chains import random_chain
import numpy as np
import pytest


def quiet(name, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        return load_robot(name, **kw)


def rel(a, b):
    return np.abs(np.asarray(a) - b).max() / max(np.abs(b).max(), 1e-300)


def states(rng, m, n, scale=1.5):
    return (rng.uniform(-scale, scale, (m, n)) for _ in range(3))


@pytest.mark.parametrize('name', bundled_robots())
def test_y_pi_is_inverse_dynamics_on_bundled_robots(name):
    model = quiet(name)
    rng = np.random.default_rng(sum(map(ord, name)))
    Q, QD, QDD = states(rng, 20, model.n)
    Y = regressor_batch(model, Q, QD, QDD)
    assert Y.shape == (20, model.n, 10 * model.n)
    tau = inverse_dynamics_batch(model, Q, QD, QDD)
    assert rel(Y @ inertial_parameters(model), tau) < 1e-13
    # the single call is the batch's row
    np.testing.assert_array_equal(regressor(model, Q[3], QD[3], QDD[3]),
                                  Y[3])


def general_chain(rng, n):
    """Return a URDF-style chain: any axes, placements, post transforms."""
    types = ['prismatic' if rng.random() < 0.3 else 'revolute'
             for _ in range(n)]
    pre = [pose_matrix(rng.uniform(-0.3, 0.3, 3),
                       rng.uniform(-math.pi, math.pi, 3)) for _ in range(n)]
    post = [pose_matrix(rng.uniform(-0.2, 0.2, 3),
                        rng.uniform(-math.pi, math.pi, 3)) for _ in range(n)]
    axes = rng.normal(size=(n, 3))
    mass = rng.uniform(0.5, 4, n)
    inertia = []
    for m in mass:
        A = rng.normal(size=(3, 3))
        inertia.append(0.05 * m * (A @ A.T + np.eye(3)))
    return make_chain('g', [f'j{k}' for k in range(n)], types, pre, axes,
                      mass, rng.uniform(-0.2, 0.2, (n, 3)), inertia,
                      joint_post=post, gravity=rng.normal(size=3) * 5)


@pytest.mark.parametrize('seed', range(4))
def test_random_chains(seed):
    rng = np.random.default_rng(seed)
    for model in (random_chain(3 + 2 * seed, seed),
                  random_chain(4 + seed, seed, convention='modified'),
                  general_chain(rng, 2 + 3 * seed)):
        Q, QD, QDD = states(rng, 10, model.n)
        Y = regressor_batch(model, Q, QD, QDD)
        tau = inverse_dynamics_batch(model, Q, QD, QDD)
        assert rel(Y @ inertial_parameters(model), tau) < 1e-12


def test_linear_in_each_link_alone():
    # the columns of link k reproduce the dynamics of that link alone
    model = quiet('panda')
    rng = np.random.default_rng(3)
    Q, QD, QDD = states(rng, 5, model.n)
    Y = regressor_batch(model, Q, QD, QDD)
    pi = inertial_parameters(model)
    for k in range(model.n):
        mass = np.zeros(model.n)
        mass[k] = model.mass[k]
        inertia = np.zeros_like(model.inertia)
        inertia[k] = model.inertia[k]
        alone = model.replace(mass=mass, inertia=inertia)
        cols = slice(10 * k, 10 * k + 10)
        assert rel(Y[:, :, cols] @ pi[cols],
                   inverse_dynamics_batch(alone, Q, QD, QDD)) < 1e-13


PUBLISHED = [
    ('ur_description/urdf/ur5_robot.urdf', 'tool0'),
    ('panda_description/urdf/panda.urdf', 'panda_hand_tcp'),
    ('kinova_description/robots/kinova.urdf', 'j2s6s200_end_effector'),
    ('xarm_description/urdf/xarm7.urdf', None),
    ('z1_description/urdf/z1.urdf', None),
]


@pytest.mark.parametrize('relative,tip', PUBLISHED)
def test_matches_pinocchio_regressor(relative, tip):
    import pinocchio as pin
    from newton_euler_tools.peers import example_robot_urdf, PinocchioUrdf
    path = example_robot_urdf(relative)
    model = quiet(path, tip=tip)
    peer = PinocchioUrdf(path, model.joint_names, model.info['urdf']['tip'])
    rng = np.random.default_rng(len(relative))
    Q, QD, QDD = states(rng, 5, model.n)
    Y = regressor_batch(model, Q, QD, QDD)
    for i in range(5):
        x = peer.config(Q[i])
        theirs = pin.computeJointTorqueRegressor(
            peer.model, peer.data, x, QD[i], QDD[i])
        assert rel(Y[i], theirs) < 1e-13
        # and their parameters are ours (same link frames)
        assert rel(Y[i] @ inertial_parameters(model),
                   pin.rnea(peer.model, peer.data, x, QD[i], QDD[i])) < 1e-13
    theirs = np.concatenate([peer.model.inertias[j].toDynamicParameters()
                             for j in range(1, peer.model.njoints)])
    assert rel(inertial_parameters(model), theirs) < 1e-12


def test_drive_columns():
    model = quiet('panda')
    rng = np.random.default_rng(4)
    Q, QD, QDD = states(rng, 6, model.n)
    eps = 0.05
    Y = regressor_batch(model, Q, QD, QDD, drives=True, coulomb_width=eps)
    n = model.n
    assert Y.shape == (6, n, 14 * n)
    np.testing.assert_array_equal(Y[:, :, :10 * n],
                                  regressor_batch(model, Q, QD, QDD))
    fv, fc, off, arm = rng.uniform(0.1, 2, (4, n))
    drives = np.stack([fv, fc, off, arm], axis=1).ravel()
    expect = fv * QD + fc * np.tanh(QD / eps) + off + arm * QDD
    np.testing.assert_allclose(Y[:, :, 10 * n:] @ drives, expect,
                               rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(drive_regressor(QD, QDD, eps),
                               Y[:, :, 10 * n:], rtol=1e-15, atol=1e-15)


def test_parameters_round_trip_and_pseudo_inertia():
    model = quiet('panda')
    pi = inertial_parameters(model)
    back = with_parameters(model, pi)
    np.testing.assert_allclose(back.mass, model.mass, rtol=1e-14)
    np.testing.assert_allclose(back.com, model.com, atol=1e-14)
    np.testing.assert_allclose(back.inertia, model.inertia, atol=1e-14)
    for j in range(model.n):
        # a real body: positive definite pseudo-inertia, whose trace
        # identity holds: tr(S) = sum m x^2 = (tr I) / 2
        J = pseudo_inertia(pi[10 * j:10 * j + 10])
        assert np.linalg.eigvalsh(J).min() > 0
        m, c, Ic = link_inertials(link_parameters(2.0, [0.1, 0, 0],
                                                  np.eye(3)))
        assert m == 2.0 and np.allclose(c, [0.1, 0, 0])
        assert np.allclose(Ic, np.eye(3))
    # a point mass at c: J = m [c; 1][c; 1]^T, rank one
    J = pseudo_inertia(link_parameters(3.0, [0.1, 0.2, 0.3], np.zeros((3, 3))))
    v = np.array([0.1, 0.2, 0.3, 1.0])
    np.testing.assert_allclose(J, 3.0 * np.outer(v, v), atol=1e-15)


def test_bad_input():
    model = quiet('panda')
    q = np.zeros(7)
    with pytest.raises(DynamicsInputError, match='7 columns'):
        regressor(model, np.zeros(6), q, q)
    with pytest.raises(DynamicsInputError, match='QD row 0'):
        regressor(model, q, q + np.nan, q)
    with pytest.raises(DynamicsInputError, match='coulomb_width'):
        regressor(model, q, q, q, drives=True, coulomb_width=0.0)
