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
inverse_dynamics_node on a whole robot, over DDS, against Pinocchio.

The test plays robot_state_publisher with Baxter's published URDF
(example-robot-data: two arms and a head, each gripper with a mimic
finger) on a latched ``/robot_description``, and starts the node as a
user would for a whole robot: ``config/params/baxter.yaml``, ``base_link``
only, no ``tip_link``, the left arm's joints (shuffled) on
``~/torque_command`` for an effort controller.  Then, as the robot's drivers and sensors would:

- full JointStates, every joint (the mimic fingers too) in shuffled
  order: ``~/torques`` names all 17 independent joints and equals
  Pinocchio's ``rnea`` on ``buildModelFromUrdf(path, mimic=True)``
  (joints matched by name), ``~/torque_command`` those of ``joints`` in
  its order;
- the same state split across two publishers (an arm driver, a gripper
  driver), the gripper's message alone publishing nothing;
- the service's D, C and g of the whole tree against Pinocchio's;
- a force-torque sensor at each wrist (two frame_ids, the sensors'
  sign) against sum J_link^T F of Pinocchio's Jacobians in link axes,
  each sensor expiring alone, an unknown frame counted and dropped;
- a mimic finger off its leader: refused, counted, one log line naming
  both joints and their values;
- a trajectory of the left arm alone: its efforts with the other joints
  held where they were last measured (that the hold counts where a joint
  carries the arm, as a torso does, is in ``core/test_trajectory.py``);
- a payload in the left gripper (``payload.link``): Pinocchio with the
  same inertia added to the gripper's joint;
- the momentum observer on efforts of a robot at rest pushed at its left
  gripper: the external torque on every joint is J^T F, and of the
  wrenches of ``observer.end_effectors`` (estimated jointly) the left
  gripper's is F, the right one's zero, and nothing is ambiguous.

