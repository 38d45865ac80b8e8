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
robot_sim_node's live wrench (``source: topic``), as a real process.

The node simulates a Puma 560 without gravity and without torque
commands, so the arm rests until a wrench arrives on ``wrench``.  The
wrench is what the end effector exerts (F_e); the environment pushes
back with -F_e, so from rest the joints accelerate at
qdd = -D^-1 J^T F_e.  The test checks the published joint states against
that prediction, and that malformed wrenches are ignored.
"""
import math
import os
import sys
import warnings

import numpy as np
import pytest

pytest.importorskip('rclpy')

# After the skip: pytest must be imported first, hence E402 and I100.
from geometry_msgs.msg import WrenchStamped  # noqa: E402, I100
from newton_euler_ros.core import (forward_dynamics, jacobian,  # noqa: E402
                                   mass_matrix)
from newton_euler_ros.sim.scene import load_scene  # noqa: E402
from ros_harness import domain_id, NodeProcess, Probe  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402

pytestmark = pytest.mark.ros

# away from the wrist singularity, with the tool axes far from the base
# axes: a wrench read in the wrong frame moves most joints the wrong way
Q0 = [2.0, -0.4, 0.6, 1.0, -0.9, 0.5]
RATE = 100.0        # Hz: joint states every 10 ms of simulated time
SCENE = f"""\
name: live_wrench_test
robot: puma560
effects:
  gravity: false
  wrench: {{frame: base, source: topic}}
