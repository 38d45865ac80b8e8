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
Trusted on hardware: what inverse_dynamics_node refuses to publish.

Over real DDS, on the Panda (Franka's torque limits, 87 and 12 N m):
absurd wrenches and speeds are rejected before the dynamics; a torque
above a limit is clamped to it (the default), or the message dropped;
oversized and control-character joint states are rejected at once; bad
stamps are rejected; logs stay short.
"""
import os
import time
import warnings

import numpy as np
import pytest

pytest.importorskip('rclpy')

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402, I100
from geometry_msgs.msg import WrenchStamped  # noqa: E402
from newton_euler_interfaces.srv import ComputeDynamics  # noqa: E402
from newton_euler_ros.core import (inverse_dynamics, jacobian,  # noqa: E402
                                   load_robot)
from ros_harness import (domain_id, FAST_DIAGNOSTICS,  # noqa: E402
                         id_node_cmd, joint_state, NodeProcess, Probe, wrench)
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import Float64MultiArray  # noqa: E402

pytestmark = pytest.mark.ros

NODE = '/inverse_dynamics_node'
LIMITS = np.array([87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0])


def node_cmd(*extra):
    return id_node_cmd('panda.yaml', '-p', 'log_throttle:=0.01',
                       '-p', 'wrench.timeout:=2.0',
                       *FAST_DIAGNOSTICS, *extra)


@pytest.fixture(scope='module')
def panda():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot('panda')


class Graph:
    def __init__(self, tmp, offset, *extra):
        self.domain = domain_id(offset)
        self.node = NodeProcess(node_cmd(*extra), self.domain,
                                os.path.join(tmp, f'node{offset}.log'))
        self.probe = Probe(self.domain)
        self.torques = self.probe.collect(JointState, f'{NODE}/torques')
        self.cmds = self.probe.collect(Float64MultiArray,
                                       f'{NODE}/torque_command')
        self.diag = self.probe.collect(DiagnosticArray, '/diagnostics')
        self.js = self.probe.publisher(JointState, 'joint_states')
        self.wr = self.probe.publisher(WrenchStamped, 'wrench')
        self.probe.call(ComputeDynamics, f'{NODE}/compute_dynamics',
                        ComputeDynamics.Request(), timeout=90.0)
        assert self.probe.spin_until(
            lambda: self.js.get_subscription_count() > 0
            and self.wr.get_subscription_count() > 0
            and self.probe.node.count_publishers(f'{NODE}/torques') > 0,
            20.0), self.node.log()
        self.seq = 0

    def stamp(self, offset_s=0.0):
        self.seq += 1
        return self.probe.keyed_stamp(self.seq, offset_s)

    def send(self, names, q, qd, stamp=None, wait=3.0):
        stamp = stamp if stamp is not None else self.stamp()
        self.js.publish(joint_state(names, q, qd, stamp))
        out = self.probe.answer(self.torques, stamp, wait)
        return None if out is None else np.array(out.effort)

    def rejected(self, names, q, qd, key, stamp=None):
        """
        Publish a state; True once the node counted it as ``key``, unanswered.

        The node may skip a state when a newer one is waiting, so nothing
        is sent after it: the node's own ``published`` counter tells
        whether it answered.
        """
        before = self.counters()
        stamp = stamp if stamp is not None else self.stamp()
        self.js.publish(joint_state(names, q, qd, stamp))
        deadline = time.monotonic() + 10.0
        while True:
            after = self.counters()
            if after[key] > before[key] or time.monotonic() > deadline:
                break
        return (after[key] > before[key]
                and after['published'] == before['published']
                and self.probe.answer(self.torques, stamp, 0.1) is None)

    def wrench(self, frame, values):
        now = self.probe.node.get_clock().now().to_msg()
        self.wr.publish(wrench(frame, values, now))
        self.probe.spin_for(0.2)

    def send_until(self, names, q, qd, ok, timeout=10.0):
        """
        Send states until ``ok(torques)``; return the last torques.

        A wrench and a joint state pending at once are taken in the
        executor's order, not the order sent: on a loaded machine the
        first states after a new wrench may still be computed without it.
        """
        deadline = time.monotonic() + timeout
        while True:
            tau = self.send(names, q, qd, wait=1.0)
            if ok(tau) or time.monotonic() > deadline:
                return tau

    def counters(self):
        return self.probe.next_counters(self.diag)

    def counted(self, key, before, timeout=10.0):
        """
        Return True once the node's ``key`` counter is above before[key].

        The diagnostics message after a publish may have left before the
        node took the message (a loaded machine): wait for later ones.
        """
        deadline = time.monotonic() + timeout
        while True:
            if self.counters()[key] > before[key]:
                return True
            if time.monotonic() > deadline:
                return False

    def close(self):
        code = self.node.stop()
        self.probe.close()
        return code


@pytest.fixture(scope='module')
def clamp(tmp_path_factory):
    g = Graph(str(tmp_path_factory.mktemp('clamp')), 41)
    yield g
    g.close()


@pytest.fixture(scope='module')
def drop(tmp_path_factory):
    g = Graph(str(tmp_path_factory.mktemp('drop')), 43,
              '-p', 'limits.action:=drop')
    yield g
    g.close()


Q = np.array([0.1, -0.4, 0.2, -1.8, 0.1, 1.5, 0.3])


def test_an_absurd_wrench_never_reaches_the_torques(clamp, panda):
    before = clamp.counters()
    clamp.wrench('base_link', [1e200, 0, 0, 0, 0, 0])
    tau = clamp.send(panda.joint_names, Q, np.zeros(7))
    # rejected before the dynamics: the torques are those without it
    np.testing.assert_allclose(tau, inverse_dynamics(panda, Q),
                               rtol=1e-12, atol=1e-12)
    assert clamp.counted('implausible', before)
    assert 'wrench with a force of 1e+200 N' in clamp.node.log()


def test_an_absurd_speed_is_rejected(clamp, panda):
    assert clamp.rejected(panda.joint_names, Q, [1e150] * 7, 'implausible')


def test_torques_above_the_limits_are_clamped(clamp, panda):
    # a plausible but strong push: 400 N along x in the end-effector frame
    F = np.array([400.0, 0.0, 0.0, 0.0, 0.0, 40.0])
    raw = inverse_dynamics(panda, Q) + jacobian(panda, Q, 'end_effector').T @ F
    assert (np.abs(raw) > LIMITS).any()        # the case is real
    before = clamp.counters()
    clamp.wrench('tool0', F)
    clipped = np.clip(raw, -LIMITS, LIMITS)
    tau = clamp.send_until(panda.joint_names, Q, np.zeros(7),
                           lambda t: t is not None and np.allclose(t, clipped))
    np.testing.assert_allclose(tau, clipped,
                               rtol=1e-12, atol=1e-12)
    assert np.all(np.abs(tau) <= LIMITS)
    assert np.all(np.abs(clamp.cmds[-1].data) <= LIMITS)
    assert clamp.counted('over_limit', before)
    # more states over the same joints: counted, not said again
    for _ in range(3):
        clamp.send(panda.joint_names, Q, np.zeros(7), wait=1.0)
    # said once, naming only the joints over, the torques asked and the
    # bounds (not the seven bounds of every joint)
    said = [line for line in clamp.node.log().splitlines()
            if 'above the torque bound' in line]
    assert len(said) == 1, said
    over = [f'{panda.joint_names[j]} asked {raw[j]:.4g} N m, bound '
            f'{LIMITS[j]:.4g}' for j in np.flatnonzero(np.abs(raw) > LIMITS)]
    assert ('torque command above the torque bound (clamped to it): '
            + '; '.join(over) + " (bounds from the robot's effort limits; "
            in said[0]), said
    assert '[87.0, 87.0' not in said[0]
    clamp.wrench('tool0', np.zeros(6))
    free = inverse_dynamics(panda, Q)
    clamp.send_until(panda.joint_names, Q, np.zeros(7),
                     lambda t: t is not None and np.allclose(t, free))


def test_drop_publishes_nothing_above_the_limits(drop, panda):
    F = np.array([400.0, 0.0, 0.0, 0.0, 0.0, 40.0])
    drop.wrench('tool0', F)
    before = drop.counters()
    assert drop.send_until(panda.joint_names, Q, np.zeros(7),
                           lambda t: t is None) is None
    assert drop.counted('over_limit', before)
    drop.wrench('tool0', np.zeros(6))
    free = inverse_dynamics(panda, Q)
    tau = drop.send_until(panda.joint_names, Q, np.zeros(7),
                          lambda t: t is not None and np.allclose(t, free))
    np.testing.assert_allclose(tau, inverse_dynamics(panda, Q), rtol=1e-12,
                               atol=1e-12)


def test_oversized_states_are_rejected_at_once(clamp, panda):
    names = [f'j{i}' for i in range(1_000_000)]
    before = clamp.counters()
    msg = JointState()
    msg.header.stamp = clamp.stamp()
    msg.name = names
    clamp.js.publish(msg)
    # the next good state is answered promptly
    start = time.monotonic()
    tau = clamp.send(panda.joint_names, Q, np.zeros(7), wait=10.0)
    assert tau is not None and time.monotonic() - start < 5.0
    assert clamp.counted('oversized', before)


@pytest.mark.parametrize('bad', ['joint3\x1b[2J', 'joint3\nFAKE LOG LINE',
                                 'joint3\x07'])
def test_names_with_control_characters_are_rejected(clamp, panda, bad):
    # (a NUL never arrives: rclpy cuts the string at it when publishing)
    names = list(panda.joint_names)
    names[2] = bad
    assert clamp.rejected(names, Q, np.zeros(7), 'malformed')
    assert 'has control characters' in clamp.node.log()
    # the name is logged escaped (repr): no forged line
    assert '\nFAKE LOG LINE' not in clamp.node.log()


def test_long_strings_are_clipped_in_the_log(clamp, panda):
    size = len(clamp.node.log())
    huge = 'x' * 1_000_000
    for _ in range(5):
        clamp.wrench(huge, np.zeros(6))
        names = list(panda.joint_names)
        names[0] = huge
        clamp.send(names, Q, np.zeros(7), wait=0.2)
    clamp.probe.spin_for(0.5)
    grown = len(clamp.node.log()) - size
    assert grown < 20_000, grown


@pytest.mark.parametrize('offset, accepted', [
    (None, True),                 # zero stamp: unknown, accepted
    (-1e9, False),                # before 1970: negative
    (15 * 365 * 86400.0, False),  # 2041: far future
    (0.5, True),                  # half a second ahead: clock skew
])
def test_joint_state_stamp_policy(clamp, panda, offset, accepted):
    from builtin_interfaces.msg import Time
    if offset is None:
        stamp = Time(sec=0, nanosec=0)
    elif offset < 0:
        stamp = Time(sec=-5, nanosec=0)
    else:
        stamp = clamp.stamp(offset)
    if accepted:
        assert clamp.send(panda.joint_names, Q, np.zeros(7), stamp=stamp,
                          wait=2.0) is not None
    else:
        assert clamp.rejected(panda.joint_names, Q, np.zeros(7), 'bad_stamp',
                              stamp=stamp)


def test_nodes_stop_cleanly(clamp, drop):
    for g in (clamp, drop):
        assert g.node.stop() == 0
        assert 'Traceback' not in g.node.log()