And PR2 from ``robot_file``: the start-up line counts its ten mimic
joints, the next line lists them all under their leaders, none cut off.
"""
import os
import random
import warnings

import numpy as np
import pytest

pytest.importorskip('rclpy')

from builtin_interfaces.msg import Duration  # noqa: E402, I100
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from geometry_msgs.msg import WrenchStamped  # noqa: E402
from newton_euler_interfaces.srv import ComputeDynamics  # noqa: E402
from newton_euler_ros.core import load_urdf  # noqa: E402
from rcl_interfaces.srv import SetParametersAtomically  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from rclpy.qos import (DurabilityPolicy, QoSProfile,  # noqa: E402
                       ReliabilityPolicy)
from ros_harness import (domain_id, FAST_DIAGNOSTICS,  # noqa: E402
                         id_node_cmd, joint_state, NodeProcess, Probe, wrench)
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import Float64MultiArray, String  # noqa: E402
from trajectory_msgs.msg import (JointTrajectory,  # noqa: E402
                                 JointTrajectoryPoint)

pytestmark = pytest.mark.ros

NODE = '/inverse_dynamics_node'
BAXTER = 'baxter_description/urdf/baxter.urdf'
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
LEFT_ARM = ['left_s0', 'left_s1', 'left_e0', 'left_e1', 'left_w0', 'left_w1',
            'left_w2']
# what an effort controller of the left arm commands, in its own order
COMMANDED = ['left_w2', 'left_e1', 'left_s0', 'left_w0', 'left_s1',
             'left_e0', 'left_w1']
FINGERS = ['r_gripper_l_finger_joint', 'r_gripper_r_finger_joint',
           'l_gripper_l_finger_joint', 'l_gripper_r_finger_joint']
TIMEOUT = 2.0           # wrench.timeout, s
WRISTS = ('left_gripper', 'right_gripper')


@pytest.fixture(scope='module')
def baxter():
    from newton_euler_tools.peers import example_robot_urdf, PinocchioTree
    path = example_robot_urdf(BAXTER)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_urdf(path)
    with open(path, encoding='utf-8') as fh:
        text = fh.read()
    return model, PinocchioTree(path, model), text


class Robot:
    """The graph: description, the node, two drivers, two sensors."""

    def __init__(self, tmp, text):
        self.domain = domain_id(41)
        self.probe = Probe(self.domain)
        self.description = self.probe.node.create_publisher(
            String, '/robot_description', LATCHED)
        self.description.publish(String(data=text))
        # the bundled parameter file for Baxter, base_link only (no tip)
        self.node = NodeProcess(id_node_cmd(
            'baxter.yaml', '-p', 'base_link:=base',
            '-p', 'limits.action:=publish',
            '-p', f'joints:=[{", ".join(COMMANDED)}]',
            '-p', f'wrench.timeout:={TIMEOUT}',
            '-p', 'wrench.convention:=applied_to_robot',
            '-p', 'observer.enabled:=true', '-p', 'observer.damping:=0.0',
            '-p', f'observer.end_effectors:=[{", ".join(WRISTS)}]',
            # a link's wrench needs a contact on its own joints
            '-p', 'observer.thresholds:=[1.0]',
            '-p', 'log_throttle:=0.01', *FAST_DIAGNOSTICS),
            self.domain, os.path.join(tmp, 'node.log'))
        self.torques = self.probe.collect(JointState, f'{NODE}/torques')
        self.commands = self.probe.collect(Float64MultiArray,
                                           f'{NODE}/torque_command')
        self.diag = self.probe.collect(DiagnosticArray, '/diagnostics')
        # the arm driver and the gripper driver: two publishers
        self.arm = self.probe.publisher(JointState, '/joint_states')
        self.gripper = self.probe.publisher(JointState, '/joint_states')
        self.sensors = self.probe.publisher(WrenchStamped, '/wrench')
        assert self.probe.spin_until(
            lambda: self.arm.get_subscription_count() > 0
            and self.sensors.get_subscription_count() > 0
            and 'baxter (robot_description' in self.node.log(), 90.0), \
            self.node.log()
        self.seq = 0

    def stamp(self):
        self.seq += 1
        return self.probe.keyed_stamp(self.seq)

    def send(self, publisher, names, q, qd, wait=5.0):
        stamp = self.stamp()
        publisher.publish(joint_state(names, q, qd, stamp))
        return self.probe.answer(self.torques, stamp, wait)

    def command_for(self, stamp_answer):
        """Return the torque_command published with a ~/torques message."""
        index = next(i for i, t in enumerate(self.torques)
                     if t is stamp_answer)
        self.probe.spin_until(lambda: len(self.commands) > index, 5.0)
        return self.commands[index]

    def close(self):
        code = self.node.stop()
        self.probe.close()
        return code


@pytest.fixture(scope='module')
def robot(tmp_path_factory, baxter):
    r = Robot(str(tmp_path_factory.mktemp('whole_robot')), baxter[2])
    yield r
    assert r.close() == 0, r.node.log()


def moving_state(model, q, qd):
    """Every moving joint's position and velocity, followers from leaders."""
    x, v = {}, {}
    for b, name in enumerate(model.moving_joints):
        mimic = model.mimic[b]
        lead, mult, off = ((b, 1.0, 0.0) if mimic is None else mimic)
        k = model.independent.index(lead)
        x[name], v[name] = mult * q[k] + off, mult * qd[k]
    return x, v


def by_name(message, names):
    where = {name: i for i, name in enumerate(message.name)}
    return np.array([message.effort[where[name]] for name in names])


def state(model, seed):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-1.0, 1.0, model.n)
    qd = rng.uniform(-0.8, 0.8, model.n)
    for k, name in enumerate(model.joint_names):
        if 'finger' in name:        # the fingers' range: 0 to 2 cm
            q[k], qd[k] = rng.uniform(0.0, 0.02), rng.uniform(-0.01, 0.01)
    return q, qd


def test_full_joint_states_in_any_order_against_pinocchio(robot, baxter):
    model, peer, _ = baxter
    for seed in range(4):
        q, qd = state(model, seed)
        x, v = moving_state(model, q, qd)
        names = list(model.moving_joints)       # the fingers' mimics too
        random.Random(seed).shuffle(names)
        out = robot.send(robot.arm, names, [x[j] for j in names],
                         [v[j] for j in names])
        assert out is not None, robot.node.log()
        # every independent joint, commanded ones first
        assert list(out.name[:7]) == COMMANDED
        assert sorted(out.name) == sorted(model.joint_names)
        expected = peer.terms(q, qd, np.zeros(model.n))['tau']
        got = by_name(out, model.joint_names)
        assert np.abs(got - expected).max() <= 1e-9 * max(
            1.0, np.abs(expected).max()), (got, expected)
        command = robot.command_for(out)
        assert list(command.data) == list(out.effort[:7])