initial: {{q: {Q0}}}
integrator: {{method: rk4, step: 1.0e-3, duration: 600.0, rate: {RATE}}}
"""
# direction of the test wrench [f; n], every component nonzero; scaled so
# that the fastest joint accelerates at PEAK rad/s^2: the arm then moves a
# few hundredths of a radian in TAU seconds, small enough for the
# constant-acceleration prediction (within 10 % here) and large enough to
# measure
DIRECTION = np.array([10.0, -5.0, 8.0, 0.005, -0.01, 0.008])
PEAK = 2.0
TAU = 0.2           # seconds of simulated time after the wrench arrives
REST_STATES = 50    # joint states checked at rest before any wrench
FAR_FUTURE = 2 ** 31 - 1    # seconds: the largest stamp a message holds


def node_cmd(scene_path):
    script = os.path.join(os.path.dirname(sys.executable), 'robot_sim_node')
    base = [script] if os.path.exists(script) else [
        sys.executable, '-m', 'newton_euler_ros.nodes.robot_sim_node']
    return base + ['--ros-args', '-p', f'scene:={scene_path}',
                   '-p', 'wait_for_controller:=false']


def predicted_accelerations(scene, wrench, axes):
    """Accelerations from rest under an exerted wrench: -D^-1 J^T F_e."""
    model, q0 = scene.model, scene.q0
    qdd = -np.linalg.solve(mass_matrix(model, q0),
                           jacobian(model, q0, axes).T @ wrench)
    # the library's forward dynamics agree (no gravity, no velocity)
    zero = np.zeros(model.n)
    np.testing.assert_allclose(
        forward_dynamics(model, q0, zero, zero, wrench, axes,
                         gravity=False), qdd, rtol=1e-9, atol=1e-12)
    return qdd


def wrench_msg(frame_id, values, sec=0, nanosec=0):
    msg = WrenchStamped()
    msg.header.frame_id = frame_id
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, nanosec
    f, n = msg.wrench.force, msg.wrench.torque
    f.x, f.y, f.z, n.x, n.y, n.z = (float(v) for v in values)
    return msg


def stamp_ns(msg):
    return msg.header.stamp.sec * 10 ** 9 + msg.header.stamp.nanosec


def assert_at_rest(states, q0, log):
    for msg in states:
        np.testing.assert_array_equal(msg.position, q0, err_msg=log)
        np.testing.assert_array_equal(msg.velocity, 0.0, err_msg=log)
        np.testing.assert_array_equal(msg.effort, 0.0, err_msg=log)


def assert_close_per_joint(observed, predicted, rtol, what):
    """Assert the same sign and rtol on every joint that moves at all."""
    big = np.abs(predicted) > 1e-3 * np.abs(predicted).max()
    assert big.sum() >= 5, predicted
    report = f'{what}: observed {observed}, predicted {predicted}'
    assert np.all(np.sign(observed[big]) == np.sign(predicted[big])), report
    assert np.all(np.abs(observed - predicted)[big]
                  <= rtol * np.abs(predicted[big])), report
    assert np.linalg.norm(observed - predicted) \
        <= rtol * np.linalg.norm(predicted), report


@pytest.mark.parametrize('frame_id, axes, offset', [
    ('base_link', 'base', 89),
    ('tool0', 'end_effector', 97),
])
def test_live_wrench_moves_the_arm_as_physics_predicts(tmp_path, frame_id,
                                                       axes, offset):
    scene_path = tmp_path / 'live_wrench.yaml'
    scene_path.write_text(SCENE)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        scene = load_scene(str(scene_path))
    q0 = np.array(Q0)
    unit = predicted_accelerations(scene, DIRECTION, axes)
    wrench = DIRECTION * (PEAK / np.abs(unit).max())
    qdd = unit * (PEAK / np.abs(unit).max())
    period_ns = int(round(1e9 / RATE))

    domain = domain_id(offset)
    node = NodeProcess(node_cmd(str(scene_path)), domain,
                       str(tmp_path / 'robot_sim_node.log'))
    probe = Probe(domain, name='sim_probe')
    try:
        states = probe.collect(JointState, 'joint_states')
        pub = probe.publisher(WrenchStamped, 'wrench')
        # up (kernels loaded), simulating, and subscribed to the wrench
        assert probe.spin_until(
            lambda: len(states) >= 2 and pub.get_subscription_count() > 0,
            90.0), node.log()
        # a live wrench is read, not published: only the probe publishes
        assert probe.node.count_publishers('/wrench') == 1

        # 1. no wrench, no torque: the arm stays exactly at rest
        assert probe.spin_until(lambda: len(states) >= REST_STATES, 30.0), \
            node.log()
        assert_at_rest(states, q0, node.log())

        # 2. malformed wrenches are dropped; each would move the arm (the
        # opposite way to the good one below) if it were applied
        bad = -20.0 * wrench
        now = probe.node.get_clock().now().seconds_nanoseconds()
        pub.publish(wrench_msg(frame_id, [math.nan, *bad[1:]], *now))
        pub.publish(wrench_msg(frame_id, [*bad[:5], math.inf], *now))
        pub.publish(wrench_msg('camera_link', bad, *now))
        pub.publish(wrench_msg(frame_id, bad, FAR_FUTURE, 999_999_999))
        count = len(states)
        assert probe.spin_until(
            lambda: len(states) >= count + REST_STATES, 30.0), node.log()
        assert node.alive(), node.log()
        assert_at_rest(states, q0, node.log())
        assert 'dropped wrench' in node.log()

        # 3. a constant wrench (delivered after the bad ones, in order)
        now = probe.node.get_clock().now().seconds_nanoseconds()
        pub.publish(wrench_msg(frame_id, wrench, *now))

        def first_motion():
            for k, msg in enumerate(states):
                if not np.array_equal(msg.position, q0) or \
                        np.any(msg.velocity):
                    return k
            return None

        assert probe.spin_until(lambda: first_motion() is not None, 30.0), \
            node.log()
        k = first_motion()
        # the wrench acts from the tick after the last state at rest; that
        # state and the first one moving are one period apart
        assert k > 0 and stamp_ns(states[k]) - stamp_ns(states[k - 1]) \
            == period_ns, [stamp_ns(m) for m in states[max(0, k - 3):k + 3]]
        t_wrench = stamp_ns(states[k - 1])
        t_check = t_wrench + int(round(TAU * 1e9))
        assert probe.spin_until(
            lambda: stamp_ns(states[-1]) >= t_check, 30.0), node.log()
        msg = next(m for m in states[k:] if stamp_ns(m) >= t_check)
        tau = (stamp_ns(msg) - t_wrench) * 1e-9
        assert abs(tau - TAU) < 0.5 / RATE
        # from rest under a constant acceleration: dq = qdd t^2 / 2,
        # qd = qdd t (the state changes little in TAU: 30 % tolerance)
        assert_close_per_joint(np.array(msg.position) - q0,
                               0.5 * qdd * tau ** 2, 0.3, 'q - q0')
        assert_close_per_joint(np.array(msg.velocity), qdd * tau, 0.3,
                               'qd')
        # the wrench is no torque command: the applied torque stays zero
        assert all(not np.any(m.effort) for m in states)
        assert all(np.isfinite(m.position).all()
                   and np.isfinite(m.velocity).all() for m in states)
    finally:
        probe.close()
        status = node.stop()
    assert status == 0, node.log()
    assert 'Traceback' not in node.log(), node.log()


PAYLOAD_SCENE = f"""\
name: scheduled_payload_test
robot: puma560
effects: {{gravity: true}}
initial: {{q: {Q0}}}
integrator: {{method: rk4, step: 1.0e-3, duration: 600.0, rate: {RATE}}}
"""
PAYLOAD = {'mass': 2.0, 'com': [0.02, -0.01, 0.08],
           'inertia': [0.01, 0.012, 0.008, 0.001, 0.0, -0.002]}


def offline_states(scene, ticks, switch):
    """(q, qd) at ticks 0..ticks, the payload on the plant from tick ``switch``."""
    import dataclasses
    from newton_euler_ros.feedforward_build import payload_model
    from newton_euler_ros.nodes.robot_sim_node import advance
    from newton_euler_ros.sim.simulate import SceneDynamics

    def plant(mass, com, inertia):
        return SceneDynamics(dataclasses.replace(
            scene, model=payload_model(scene.model, mass, com, inertia)))
    empty, loaded = plant(0.0, [0.0] * 3, [0.0] * 6), plant(**PAYLOAD)
    period = 1.0 / RATE
    q, qd, zero = np.array(Q0), np.zeros(6), np.zeros(6)
    out = [(q, qd)]
    for k in range(ticks):
        q, qd = advance(loaded if k >= switch else empty, q, qd, zero,
                        k * period, period, scene.step, scene.integrator)
        out.append((q, qd))
    return out


def test_payload_at_takes_effect_at_its_simulated_time(tmp_path):
    """A payload change with payload.at reaches the plant at that tick."""
    from rcl_interfaces.srv import SetParametersAtomically
    from rclpy.parameter import Parameter
    scene_path = tmp_path / 'payload.yaml'
    scene_path.write_text(PAYLOAD_SCENE)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        scene = load_scene(str(scene_path))
    domain = domain_id(93)
    # the probe is counted before t = 0: it sees the state at t = 0
    node = NodeProcess(node_cmd(str(scene_path))
                       + ['-p', 'wait_for_subscribers:=1'], domain,
                       str(tmp_path / 'robot_sim_node.log'))
    probe = Probe(domain, name='payload_probe')
    service = 'robot_sim_node/set_parameters_atomically'

    def request(**values):
        return SetParametersAtomically.Request(parameters=[
            Parameter(f'payload.{k}', value=v).to_parameter_msg()
            for k, v in values.items()])

    try:
        states = probe.collect(JointState, 'joint_states')
        assert probe.spin_until(lambda: len(states) >= 2, 90.0), node.log()
        assert list(states[0].position) == Q0, node.log()
        # a time before t = 0 is refused, and nothing changes
        bad = probe.call(SetParametersAtomically, service,
                         request(at=-1.0, **PAYLOAD)).result
        assert not bad.successful and 'payload.at' in bad.reason
        # T well ahead of the clock, on a tick; the answer comes first
        t_now = (stamp_ns(states[-1]) - stamp_ns(states[0])) * 1e-9
        switch = int(round((t_now + 1.0) * RATE))
        ok = probe.call(SetParametersAtomically, service,
                        request(at=switch / RATE, **PAYLOAD)).result
        assert ok.successful, ok.reason
        assert (stamp_ns(states[-1]) - stamp_ns(states[0])) * 1e-9 \
            < switch / RATE, 'the call came back after its own time'
        ticks = switch + 20
        assert probe.spin_until(lambda: len(states) > ticks, 30.0), \
            node.log()
    finally:
        probe.close()
        status = node.stop()
    assert status == 0, node.log()
    assert f'plant payload 2.0 kg from t = {switch / RATE:.3f} s' \
        in node.log(), node.log()
    period_ns = int(round(1e9 / RATE))
    index = [(stamp_ns(m) - stamp_ns(states[0])) // period_ns for m in states]
    assert index[:ticks + 1] == list(range(ticks + 1)), 'a state was lost'
    published = [(np.array(m.position), np.array(m.velocity))
                 for m in states[:ticks + 1]]
    expected = offline_states(scene, ticks, switch)
    for k, ((q, qd), (q_x, qd_x)) in enumerate(zip(published, expected)):
        np.testing.assert_allclose(q, q_x, rtol=0, atol=1e-12, err_msg=k)
        np.testing.assert_allclose(qd, qd_x, rtol=0, atol=1e-12, err_msg=k)
    # one tick early or late would show: the test can tell
    for other in (switch - 1, switch + 1):
        q_o, _ = offline_states(scene, ticks, other)[-1]
        assert np.abs(q_o - published[-1][0]).max() > 1e-9
