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
inverse_dynamics_node as a real process on loopback DDS.

The node starts through its console script with a bundled parameter file;
this process publishes joint states and wrenches, collects the outputs and
calls the service through a separate rclpy context.
"""
import math
import os
import subprocess
import time
import warnings

import numpy as np
import pytest

pytest.importorskip('rclpy')

# After the skip: pytest must be imported first, hence E402 and I100.
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402, I100
from geometry_msgs.msg import WrenchStamped  # noqa: E402
from newton_euler_interfaces.srv import ComputeDynamics  # noqa: E402
from newton_euler_ros.core import (coriolis_matrix, gravity_torques,  # noqa: E402
                                   inverse_dynamics, load_robot,
                                   mass_matrix)
from ros_harness import (domain_id, FAST_DIAGNOSTICS,  # noqa: E402
                         id_node_cmd, joint_state, NodeProcess, Probe, ros_env,
                         wrench)
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import Float64MultiArray  # noqa: E402

pytestmark = pytest.mark.ros

NODE = '/inverse_dynamics_node'
# output order deliberately differs from the robot file's
OUTPUT = ['joint3', 'joint1', 'joint2', 'joint6', 'joint4', 'joint5']
TIMEOUT = 1.0   # wrench.timeout for this node, seconds


def node_cmd(*extra):
    return id_node_cmd('puma560.yaml', *FAST_DIAGNOSTICS, *extra)


@pytest.fixture(scope='module')
def model():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot('puma560')


class Graph:
    def __init__(self, tmp):
        self.domain = domain_id(11)
        self.node = NodeProcess(
            node_cmd('-p', f'joints:=[{",".join(OUTPUT)}]',
                     '-p', f'wrench.timeout:={TIMEOUT}',
                     '-p', 'log_throttle:=0.01'),
            self.domain, os.path.join(tmp, 'node.log'))
        self.probe = Probe(self.domain)
        self.cmds = self.probe.collect(Float64MultiArray,
                                       f'{NODE}/torque_command')
        self.torques = self.probe.collect(JointState, f'{NODE}/torques')
        self.diag = self.probe.collect(DiagnosticArray, '/diagnostics')
        self.js = self.probe.publisher(JointState, 'joint_states')
        self.wr = self.probe.publisher(WrenchStamped, 'wrench')
        self.seq = 0
        # the service answers once the node is up and its kernels are warm
        self.probe.call(ComputeDynamics, f'{NODE}/compute_dynamics',
                        ComputeDynamics.Request(), timeout=90.0)
        assert self.probe.spin_until(
            lambda: self.js.get_subscription_count() > 0
            and self.wr.get_subscription_count() > 0
            and self.node_pubs_matched(), 20.0), self.node.log()

    def node_pubs_matched(self):
        return (self.probe.node.count_publishers(f'{NODE}/torques') > 0 and
                self.probe.node.count_publishers(f'{NODE}/torque_command')
                > 0)

    def now(self):
        return self.probe.node.get_clock().now()

    def send_state(self, q, qd, names=None, position=None, velocity=None,
                   wait=5.0):
        """
        Publish a joint state in shuffled order with an extra joint.

        Return (torque_command data, torques msg), or None if no output.
        """
        self.seq += 1
        stamp = self.probe.keyed_stamp(self.seq)
        order = [5, 2, 0, 4, 1, 3]
        msg = joint_state(
            names if names is not None else (
                ['gripper'] + [f'joint{k + 1}' for k in order]),
            position if position is not None else (
                [0.7] + [q[k] for k in order]),
            velocity if velocity is not None else (
                [0.0] + [qd[k] for k in order]), stamp)
        before = len(self.cmds)
        self.js.publish(msg)

        def arrived():
            return any(t.header.stamp == stamp for t in self.torques) and \
                len(self.cmds) > before
        if not self.probe.spin_until(arrived, wait):
            return None
        tq = next(t for t in self.torques if t.header.stamp == stamp)
        return np.array(self.cmds[-1].data), tq

    def send_wrench(self, frame, values, age=0.0):
        self.wr.publish(wrench(frame, values,
                               self.probe.keyed_stamp(0, -age)))
        self.probe.spin_for(0.3)

    def counters(self):
        return self.probe.next_counters(self.diag)


@pytest.fixture(scope='module')
def graph(tmp_path_factory):
    g = Graph(str(tmp_path_factory.mktemp('node')))
    yield g
    g.probe.close()
    g.node.stop()


def permute(x):
    idx = [int(name[-1]) - 1 for name in OUTPUT]
    return np.asarray(x)[idx]


RNG = np.random.default_rng(7)
STATES = [RNG.uniform(-2.0, 2.0, size=(2, 6)) for _ in range(3)]


@pytest.mark.parametrize('state', range(len(STATES)))
def test_torque_command_equals_library(graph, model, state):
    q, qd = STATES[state]
    out = graph.send_state(q, qd)
    assert out is not None, graph.node.log()
    cmd, tq = out
    expected = permute(inverse_dynamics(model, q, qd))
    np.testing.assert_allclose(cmd, expected, rtol=0, atol=1e-12)
    assert list(tq.name) == OUTPUT
    np.testing.assert_allclose(tq.effort, expected, rtol=0, atol=1e-12)


@pytest.mark.parametrize('frame, axes', [('base_link', 'base'),
                                         ('tool0', 'end_effector')])
def test_wrench_in_each_frame(graph, model, frame, axes):
    q, qd = STATES[0]
    wrench = [12.0, -4.0, 30.0, 0.5, -1.5, 0.25]
    graph.send_wrench(frame, wrench)
    cmd, _ = graph.send_state(q, qd)
    expected = permute(inverse_dynamics(model, q, qd, None, wrench, axes))
    np.testing.assert_allclose(cmd, expected, rtol=0, atol=1e-12)
    assert np.abs(expected - permute(inverse_dynamics(model, q, qd))).max() \
        > 1.0   # the wrench really changed the torques


def test_expired_wrench_is_no_longer_applied(graph, model):
    q, qd = STATES[1]
    graph.send_wrench('base_link', [0.0, 0.0, 50.0, 0.0, 0.0, 0.0])
    time.sleep(TIMEOUT + 0.2)
    cmd, _ = graph.send_state(q, qd)
    np.testing.assert_allclose(cmd, permute(inverse_dynamics(model, q, qd)),
                               rtol=0, atol=1e-12)
    # said as expired, with what the node does, not as 'dropped'
    log = graph.node.log()
    assert (f'wrench expired: the last wrench is older than wrench.timeout '
            f'({TIMEOUT} s); the torques are computed without it until a '
            f'new one arrives (expired: ') in log, log
    assert not [line for line in log.splitlines()
                if 'dropped wrench' in line and 'older than' in line]


def test_service_returns_dynamics_terms(graph, model):
    q, qd = STATES[2]
    qdd = RNG.uniform(-1.0, 1.0, 6)
    req = ComputeDynamics.Request()
    req.name = list(reversed(model.joint_names))
    req.position = list(reversed(q.tolist()))
    req.velocity = list(reversed(qd.tolist()))
    req.acceleration = list(reversed(qdd.tolist()))
    res = graph.probe.call(ComputeDynamics, f'{NODE}/compute_dynamics', req)
    assert res.success, res.message
    assert list(res.name) == OUTPUT
    idx = [int(name[-1]) - 1 for name in OUTPUT]
    D = np.array(res.mass_matrix).reshape(6, 6)
    C = np.array(res.coriolis_matrix).reshape(6, 6)
    ix = np.ix_(idx, idx)
    np.testing.assert_allclose(D, mass_matrix(model, q)[ix], rtol=0,
                               atol=1e-12)
    np.testing.assert_allclose(C, coriolis_matrix(model, q, qd)[ix], rtol=0,
                               atol=1e-12)
    np.testing.assert_allclose(res.gravity, permute(gravity_torques(model,
                                                                    q)),
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.torque, permute(inverse_dynamics(
        model, q, qd, qdd)), rtol=0, atol=1e-12)


def test_service_empty_request_uses_latest_state(graph, model):
    q, qd = STATES[0]
    graph.send_state(q, qd)
    res = graph.probe.call(ComputeDynamics, f'{NODE}/compute_dynamics',
                           ComputeDynamics.Request())
    assert res.success, res.message
    np.testing.assert_allclose(res.torque, permute(inverse_dynamics(
        model, q, qd)), rtol=0, atol=1e-12)


def bad_requests(model):
    names = list(model.joint_names)
    yield ComputeDynamics.Request(name=names[:5], position=[0.0] * 5), \
        'missing joints'
    yield ComputeDynamics.Request(name=names, position=[0.0] * 5), \
        'position has 5 entries for 6 names'
    yield ComputeDynamics.Request(
        name=names, position=[0.0] * 5 + [math.nan]), 'position of'
    yield ComputeDynamics.Request(name=names, position=[0.0] * 6,
                                  velocity=[math.inf] * 6), 'velocity of'
    yield ComputeDynamics.Request(name=names + ['joint1'],
                                  position=[0.0] * 7), 'appears twice'


def test_bad_input_publishes_nothing_and_good_input_still_works(graph, model):
    q, qd = STATES[1]
    before = graph.counters()
    names6 = [f'joint{k}' for k in range(1, 7)]
    bad_states = [
        {'names': names6[:5], 'position': list(q[:5]),
         'velocity': list(qd[:5])},
        {'names': names6, 'position': [*q[:5], math.nan],
         'velocity': list(qd)},
        {'names': names6, 'position': list(q), 'velocity': [math.inf] * 6},
        {'names': names6, 'position': list(q[:5]), 'velocity': list(qd)},
        {'names': names6 + ['joint2'], 'position': [*q, 0.0],
         'velocity': [*qd, 0.0]},
    ]
    for bad in bad_states:
        assert graph.send_state(q, qd, wait=0.5, **bad) is None
    graph.send_wrench('camera_link', [1.0] * 6)         # unknown frame
    graph.send_wrench('base_link', [math.nan] + [0.0] * 5)
    graph.send_wrench('base_link', [1.0] * 6, age=10.0)  # stale on arrival
    for req, message in bad_requests(model):
        res = graph.probe.call(ComputeDynamics, f'{NODE}/compute_dynamics',
                               req)
        assert not res.success and message in res.message, res.message
    # good input works afterwards, without any of the bad wrenches applied
    cmd, _ = graph.send_state(q, qd)
    np.testing.assert_allclose(cmd, permute(inverse_dynamics(model, q, qd)),
                               rtol=0, atol=1e-12)
    after = graph.counters()
    grew = {k: after[k] - before[k] for k in after}
    assert grew['missing_joints'] >= 1
    assert grew['non_finite'] >= 3          # 2 joint states, 1 wrench
    assert grew['malformed'] >= 2
    assert grew['unknown_frame'] >= 1 and grew['stale'] >= 1
    assert grew['service_failures'] >= 5
    assert after['internal_error'] == 0
    log = graph.node.log()
    assert 'dropped joint state: missing joints' in log
    assert 'dropped wrench: wrench frame_id' in log


def test_never_published_non_finite(graph):
    assert graph.cmds and graph.torques
    assert all(np.isfinite(m.data).all() for m in graph.cmds)
    assert all(np.isfinite(m.effort).all() for m in graph.torques)


def test_diagnostics_give_the_time_per_update(graph, model):
    """/diagnostics: median, 99th percentile and largest update time."""
    for k in range(5):
        assert graph.send_state([0.1 * k] * 6, [0.0] * 6) is not None
    count = len(graph.diag)
    assert graph.probe.spin_until(lambda: len(graph.diag) > count, 5.0)
    status = next(s for s in graph.diag[-1].status
                  if s.name.endswith(': update time'))
    values = {kv.key: float(kv.value) for kv in status.values}
    assert values['updates'] >= 5 and values['window'] >= 5
    assert 0.0 < values['median_us'] <= values['p99_us'] <= \
        values['max_us'] < 1e6
    assert 'joint state to torques' in status.message


def test_stops_cleanly(graph):
    assert graph.node.stop() == 0
    log = graph.node.log()
    assert 'Traceback' not in log, log


@pytest.mark.parametrize('args, message', [
    (['-p', 'robot_file:=no_such_robot'],
     'robot_file: no_such_robot: no such file'),
    (['-p', 'joints:=[joint1, joint2]'], 'joints: must name every joint'),
    (['-p', 'wrench.convention:=pushing'], 'wrench.convention: must be one '
                                           'of'),
    (['-p', 'qos.depth:=0'], 'qos.depth: must be > 0'),
    (['-p', 'scene:=no_such_scene'], 'scene: no_such_scene: no such file'),
    (['-p', 'scene:=puma_payload_press', '-p', 'tip_link:=tool0'],
     'base_link/tip_link: not with scene'),
    (['-p', 'tip_link:=tool0'],
     'robot_file: puma560: base and tip links apply to URDF robots'),
    (['-p', 'robot_file:='], 'cannot start'),
    (['-p', 'wrench.timeout:=1'], 'wrench.timeout: wrong type: Trying to set '
                                  "parameter 'wrench.timeout' to '1' of type"
                                  " 'INTEGER', expecting type 'DOUBLE'"),
    (['-p', 'payload.com:=[0, 0, 1]'], 'payload.com: wrong type'),
    (['-p', 'payload.mass:=-2.0'], 'payload.mass: must be >= 0'),
    (['-p', 'mode:=gravity', '-p', 'acceleration_source:=reference'],
     'acceleration_source: reference needs mode full'),
])
def test_bad_parameters_refuse_to_start(tmp_path, args, message):
    proc = subprocess.run(node_cmd(*args), env=ros_env(domain_id(29)),
                          capture_output=True, text=True, timeout=90)
    assert proc.returncode == 2, proc.stderr
    assert message in proc.stderr
    assert 'Traceback' not in proc.stderr
    # one line, after the log lines of start-up
    assert len([line for line in proc.stderr.splitlines()
                if not line.startswith('[')]) == 1, proc.stderr


def test_reference_accelerations_enter_the_torques(tmp_path, model):
    from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint
    domain = domain_id(37)
    node = NodeProcess(node_cmd('-p', 'acceleration_source:=reference'),
                       domain, str(tmp_path / 'node.log'))
    probe = Probe(domain)
    try:
        probe.call(ComputeDynamics, f'{NODE}/compute_dynamics',
                   ComputeDynamics.Request(), timeout=90.0)
        torques = probe.collect(JointState, f'{NODE}/torques')
        js = probe.publisher(JointState, 'joint_states')
        ref = probe.publisher(JointTrajectory, f'{NODE}/reference')
        assert probe.spin_until(
            lambda: js.get_subscription_count() > 0
            and ref.get_subscription_count() > 0
            and probe.node.count_publishers(f'{NODE}/torques') > 0, 20.0)
        q, qd = STATES[2]
        qdd = np.linspace(-1.0, 1.0, 6)
        traj = JointTrajectory()
        traj.joint_names = list(reversed(model.joint_names))
        point = JointTrajectoryPoint()
        point.accelerations = list(reversed(qdd.tolist()))
        traj.points = [point]           # one point: held for all time
        ref.publish(traj)
        probe.spin_for(0.3)
        msg = JointState()
        msg.header.stamp = probe.node.get_clock().now().to_msg()
        msg.name = list(model.joint_names)
        msg.position, msg.velocity = q.tolist(), qd.tolist()
        js.publish(msg)
        assert probe.spin_until(lambda: torques, 5.0), node.log()
        np.testing.assert_allclose(
            torques[-1].effort, inverse_dynamics(model, q, qd, qdd),
            rtol=0, atol=1e-12)
    finally:
        probe.close()
        assert node.stop() == 0


def test_scene_parameter_selects_effects(tmp_path):
    from newton_euler_ros.sim.scene import load_scene
    from newton_euler_ros.sim.simulate import SceneDynamics
    scene = load_scene('puma_payload_press')
    domain = domain_id(43)
    node = NodeProcess(node_cmd('-p', 'scene:=puma_payload_press'), domain,
                       str(tmp_path / 'node.log'))
    probe = Probe(domain)
    try:
        q, qd = STATES[1]
        req = ComputeDynamics.Request(name=list(scene.model.joint_names),
                                      position=q.tolist(),
                                      velocity=qd.tolist())
        res = probe.call(ComputeDynamics, f'{NODE}/compute_dynamics', req,
                         timeout=90.0)
        assert res.success, res.message
        expected = SceneDynamics(scene).torques(q, qd, None, None)
        np.testing.assert_allclose(res.torque, expected, rtol=0, atol=1e-12)
        assert "effects ['gravity', 'velocity_products', 'payload'" \
            in node.log()
    finally:
        probe.close()
        assert node.stop() == 0


@pytest.mark.parametrize('sig', ['SIGINT', 'SIGTERM'])
def test_a_stop_during_start_up_is_one_line(sig):
    """SIGINT or SIGTERM while the node imports, loads, warms up: exit 0."""
    import signal
    import time
    env = ros_env(domain_id(31))
    for delay in (0.2, 1.0, 1.8, 2.6):
        proc = subprocess.Popen(node_cmd(), env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        time.sleep(delay)
        proc.send_signal(getattr(signal, sig))
        try:
            out, err = proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()         # leave nothing running in the domain
            out, err = proc.communicate()
            raise AssertionError(f'still running {delay} s after {sig}: '
                                 f'{err}') from None
        assert proc.returncode == 0, (delay, err)
        assert 'Traceback' not in err and 'Error' not in err, (delay, err)
        lines = [line for line in err.splitlines()
                 if not line.startswith('[')]
        assert len(lines) <= 1, (delay, err)