def test_joint_states_split_across_two_drivers(robot, baxter):
    model, peer, _ = baxter
    q, qd = state(model, 11)
    x, v = moving_state(model, q, qd)
    body = [j for j in model.moving_joints if j not in FINGERS]
    held = robot.probe.next_counters(robot.diag)['held']
    # the gripper driver alone: held for the arm's message, no torques
    assert robot.send(robot.gripper, FINGERS, [x[j] for j in FINGERS],
                      [v[j] for j in FINGERS], wait=0.05) is None
    out = robot.send(robot.arm, body[::-1], [x[j] for j in body[::-1]],
                     [v[j] for j in body[::-1]])
    assert out is not None, robot.node.log()
    expected = peer.terms(q, qd, np.zeros(model.n))['tau']
    np.testing.assert_allclose(by_name(out, model.joint_names), expected,
                               rtol=0, atol=1e-9)
    assert robot.probe.next_counters(robot.diag)['held'] == held + 1
    # fingers last heard of more than joint_states.hold (0.5 s) ago
    robot.probe.spin_for(0.6)
    assert robot.send(robot.arm, body, [x[j] for j in body],
                      [v[j] for j in body], wait=1.0) is None
    assert 'older than joint_states.hold (0.5 s)' in robot.node.log()
    # the fingers moved (q = 0 for them would give other torques)
    zero = q.copy()
    zero[[model.joint_names.index(j) for j in FINGERS[::2]]] = 0.0
    assert np.abs(peer.terms(zero, qd, 0 * qd)['tau'] - expected).max() \
        > 1e-6


def test_service_d_c_g_of_the_whole_tree(robot, baxter):
    model, peer, _ = baxter
    q, qd = state(model, 21)
    qdd = np.random.default_rng(21).uniform(-1, 1, model.n)
    names = list(model.joint_names)[::-1]
    order = [model.joint_names.index(j) for j in names]
    reply = robot.probe.call(ComputeDynamics, f'{NODE}/compute_dynamics',
                             ComputeDynamics.Request(
                                 name=names, position=q[order].tolist(),
                                 velocity=qd[order].tolist(),
                                 acceleration=qdd[order].tolist()))
    assert reply.success, reply.message
    n = model.n
    assert list(reply.name[:7]) == COMMANDED and len(reply.name) == n
    k = [model.joint_names.index(j) for j in reply.name]    # ours -> reply
    theirs = peer.terms(q, qd, qdd)
    D = np.reshape(reply.mass_matrix, (n, n))
    C = np.reshape(reply.coriolis_matrix, (n, n))
    for got, want in ((D, theirs['D'][np.ix_(k, k)]),
                      (C, theirs['C'][np.ix_(k, k)]),
                      (np.array(reply.gravity), theirs['g'][k]),
                      (np.array(reply.torque), theirs['tau'][k])):
        assert np.abs(got - want).max() <= 1e-9 * max(1.0,
                                                      np.abs(want).max())
    # the two arms do not couple: D is zero between them
    left = [reply.name.index(j) for j in LEFT_ARM]
    right = [reply.name.index(j.replace('left', 'right')) for j in LEFT_ARM]
    assert not D[np.ix_(left, right)].any()


def test_a_mimic_finger_off_its_leader_is_refused(robot, baxter):
    model, _, _ = baxter
    q, qd = state(model, 31)
    x, v = moving_state(model, q, qd)
    names = list(model.moving_joints)
    x['l_gripper_r_finger_joint'] = -x['l_gripper_l_finger_joint'] + 0.01
    before = robot.probe.next_counters(robot.diag)['mimic_mismatch']
    assert robot.send(robot.arm, names, [x[j] for j in names],
                      [v[j] for j in names], wait=1.0) is None
    assert robot.probe.next_counters(robot.diag)['mimic_mismatch'] == \
        before + 1
    line = next(x for x in robot.node.log().splitlines()
                if 'mimic_mismatch' in x)
    assert "mimic joint 'l_gripper_r_finger_joint' is at" in line
    assert "its leader 'l_gripper_l_finger_joint' at" in line
    # within the tolerance it is taken
    x['l_gripper_r_finger_joint'] = -x['l_gripper_l_finger_joint'] + 0.001
    assert robot.send(robot.arm, names, [x[j] for j in names],
                      [v[j] for j in names]) is not None


