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
The node's momentum observer over real DDS.

inverse_dynamics_node (bundled puma560, observer.enabled) is fed
JointStates whose efforts hold the arm still at a pose, from the
Euler-Lagrange oracle: first free, then while the environment pushes on
the tool with a known wrench (the drives then apply g - J^T F_ext).  The
three topics must answer every JointState with its stamp, the wrench
must come out as the push, and ~/contact must turn true mid-run, the log
naming the joints in contact with their residuals and thresholds.
"""
import os
import re
import subprocess
import warnings

import numpy as np
import pytest

pytest.importorskip('rclpy')

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402, I100
from geometry_msgs.msg import WrenchStamped  # noqa: E402
from newton_euler_ros.core import load_robot  # noqa: E402
import reference_dynamics as ref  # noqa: E402
from ros_harness import (domain_id, id_node_cmd, joint_state,  # noqa: E402
                         NodeProcess, Probe, ros_env)
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import Bool  # noqa: E402

pytestmark = pytest.mark.ros

NODE = '/inverse_dynamics_node'
NAMES = ['joint1', 'joint2', 'joint3', 'joint4', 'joint5', 'joint6']
Q = np.array([0.2, -0.5, 0.3, 0.1, 0.4, 0.2])
PUSH = np.array([0.0, 20.0, -30.0, 0.0, 0.0, 0.0])   # on the tool, N


@pytest.fixture(scope='module')
def graph(tmp_path_factory):
    tmp = str(tmp_path_factory.mktemp('observer'))
    domain = domain_id(73)
    cmd = id_node_cmd('puma560.yaml', '-p', 'observer.enabled:=true',
                      '-p', 'observer.gain:=50.0',
                      '-p', 'observer.thresholds:=[3.0]',
                      '-p', 'observer.contact_period:=0.2',
                      '-p', 'diagnostics_period:=0.2')
    node = NodeProcess(cmd, domain, os.path.join(tmp, 'node.log'))
    probe = Probe(domain)
    g = {'node': node, 'probe': probe,
         'torques': probe.collect(JointState, f'{NODE}/torques', 1000),
         'ext': probe.collect(JointState, f'{NODE}/external_torque', 1000),
         'wrench': probe.collect(WrenchStamped, f'{NODE}/external_wrench',
                                 1000),
         'contact': probe.collect(Bool, f'{NODE}/contact', 1000),
         'diag': probe.collect(DiagnosticArray, '/diagnostics'),
         'js': probe.publisher(JointState, 'joint_states', 1000)}
    ok = probe.spin_until(
        lambda: g['js'].get_subscription_count() > 0 and all(
            probe.node.count_publishers(f'{NODE}/{t}') > 0
            for t in ('torques', 'external_torque', 'external_wrench',
                      'contact')), 90.0)
    assert ok, node.log()
    # one answered JointState first (both ends matched), its replies
    # then left out: every later message must find the node listening
    z = np.zeros(6)
    hello = joint_state(NAMES, Q, z, probe.keyed_stamp(999))
    hello.effort = [float(x) for x in holding_effort(load_puma(), z)]
    probe.handshake(g['js'], hello, g['ext'])
    for topic in ('torques', 'ext', 'wrench'):
        g[topic].clear()
    yield g
    node.stop()
    probe.close()


def load_puma():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot('puma560')


@pytest.fixture(scope='module')
def puma():
    return load_puma()


def holding_effort(model, push):
    """Drive torques that hold the arm at Q while pushed (the oracle)."""
    z = np.zeros(6)
    # tau = g + J^T F_e with F_e = -F_ext: what the drives must apply
    return ref.inverse_dynamics(model, Q, z, z, -push, 'base')


def send(g, seq, effort, with_effort=True):
    stamp = g['probe'].keyed_stamp(seq)
    msg = joint_state(NAMES, Q, np.zeros(6), stamp)
    if with_effort:
        msg.effort = [float(x) for x in effort]
    g['js'].publish(msg)
    g['probe'].spin_for(0.01)           # about 100 Hz
    return stamp


def observer_status(g):
    count = len(g['diag'])
    assert g['probe'].spin_until(lambda: len(g['diag']) > count, 5.0)
    status = next(s for s in g['diag'][-1].status
                  if s.name.endswith(': observer'))
    return status, {kv.key: kv.value for kv in status.values}


def test_observer_topics_and_a_contact_mid_run(graph, puma):
    g = graph
    free, pushed = holding_effort(puma, np.zeros(6)), \
        holding_effort(puma, PUSH)
    stamps = []
    for k in range(80):                         # free: no contact
        stamps.append(send(g, k + 1, free))
    first_contact_index = len(stamps)
    for k in range(80):                         # pushed from here on
        stamps.append(send(g, 1000 + k, pushed))
    probe = g['probe']
    keys = [(s.sec, s.nanosec) for s in stamps]

    def answered(box):
        return {(m.header.stamp.sec, m.header.stamp.nanosec): m
                for m in box}

    # the last JointState is answered on both topics (a loaded machine
    # may drop a few inputs from the node's queue: not all are required)
    assert probe.spin_until(
        lambda: keys[-1] in answered(g['ext']) and
        keys[-1] in answered(g['wrench']), 10.0), g['node'].log()
    ext, wr = answered(g['ext']), answered(g['wrench'])
    # one of each per JointState, with its stamp, and nothing else
    assert set(ext) <= set(keys) and set(wr) <= set(keys)
    assert len(g['ext']) == len(ext) and len(g['wrench']) == len(wr)
    assert set(ext) == set(wr)
    assert len(ext) >= 0.5 * len(keys)
    last = ext[keys[-1]]
    assert list(last.name) == list(puma.joint_names)
    for m in g['ext']:
        assert np.isfinite(m.effort).all()
    for m in g['wrench']:
        f, t = m.wrench.force, m.wrench.torque
        assert np.isfinite([f.x, f.y, f.z, t.x, t.y, t.z]).all()
        assert m.header.frame_id == 'base_link'
    # free: a small residual; pushed: J^T F_ext, and the push itself
    free_keys = [k for k in keys[:first_contact_index] if k in ext]
    quiet = np.array(ext[free_keys[-1]].effort)
    assert np.abs(quiet).max() < 0.5
    r = np.array(last.effort)
    J = ref.ee_jacobian(puma, Q)
    np.testing.assert_allclose(r, J.T @ PUSH, atol=0.05 * np.abs(
        J.T @ PUSH).max())
    w = wr[keys[-1]].wrench
    F = np.array([w.force.x, w.force.y, w.force.z,
                  w.torque.x, w.torque.y, w.torque.z])
    assert np.linalg.norm(F[:3] - PUSH[:3]) <= \
        0.1 * np.linalg.norm(PUSH[:3]) + 1.0, F
    assert np.linalg.norm(F[3:] - PUSH[3:]) <= 0.2, F
    # contact: false first (steady repeats), then true once it started
    assert probe.spin_until(lambda: g['contact'] and g['contact'][-1].data,
                            3.0)
    values = [m.data for m in g['contact']]
    assert values[0] is False and True in values
    assert values.index(True) > 0
    status, kv = observer_status(g)
    assert kv['in_contact'] == 'true' and kv['contacts'] == '1', kv
    assert kv['state'] == 'running'
    # the contact's log line names the joints in contact, each with its
    # residual and threshold: those the push loads beyond 3 N m, not the
    # wrist's (J^T F is 10.1, -15.4, -4.8, 0, 0, 0 N m)
    lines = [x for x in g['node'].log().splitlines()
             if 'observer: contact (number 1)' in x]
    assert len(lines) == 1, g['node'].log()
    said = lines[0].split('observer: contact (number 1): ')[1]
    named = re.findall(r'(joint\d) (-?[\d.]+) N m \(threshold 3\)', said)
    assert named and ', '.join(
        f'{j} {v} N m (threshold 3)' for j, v in named) == said, said
    for joint, value in named:
        expected = (J.T @ PUSH)[NAMES.index(joint)]
        assert abs(float(value)) > 3.0 and \
            np.sign(float(value)) == np.sign(expected), said
    # torques went on all along: every JointState the observer answered
    # was answered with torques too
    assert probe.spin_until(
        lambda: set(ext) <= set(answered(g['torques'])), 5.0)


def test_without_effort_the_observer_says_so_and_torques_go_on(graph, puma):
    g = graph
    before = len(g['torques'])
    for k in range(5):
        send(g, 5000 + k, None, with_effort=False)
    assert g['probe'].spin_until(lambda: len(g['torques']) >= before + 5,
                                 5.0)
    status, kv = observer_status(g)
    assert kv['state'].startswith('cannot run'), kv
    log = g['node'].log()
    assert log.count('carry no effort') == 1, log


def test_the_payload_is_not_external(graph, puma):
    """A payload declared at run time leaves the residual, not a contact."""
    from rcl_interfaces.srv import SetParameters
    from rclpy.parameter import Parameter
    g = graph
    mass = 3.0
    result = g['probe'].call(SetParameters, f'{NODE}/set_parameters',
                             SetParameters.Request(parameters=[
                                 Parameter('payload.mass', value=mass)
                                 .to_parameter_msg()])).results[0]
    assert result.successful, result.reason
    # the drives now also hold a 3 kg point mass at the tool origin: its
    # weight is a force the environment applies there (oracle's gravity)
    weight = np.zeros(6)
    weight[:3] = mass * np.asarray(puma.gravity)
    effort = holding_effort(puma, weight)
    stamps = [send(g, 7000 + k, effort) for k in range(60)]
    key = (stamps[-1].sec, stamps[-1].nanosec)
    probe = g['probe']

    def last():
        return next((m for m in g['ext'] if (m.header.stamp.sec,
                                             m.header.stamp.nanosec) == key),
                    None)
    assert probe.spin_until(lambda: last() is not None, 10.0)
    assert np.abs(last().effort).max() < 0.3, last().effort
    assert probe.spin_until(lambda: not g['contact'][-1].data, 3.0)


@pytest.mark.parametrize('args, message', [
    (['-p', 'observer.thresholds:=[1.0, 2.0]'],
     'observer.thresholds: must have 1 or 6 values'),
    (['-p', 'observer.hysteresis:=1.5'], 'observer.hysteresis: must be <= 1'),
    (['-p', 'observer.gain:=0.0'], 'observer.gain: must be > 0'),
    (['-p', 'observer.rest_thresholds:=[-3.0]'],
     'observer.rest_thresholds: must be finite and >= 0'),
    (['-p', 'observer.speed_thresholds:=[-1.0]'],
     'observer.speed_thresholds: must be finite and >= 0'),
])
def test_bad_observer_settings_refuse_to_start(args, message):
    cmd = id_node_cmd('puma560.yaml', '-p', 'observer.enabled:=true', *args)
    proc = subprocess.run(cmd, env=ros_env(domain_id(71)),
                          capture_output=True, text=True, timeout=90)
    assert proc.returncode == 2, proc.stderr
    assert message in proc.stderr, proc.stderr
    assert 'Traceback' not in proc.stderr


def test_the_contact_line_gives_the_threshold_in_effect(puma):
    """With speed thresholds the line names the grown threshold, not a."""
    from newton_euler_ros.core.observer import (contact_step,
                                                initial_contact,
                                                MomentumObserver)
    from newton_euler_ros.nodes.node_observer import contact_text
    obs = MomentumObserver(puma, thresholds=2.0, speed_thresholds=10.0,
                           rest_reference=False)
    contact = initial_contact(obs)
    qd = np.full(6, 0.5)
    r = np.array([0.0, 20.0, 0.0, 0.0, 0.0, 0.0])
    for k in range(200):        # 0.2 s at 0.5 rad/s: the lag has settled
        now = contact_step(obs, contact, r, None, 1e-3 * k, Q, qd)
    assert now and contact.active[1]
    grown = float(contact.threshold[1])
    assert 2.0 + 10.0 * 0.5 * 0.99 < grown <= 2.0 + 10.0 * 0.5
    text = contact_text(obs, contact, r, None)
    assert f'joint2 20 N m (threshold {grown:.3g})' in text, text
    assert 'threshold 2)' not in text


def test_a_rest_contact_line_gives_the_rest_threshold(puma):
    """Found by the rest reference: its threshold, the rest threshold."""
    from newton_euler_ros.core.observer import (contact_step,
                                                initial_contact,
                                                MomentumObserver)
    from newton_euler_ros.nodes.node_observer import contact_text
    obs = MomentumObserver(puma, thresholds=0.5, rest_thresholds=[
        0.0, 3.0, 0.0, 0.0, 0.0, 0.0], static_friction=20.0)
    contact = initial_contact(obs)
    zero = np.zeros(6)
    r = zero.copy()
    allowance = np.full(6, 20.0)    # the band test feels nothing
    t = 0.0
    for k in range(600):            # 0.6 s settled: the rest value is 0
        t = 1e-3 * k
        contact_step(obs, contact, r, allowance, t, Q, zero)
    assert contact.rest.armed
    r[1] = 2.5                      # within the rest threshold: nothing
    for k in range(200):
        t += 1e-3
        assert not contact_step(obs, contact, r, allowance, t, Q, zero)
    r[1] = 4.0                      # beyond it, for 80 ms: contact
    for k in range(100):
        t += 1e-3
        now = contact_step(obs, contact, r, allowance, t, Q, zero)
    assert now and contact.rest.active[1] and not contact.active[1]
    text = contact_text(obs, contact, r, allowance)
    # (the rest value followed the 2.5 N m's drift a little, 2 s lag)
    dev = float(contact.rest.deviation[1])
    assert 3.0 < dev < 4.0
    assert text == (f'joint2 4 N m, {dev:.3g} from its rest value '
                    '(threshold 3)'), text
