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
The other terms on trees: regressor, observer terms, copies, wrenches, sim.

- The regressor against ``pin.computeJointTorqueRegressor`` (on the
  mimic-free model mapped by G: Pinocchio refuses mimic joints there) and
  Y pi = tau.
- The momentum observer's terms (D qd, C^T qd, g in one recursion) equal
  those of the matrices.
- The float32 copy and the batch calls run the same kernels on trees.
- Wrenches at links, several at once, in base or link axes: the
  recursion (and the articulated-body algorithm) against J_link^T F from
  the Jacobians of those links and from the Euler-Lagrange reference.
- Energy is conserved in simulation of a tree with mimic joints.
"""
import warnings

from newton_euler_ros.core import (coriolis_matrix, forward_dynamics,
                                   forward_dynamics_batch, gravity_torques,
                                   inverse_dynamics, inverse_dynamics_batch,
                                   jacobian, load_robot, load_urdf,
                                   mass_matrix, mass_matrix_batch,
                                   Workspace, wrench_torques)
from newton_euler_ros.core import kernels as K
from newton_euler_ros.core.errors import DynamicsInputError
from newton_euler_ros.core.float32 import Float32Dynamics
from newton_euler_ros.core.regressor import (inertial_parameters,
                                             n_parameters, regressor)
from newton_euler_ros.core.robot_file import RobotFileWarning
import numpy as np
import pytest
from random_tree import random_tree_urdf
import reference_dynamics as ref
from test_trees import BRANCHED, robot_path, torso, urdf_path

EPS32 = float(np.finfo(np.float32).eps)


def quiet(text):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        return load_urdf(text)


def rel(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


@pytest.mark.parametrize('source', [BRANCHED[0][0], BRANCHED[4][0],
                                    BRANCHED[5][0], 1, 4, 16])
def test_regressor_on_trees_matches_pinocchio(source, tmp_path):
    from newton_euler_tools.peers import PinocchioTree
    path = urdf_path(source, tmp_path)
    model = quiet(path)
    peer = PinocchioTree(path, model)
    rng = np.random.default_rng(7)
    pi = inertial_parameters(model)
    for _ in range(2):
        q, qd, qdd = rng.uniform(-1.2, 1.2, (3, model.n))
        Y = regressor(model, q, qd, qdd)
        assert Y.shape == (model.n, 10 * model.nb)
        assert rel(Y, peer.regressor(q, qd, qdd)) < 1e-12
        assert rel(Y @ pi, inverse_dynamics(model, q, qd, qdd)) < 1e-12
    Yd = regressor(model, q, qd, qdd, drives=True)
    assert Yd.shape == (model.n, n_parameters(model, True))
    assert np.array_equal(Yd[:, :10 * model.nb], Y)


def test_observer_terms_on_a_tree():
    model = quiet(random_tree_urdf(21, links=10)[0])
    ws = Workspace(model)
    rng = np.random.default_rng(2)
    terms = np.empty((3, model.n))
    for _ in range(3):
        q, qd = rng.uniform(-1.5, 1.5, (2, model.n))
        assert K.run_momentum_terms(model.packed, q, qd, ws.ws, ws.cw,
                                    terms) == -1
        D = mass_matrix(model, q)
        C = coriolis_matrix(model, q, qd)
        assert rel(terms[0], D @ qd) < 1e-12
        assert rel(terms[1], C.T @ qd) < 1e-12
        assert rel(terms[2], gravity_torques(model, q)) < 1e-12


def test_float32_and_batches_on_a_tree():
    model = quiet(random_tree_urdf(22, links=10)[0])
    assert model.nb > model.n               # mimic joints present
    f32 = Float32Dynamics(model)
    rng = np.random.default_rng(3)
    Q, QD, QDD = rng.uniform(-1, 1, (3, 4, model.n))
    TAU = inverse_dynamics_batch(model, Q, QD, QDD)
    DD = mass_matrix_batch(model, Q)
    QDD_back = forward_dynamics_batch(model, Q, QD, TAU)  # Cholesky rows
    for k in range(4):
        q, qd, qdd = Q[k], QD[k], QDD[k]
        tau = inverse_dynamics(model, q, qd, qdd)
        assert np.array_equal(TAU[k], tau)
        assert np.array_equal(DD[k], mass_matrix(model, q))
        assert rel(QDD_back[k], qdd) < 1e-11
        bound = 100 * model.n * EPS32
        assert rel(f32.inverse_dynamics(q, qd, qdd), tau) < bound
        assert rel(f32.mass_matrix(q), mass_matrix(model, q)) < bound
        assert rel(f32.coriolis_matrix(q, qd),
                   coriolis_matrix(model, q, qd)) < bound
        D = mass_matrix(model, q)
        assert rel(f32.forward_dynamics(q, qd, tau), qdd) \
            < bound * np.linalg.cond(D)


# ---------------------------------------------------------------------------
# wrenches at links
# ---------------------------------------------------------------------------
def test_wrenches_at_links_recursion_equals_jacobians():
    model = quiet(torso())
    rng = np.random.default_rng(4)
    q, qd, qdd = rng.uniform(-1, 1, (3, model.n))
    F = {'la2': rng.normal(size=6), 'ra2': rng.normal(size=6),
         'fa': rng.normal(size=6), 'cam': rng.normal(size=6)}
    frames = {'la2': 'link', 'ra2': 'base', 'fa': 'link', 'cam': 'base'}
    tau = inverse_dynamics(model, q, qd, qdd, F, frames)
    bare = inverse_dynamics(model, q, qd, qdd)
    JtF = wrench_torques(model, q, F, frames)
    assert rel(tau - bare, JtF) < 1e-13
    # the independent reference: each frame's Jacobian from the FK
    total = np.zeros(model.n)
    for name, f in F.items():
        body, pose = model.link_frames[name]
        total += ref.frame_jacobian(model, q, body, pose, frames[name]).T @ f
    assert rel(tau - bare, total) < 1e-12
    # forward dynamics with the same wrenches inverts it
    for method in ('aba', 'cholesky'):
        assert rel(forward_dynamics(model, q, qd, tau, F, frames,
                                    method=method), qdd) < 1e-11


def test_wrench_on_a_frame_fixed_to_the_base_moves_nothing():
    model = quiet(torso())
    q = np.linspace(-0.5, 0.5, model.n)
    F = {'base': np.arange(6.0)}
    assert np.array_equal(inverse_dynamics(model, q, wrench=F),
                          inverse_dynamics(model, q))
    assert np.array_equal(wrench_torques(model, q, F), np.zeros(model.n))


def test_end_effector_wrench_two_ways_on_a_chain():
    arm = load_robot('puma560')
    rng = np.random.default_rng(5)
    q, qd, qdd = rng.uniform(-1, 1, (3, 6))
    w = rng.normal(size=6)
    for old, new in (('base', 'base'), ('end_effector', 'link')):
        a = inverse_dynamics(arm, q, qd, qdd, w, old)
        b = inverse_dynamics(arm, q, qd, qdd, {'end_effector': w}, new)
        assert rel(a, b) < 1e-14
        assert rel(wrench_torques(arm, q, w, old),
                   wrench_torques(arm, q, {'end_effector': w}, new)) < 1e-14
        # the same to round-off times the conditioning of D
        cond = np.linalg.cond(mass_matrix(arm, q))
        assert rel(forward_dynamics(arm, q, qd, a, w, old),
                   forward_dynamics(arm, q, qd, a, {'end_effector': w},
                                    new)) < 100 * cond * 2.2e-16


def test_urdf_wrench_at_a_sensor_frame_on_a_chain():
    arm = quiet(robot_path('panda_description/urdf/panda.urdf'))
    q = np.random.default_rng(6).uniform(-1, 1, arm.n)
    F = np.array([1.0, -2.0, 3.0, 0.1, 0.2, -0.3])
    for axes in ('base', 'link'):
        tau = inverse_dynamics(arm, q, wrench={'panda_hand_tcp': F},
                               wrench_frame=axes) - gravity_torques(arm, q)
        J = jacobian(arm, q, 'panda_hand_tcp', axes=axes)
        assert rel(tau, J.T @ F) < 1e-13


@pytest.mark.parametrize('wrench,frame,message', [
    ({'nowhere': np.zeros(6)}, 'base', "'nowhere' is not one"),
    ({'la2': np.zeros(6)}, 'world', "wrench_frame of 'la2' must be 'base'"),
    ({'la2': [0, 0, np.nan, 0, 0, 0]}, 'base',
     "wrench['la2'][2] is nan"),
    ({'la2': [0, 0, 0]}, 'base', "wrench['la2'] must have 6 entries"),
    ({'la2': np.zeros(6)}, {'ra2': 'base'},
     "wrench_frame names 'ra2' without a wrench"),
])
def test_bad_link_wrenches_are_one_line(wrench, frame, message):
    model = quiet(torso())
    with pytest.raises(DynamicsInputError) as info:
        inverse_dynamics(model, np.zeros(model.n), wrench=wrench,
                         wrench_frame=frame)
    assert message in str(info.value)
    assert '\n' not in str(info.value)


# ---------------------------------------------------------------------------
# simulation
# ---------------------------------------------------------------------------
def test_energy_is_conserved_simulating_a_tree(tmp_path):
    from newton_euler_ros.sim.scene import scene_from_dict
    from newton_euler_ros.sim.run import simulate
    path = tmp_path / 'tree.urdf'
    path.write_text(random_tree_urdf(11, links=9)[0])
    model = quiet(str(path))
    assert model.nb > model.n and model.parents.count(-1) > 1
    scene = scene_from_dict({
        'name': 'tree', 'robot': str(path),
        'initial': {'q': [0.3] * model.n, 'qd': [0.5] * model.n},
        'controller': {'kp': 0.0, 'kd': 0.0, 'feedforward': False},
        'integrator': {'method': 'rk4', 'step': 1e-3, 'duration': 0.2}},
        'tree')
    result = simulate(scene)
    assert result.summary['energy_drift_relative'] < 1e-10
    assert np.abs(np.asarray(result.summary['final_qd'])).max() > 0.1