def test_a_sensor_at_each_wrist(robot, baxter):
    model, peer, _ = baxter
    q, qd = state(model, 61)
    x, v = moving_state(model, q, qd)
    names = list(model.moving_joints)
    F = {'left_gripper': np.array([5.0, -12.0, 20.0, 0.5, -0.3, 0.8]),
         'right_gripper': np.array([-8.0, 3.0, -15.0, -0.2, 0.9, 0.1])}
    theirs = peer.terms(q, qd, np.zeros(model.n), WRISTS)
    # what each sensor adds: the environment pushes on the gripper, the
    # arm holds it (applied_to_robot: -J^T F)
    adds = {link: -theirs[f'J {link} link'].T @ F[link] for link in WRISTS}

    def torques():
        out = robot.send(robot.arm, names, [x[j] for j in names],
                         [v[j] for j in names])
        assert out is not None, robot.node.log()
        return by_name(out, model.joint_names)

    def publish(link):
        now = robot.probe.node.get_clock().now().to_msg()
        robot.sensors.publish(wrench(link, F[link], now))

    publish('left_gripper')
    robot.probe.spin_for(1.2)
    publish('right_gripper')
    robot.probe.spin_for(0.1)
    np.testing.assert_allclose(
        torques(), theirs['tau'] + adds['left_gripper']
        + adds['right_gripper'], rtol=0, atol=1e-9)
    assert np.abs(adds['left_gripper']).max() > 1.0
    # the left sensor's wrench is older than wrench.timeout, the right
    # one's not: it applies alone
    robot.probe.spin_for(1.2)
    np.testing.assert_allclose(torques(), theirs['tau']
                               + adds['right_gripper'], rtol=0, atol=1e-9)
    assert 'the last wrench (left_gripper) is older than' in \
        robot.node.log()
    # a frame that is no link of Baxter; base axes (wrench.base_frames)
    # with no link to act at (no wrench.link, several tips)
    unknown = robot.probe.next_counters(robot.diag)['unknown_frame']
    for frame in ('left_ft_sensor', 'base_link'):
        now = robot.probe.node.get_clock().now().to_msg()
        robot.sensors.publish(wrench(frame, F['left_gripper'], now))
    assert robot.probe.spin_until(
        lambda: robot.probe.next_counters(robot.diag)['unknown_frame']
        == unknown + 2, 5.0)
    robot.probe.spin_for(TIMEOUT)       # the right one expires too


def test_a_trajectory_of_one_arm_holds_the_others(robot, baxter):
    model, peer, _ = baxter
    q, qd = state(model, 41)
    x, v = moving_state(model, q, qd)
    names = list(model.moving_joints)
    assert robot.send(robot.arm, names, [x[j] for j in names],
                      [v[j] for j in names]) is not None
    traj_in = robot.probe.publisher(JointTrajectory, f'{NODE}/trajectory_in')
    traj_out = robot.probe.collect(JointTrajectory, f'{NODE}/trajectory_out')
    assert robot.probe.spin_until(
        lambda: traj_in.get_subscription_count() > 0, 10.0)
    rng = np.random.default_rng(41)
    arm = [model.joint_names.index(j) for j in LEFT_ARM]
    points = [rng.uniform(-1, 1, (3, 7)) for _ in range(3)]
    msg = JointTrajectory(joint_names=LEFT_ARM)
    for k, (p, pd, pdd) in enumerate(points):
        msg.points.append(JointTrajectoryPoint(
            positions=p.tolist(), velocities=pd.tolist(),
            accelerations=pdd.tolist(), time_from_start=Duration(sec=k)))
    traj_in.publish(msg)
    assert robot.probe.spin_until(lambda: len(traj_out) > 0, 10.0), \
        robot.node.log()
    assert list(traj_out[0].joint_names) == LEFT_ARM
    for (p, pd, pdd), point in zip(points, traj_out[0].points):
        full = [q.copy(), np.zeros(model.n), np.zeros(model.n)]
        for X, part in zip(full, (p, pd, pdd)):
            X[arm] = part
        expected = peer.terms(*full)['tau'][arm]
        np.testing.assert_allclose(point.effort, expected, rtol=0,
                                   atol=1e-9)


