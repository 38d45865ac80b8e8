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
mujoco_sim_node as a process: the MuJoCo plant over real DDS.

- With no command the Panda holds its initial pose (brakes on); after a
  command of zeros it falls exactly as MuJoCo's own simulation of the
  same robot does, run here offline from the same state (to 1e-9: the
  stepping is deterministic).
- A one-joint URDF's ``<dynamics damping friction>`` reach the plant: a
  torque below the Coulomb friction barely creeps (MuJoCo's friction loss
  is a soft constraint), one above it moves the joint at the terminal
  speed (tau - friction) / damping.  The robot comes from the latched
  ``robot_description`` here.  Bad commands (wrong length, NaN, inf) are
  counted in /diagnostics and not obeyed; a stale command gives zero
  effort, said once, and again once when commands resume.
- PD plus the library's g(q), computed here and sent over the topic at
  250 Hz, holds the Panda at a pose to a millimetre and a milliradian:
  gravity, joint order and units agree between the library and MuJoCo.
- An MJCF bar falls onto a floor: its contact wrench on
  ``~/contact_wrenches/bar`` (world axes, about the link's origin) holds
  it up against gravity at rest.
- A bad robot_file or a wrong number of initial positions: one line, exit
  status 2; so is a negative or NaN sensor noise.
- Lockstep: brakes on, at most 20 ticks a second of wall clock (nothing
  else paces them); once released, one tick per command and none
  without.
- Sensor noise (``noise.*``): zero gives MuJoCo's state exactly; on, the
  published states scatter about it with the requested standard
  deviations (to sampling error), the plant itself untouched.
"""
import math
import os
import re
import subprocess
import sys
import time

import numpy as np
import pytest

pytest.importorskip('rclpy')
pytest.importorskip('mujoco')

# After the skips: pytest must be imported first, hence E402 and I100.
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402, I100
from newton_euler_ros.core import (end_effector_pose,  # noqa: E402
                                   gravity_torques, load_robot,
                                   mass_matrix)
from newton_euler_ros.sim.mujoco_model import load_mujoco  # noqa: E402
from newton_euler_ros.sim.mujoco_plant import MujocoPlant  # noqa: E402
from rclpy.qos import (DurabilityPolicy, QoSProfile,  # noqa: E402
                       ReliabilityPolicy)
from ros_harness import domain_id, NodeProcess, Probe, ros_env  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import Float64MultiArray, String  # noqa: E402
import yaml  # noqa: E402

pytestmark = pytest.mark.ros

COMMANDS = 'effort_controller/commands'
START = 60.0        # s: start-up on a loaded 2-core machine (MuJoCo, numba)
# the Panda away from its joint limits, its links off the vertical
Q0 = [0.3, -0.4, 0.2, -2.0, 0.3, 1.7, 0.5]
# one joint about the vertical axis (no gravity torque): inertia about
# the axis 0.03 + 1 * 0.1^2 = 0.04 kg m^2
DAMPING, FRICTION = 2.0, 1.0
ONE_JOINT = (
    '<robot name="one"><link name="base"/>'
    '<link name="arm"><inertial><origin xyz="0.1 0 0"/>'
    '<mass value="1.0"/><inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" '
    'ixz="0" iyz="0"/></inertial></link>'
    '<joint name="j1" type="revolute"><parent link="base"/>'
    '<child link="arm"/><axis xyz="0 0 1"/>'
    '<limit lower="-3" upper="3" effort="7" velocity="5"/>'
    f'<dynamics damping="{DAMPING}" friction="{FRICTION}"/></joint>'
    '</robot>')


def node_cmd(tmp_path, **params):
    """Return the console script's command with a params file."""
    path = tmp_path / 'mujoco_sim.yaml'
    path.write_text(yaml.safe_dump(
        {'mujoco_sim_node': {'ros__parameters': params}}))
    script = os.path.join(os.path.dirname(sys.executable), 'mujoco_sim_node')
    base = [script] if os.path.exists(script) else [
        sys.executable, '-m', 'newton_euler_ros.nodes.mujoco_sim_node']
    return base + ['--ros-args', '--params-file', str(path)]


def t_of(msg):
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def on_grid(stamps, origin=0.0, step=0.002):
    """
    Check that stamps lie on the tick grid, increasing; return the ticks.

    Some states may be missing (dropped between the processes on a
    loaded machine); the ones that arrive are ticks of the plant.
    """
    ticks = np.rint((np.asarray(stamps) - origin) / step).astype(int)
    np.testing.assert_allclose(np.asarray(stamps) - origin, ticks * step,
                               rtol=0, atol=1e-6)
    assert (np.diff(ticks) > 0).all(), ticks
    return ticks


def command(values):
    return Float64MultiArray(data=[float(v) for v in values])


def diagnostics_values(msg):
    return {kv.key: kv.value for kv in msg.status[0].values}


class Session:
    """The node under test and a probe talking to it."""

    def __init__(self, tmp_path, offset, **params):
        self.domain = domain_id(offset)
        self.node = NodeProcess(node_cmd(tmp_path, **params), self.domain,
                                str(tmp_path / 'mujoco_sim_node.log'))
        self.probe = Probe(self.domain, name='mujoco_probe')
        self.states = self.probe.collect(JointState, 'joint_states', 1000)
        self.diagnostics = self.probe.collect(DiagnosticArray,
                                              '/diagnostics', 10)
        self.pub = self.probe.publisher(Float64MultiArray, COMMANDS)

    def wait_up(self, count=2):
        """Wait for states, and for the node to hear the commands."""
        assert self.probe.spin_until(
            lambda: len(self.states) >= count
            and self.pub.get_subscription_count() > 0, START), \
            self.node.log()

    def wait_states(self, count, timeout=30.0):
        assert self.probe.spin_until(lambda: len(self.states) >= count,
                                     timeout), self.node.log()

    def wait_time(self, t, timeout=30.0):
        """Spin until a state stamped t or later; return its index."""
        assert self.probe.spin_until(
            lambda: self.states and t_of(self.states[-1]) >= t - 1e-9,
            timeout), self.node.log()
        return next(k for k, m in enumerate(self.states)
                    if t_of(m) >= t - 1e-9)

    def drive(self, effort, duration, every=0.01, bad=()):
        """
        Send ``effort`` every ``every`` s of simulated time for ``duration``.

        ``bad`` commands are sent too, half-way.  Return the index of the
        first state after the first command was sent.
        """
        start = len(self.states)
        self.wait_states(start + 1)
        t0 = t_of(self.states[-1])
        sent = -math.inf
        first = None
        while True:
            t = t_of(self.states[-1])
            if t >= t0 + duration:
                return first
            if t >= sent + every:
                self.pub.publish(command(effort))
                sent = t
                if first is None:
                    first = len(self.states)
            if bad and t >= t0 + duration / 2:
                for values in bad:
                    self.pub.publish(Float64MultiArray(data=values))
                bad = ()
            count = len(self.states)
            assert self.probe.spin_until(lambda: len(self.states) > count,
                                         10.0), self.node.log()

    def last_diagnostics(self, predicate, timeout=10.0):
        """Return the values of the first diagnostics that ``predicate``."""
        def found():
            return next((v for v in map(diagnostics_values,
                                        self.diagnostics) if predicate(v)),
                        None)
        self.probe.spin_until(lambda: found() is not None, timeout)
        values = found()
        assert values is not None, (
            [diagnostics_values(m) for m in self.diagnostics[-3:]],
            self.node.log())
        return values

    def close(self):
        self.probe.close()
        status = self.node.stop()
        log = self.node.log()
        assert status == 0, log
        assert 'Traceback' not in log, log
        return log


def test_holds_then_falls_as_mujoco_does(tmp_path):
    run = Session(tmp_path, 41, robot_file='panda',
                  initial_positions=Q0, rate=500.0)
    clock = run.probe.collect(Clock, '/clock', 10)
    try:
        run.wait_up(50)
        # 1. brakes on: exactly the initial pose, no effort, time runs
        for msg in run.states:
            assert list(msg.name) == [f'joint{i}' for i in range(1, 8)]
            np.testing.assert_array_equal(msg.position, Q0)
            np.testing.assert_array_equal(msg.velocity, 0.0)
            np.testing.assert_array_equal(msg.effort, 0.0)
        on_grid([t_of(m) for m in run.states])
        assert clock, 'no /clock'
        held = run.last_diagnostics(lambda v: v['held'] == 'true')
        assert held['commands received'] == '0'

        # 2. a command of zeros releases the brakes: the arm falls
        run.pub.publish(command(np.zeros(7)))
        ticks = 200

        def moved():
            return next((m for m in run.states
                         if not np.array_equal(m.position, Q0)), None)
        # the first moving state comes one tick after the release
        assert run.probe.spin_until(
            lambda: moved() is not None and t_of(run.states[-1])
            >= t_of(moved()) + (ticks - 1) * 0.002 - 1e-9, 30.0), \
            run.node.log()
        states = list(run.states)

        def clock_time():
            c = clock[-1].clock
            return c.sec + c.nanosec * 1e-9
        # /clock runs on with the states (its own topic, its own pace)
        assert run.probe.spin_until(
            lambda: clock_time() >= t_of(states[-1]) - 1e-9, 10.0), \
            (clock_time(), t_of(states[-1]))
    finally:
        log = run.close()
    # the node's log gives the simulated time of the release
    released = re.search(r'first command at t = ([0-9.]+) s: brakes '
                         r'released', log)
    assert released, log
    t_release = float(released.group(1))
    steps = on_grid([t_of(m) for m in states], origin=t_release)
    after = {k: m for k, m in zip(steps, states) if 0 < k <= ticks}
    held = [m for k, m in zip(steps, states) if k <= 0]
    assert held and all(np.array_equal(m.position, Q0) for m in held)
    # a loaded machine may drop some states between the processes (the
    # publisher keeps the last 100): most of them arrive
    assert len(after) >= ticks // 2, sorted(after)

    # MuJoCo's own simulation of the same robot from the same state
    plant = MujocoPlant(load_mujoco('panda', timestep=0.001), Q0)
    plant.release()
    fell = 0.0
    for k in range(1, ticks + 1):
        plant.advance(np.zeros(7), 0.002)
        if k in after:
            q, qd = plant.state()
            msg = after[k]
            np.testing.assert_allclose(msg.position, q, rtol=0, atol=1e-9,
                                       err_msg=f'tick {k}')
            np.testing.assert_allclose(msg.velocity, qd, rtol=0,
                                       atol=1e-9, err_msg=f'tick {k}')
            np.testing.assert_array_equal(msg.effort, 0.0)
            fell = np.abs(q - Q0).max()
    assert fell > 0.05          # it did fall: 0.4 s without torques


def test_damping_friction_bad_and_stale_commands(tmp_path):
    # at half real time: a test process slowed by a busy machine still
    # commands within command_timeout of the plant's simulated time
    run = Session(tmp_path, 43, rate=500.0, command_timeout=0.5,
                  real_time_factor=0.5)
    latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
    description = run.probe.node.create_publisher(
        String, 'robot_description', latched)
    description.publish(String(data=ONE_JOINT))
    try:
        run.wait_up(20)
        assert list(run.states[-1].name) == ['j1']

        # 1. bad commands while held: counted, and the brakes stay on
        for values in ([1.0, 2.0], [math.nan], [math.inf], []):
            run.pub.publish(Float64MultiArray(data=values))
        values = run.last_diagnostics(
            lambda v: v.get('bad commands ignored') == '4')
        assert values['held'] == 'true' and \
            values['commands received'] == '0', values
        assert all(m.position[0] == 0.0 for m in run.states)

        # 2. below the Coulomb friction: it barely creeps (MuJoCo's
        # friction loss is a soft constraint: 0.0125 rad/s here); without
        # friction it would reach 0.5 / DAMPING = 0.25 rad/s
        k = run.drive([0.5], 0.5)
        below = run.states[k + 5:]
        assert all(m.effort[0] == 0.5 for m in below)
        assert max(abs(m.velocity[0]) for m in below) < 0.1 * 0.25
        assert abs(below[-1].position[0]) < 0.02

        # 3. above it: terminal speed (tau - friction) / damping; the bad
        # commands sent half-way are not obeyed
        k = run.drive([3.0], 0.6, bad=([math.nan], [5.0, 5.0]))
        above = run.states[k + 5:]
        assert all(m.effort[0] == 3.0 for m in above), \
            sorted({m.effort[0] for m in above})
        speed = (3.0 - FRICTION) / DAMPING
        assert abs(above[-1].velocity[0] - speed) < 0.02 * speed, \
            above[-1].velocity[0]
        last_sent = t_of(run.states[-1])

        # 4. no new command: zero effort after command_timeout of
        # simulated time (the joint then stops)
        k = run.wait_time(last_sent + 0.7)
        zero = next(m for m in run.states[-400:] if m.effort[0] == 0.0)
        assert 0.45 <= t_of(zero) - last_sent <= 0.55, t_of(zero) - last_sent
        assert abs(run.states[k].velocity[0]) < 0.05
        assert all(m.effort[0] == 0.0 for m in run.states[k - 50:k + 1])
        run.drive([0.0], 0.05)
        values = run.last_diagnostics(
            lambda v: v.get('bad commands ignored') == '6'
            and v.get('stale periods') == '1' and v.get('stale') == 'false')
        assert values['held'] == 'false'
        assert int(values['commands received']) > 100
    finally:
        log = run.close()
    assert log.count('command ignored') >= 1
    assert log.count('zero effort until the next one') == 1, log
    assert log.count('commands resumed') == 1, log


def test_pd_plus_the_library_gravity_holds_a_pose(tmp_path):
    model = load_robot('panda')
    target = np.array(Q0)
    start = target + np.array([0.04, -0.05, 0.05, 0.04, -0.05, 0.05, 0.05])
    # per-joint gains for about 10 rad/s, damped: without the gravity
    # torques the arm would sag by g / kp, tenths of a radian at the
    # shoulder
    m = np.diag(mass_matrix(model, target))
    kp, kd = 100.0 * m, 14.0 * m
    g_target = gravity_torques(model, target)
    assert np.abs(g_target / kp).max() > 0.05
    run = Session(tmp_path, 47, robot_file='panda',
                  initial_positions=start.tolist(), rate=250.0)
    sent = []

    def control(msg):
        q, qd = np.array(msg.position), np.array(msg.velocity)
        tau = gravity_torques(model, q) + kp * (target - q) - kd * qd
        run.pub.publish(command(tau))
        sent.append(t_of(msg))
    try:
        run.wait_up(5)
        names = list(run.states[-1].name)
        assert names == list(model.joint_names), names
        run.probe.node.create_subscription(JointState, 'joint_states',
                                           control, 10)
        assert run.probe.spin_until(lambda: len(sent) > 10, 20.0), \
            run.node.log()
        # settled in about 1 s; the last half second of the first 3 s is
        # judged, or of a later second: on a busy machine this process
        # (the controller) can fall silent for a moment, and the plant
        # then zeroes its effort until the next command (CI once saw
        # 1.003 mrad there).  Without g the arm would sag by g / kp.
        t_end = sent[0] + 3.0
        while True:
            run.wait_time(t_end, timeout=60.0)
            window = [msg for msg in run.states
                      if t_end - 0.5 <= t_of(msg) <= t_end]
            if t_end >= sent[0] + 12.0 or all(
                    np.abs(np.array(msg.position) - target).max() < 1e-3
                    for msg in window):
                break
            t_end += 1.0
        assert len(window) > 100
        tip = end_effector_pose(model, target)[:3, 3]
        for msg in window:
            q = np.array(msg.position)
            assert np.abs(q - target).max() < 1e-3, q - target
            assert np.linalg.norm(end_effector_pose(model, q)[:3, 3]
                                  - tip) < 1e-3
        # the effort the plant applied is the library's g at the pose
        np.testing.assert_allclose(window[-1].effort, g_target, atol=0.05)
        values = run.last_diagnostics(lambda v: v['held'] == 'false')
        assert values['bad commands ignored'] == '0', values
    finally:
        run.close()
    # the test kept up: commands at the plant's rate, 250 Hz
    gaps = np.diff(sent)
    assert np.median(gaps) < 0.0045, np.median(gaps)


# a bar hinged 0.3 m above a floor, its axis y, falls onto the floor
BAR = """\
<mujoco model="bar">
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="base" pos="0 0 0.3">
      <body name="bar">
        <joint name="hinge" type="hinge" axis="0 1 0" damping="0.5"/>
        <inertial pos="0.25 0 0" mass="1" diaginertia="0.001 0.02 0.02"/>
        <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.02"/>
      </body>
    </body>
  </worldbody>
  <actuator><motor joint="hinge" name="hinge"/></actuator>
</mujoco>
"""


def test_contact_wrench_of_a_bar_resting_on_the_floor(tmp_path):
    """
    An MJCF bar falls onto a floor; at rest its contact wrench holds it.

    Static, no motor torque: about the hinge (the bar's origin) the
    floor's moment cancels gravity's, -m g 0.25 cos q about y.
    """
    from geometry_msgs.msg import WrenchStamped
    path = tmp_path / 'bar.xml'
    path.write_text(BAR)
    run = Session(tmp_path, 53, robot_file=str(path), rate=250.0)
    wrenches = run.probe.collect(
        WrenchStamped, '/mujoco_sim_node/contact_wrenches/bar', 1000)
    try:
        run.wait_up(5)
        run.drive([0.0], 1.2, every=0.1)
        assert wrenches, run.node.log()
        last = wrenches[-1]
        assert last.header.frame_id == 'base'
        state = next(m for m in run.states if m.header.stamp ==
                     last.header.stamp)
        q = state.position[0]
        assert 0.5 < q < 0.7 and abs(state.velocity[0]) < 1e-3, q
        f, n = last.wrench.force, last.wrench.torque
        weight = 9.81
        np.testing.assert_allclose(n.y, -weight * 0.25 * math.cos(q),
                                   rtol=1e-3)
        assert abs(n.x) < 1e-6 and abs(n.z) < 1e-6 and abs(f.y) < 1e-6
        # the hinge and the floor share the weight: by moments about the
        # tip, the floor takes half of it
        assert abs(f.z - weight / 2) < 0.01 * weight, f.z
    finally:
        run.close()


@pytest.mark.parametrize('params, message', [
    ({'robot_file': '/no/such/robot.urdf'},
     'robot_file: /no/such/robot.urdf: cannot read'),
    ({'robot_file': 'panda', 'initial_positions': [0.1, 0.2]},
     'initial_positions: 7 values expected'),
    ({'scene': 'panda_mujoco_push', 'robot_file': 'panda'},
     'robot_file: the scene gives it; leave it unset with scene'),
    ({'scene': 'puma_payload_press'},
     "scene: puma560.yaml: MuJoCo refuses link 'link1'"),
    ({'robot_file': 'panda', 'noise': {'velocity': -0.1}},
     'noise.velocity: must be >= 0'),
    ({'robot_file': 'panda', 'noise': {'position': math.nan}},
     'noise.position: must be finite, got nan'),
])
def test_configuration_errors_are_one_line(tmp_path, params, message):
    proc = subprocess.run(node_cmd(tmp_path, **params),
                          env=ros_env(domain_id(49)), capture_output=True,
                          text=True, timeout=90)
    assert proc.returncode == 2, proc.stderr
    lines = [line for line in proc.stderr.splitlines()
             if not line.startswith('[')]
    assert lines == [f'mujoco_sim_node: invalid configuration: '
                     f'{lines[0].split(": ", 2)[-1]}'], proc.stderr
    assert message in lines[0], proc.stderr


def test_a_scene_makes_the_plant_and_its_pusher_is_felt_on_the_topic(
        tmp_path):
    """
    With ``scene``: the scene's robot, state and objects; t = 0 latched.

    panda_mujoco_push: once released, the arm (zero effort) falls while
    the pusher presses link 7 with 20 N along +y from t = 1.22 s to
    1.9 s; ~/contact_wrenches/link7 carries MuJoCo's contact force, and
    a link that leaves contact gets one zero wrench.
    """
    from geometry_msgs.msg import WrenchStamped
    from std_msgs.msg import Header
    run = Session(tmp_path, 45, scene='panda_mujoco_push',
                  real_time_factor=2.0, wait_for_subscribers=1)
    latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
    start = []
    run.probe.node.create_subscription(
        Header, '/mujoco_sim_node/start', start.append, latched)
    pushes = run.probe.collect(
        WrenchStamped, '/mujoco_sim_node/contact_wrenches/link7', 1000)
    try:
        run.wait_up(2)
        # the latched start can reach the probe after the first states
        # (discovery of each topic is its own): wait for it
        assert run.probe.spin_until(lambda: bool(start), 10.0)
        assert start[-1].stamp.sec == start[-1].stamp.nanosec == 0
        np.testing.assert_array_equal(
            run.states[0].position, [0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.8])
        run.pub.publish(command(np.zeros(7)))
        run.wait_time(2.1, timeout=60.0)
        run.probe.spin_for(0.2)
        assert pushes, run.node.log()
        t = np.array([t_of(m) for m in pushes])
        fy = np.array([m.wrench.force.y for m in pushes])
        assert 1.2 <= t[0] <= 1.25
        held = (t > 1.4) & (t < 1.85)
        assert held.any()
        # the ball's inertia and the soft contact ride on the 20 N push
        assert 15.0 < np.median(fy[held]) < 25.0
        assert pushes[-1].wrench.force.y == 0.0     # left contact
        assert pushes[-1].header.frame_id == 'base_link'
    finally:
        run.close()


def held_states(tmp_path, offset, count, **params):
    """Return ``count`` states (position, velocity, effort) while held."""
    run = Session(tmp_path, offset, robot_file='panda',
                  initial_positions=Q0, rate=500.0, **params)
    try:
        run.wait_up(count)
        rows = [(m.position, m.velocity, m.effort)
                for m in run.states[:count]]
    finally:
        run.close()
    return [np.array([r[i] for r in rows]) for i in range(3)]


def test_sensor_noise_off_is_mujoco_on_has_the_asked_deviation(tmp_path):
    """
    Brakes on, the true state is Q0 at rest with zero effort.

    Noise zero: exactly that.  Noise on: the published values minus the
    truth have the asked standard deviations, to sampling error (7 x 600
    samples: about 1.1 % of sigma; the bound is 6 %), mean about zero.
    """
    q, qd, effort = held_states(tmp_path, 47, 50, noise={
        'position': 0.0, 'velocity': 0.0, 'effort': 0.0, 'seed': 3})
    np.testing.assert_array_equal(q, np.broadcast_to(Q0, q.shape))
    np.testing.assert_array_equal(qd, 0.0)
    np.testing.assert_array_equal(effort, 0.0)
    sigma = {'position': 1e-3, 'velocity': 2e-2, 'effort': 0.05}
    count = 600
    q, qd, effort = held_states(tmp_path, 47, count,
                                noise=dict(sigma, seed=3))
    for name, err in (('position', q - np.asarray(Q0)),
                      ('velocity', qd), ('effort', effort)):
        s = sigma[name]
        assert abs(err.std() - s) < 0.06 * s, (name, err.std(), s)
        assert abs(err.mean()) < 5 * s / math.sqrt(err.size), name
        # fresh noise every tick, every joint: no two samples alike
        assert np.unique(err).size == err.size, name


def test_lockstep_paces_the_braked_ticks_and_ticks_once_per_command(
        tmp_path):
    """
    Lockstep: braked ticks at most 20 a second, then one per command.

    Before the first command nothing paces a lockstep plant's ticks: at
    its full rate (real-time factor 0) a graph that answers every state
    could fall behind them for good, so the plant holds them to at most
    20 a second of wall clock (simulated time still runs a tick each).
    Once released, each command makes exactly one tick.
    """
    run = Session(tmp_path, 51, robot_file='panda', initial_positions=Q0,
                  rate=500.0, lockstep=True, real_time_factor=0.0,
                  command_timeout=30.0)
    try:
        run.wait_up(2)
        count, start = len(run.states), time.monotonic()
        run.probe.spin_for(1.0)
        held = len(run.states) - count
        elapsed = time.monotonic() - start
        assert 1 <= held <= elapsed / 0.05 + 2, (held, elapsed)
        stamps = np.array([t_of(m) for m in run.states])
        np.testing.assert_allclose(np.diff(stamps), 0.002, atol=1e-6)
        for msg in run.states:
            np.testing.assert_array_equal(msg.position, Q0)
        # the first command releases the brakes (a held tick may come
        # before it); from then on one tick per command
        run.pub.publish(command(np.zeros(7)))
        assert run.probe.spin_until(lambda: not np.array_equal(
            run.states[-1].position, Q0), 10.0), run.node.log()
        run.probe.spin_for(0.1)
        for k in range(20):
            count = len(run.states)
            run.pub.publish(command(np.zeros(7)))
            assert run.probe.spin_until(lambda: len(run.states) > count,
                                        10.0), run.node.log()
            run.probe.spin_for(0.05)        # no tick without a command
            assert len(run.states) == count + 1, (k, run.node.log())
    finally:
        log = run.close()
    assert 'brakes released' in log, log
