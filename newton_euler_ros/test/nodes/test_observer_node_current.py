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
The node's observer on a current-sensing arm, over real DDS.

inverse_dynamics_node reads a UR5 URDF (example-robot-data's, with its
transmissions) that carries friction and torque constants as identify
writes them (``<dynamics friction>``, ``<ne:drive torque_constant>``).
It is fed JointStates of the arm holding a pose whose efforts are motor
currents (A): the Euler-Lagrange oracle's gravity torque plus a static
friction each joint holds at rest (1.3 x its Coulomb friction, signs
mixed, far above the 1 N m thresholds), divided by the torque constants.
No contact may be reported, and the external torque must come out in
N m as minus the held friction.  Then a push on the tool (the drives
take J^T F on top) must be reported within 0.2 s of its stamps.  And
on the settled arm a 10 N push whose torques stay within every joint's
friction band (the threshold test cannot feel it) is reported by the
rest reference within 0.2 s.
"""
import os
import re
import warnings

import numpy as np
import pytest

pytest.importorskip('rclpy')

from newton_euler_ros.core import load_robot  # noqa: E402, I100
from newton_euler_ros.core.drives import DRIVES_NS  # noqa: E402
import reference_dynamics as ref  # noqa: E402
from ros_harness import (domain_id, id_node_cmd, joint_state,  # noqa: E402
                         NodeProcess, Probe)
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402, I100
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import Bool  # noqa: E402

pytestmark = pytest.mark.ros

NODE = '/inverse_dynamics_node'
UR5 = 'ur_description/urdf/ur5_robot.urdf'
K = np.array([13.1, 12.7, 11.9, 9.6, 9.3, 9.8])           # N m per A
COULOMB = np.array([9.0, 11.0, 7.5, 2.6, 2.4, 2.2])        # N m
HELD = 1.3 * COULOMB * np.array([1, -1, 1, -1, 1, 1])      # at rest
Q = np.array([0.3, -1.2, 1.4, -1.8, -1.57, 0.2])
PUSH = np.array([0.0, 30.0, -90.0, 0.0, 0.0, 0.0])          # on the tool, N
THRESHOLD = 1.0


def current_urdf(path):
    """Write the UR5 with friction and torque constants; return its model."""
    from newton_euler_tools.peers import example_robot_urdf
    with open(example_robot_urdf(UR5), encoding='utf-8') as fh:
        text = fh.read()
    text = text.replace('<robot ', f'<robot xmlns:ne="{DRIVES_NS}" ', 1)
    joint = iter(range(6))

    def drive(_match):
        j = next(joint)
        return (f'<dynamics damping="2.0" friction="{COULOMB[j]}"/>'
                f'<ne:drive torque_constant="{K[j]}" coulomb_width="0.02"/>')
    text = re.sub(r'<dynamics damping="0.0" friction="0.0"/>', drive, text)
    assert next(joint, None) is None and '<transmission' in text
    with open(path, 'w', encoding='utf-8') as fh:
        fh.write(text)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot(path, base='base_link', tip='tool0')


@pytest.fixture(scope='module')
def graph(tmp_path_factory):
    tmp = str(tmp_path_factory.mktemp('observer_current'))
    urdf = os.path.join(tmp, 'ur5_current.urdf')
    model = current_urdf(urdf)
    domain = domain_id(89)
    cmd = id_node_cmd(None, '-p', f'robot_file:={urdf}',
                      '-p', 'base_link:=base_link', '-p', 'tip_link:=tool0',
                      '-p', 'observer.enabled:=true',
                      '-p', 'observer.gain:=50.0',
                      '-p', f'observer.thresholds:=[{THRESHOLD}]',
                      '-p', 'observer.contact_period:=0.2',
                      '-p', 'diagnostics_period:=0.2')
    node = NodeProcess(cmd, domain, os.path.join(tmp, 'node.log'))
    probe = Probe(domain)
    g = {'node': node, 'probe': probe, 'model': model,
         'ext': probe.collect(JointState, f'{NODE}/external_torque', 2000),
         'contact': probe.collect(Bool, f'{NODE}/contact', 2000),
         'diagnostics': probe.collect(DiagnosticArray, '/diagnostics'),
         'js': probe.publisher(JointState, 'joint_states', 1000)}
    ok = probe.spin_until(
        lambda: g['js'].get_subscription_count() > 0 and all(
            probe.node.count_publishers(f'{NODE}/{t}') > 0
            for t in ('external_torque', 'contact')), 90.0)
    assert ok, node.log()
    yield g
    node.stop()
    probe.close()


def test_resting_in_the_friction_band_is_no_contact_and_a_push_is(graph):
    g, model = graph, graph['model']
    rng = np.random.default_rng(4)
    zero = np.zeros(6)
    gravity = ref.inverse_dynamics(model, Q, zero, zero, None, 'base')
    J = ref.ee_jacobian(model, Q)
    # the push exceeds threshold + allowance + held friction on a joint
    push = J.T @ PUSH
    assert np.any(np.abs(push) > THRESHOLD + 2.9 * COULOMB), push
    names = list(model.joint_names)
    sent = []

    def send(seq, torque):
        stamp = g['probe'].keyed_stamp(seq)
        msg = joint_state(names, Q, rng.normal(0.0, 1e-3, 6), stamp)
        amps = (torque + rng.normal(0.0, 0.3, 6)) / K
        msg.effort = [float(x) for x in amps]
        g['js'].publish(msg)
        g['probe'].spin_for(0.01)                   # about 100 Hz
        sent.append(stamp)
    for k in range(200):                            # 2 s at rest
        send(k + 1, gravity + HELD)
    resting = len(sent)
    g['probe'].spin_for(0.3)                        # a ~/contact repeat
    at_rest = [m.data for m in g['contact']]
    # the arm has rested and settled: the rest reference is armed
    rest = [kv.value for a in g['diagnostics'][-2:] for st in a.status
            if st.name.endswith(': observer') for kv in st.values
            if kv.key == 'rest_reference']
    assert rest and rest[-1] == 'armed (the arm rests)', rest
    for k in range(60):                             # then pushed
        # the drives hold the pose against the push: tau - J^T F_ext
        send(2000 + k, gravity + HELD - push)
    probe = g['probe']
    keys = [(s.sec, s.nanosec) for s in sent]

    def answers():
        return {(m.header.stamp.sec, m.header.stamp.nanosec): m
                for m in g['ext']}
    assert probe.spin_until(lambda: keys[-1] in answers(), 10.0), \
        g['node'].log()
    ext = answers()
    rest = [k for k in keys[50:resting] if k in ext]
    assert len(rest) > 50
    # in N m (the currents times K), minus the friction held at rest
    r = np.array([ext[k].effort for k in rest])
    np.testing.assert_allclose(r.mean(axis=0), -HELD, atol=0.2)
    assert np.abs(r).max(axis=0).max() > 10 * THRESHOLD
    # ~/contact: false all through the rest, true once pushed
    assert probe.spin_until(lambda: g['contact'] and g['contact'][-1].data,
                            3.0), [m.data for m in g['contact']]
    assert at_rest and not any(at_rest), at_rest
    assert True in [m.data for m in g['contact']]
    # no contact from any rest answer; the push within 0.2 s of stamps
    bound = THRESHOLD + 1.5 * COULOMB
    assert all((np.abs(ext[k].effort) <= bound).all() for k in rest)
    t_push = sent[resting].sec + sent[resting].nanosec * 1e-9
    first = next(k for k in keys[resting:] if k in ext and (np.abs(
        ext[k].effort) > bound + THRESHOLD).any())
    assert first[0] + first[1] * 1e-9 - t_push < 0.2
    log = g['node'].log()
    assert 'torque constants 13.1, 12.7, 11.9, 9.6, 9.3, 9.8' in log, log
    assert log.count('observer: contact (number 1)') == 1, log


def test_a_push_within_the_band_on_the_settled_arm(graph):
    g, model = graph, graph['model']
    rng = np.random.default_rng(5)
    zero = np.zeros(6)
    gravity = ref.inverse_dynamics(model, Q, zero, zero, None, 'base')
    push = ref.ee_jacobian(model, Q)[:3].T @ np.array([0.0, 10.0, 0.0])
    band = THRESHOLD + 1.5 * COULOMB            # threshold + allowance
    assert (np.abs(push - HELD) < band - 0.5).all(), (push - HELD, band)
    assert np.abs(push).max() > 5 * THRESHOLD, push
    names = list(model.joint_names)
    sent = []

    def send(seq, torque):
        stamp = g['probe'].keyed_stamp(seq)
        msg = joint_state(names, Q, rng.normal(0.0, 1e-3, 6), stamp)
        msg.effort = [float(x) for x in
                      (torque + rng.normal(0.0, 0.3, 6)) / K]
        g['js'].publish(msg)
        g['probe'].spin_for(0.01)
        sent.append(stamp)
    for k in range(300):                            # 3 s at rest
        send(5000 + k, gravity + HELD)
    resting = len(sent)
    # the repeats of ~/contact while it rested (no pause: a gap in the
    # stamps would end the rest)
    assert g['contact'] and not g['contact'][-1].data, g['node'].log()
    seen = len(g['contact'])
    for k in range(40):                             # then pushed, held
        send(7000 + k, gravity + HELD - push)
    keys = [(s.sec, s.nanosec) for s in sent]
    probe = g['probe']
    assert probe.spin_until(lambda: any(
        (m.header.stamp.sec, m.header.stamp.nanosec) == keys[-1]
        for m in g['ext']), 10.0), g['node'].log()
    ext = {(m.header.stamp.sec, m.header.stamp.nanosec): m for m in g['ext']}
    # the threshold test's bound is never crossed (once the residual of
    # the previous test's push has faded) ...
    assert all((np.abs(ext[k].effort) < band).all() for k in keys[50:]
               if k in ext)
    # ... yet ~/contact turns true, within 0.2 s of the push's stamps
    probe.spin_for(0.3)
    log = g['node'].log()
    assert log.count('observer: contact (number') >= 2, log
    t_push = sent[resting].sec + sent[resting].nanosec * 1e-9
    assert any(m.data for m in g['contact'][seen:]), \
        [m.data for m in g['contact']]
    first = next(k for k in keys[resting:] if k in ext and np.abs(
        np.array(ext[k].effort) + HELD).max() > 0.9 * np.abs(push).max())
    assert first[0] + first[1] * 1e-9 - t_push < 0.2