def test_a_payload_in_one_gripper(robot, baxter):
    model, peer, _ = baxter
    pin = peer.pin
    mass, com = 1.5, [0.01, -0.02, 0.05]
    inertia = [0.004, 0.005, 0.003, 0.0002, -0.0001, 0.0003]
    params = [Parameter(name, value=value).to_parameter_msg()
              for name, value in (('payload.mass', mass),
                                  ('payload.com', com),
                                  ('payload.inertia', inertia),
                                  ('payload.link', 'left_gripper'))]
    result = robot.probe.call(
        SetParametersAtomically, f'{NODE}/set_parameters_atomically',
        SetParametersAtomically.Request(parameters=params)).result
    assert result.successful, result.reason
    # Pinocchio: the same rigid body added to the joint carrying the
    # gripper frame
    from newton_euler_tools.peers import example_robot_urdf
    loaded = pin.buildModelFromUrdf(example_robot_urdf(BAXTER), mimic=True)
    frame = loaded.frames[loaded.getFrameId('left_gripper')]
    Ixx, Iyy, Izz, Ixy, Iyz, Ixz = inertia
    body = pin.Inertia(mass, np.array(com), np.array(
        [[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz, Izz]]))
    loaded.inertias[frame.parentJoint] += frame.placement.act(body)
    data = loaded.createData()
    q, qd = state(model, 51)
    x, v = moving_state(model, q, qd)
    names = list(model.moving_joints)
    out = robot.send(robot.arm, names, [x[j] for j in names],
                     [v[j] for j in names])
    assert out is not None, robot.node.log()
    expected = pin.rnea(loaded, data, peer.config(q), peer.vector(qd),
                        np.zeros(loaded.nv))[peer.iv]
    np.testing.assert_allclose(by_name(out, model.joint_names), expected,
                               rtol=0, atol=1e-9)
    without = peer.terms(q, qd, 0 * qd)['tau']
    changed = {model.joint_names[k] for k in
               np.flatnonzero(np.abs(expected - without) > 1e-9)}
    assert changed and changed <= set(LEFT_ARM)     # the left arm's only
    params = [Parameter('payload.mass', value=0.0).to_parameter_msg(),
              Parameter('payload.inertia', value=[0.0] * 6).to_parameter_msg()]
    assert robot.probe.call(
        SetParametersAtomically, f'{NODE}/set_parameters_atomically',
        SetParametersAtomically.Request(parameters=params)).result.successful


def test_the_observer_reports_each_end_effector(robot, baxter):
    model, peer, _ = baxter
    external = robot.probe.collect(JointState, f'{NODE}/external_torque')
    wrenches = robot.probe.collect(WrenchStamped, f'{NODE}/external_wrench')
    q, _ = state(model, 71)
    rest = np.zeros(model.n)
    F = np.array([4.0, -6.0, 15.0, 0.4, 0.7, -0.3])    # on the gripper
    theirs = peer.terms(q, rest, rest, WRISTS)
    tau_ext = theirs['J left_gripper link'].T @ F
    effort = dict(zip(model.joint_names, theirs['g'] - tau_ext))
    x, v = moving_state(model, q, rest)
    names = list(model.moving_joints)
    for _ in range(40):         # 100 Hz, the observer's time constant 20 ms
        stamp = robot.stamp()
        msg = joint_state(names, [x[j] for j in names], [v[j] for j in names],
                          stamp)
        msg.effort = [effort.get(j, 0.0) for j in names]
        robot.arm.publish(msg)
        robot.probe.spin_for(0.01)
    assert robot.probe.spin_until(
        lambda: any(m.header.stamp == stamp for m in external), 5.0), \
        robot.node.log()
    last = next(m for m in external if m.header.stamp == stamp)
    assert list(last.name) == list(model.joint_names)
    np.testing.assert_allclose(last.effort, tau_ext, rtol=0, atol=1e-6)
    robot.probe.spin_for(0.2)
    got = {m.header.frame_id: m.wrench for m in wrenches
           if m.header.stamp == stamp}
    assert set(got) == set(WRISTS)
    for link, expected in (('left_gripper', F), ('right_gripper', 0 * F)):
        w = got[link]
        values = [w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y,
                  w.torque.z]
        np.testing.assert_allclose(values, expected, rtol=0, atol=1e-6)
    # estimated jointly; the two arms share no joint: all separable
    assert 'left_gripper, right_gripper estimated jointly; not separable ' \
        'by the joints (at the first pose, all pushed): none' in \
        robot.node.log(), robot.node.log()

    def separable():
        for msg in robot.diag:
            for status in msg.status:
                if status.name.endswith(': observer'):
                    values = {v.key: v.value for v in status.values}
                    if 'wrench_not_separable' in values:
                        return values['wrench_not_separable']
    assert robot.probe.spin_until(lambda: separable() is not None, 5.0)
    assert separable() == 'none'


