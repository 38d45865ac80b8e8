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
Load over real DDS, bounded in count and time.

A burst of service calls from separate clients, and a flood of joint
states.
"""
import time

import pytest

pytest.importorskip('rclpy')

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402, I100
from newton_euler_interfaces.srv import ComputeDynamics  # noqa: E402
from rclpy.qos import QoSProfile  # noqa: E402
from ros_harness import (domain_id, FAST_DIAGNOSTICS,  # noqa: E402
                         id_node_cmd, NodeProcess, Probe)
from sensor_msgs.msg import JointState  # noqa: E402

pytestmark = [pytest.mark.ros, pytest.mark.slow]

NODE = '/inverse_dynamics_node'
CALLERS = 100
FLOOD_S = 15.0


def node_cmd():
    return id_node_cmd('puma560.yaml', *FAST_DIAGNOSTICS)


@pytest.fixture(scope='module')
def graph(tmp_path_factory):
    domain = domain_id(47)
    node = NodeProcess(node_cmd(), domain,
                       str(tmp_path_factory.mktemp('load') / 'node.log'))
    probe = Probe(domain)
    probe.call(ComputeDynamics, f'{NODE}/compute_dynamics',
               ComputeDynamics.Request(), timeout=90.0)
    yield node, probe
    assert node.stop() == 0
    probe.close()


def rss_kb(pid):
    with open(f'/proc/{pid}/status') as fh:
        for line in fh:
            if line.startswith('VmRSS:'):
                return int(line.split()[1])
    raise AssertionError('no VmRSS')


def test_a_burst_of_callers_is_answered(graph):
    """100 separate clients call at once; every one gets its answer."""
    node, probe = graph
    diag = probe.collect(DiagnosticArray, '/diagnostics')
    before = probe.next_counters(diag)['service_calls']
    # the caller-side QoS the README documents for bursts: responses go to
    # every client's reader, so each needs room for the burst's answers
    qos = QoSProfile(depth=2 * CALLERS)
    clients = [probe.node.create_client(
        ComputeDynamics, f'{NODE}/compute_dynamics', qos_profile=qos)
        for _ in range(CALLERS)]
    assert probe.spin_until(lambda: all(c.service_is_ready()
                                        for c in clients), 30.0)
    # ready means the request path is matched; give the response path (the
    # node's writer to each new client's reader) a moment too, or DDS may
    # drop a first response (ros2/rmw_fastrtps#418): not the node's queue
    probe.spin_for(1.0)
    request = ComputeDynamics.Request(
        name=[f'joint{i}' for i in range(1, 7)],
        position=[0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    futures = [c.call_async(request) for c in clients]
    assert probe.spin_until(lambda: all(f.done() for f in futures), 60.0), \
        f'{sum(f.done() for f in futures)} of {CALLERS} answered'
    assert all(f.result().success for f in futures)
    after = probe.next_counters(diag)['service_calls']
    assert after - before == CALLERS
    for client in clients:
        probe.node.destroy_client(client)


def test_a_flood_leaves_memory_and_latency_as_they_were(graph):
    """Joint states as fast as one publisher can send, for FLOOD_S s."""
    node, probe = graph
    js = probe.publisher(JointState, 'joint_states', depth=10)
    # depth 10: the probe does not spin during the flood, and a deeper
    # reader would leave it a backlog of its own to take one message at a
    # time afterwards (a second on a loaded CI machine) before it reached
    # the answer whose latency is measured: the node's queue, not the
    # probe's, is under test
    torques = probe.collect(JointState, f'{NODE}/torques', depth=10)
    assert probe.spin_until(lambda: js.get_subscription_count() > 0, 20.0)
    msg = JointState()
    msg.name = [f'joint{i}' for i in range(1, 7)]
    msg.position = [0.1] * 6
    msg.velocity = [0.0] * 6
    probe.spin_for(2.0)
    start_rss = rss_kb(node.proc.pid)
    sent = 0
    peak = 0
    end = time.monotonic() + FLOOD_S
    while time.monotonic() < end:
        msg.header.stamp = probe.node.get_clock().now().to_msg()
        js.publish(msg)
        sent += 1
        if sent % 2000 == 0:
            peak = max(peak, rss_kb(node.proc.pid) - start_rss)
    # memory during the flood: bounded by the subscription's depth
    assert peak < 5 * 1024, f'RSS rose {peak} kB during the flood'
    assert sent > 50_000        # it was a flood
    # latency: a state sent now is answered within a second
    stopped = time.monotonic()
    msg.header.stamp = probe.node.get_clock().now().to_msg()
    key = (msg.header.stamp.sec, msg.header.stamp.nanosec)
    js.publish(msg)
    assert probe.spin_until(lambda: any(
        (t.header.stamp.sec, t.header.stamp.nanosec) == key
        for t in torques[-10:]), 1.0)
    assert time.monotonic() - stopped < 1.0
    # memory: what the backlog took is given back (the node trims its
    # heap once a second)
    probe.spin_for(3.0)
    grown = rss_kb(node.proc.pid) - start_rss
    assert grown < 5 * 1024, f'RSS grew {grown} kB after {sent} messages'
