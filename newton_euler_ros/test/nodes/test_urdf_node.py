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
inverse_dynamics_node on a URDF from the robot_description topic, over DDS.

The test plays robot_state_publisher: it publishes the URDF text on a
reliable, transient-local ``robot_description`` (so the node, started
with no robot file, gets it however late it joins), then swaps it for a
different robot, then for broken text, and sends joint states and
wrenches as a driver and a force/torque sensor would.
"""
import math
import os
import random
import warnings

import numpy as np
import pytest

pytest.importorskip('rclpy')

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402, I100
from geometry_msgs.msg import WrenchStamped  # noqa: E402
from newton_euler_interfaces.srv import ComputeDynamics  # noqa: E402
from newton_euler_ros.core import (inverse_dynamics, jacobian,  # noqa: E402
                                   load_robot, mass_matrix)
from newton_euler_ros.core.model import rpy_matrix  # noqa: E402
from newton_euler_ros.core.urdf import load_urdf, model_to_urdf  # noqa: E402
from rclpy.qos import (DurabilityPolicy, QoSProfile,  # noqa: E402
                       ReliabilityPolicy)
from ros_harness import (domain_id, FAST_DIAGNOSTICS,  # noqa: E402
                         id_node_cmd, joint_state, NodeProcess, Probe, wrench)
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import String  # noqa: E402

pytestmark = pytest.mark.ros

NODE = '/inverse_dynamics_node'
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
# a force/torque sensor 5 cm beyond the flange, turned 90 deg about x and
# 30 deg about z: fixed to tool0, so to the tip
SENSOR_XYZ = (0.01, -0.02, 0.05)
SENSOR_RPY = (math.pi / 2, 0.0, math.pi / 6)


def node_cmd(*extra):
    # the bundled parameter file for URDF robots, as the README runs it
    return id_node_cmd('urdf.yaml', '-p', 'base_link:=base_link',
                       '-p', 'tip_link:=tool0', '-p', 'log_throttle:=0.01',
                       *FAST_DIAGNOSTICS, *extra)


def with_sensor(urdf_text):
    xyz = ' '.join(repr(x) for x in SENSOR_XYZ)
    rpy = ' '.join(repr(x) for x in SENSOR_RPY)
    return urdf_text.replace('</robot>', f"""
  <link name="ft_sensor"/>
  <joint name="ft_mount" type="fixed"><parent link="tool0"/>
    <child link="ft_sensor"/><origin xyz="{xyz}" rpy="{rpy}"/></joint>