def test_the_simulated_tree_held_by_the_node(baxter, tmp_path):
    """robot_sim_node plays Baxter; the node's torques hold it still."""
    import sys
    model, _, _ = baxter
    from newton_euler_tools.peers import example_robot_urdf
    path = example_robot_urdf(BAXTER)
    q0 = state(model, 81)[0]
    scene = tmp_path / 'baxter.yaml'
    scene.write_text(
        f'name: baxter_hold\nrobot: {path}\n'
        f'effects: {{gravity: true, velocity_products: true}}\n'
        f'initial: {{q: {q0.tolist()}}}\n'
        f'integrator: {{method: rk4, step: 1.0e-3, duration: 600.0, '
        f'rate: 200.0}}\n')
    domain = domain_id(43)
    bindir = os.path.dirname(sys.executable)
    sim = NodeProcess([os.path.join(bindir, 'robot_sim_node'), '--ros-args',
                       '-p', f'scene:={scene}'], domain,
                      str(tmp_path / 'sim.log'))
    node = NodeProcess(id_node_cmd(
        None, '-p', f'robot_file:={path}', '-p', 'base_link:=base',
        '-p', 'limits.action:=publish',
        '-r', '~/torque_command:=/robot_sim_node/commands'), domain,
        str(tmp_path / 'node.log'))
    probe = Probe(domain)
    try:
        heard = probe.collect(JointState, '/joint_states')

        def states():       # the simulator's (a stray graph may share it)
            return [m for m in heard if m.name[:1] == ['head_pan']]
        assert probe.spin_until(lambda: len(states()) > 300, 90.0), \
            sim.log() + node.log()
        last = states()[-1]
        assert list(last.name) == list(model.joint_names) + [
            'r_gripper_r_finger_joint', 'l_gripper_r_finger_joint']
        x = dict(zip(last.name, last.position))
        for side in 'rl':
            assert x[f'{side}_gripper_r_finger_joint'] == \
                -x[f'{side}_gripper_l_finger_joint']
        # 1.5 s of simulated time later, still where it started (a
        # shoulder held by nothing drops by a radian in that time)
        drift = np.abs(np.array(last.position[:model.n]) - q0).max()
        assert drift < 1e-3, (drift, node.log())
        assert 'mimic_mismatch' not in node.log()
    finally:
        probe.close()
        assert node.stop() == 0, node.log()
        assert sim.stop() == 0, sim.log()
    # the simulator ran on the node's commands (it holds t = 0 without)
    received = int(sim.log().split('commands received: ')[1].split()[0])
    assert received > 300, sim.log()


