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
The nodes in a real robot graph, as processes over DDS.

A robot bringup shares one parameter file among its nodes (a ``/**:``
section with ``use_sim_time`` and ``qos_overrides``): every node of the
package starts with it, and inverse_dynamics_node applies it (its
``joint_states`` subscription best effort as the graph sees it, its clock
the simulated ``/clock``).  The node's own parameters are still checked
for typos, and a bad QoS override is one line.

A gripper driver publishing its own JointStates on ``joint_states``
beside the arm's: its messages are counted in ``/diagnostics``
(``other_joints``), not warned about, and the arm's torques keep coming
at the arm's rate.

A rejected ``robot_description`` shows as rejected, with its reason, in
``/diagnostics`` and in the service's answer (not as "waiting").

A Panda (Franka's torque interface adds gravity itself) with
``robot_compensates_gravity``: the published torques are Pinocchio's
C(q, qd) qd on the same published URDF, and trajectory efforts
D qdd + C qd, while the service still reports g.
"""
import os
import sys
import time

import numpy as np
import pytest
import yaml

pytest.importorskip('rclpy')

from builtin_interfaces.msg import Duration, Time  # noqa: E402, I100
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from newton_euler_interfaces.srv import ComputeDynamics  # noqa: E402
from rclpy.qos import (DurabilityPolicy, QoSProfile,  # noqa: E402
                       ReliabilityPolicy)
from ros_harness import (domain_id, id_node_cmd, joint_state,  # noqa: E402
                         NodeProcess, Probe, ros_env)
from rosgraph_msgs.msg import Clock  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import String  # noqa: E402
from trajectory_msgs.msg import (JointTrajectory,  # noqa: E402
                                 JointTrajectoryPoint)

pytestmark = pytest.mark.ros

DOMAIN = domain_id(61)
NODE = '/inverse_dynamics_node'
PUMA_JOINTS = [f'joint{k}' for k in range(1, 7)]
SCENE = 'puma_payload_press'


def script(node):
    return os.path.join(os.path.dirname(sys.executable), node)


def shared_params(tmp_path, use_sim_time, extra=None):
    """Write a bringup's shared parameter file: one ``/**:`` section."""
    params = {
        'use_sim_time': use_sim_time,
        'start_type_description_service': True,
        'qos_overrides': {
            '/joint_states': {
                'subscription': {'reliability': 'best_effort', 'depth': 3},
                'publisher': {'depth': 50}},
            '/tracking_controller_node/commands': {
                'publisher': {'depth': 20}},
            '/tf': {'publisher': {'durability': 'volatile'}}},
        **(extra or {})}
    path = tmp_path / 'shared.yaml'
    path.write_text(yaml.safe_dump({'/**': {'ros__parameters': params}}))
    return str(path)


def wait_for(node, text, timeout=90.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if text in node.log():
            return node.log()
        assert node.alive(), node.log()
        time.sleep(0.2)
    raise AssertionError(f'no {text!r} in:\n{node.log()}')


def test_shared_params_file_is_applied(tmp_path):
    """
    use_sim_time and the joint_states QoS override take effect.

    With ``joint_states.max_age: 0.5`` a joint state stamped at 1000 s is
    answered only if the node's clock is the simulated one the probe
    publishes on /clock (against the wall clock it is 55 years old), and
    the graph shows the node's joint_states subscription best effort
    (the node's own qos.reliability is reliable).
    """
    shared = shared_params(tmp_path, use_sim_time=True)
    probe = Probe(DOMAIN)
    node = NodeProcess(id_node_cmd('puma560.yaml', '--params-file', shared,
                                   '-p', 'joint_states.max_age:=0.5'),
                       DOMAIN, str(tmp_path / 'node.log'))
    try:
        clock = probe.node.create_publisher(Clock, '/clock', 10)
        js = probe.node.create_publisher(
            JointState, 'joint_states',
            QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
        torques = probe.collect(JointState, f'{NODE}/torques')
        diagnostics = probe.collect(DiagnosticArray, '/diagnostics')

        def ours():
            return [info for info in probe.node.get_subscriptions_info_by_topic(
                '/joint_states') if info.node_name == NODE[1:]]
        assert probe.spin_until(lambda: ours() and js.get_subscription_count()
                                and 'puma560 (' in node.log(), 90.0), \
            node.log()
        [info] = ours()
        assert info.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT
        log = node.log()
        assert 'qos_overrides: /joint_states.subscription: depth 3, ' \
            'reliability best_effort' in log, log
        assert 'unknown parameter' not in log and 'WARN' not in log, log

        sim = 1000.0
        answer = None
        for seq in range(1, 200):
            sim += 0.01
            now = Time(sec=int(sim), nanosec=int(round(sim % 1 * 1e9)))
            clock.publish(Clock(clock=now))
            probe.spin_for(0.01)
            stamp = Time(sec=now.sec, nanosec=now.nanosec + seq % 1000)
            js.publish(joint_state(PUMA_JOINTS, [0.1] * 6, [0.0] * 6, stamp))
            answer = probe.answer(torques, stamp, 0.05)
            if answer is not None and len(diagnostics) > 0:
                break
        assert answer is not None, node.log()
        # the diagnostics timer runs on the simulated clock too
        assert probe.spin_until(lambda: len(diagnostics) > 0, 5.0)
        counts = {kv.key: kv.value for kv in diagnostics[-1].status[0].values}
        assert counts['stale'] == '0' and counts['bad_stamp'] == '0', counts
    finally:
        code = node.stop()
        probe.close()
    assert code == 0, node.log()


@pytest.mark.parametrize('cmd, applied', [
    ([script('robot_sim_node'), '--ros-args', '-p', f'scene:={SCENE}',
      '-p', 'wait_for_controller:=false'],
     'qos_overrides: /joint_states.publisher: depth 50'),
    ([script('tracking_controller_node'), '--ros-args', '-p',
      f'scene:={SCENE}'],
     'qos_overrides: /tracking_controller_node/commands.publisher: '
     'depth 20'),
    (id_node_cmd('puma560.yaml'),
     'qos_overrides: /joint_states.subscription: depth 3, '
     'reliability best_effort'),
], ids=['robot_sim_node', 'tracking_controller_node',
        'inverse_dynamics_node'])
def test_every_node_starts_with_the_shared_file(cmd, applied, tmp_path):
    node = NodeProcess([*cmd, '--params-file',
                        shared_params(tmp_path, use_sim_time=False)],
                       DOMAIN, str(tmp_path / 'node.log'))
    try:
        wait_for(node, applied)
        time.sleep(1.0)
        assert node.alive(), node.log()
    finally:
        code = node.stop()
    assert code == 0, node.log()
    assert 'unknown parameter' not in node.log(), node.log()


def run(cmd):
    import subprocess
    return subprocess.run(cmd, env=ros_env(DOMAIN), capture_output=True,
                          text=True, timeout=120)


@pytest.mark.parametrize('extra, message', [
    ({'robot_flie': 'puma560'},
     "unknown parameter 'robot_flie' (did you mean 'robot_file'?)"),
    ({'qos_overrides': {'/joint_states': {'subscription': {
        'reliability': 'sure'}}}},
     'qos_overrides./joint_states.subscription.reliability: Unexpected QoS '
     'override for policy `reliability`: `sure`'),
    ({'qos_overrides': {'/joint_states': {'subscription': {'depth': 0}}}},
     'qos_overrides./joint_states.subscription.depth: depth must be >= 1 '
     'with history keep_last, got 0'),
])
def test_typos_and_bad_overrides_still_stop_the_node(extra, message,
                                                     tmp_path):
    shared = shared_params(tmp_path, use_sim_time=False, extra=extra)
    proc = run(id_node_cmd('puma560.yaml', '--params-file', shared))
    assert proc.returncode == 2, proc.stderr
    lines = [x for x in proc.stderr.splitlines() if not x.startswith('[')]
    assert lines == [f'inverse_dynamics_node: invalid configuration: '
                     f'{message}'], proc.stderr


# ---------------------------------------------------------------------------
# a gripper driver's joint states beside the arm's
# ---------------------------------------------------------------------------
GRIPPER = ['gripper_finger_joint1', 'gripper_finger_joint2']


def test_gripper_joint_states_beside_the_arms(tmp_path):
    probe = Probe(DOMAIN)
    node = NodeProcess(id_node_cmd('puma560.yaml'), DOMAIN,
                       str(tmp_path / 'node.log'))
    try:
        js = probe.publisher(JointState, 'joint_states')
        torques = probe.collect(JointState, f'{NODE}/torques')
        diagnostics = probe.collect(DiagnosticArray, '/diagnostics')
        assert probe.spin_until(lambda: js.get_subscription_count() > 0
                                and 'puma560 (' in node.log(), 90.0), \
            node.log()
        # one arm message answered first: both ends have matched
        hello = probe.handshake(
            js, joint_state(PUMA_JOINTS, [0.0] * 6, [0.0] * 6,
                            probe.keyed_stamp(999)), torques)
        # the arm and the gripper at 100 Hz each, interleaved, for 2 s
        arm_stamps = []
        start = time.monotonic()
        for seq in range(1, 401):
            stamp = probe.keyed_stamp(seq)
            if seq % 2:
                arm_stamps.append(stamp)
                js.publish(joint_state(PUMA_JOINTS, [0.1 * seq % 1.0] * 6,
                                       [0.2] * 6, stamp))
            else:
                msg = joint_state(GRIPPER, [0.01, 0.01], [0.0, 0.0], stamp)
                msg.effort = [5.0, 5.0]
                js.publish(msg)
            probe.spin_until(lambda: False,
                             max(0.0, start + seq * 0.005 - time.monotonic()))
        sent_for = time.monotonic() - start
        greetings = sum(t.header.stamp == hello for t in torques)
        probe.spin_until(
            lambda: len(torques) >= greetings + len(arm_stamps), 5.0)
        run = [t for t in torques if t.header.stamp != hello]
        answered = {(t.header.stamp.sec, t.header.stamp.nanosec)
                    for t in run}
        arm = {(s.sec, s.nanosec) for s in arm_stamps}
        assert answered <= arm          # no answer to a gripper message
        # every arm message answered (reliable, 100 Hz), at the arm's rate
        assert len(answered) >= 0.95 * len(arm), (len(answered), len(arm))
        stamps = sorted(t.header.stamp.sec + t.header.stamp.nanosec * 1e-9
                        for t in run)
        rate = (len(stamps) - 1) / (stamps[-1] - stamps[0])
        assert 80.0 < rate < 120.0, (rate, sent_for)
        counts = probe.next_counters(diagnostics)
        counts = probe.next_counters(diagnostics)
        assert counts['other_joints'] >= 0.95 * 200, counts
        assert counts['other_joints'] <= 200, counts
        assert counts['missing_joints'] == 0, counts
        assert counts['published'] == len(torques), counts
    finally:
        code = node.stop()
        probe.close()
    assert code == 0, node.log()
    log = node.log()
    assert 'WARN' not in log and 'dropped' not in log, log


# ---------------------------------------------------------------------------
# a rejected robot_description
# ---------------------------------------------------------------------------
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
ZERO_AXIS = ('<robot name="r"><link name="b"/><link name="a"/>'
             '<joint name="j" type="revolute"><parent link="b"/>'
             '<child link="a"/><axis xyz="0 0 0"/></joint></robot>')
GOOD = ('<robot name="r"><link name="base_link"/><link name="a">'
        '<inertial><mass value="1"/><origin xyz="0.1 0 0"/><inertia '
        'ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'
        '</inertial></link><link name="tool0"/>'
        '<joint name="j" type="revolute"><parent link="base_link"/>'
        '<child link="a"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" '
        'effort="50" velocity="2"/></joint><joint name="flange" '
        'type="fixed"><parent link="a"/><child link="tool0"/></joint>'
        '</robot>')
REASON = "joint 'j' <axis> xyz: must be a nonzero vector, got 0 0 0"


def test_a_rejected_description_says_so(tmp_path):
    probe = Probe(DOMAIN)
    node = NodeProcess(id_node_cmd('urdf.yaml'), DOMAIN,
                       str(tmp_path / 'node.log'))
    try:
        description = probe.node.create_publisher(
            String, 'robot_description', LATCHED)
        diagnostics = probe.collect(DiagnosticArray, '/diagnostics')
        assert probe.spin_until(
            lambda: description.get_subscription_count() > 0, 90.0), \
            node.log()

        def status():
            count = len(diagnostics)
            assert probe.spin_until(lambda: len(diagnostics) > count, 5.0)
            return diagnostics[-1].status[0]

        def service():
            return probe.call(ComputeDynamics, f'{NODE}/compute_dynamics',
                              ComputeDynamics.Request(
                                  name=['j'], position=[0.1]))
        first = status()
        assert 'waiting for robot_description' in first.message
        description.publish(String(data=ZERO_AXIS))
        assert probe.spin_until(lambda: 'rejected' in node.log(), 10.0)
        rejected = status()
        assert rejected.level == rejected.ERROR
        assert 'robot_description rejected' in rejected.message
        assert REASON in rejected.message, rejected.message
        assert 'waiting' not in rejected.message
        reply = service()
        assert not reply.success
        assert reply.message == ('no robot model: robot_description '
                                 f'rejected: robot_description: {REASON}'), \
            reply.message

        # a good one loads and clears it; a bad one after it is a warning
        description.publish(String(data=GOOD))
        assert probe.spin_until(lambda: service().success, 20.0), node.log()
        loaded = status()
        assert loaded.level == loaded.OK and loaded.message == \
            'input counters', loaded.message
        description.publish(String(data=ZERO_AXIS))
        assert probe.spin_until(
            lambda: node.log().count('robot_description rejected') == 2, 10.0)
        kept = status()
        assert kept.level == kept.WARN
        assert REASON in kept.message and \
            'the previous model keeps working' in kept.message, kept.message
        assert service().success
    finally:
        code = node.stop()
        probe.close()
    assert code == 0, node.log()


# ---------------------------------------------------------------------------
# robot_compensates_gravity, against Pinocchio on a published Panda
# ---------------------------------------------------------------------------
PANDA = 'panda_description/urdf/panda.urdf'
PANDA_JOINTS = [f'panda_joint{k}' for k in range(1, 8)]
PANDA_TIP = 'panda_hand_tcp'


@pytest.fixture(scope='module')
def panda_peer():
    from newton_euler_tools.peers import example_robot_urdf, PinocchioUrdf
    path = example_robot_urdf(PANDA)
    return path, PinocchioUrdf(path, PANDA_JOINTS, PANDA_TIP)


def test_robot_compensates_gravity_against_pinocchio(panda_peer, tmp_path):
    path, peer = panda_peer
    pin, m, d = peer.pin, peer.model, peer.data
    probe = Probe(DOMAIN)
    node = NodeProcess(id_node_cmd(
        None, '-p', f'robot_file:={path}', '-p', 'base_link:=panda_link0',
        '-p', f'tip_link:={PANDA_TIP}', '-p', 'robot_compensates_gravity:=true'),
        DOMAIN, str(tmp_path / 'node.log'))
    try:
        js = probe.publisher(JointState, 'joint_states')
        torques = probe.collect(JointState, f'{NODE}/torques')
        traj_in = probe.publisher(JointTrajectory, f'{NODE}/trajectory_in')
        traj_out = probe.collect(JointTrajectory, f'{NODE}/trajectory_out')
        assert probe.spin_until(
            lambda: js.get_subscription_count() > 0
            and traj_in.get_subscription_count() > 0
            and traj_out is not None and 'panda (' in node.log(), 90.0), \
            node.log()
        assert 'without g(q): the robot adds it' in node.log()
        rng = np.random.default_rng(28)
        for seq in range(1, 6):
            q = rng.uniform(-1.2, 1.2, 7)
            qd = rng.uniform(-1.0, 1.0, 7)
            stamp = probe.keyed_stamp(seq)
            js.publish(joint_state(PANDA_JOINTS, q, qd, stamp))
            answer = probe.answer(torques, stamp, 10.0)
            assert answer is not None, node.log()
            assert list(answer.name) == PANDA_JOINTS
            x = peer.config(q)
            coriolis = pin.computeCoriolisMatrix(m, d, x, qd) @ qd
            gravity = pin.computeGeneralizedGravity(m, d, x)
            assert np.abs(gravity).max() > 1.0      # g would be seen
            assert np.allclose(answer.effort, coriolis, rtol=0,
                               atol=1e-9), (answer.effort, coriolis)

        # trajectory efforts: D qdd + C qd at every point
        points = [(rng.uniform(-1.2, 1.2, 7), rng.uniform(-1.0, 1.0, 7),
                   rng.uniform(-2.0, 2.0, 7)) for _ in range(4)]
        msg = JointTrajectory(joint_names=PANDA_JOINTS)
        for k, (q, qd, qdd) in enumerate(points):
            msg.points.append(JointTrajectoryPoint(
                positions=q.tolist(), velocities=qd.tolist(),
                accelerations=qdd.tolist(),
                time_from_start=Duration(sec=k, nanosec=0)))
        traj_in.publish(msg)
        assert probe.spin_until(lambda: len(traj_out) > 0, 10.0), node.log()
        for (q, qd, qdd), point in zip(points, traj_out[0].points):
            x = peer.config(q)
            D = pin.crba(m, d, x)
            D = np.triu(D) + np.triu(D, 1).T
            expected = D @ qdd + pin.computeCoriolisMatrix(m, d, x, qd) @ qd
            assert np.allclose(point.effort, expected, rtol=0, atol=1e-9)

        # the service: tau without g, and g itself reported
        q, qd, qdd = points[0]
        reply = probe.call(ComputeDynamics, f'{NODE}/compute_dynamics',
                           ComputeDynamics.Request(
                               name=PANDA_JOINTS, position=q.tolist(),
                               velocity=qd.tolist(),
                               acceleration=qdd.tolist()))
        assert reply.success, reply.message
        x = peer.config(q)
        assert np.allclose(reply.gravity,
                           pin.computeGeneralizedGravity(m, d, x), atol=1e-9)
        assert np.allclose(reply.torque, traj_out[0].points[0].effort,
                           atol=1e-9)
    finally:
        code = node.stop()
        probe.close()
    assert code == 0, node.log()
