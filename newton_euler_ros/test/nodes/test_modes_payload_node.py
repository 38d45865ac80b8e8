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
Modes, run-time payload and trajectory efforts, over real DDS.

The node runs with the bundled per-mode parameter files; the payload is
set through the node's own parameter service, as ``ros2 param set`` would,
and its effect is checked against the payload's gravity and inertia
computed independently: its weight as a wrench at the end effector
(J^T F) and its inertia through the Jacobian of its centre of mass.
"""
import math
import os
import warnings

import numpy as np
import pytest

pytest.importorskip('rclpy')

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402, I100
from newton_euler_interfaces.srv import ComputeDynamics  # noqa: E402
from newton_euler_ros.core import (end_effector_pose,  # noqa: E402
                                   gravity_torques, inverse_dynamics,
                                   jacobian, load_robot, velocity_products,
                                   wrench_torques)
from rcl_interfaces.srv import (SetParameters,  # noqa: E402
                                SetParametersAtomically)
from rclpy.parameter import Parameter  # noqa: E402
from ros_harness import (domain_id, FAST_DIAGNOSTICS,  # noqa: E402
                         id_node_cmd, joint_state, NodeProcess, Probe)
from sensor_msgs.msg import JointState  # noqa: E402
from trajectory_msgs.msg import (JointTrajectory,  # noqa: E402
                                 JointTrajectoryPoint)

pytestmark = pytest.mark.ros

NODE = '/inverse_dynamics_node'


def node_cmd(mode, *extra):
    return id_node_cmd(f'puma560_{mode}.yaml', '-p', 'log_throttle:=0.01',
                       *FAST_DIAGNOSTICS, *extra)


@pytest.fixture(scope='module')
def puma():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot('puma560')


class Graph:
    def __init__(self, tmp, mode, offset):
        self.domain = domain_id(offset)
        self.node = NodeProcess(node_cmd(mode), self.domain,
                                os.path.join(tmp, f'{mode}.log'))
        self.probe = Probe(self.domain)
        self.torques = self.probe.collect(JointState, f'{NODE}/torques')
        self.traj = self.probe.collect(JointTrajectory,
                                       f'{NODE}/trajectory_out')
        self.diag = self.probe.collect(DiagnosticArray, '/diagnostics')
        self.js = self.probe.publisher(JointState, 'joint_states')
        self.traj_in = self.probe.publisher(JointTrajectory,
                                            f'{NODE}/trajectory_in')
        self.probe.call(ComputeDynamics, f'{NODE}/compute_dynamics',
                        ComputeDynamics.Request(), timeout=90.0)
        assert self.probe.spin_until(
            lambda: self.js.get_subscription_count() > 0
            and self.traj_in.get_subscription_count() > 0
            and self.probe.node.count_publishers(f'{NODE}/torques') > 0
            and self.probe.node.count_publishers(f'{NODE}/trajectory_out')
            > 0, 20.0), self.node.log()
        self.seq = 0

    def send(self, names, q, qd):
        self.seq += 1
        stamp = self.probe.keyed_stamp(self.seq)
        self.js.publish(joint_state(names, q, qd, stamp))
        out = self.probe.answer(self.torques, stamp, 5.0)
        assert out is not None, self.node.log()
        return np.array(out.effort)

    def set_params(self, atomically=False, **values):
        """Set parameters (``payload__mass`` for payload.mass)."""
        params = [
            Parameter(name.replace('__', '.'), value=value).to_parameter_msg()
            for name, value in values.items()]
        if atomically:      # one change: mass, com and inertia together
            return self.probe.call(
                SetParametersAtomically, f'{NODE}/set_parameters_atomically',
                SetParametersAtomically.Request(parameters=params)).result
        results = self.probe.call(
            SetParameters, f'{NODE}/set_parameters',
            SetParameters.Request(parameters=params)).results
        # one result per parameter: the first failure, or the last success
        return next((r for r in results if not r.successful), results[-1])

    def close(self):
        code = self.node.stop()
        self.probe.close()
        return code


@pytest.fixture(scope='module')
def gravity_graph(tmp_path_factory):
    g = Graph(str(tmp_path_factory.mktemp('gravity')), 'gravity', 61)
    yield g
    g.close()


@pytest.fixture(scope='module')
def gc_graph(tmp_path_factory):
    g = Graph(str(tmp_path_factory.mktemp('gc')), 'gravity_coriolis', 67)
    yield g
    g.close()


def state(seed, n=6):
    return np.random.default_rng(seed).uniform(-1.2, 1.2, size=(2, n))


def test_gravity_mode_publishes_g_only(gravity_graph, puma):
    q, qd = state(1)
    tau = gravity_graph.send(puma.joint_names, q, qd)
    np.testing.assert_allclose(tau, gravity_torques(puma, q), rtol=1e-12,
                               atol=1e-12)


def test_gravity_coriolis_mode_adds_the_velocity_products(gc_graph, puma):
    q, qd = state(2)
    tau = gc_graph.send(puma.joint_names, q, qd)
    np.testing.assert_allclose(
        tau, gravity_torques(puma, q) + velocity_products(puma, q, qd),
        rtol=1e-12, atol=1e-12)


def test_payload_set_at_run_time_adds_exactly_its_torques(gravity_graph,
                                                          puma):
    g = gravity_graph
    q, qd = state(3)
    before = g.send(puma.joint_names, q, qd)
    D_before = np.reshape(g.probe.call(
        ComputeDynamics, f'{NODE}/compute_dynamics',
        ComputeDynamics.Request(name=list(puma.joint_names),
                                position=q.tolist())).mass_matrix, (6, 6))
    m, com = 2.0, [0.01, -0.02, 0.08]
    inertia6 = [0.004, 0.005, 0.003, 0.0005, 0.0, -0.0002]
    result = g.set_params(atomically=True, payload__mass=m,
                          payload__com=com, payload__inertia=inertia6)
    assert result.successful, result.reason
    after = g.send(puma.joint_names, q, qd)
    # independently: the weight m g hangs at the payload's centre of mass;
    # holding it is the wrench [-m g; r x (-m g)] at the end-effector
    # origin (r from it to the centre of mass, base axes): J^T F
    T = end_effector_pose(puma, q)
    r = T[:3, :3] @ np.array(com)
    F = -m * puma.gravity
    hold = wrench_torques(puma, q, np.concatenate([F, np.cross(r, F)]))
    np.testing.assert_allclose(after - before, hold, rtol=1e-11, atol=1e-11)
    # its inertia: m Jc^T Jc + Jw^T (R I R^T) Jw, Jc = Jv - [r]x Jw
    J = jacobian(puma, q)
    Jv, Jw = J[:3], J[3:]
    Jc = Jv - np.cross(r, Jw.T).T
    ixx, iyy, izz, ixy, iyz, ixz = inertia6
    Ic = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    R = T[:3, :3]
    dD = m * Jc.T @ Jc + Jw.T @ (R @ Ic @ R.T) @ Jw
    D_after = np.reshape(g.probe.call(
        ComputeDynamics, f'{NODE}/compute_dynamics',
        ComputeDynamics.Request(name=list(puma.joint_names),
                                position=q.tolist())).mass_matrix, (6, 6))
    np.testing.assert_allclose(D_after - D_before, dD, rtol=1e-10,
                               atol=1e-12)
    counters = g.probe.next_counters(g.diag)
    assert counters['payload_changes'] == 1
    model_status = g.diag[-1].status[1]
    assert {kv.key: kv.value for kv in model_status.values}[
        'payload.mass'] == '2.0'


@pytest.mark.parametrize('values, reason', [
    ({'payload__mass': -1.0}, 'payload.mass: must be >= 0'),
    ({'payload__com': [0.0, 0.1]}, 'payload.com: must have 3 entries'),
    ({'payload__inertia': [1.0, 1.0, 1.0, 5.0, 0.0, 0.0]},
     'payload.inertia: not positive semi-definite'),
    ({'payload__mass': math.nan}, 'payload.mass: must be finite'),
])
def test_a_rejected_payload_keeps_the_old_one(gravity_graph, puma, values,
                                              reason):
    q, qd = state(4)
    before = gravity_graph.send(puma.joint_names, q, qd)
    result = gravity_graph.set_params(**values)
    assert not result.successful and reason in result.reason
    np.testing.assert_array_equal(
        gravity_graph.send(puma.joint_names, q, qd), before)


def test_trajectory_gets_its_efforts(gc_graph, puma):
    order = [2, 0, 1, 5, 3, 4]
    names = [puma.joint_names[k] for k in order]
    rng = np.random.default_rng(6)
    msg = JointTrajectory()
    msg.joint_names = names
    states = []
    for k in range(20):
        q, qd, qdd = rng.uniform(-1, 1, size=(3, 6))
        states.append((q, qd, qdd))
        pt = JointTrajectoryPoint()
        pt.time_from_start.sec = 0
        pt.time_from_start.nanosec = 50_000_000 * (k + 1)
        pt.positions = q[order].tolist()
        pt.velocities = qd[order].tolist()
        pt.accelerations = qdd[order].tolist()
        msg.points.append(pt)
    gc_graph.traj_in.publish(msg)
    assert gc_graph.probe.spin_until(lambda: gc_graph.traj, 5.0)
    out = gc_graph.traj[-1]
    assert list(out.joint_names) == names and len(out.points) == 20
    for pt, (q, qd, qdd) in zip(out.points, states):
        np.testing.assert_allclose(
            pt.effort, inverse_dynamics(puma, q, qd, qdd)[order],
            rtol=1e-12, atol=1e-12)
        np.testing.assert_array_equal(pt.positions, q[order])
    # a bad one (times going back) is counted, not published
    before = gc_graph.probe.next_counters(gc_graph.diag)
    msg.points[5].time_from_start.nanosec = 1
    count = len(gc_graph.traj)
    gc_graph.traj_in.publish(msg)
    gc_graph.probe.spin_for(0.5)
    assert len(gc_graph.traj) == count
    after = gc_graph.probe.next_counters(gc_graph.diag)
    assert after['malformed'] == before['malformed'] + 1
    assert 'trajectory: points[5].time_from_start' in gc_graph.node.log()


def test_nodes_stop_cleanly(gravity_graph, gc_graph):
    for g in (gravity_graph, gc_graph):
        assert g.node.stop() == 0
        assert 'Traceback' not in g.node.log()