def test_the_start_up_line_counts_the_mimic_joints_the_next_lists_all(
        tmp_path):
    """PR2: ten mimic joints, none of them cut off with '...'."""
    import time
    from newton_euler_tools.peers import example_robot_urdf
    path = example_robot_urdf('pr2_description/urdf/pr2.urdf')
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_urdf(path, base='base_link')
    followers = {name: model.moving_joints[model.mimic[b][0]]
                 for b, name in enumerate(model.moving_joints)
                 if model.mimic[b] is not None}
    assert len(followers) == 10
    node = NodeProcess(id_node_cmd(
        None, '-p', f'robot_file:={path}', '-p', 'base_link:=base_link'),
        domain_id(47), str(tmp_path / 'node.log'))
    try:
        deadline = time.monotonic() + 90.0
        while 'mimic joints, each following' not in node.log():
            assert node.alive() and time.monotonic() < deadline, node.log()
            time.sleep(0.2)
    finally:
        assert node.stop() == 0, node.log()
    # make setup compiled the kernels ahead: loaded, and said how long
    assert 'kernels ready in' in node.log(), node.log()
    assert '(loaded from the cache)' in node.log(), node.log()
    assert 'not compiled ahead' not in node.log(), node.log()
    lines = node.log().splitlines()
    at = next(k for k, line in enumerate(lines) if 'whole robot' in line)
    start, listed = lines[at], lines[at + 1]
    assert (f'whole robot, {model.nb} moving joints (10 of them mimic, '
            f'listed on the next line), commanding {model.n} on '
            f'torque_command') in start, start
    assert listed.endswith(f'{model.name}: 10 mimic joints, each following '
                           'its leader: ' + '; '.join(
                               f'{lead} leads ' + ', '.join(
                                   f for f, x in followers.items()
                                   if x == lead)
                               for lead in dict.fromkeys(
                                   followers.values()))), listed
    assert '...' not in start + listed


def test_a_description_with_a_floating_root_gets_torques(tmp_path):
    """
    The TIAGo Pro description below an ``odom`` link (a floating joint).

    robot_state_publisher publishes it so on a mobile robot; the node
    starts the model at base_footprint, says so, and answers states.
    """
    import time
    from newton_euler_tools.peers import example_robot_urdf
    path = example_robot_urdf('tiago_pro_description/robots/tiago_pro.urdf')
    with open(path, encoding='utf-8') as fh:
        text = fh.read()
    text = text.replace('</robot>', (
        '<link name="odom"/><joint name="odom_to_base" type="floating">'
        '<parent link="odom"/><child link="base_footprint"/></joint>'
        '</robot>'))
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_urdf(path)
    domain = domain_id(43)
    probe = Probe(domain)
    description = probe.node.create_publisher(String, '/robot_description',
                                              LATCHED)
    description.publish(String(data=text))
    node = NodeProcess(id_node_cmd(None), domain, str(tmp_path / 'node.log'))
    try:
        torques = probe.collect(JointState, f'{NODE}/torques')
        states = probe.publisher(JointState, '/joint_states')
        names = list(model.moving_joints)
        deadline = time.monotonic() + 90.0
        k = 0
        while not torques:
            assert node.alive() and time.monotonic() < deadline, node.log()
            k += 1
            states.publish(joint_state(names, [0.0] * len(names),
                                       [0.0] * len(names),
                                       probe.keyed_stamp(k)))
            probe.spin_for(0.1)
        assert len(torques[-1].effort) == model.n
        assert np.isfinite(torques[-1].effort).all()
    finally:
        assert node.stop() == 0, node.log()
        probe.close()
    log = node.log()
    assert ("'odom' carries the rest through the floating joint "
            "'odom_to_base': the model starts at 'base_footprint'") in log, log