</robot>""")


def quiet(fn, *args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return fn(*args, **kw)


@pytest.fixture(scope='module')
def robots():
    puma = quiet(load_robot, 'puma560')
    panda = quiet(load_robot, 'panda')
    # the arms as robot_state_publisher would publish them; the puma's
    # tool0 carries a sensor link, so its tip (tool0) is no longer a leaf
    puma_text = with_sensor(model_to_urdf(puma))
    panda_text = model_to_urdf(panda)
    return {'puma': (quiet(load_urdf, puma_text, tip='tool0'), puma_text),
            'panda': (quiet(load_urdf, panda_text, tip='tool0'),
                      panda_text)}


class Graph:
    def __init__(self, tmp):
        self.domain = domain_id(53)
        self.probe = Probe(self.domain)
        self.description = self.probe.node.create_publisher(
            String, 'robot_description', LATCHED)
        self.node = NodeProcess(node_cmd(), self.domain,
                                os.path.join(tmp, 'node.log'))
        self.torques = self.probe.collect(JointState, f'{NODE}/torques')
        self.diag = self.probe.collect(DiagnosticArray, '/diagnostics')
        self.js = self.probe.publisher(JointState, 'joint_states')
        self.wr = self.probe.publisher(WrenchStamped, 'wrench')
        assert self.probe.spin_until(
            lambda: self.js.get_subscription_count() > 0
            and self.description.get_subscription_count() > 0, 60.0), \
            self.node.log()
        self.seq = 0

    def describe(self, text):
        self.description.publish(String(data=text))

    def send(self, names, q, qd, wait=5.0):
        self.seq += 1
        stamp = self.probe.keyed_stamp(self.seq)
        self.js.publish(joint_state(names, q, qd, stamp))
        return self.probe.answer(self.torques, stamp, wait)

    def wait_for_model(self, names, q, qd, timeout=60.0):
        """Send states until the node answers for this joint set."""
        end = self.probe.node.get_clock().now().nanoseconds + timeout * 1e9
        while self.probe.node.get_clock().now().nanoseconds < end:
            out = self.send(names, q, qd, wait=0.5)
            if out is not None and list(out.name) == list(names):
                return out
        raise AssertionError('no torques for ' + ', '.join(names) + '\n'
                             + self.node.log())

    def wrench(self, frame_id, values):
        now = self.probe.node.get_clock().now().to_msg()
        self.wr.publish(wrench(frame_id, values, now))
        self.probe.spin_for(0.2)

    def close(self):
        code = self.node.stop()
        self.probe.close()
        return code


@pytest.fixture(scope='module')
def graph(tmp_path_factory):
    g = Graph(str(tmp_path_factory.mktemp('urdf_node')))
    yield g
    g.close()


def test_waits_for_the_description_and_says_so(graph, robots):
    model, _ = robots['puma']
    rng = np.random.default_rng(1)
    q, qd = rng.uniform(-1, 1, size=(2, model.n))
    assert graph.send(model.joint_names, q, qd, wait=1.0) is None
    counters = graph.probe.next_counters(graph.diag)
    assert counters['no_model'] >= 1 and counters['published'] == 0
    status = graph.diag[-1].status[0]
    assert 'waiting for robot_description' in status.message
    log = graph.node.log()
    assert log.count('waiting for the robot_description topic') == 1


def test_torques_from_the_published_urdf(graph, robots):
    model, text = robots['puma']
    graph.describe(text)
    rng = np.random.default_rng(2)
    q, qd = rng.uniform(-1, 1, size=(2, model.n))
    out = graph.wait_for_model(model.joint_names, q, qd)
    for _ in range(5):
        q, qd = rng.uniform(-1.5, 1.5, size=(2, model.n))
        out = graph.send(model.joint_names, q, qd)
        np.testing.assert_allclose(out.effort,
                                   inverse_dynamics(model, q, qd),
                                   rtol=1e-12, atol=1e-12)
    response = graph.probe.call(
        ComputeDynamics, f'{NODE}/compute_dynamics',
        ComputeDynamics.Request(name=list(model.joint_names),
                                position=q.tolist()))
    assert response.success, response.message
    np.testing.assert_allclose(
        np.reshape(response.mass_matrix, (model.n, model.n)),
        mass_matrix(model, q), rtol=1e-12, atol=1e-12)


def test_wrench_in_a_sensor_link_is_moved_to_the_tip(graph, robots):
    model, _ = robots['puma']
    rng = np.random.default_rng(3)
    q, qd = rng.uniform(-1, 1, size=(2, model.n))
    F = np.array([12.0, -7.0, 3.0, 0.4, -0.9, 0.25])
    graph.wrench('ft_sensor', F)
    out = graph.send(model.joint_names, q, qd)
    # by hand: the sensor's axes are R in tool0, its origin p; the force
    # is the same vector, the moment about tool0's origin gains p x f
    R = rpy_matrix(*SENSOR_RPY)
    p = np.array(SENSOR_XYZ)
    f = R @ F[:3]
    n = R @ F[3:] + np.cross(p, f)
    J = jacobian(model, q, 'end_effector')
    expected = inverse_dynamics(model, q, qd) + J.T @ np.concatenate([f, n])
    np.testing.assert_allclose(out.effort, expected, rtol=1e-12, atol=1e-11)
    # and it differs from the same numbers taken in tool0 axes
    assert np.abs(np.asarray(out.effort) - (
        inverse_dynamics(model, q, qd) + J.T @ F)).max() > 0.1


def test_a_new_description_swaps_the_model(graph, robots):
    model, text = robots['panda']
    graph.describe(text)
    rng = np.random.default_rng(4)
    q, qd = rng.uniform(-1, 1, size=(2, model.n))
    graph.wait_for_model(model.joint_names, q, qd)
    out = graph.send(model.joint_names, q, qd)
    np.testing.assert_allclose(out.effort, inverse_dynamics(model, q, qd),
                               rtol=1e-12, atol=1e-12)
    # the service follows the current model too
    response = graph.probe.call(
        ComputeDynamics, f'{NODE}/compute_dynamics',
        ComputeDynamics.Request(name=list(model.joint_names),
                                position=q.tolist()))
    assert response.success and list(response.name) == list(
        model.joint_names)


def test_a_malformed_description_leaves_the_model_working(graph, robots):
    model, _ = robots['panda']
    before = graph.probe.next_counters(graph.diag)
    graph.describe('<robot name="broken"><link name="a"></robot>')
    # depth 1, as robot_state_publisher: let the node take each in turn
    assert graph.probe.spin_until(
        lambda: 'not well-formed XML' in graph.node.log(), 10.0)
    graph.describe('<robot name="r"><link name="b"/><link name="a"/>'
                   '<joint name="j" type="revolute"><parent link="b"/>'
                   '<child link="a"/><axis xyz="0 0 0"/></joint></robot>')
    assert graph.probe.spin_until(
        lambda: 'robot_description rejected' in graph.node.log()
        and 'axis> xyz: must be a nonzero vector' in graph.node.log(), 10.0)
    rng = np.random.default_rng(5)
    q, qd = rng.uniform(-1, 1, size=(2, model.n))
    out = graph.send(model.joint_names, q, qd)
    np.testing.assert_allclose(out.effort, inverse_dynamics(model, q, qd),
                               rtol=1e-12, atol=1e-12)
    after = graph.probe.next_counters(graph.diag)
    assert after['descriptions_rejected'] - before[
        'descriptions_rejected'] == 2


def test_random_descriptions_never_crash_it(graph, robots):
    """A bounded, seeded fuzz of the description topic."""
    model, text = robots['panda']
    rnd = random.Random(17)
    pieces = ['<robot name="x">', '</robot>', '<link name="a"/>',
              '<joint name="j" type="revolute">', '</joint>',
              '<parent link="a"/>', '<child link="b"/>',
              '<axis xyz="1 0 0"/>', '<inertial>', '<mass value="-1"/>',
              '&amp;', '<!DOCTYPE x [<!ENTITY e "e">]>', '\x00', 'nan',
              '<origin xyz="1e400 0 0"/>', '"', '<link name="b"/>']
    for k in range(40):
        if k % 4 == 0:      # mutate the real one
            cut = rnd.randrange(len(text))
            blob = text[:cut] + rnd.choice(pieces) + text[cut + 7:]
        else:
            blob = ''.join(rnd.choice(pieces)
                           for _ in range(rnd.randrange(1, 12)))
        graph.describe(blob)
        graph.probe.spin_for(0.02)
    graph.probe.spin_for(1.0)
    assert graph.node.proc.poll() is None, graph.node.log()
    # the last good model (or a good mutation of it) still answers
    graph.describe(text)
    q, qd = np.zeros((2, model.n))
    graph.wait_for_model(model.joint_names, q, qd)
    log = graph.node.log()
    assert 'Traceback' not in log, log


def test_stops_cleanly(graph):
    assert graph.node.stop() == 0
    assert 'Traceback' not in graph.node.log()