def test_one_arm_without_the_wheels_and_a_locked_gripper(tmp_path):
    """
    The right arm of TIAGo Pro commanded, the wheels never published.

    Its states, the torso's and its gripper's arrive; the wheels, the
    head and the left arm never do; the left gripper is locked.  The
    torques come, and equal the library's at the locked position.
    """
    import time
    from newton_euler_ros.core import inverse_dynamics
    from newton_euler_tools.peers import example_robot_urdf
    path = example_robot_urdf('tiago_pro_description/robots/tiago_pro.urdf')
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_urdf(path)
    names = list(model.joint_names)
    arm = [j for j in names if j.startswith('arm_right')]
    sent = arm + ['torso_lift_joint', 'gripper_right_finger_joint']
    domain = domain_id(29)
    probe = Probe(domain)
    node = NodeProcess(id_node_cmd(
        None, '-p', f'robot_file:={path}',
        '-p', f'joints:=[{", ".join(arm)}]',
        '-p', 'joint_states.lock:=[gripper_left_finger_joint]',
        '-p', 'joint_states.lock_positions:=[0.03]'),
        domain, str(tmp_path / 'node.log'))
    try:
        commands = probe.collect(Float64MultiArray, f'{NODE}/torque_command')
        states = probe.publisher(JointState, '/joint_states')
        deadline = time.monotonic() + 90.0
        k = 0
        q = np.linspace(0.1, 0.4, len(sent))
        while not commands:
            assert node.alive() and time.monotonic() < deadline, node.log()
            k += 1
            states.publish(joint_state(sent, q.tolist(), [0.0] * len(sent),
                                       probe.keyed_stamp(k)))
            probe.spin_for(0.1)
    finally:
        assert node.stop() == 0, node.log()
        probe.close()
    full = np.zeros(model.n)
    full[[names.index(j) for j in sent]] = q
    full[names.index('gripper_left_finger_joint')] = 0.03
    expected = inverse_dynamics(model, full, np.zeros(model.n))
    np.testing.assert_allclose(
        commands[-1].data, expected[[names.index(j) for j in arm]],
        rtol=1e-12, atol=1e-12)
    assert 'missing' not in node.log(), node.log()


def test_a_push_on_one_pr2_hand_is_not_read_at_the_other(tmp_path):
    """
    PR2 resting, pushed at its right hand (issue 37): the torso is shared.

    Estimating each hand alone read the torso's share at the left hand
    (37.5 N for a 15 N push); jointly, the right hand's wrench is F and
    the left one's zero, the seven-joint arms leaving nothing ambiguous.
    """
    import time
    from newton_euler_tools.peers import example_robot_urdf, PinocchioTree
    path = example_robot_urdf('pr2_description/urdf/pr2.urdf')
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_urdf(path)
    hands = ('r_gripper_tool_frame', 'l_gripper_tool_frame')
    q = 0.3 * np.sin(np.arange(model.n) + 1.0)
    for k, name in enumerate(model.joint_names):
        if 'torso' in name or 'gripper' in name:
            q[k] = 0.02
    rest = np.zeros(model.n)
    F = np.array([5.0, -3.0, -15.0, 0.4, 0.6, -0.2])
    theirs = PinocchioTree(path, model).terms(q, rest, rest, hands)
    effort = dict(zip(model.joint_names, theirs['g'] - theirs[
        f'J {hands[0]} link'].T @ F))
    x, v = moving_state(model, q, rest)
    names = list(model.moving_joints)
    domain = domain_id(13)
    probe = Probe(domain)
    node = NodeProcess(id_node_cmd(
        None, '-p', f'robot_file:={path}', '-p', 'observer.enabled:=true',
        '-p', 'observer.damping:=0.0', '-p', 'observer.thresholds:=[1.0]',
        '-p', f'observer.end_effectors:=[{", ".join(hands)}]'),
        domain, str(tmp_path / 'node.log'))
    try:
        wrenches = probe.collect(WrenchStamped, f'{NODE}/external_wrench')
        states = probe.publisher(JointState, '/joint_states')
        deadline = time.monotonic() + 90.0
        k = 0
        while len(wrenches) < 2 * 40:   # 40 samples: 2 time constants x 10
            assert node.alive() and time.monotonic() < deadline, node.log()
            k += 1
            msg = joint_state(names, [x[j] for j in names],
                              [v[j] for j in names], probe.keyed_stamp(k))
            msg.effort = [effort.get(j, 0.0) for j in names]
            states.publish(msg)
            probe.spin_for(0.01)
    finally:
        assert node.stop() == 0, node.log()
        probe.close()
    last = {m.header.frame_id: m.wrench for m in wrenches[-2:]}
    assert set(last) == set(hands)
    for link, expected in zip(hands, (F, 0 * F)):
        w = last[link]
        values = [w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y,
                  w.torque.z]
        np.testing.assert_allclose(values, expected, rtol=0, atol=1e-3)
    assert not any(m.wrench.force.z for m in wrenches
                   if m.header.frame_id == hands[1])
    assert 'all pushed): none' in node.log(), node.log()
