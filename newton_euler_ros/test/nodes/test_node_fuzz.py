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
A bounded, seeded fuzz run against one inverse_dynamics_node process.

Random and malformed joint states, wrenches and service requests are
interleaved with valid ones.  The node must survive, never publish a
non-finite number, count every rejection as a clean one (no
``internal_error``), still compute correct torques afterwards and exit 0
on SIGINT.
"""
import math
import os
import time
import warnings

import numpy as np
import pytest

pytest.importorskip('rclpy')

# After the skip: pytest must be imported first, hence E402 and I100.
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402, I100
from geometry_msgs.msg import WrenchStamped  # noqa: E402
from newton_euler_interfaces.srv import ComputeDynamics  # noqa: E402
from newton_euler_ros.core import (DynamicsInputError,  # noqa: E402
                                   inverse_dynamics, load_robot)
from rclpy.qos import QoSProfile, ReliabilityPolicy  # noqa: E402
from ros_harness import (domain_id, FAST_DIAGNOSTICS,  # noqa: E402
                         id_node_cmd, NodeProcess, Probe, wrench)
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import Float64MultiArray  # noqa: E402

pytestmark = pytest.mark.ros

NODE = '/inverse_dynamics_node'
SERVICE = f'{NODE}/compute_dynamics'
JOINTS = [f'joint{k}' for k in range(1, 7)]   # the params file's order
N = len(JOINTS)
TIMEOUT = 0.3          # wrench.timeout for this node, seconds
SEED = 20260
N_STATES, N_WRENCHES, N_REQUESTS = 300, 150, 60

SPECIAL = [math.nan, -math.nan, math.inf, -math.inf, 1e308, -1e308,
           1.7976931348623157e308, 1e-300, -1e-300, 5e-324, 2.2e-308, 0.0,
           -0.0, 1e20, -1e20, 1e154]
WEIRD_NAMES = ['', ' ', 'joint1 ', 'JOINT1', 'joint7', 'joint0', 'jöint1',
               '関節1', '\U0001f916', 'joint1\u200b', 'j' * 5000,
               'joint' * 2000, '/joint1', 'base_link', 'tool0', 'gripper',
               '\t', 'joint-1']
FRAMES_OK = ['base_link', 'tool0']
FRAMES_BAD = ['', 'world', 'base_link ', 'BASE_LINK', 'tool0/', '/tool0',
              'camera_link', 'tööl0', '\U0001f527', 'f' * 5000, 'tool1']


def node_cmd(*extra):
    return id_node_cmd('puma560.yaml', *FAST_DIAGNOSTICS, *extra)


def finite(values):
    return bool(np.isfinite(np.asarray(values, dtype=np.float64)).all())


class Fuzzer:
    """Seeded generators of random/malformed inputs."""

    def __init__(self, seed):
        self.rng = np.random.default_rng(seed)

    def pick(self, seq):
        return seq[int(self.rng.integers(len(seq)))]

    def value(self, p_special=0.25):
        if self.rng.random() < p_special:
            return float(self.pick(SPECIAL))
        return float(self.rng.uniform(-3.0, 3.0))

    def values(self, count, p_special=0.25):
        return [self.value(p_special) for _ in range(count)]

    def shuffled_joints(self):
        return [JOINTS[i] for i in self.rng.permutation(N)]

    def names(self):
        kind = int(self.rng.integers(9))
        valid = self.shuffled_joints()
        if kind == 0:      # subset
            return valid[:int(self.rng.integers(0, N))]
        if kind == 1:      # superset with extra joints
            extra = [self.pick(WEIRD_NAMES)
                     for _ in range(int(self.rng.integers(1, 4)))]
            out = valid + [e for e in extra if e not in JOINTS]
            return [out[i] for i in self.rng.permutation(len(out))]
        if kind == 2:      # duplicates
            return valid + [self.pick(JOINTS)]
        if kind == 3:
            return []
        if kind == 4:      # unicode / very long / look-alikes only
            return [self.pick(WEIRD_NAMES)
                    for _ in range(int(self.rng.integers(1, 9)))]
        if kind == 5:      # random garbage strings
            return [''.join(chr(int(c)) for c in
                            self.rng.integers(32, 0x3000,
                                              int(self.rng.integers(0, 30))))
                    for _ in range(int(self.rng.integers(0, 10)))]
        if kind == 6:      # one valid joint replaced by a look-alike
            valid[int(self.rng.integers(N))] = self.pick(WEIRD_NAMES)
            return valid
        return valid       # well-formed names (values may still be bad)

    def length(self, n):
        """Return a length near n: mostly right, sometimes wrong."""
        r = self.rng.random()
        if r < 0.7:
            return n
        if r < 0.8:
            return 0
        return max(0, n + int(self.rng.integers(-3, 4)))

    def stamp(self, now_ns):
        kind = int(self.rng.integers(6))
        if kind == 0:
            return 0, 0
        if kind == 1:      # far past
            return int(self.rng.integers(0, 1000)), \
                int(self.rng.integers(0, 10**9))
        if kind == 2:      # far future
            return 2**31 - 1, 999_999_999
        if kind == 3:      # odd nanoseconds (>= 1e9 is representable)
            return int(now_ns // 10**9), int(self.rng.integers(0, 2**32))
        if kind == 4:      # negative seconds
            return -int(self.rng.integers(1, 2**31)), 0
        return int(now_ns // 10**9), int(now_ns % 10**9)


class Graph:
    def __init__(self, tmp):
        self.domain = domain_id(79)
        self.node = NodeProcess(
            node_cmd('-p', 'log_throttle:=0.5',
                     '-p', f'wrench.timeout:={TIMEOUT}'),
            self.domain, os.path.join(tmp, 'node.log'))
        self.probe = Probe(self.domain, name='fuzz_probe')
        qos = QoSProfile(depth=1000,
                         reliability=ReliabilityPolicy.RELIABLE)
        self.cmds = self.probe.collect(Float64MultiArray,
                                       f'{NODE}/torque_command', qos)
        self.torques = self.probe.collect(JointState, f'{NODE}/torques', qos)
        self.diag = self.probe.collect(DiagnosticArray, '/diagnostics', qos)
        self.js = self.probe.publisher(JointState, 'joint_states', qos)
        self.wr = self.probe.publisher(WrenchStamped, 'wrench', qos)
        self.client = self.probe.node.create_client(ComputeDynamics, SERVICE)
        # the service answers once the node is up and its kernels are warm
        assert self.client.wait_for_service(timeout_sec=90.0), \
            self.node.log()
        assert self.probe.call(ComputeDynamics, SERVICE,
                               ComputeDynamics.Request(), 90.0) is not None
        assert self.probe.spin_until(
            lambda: self.js.get_subscription_count() > 0
            and self.wr.get_subscription_count() > 0
            and self.probe.node.count_publishers(f'{NODE}/torques') > 0
            and self.probe.node.count_publishers(f'{NODE}/torque_command')
            > 0, 20.0), self.node.log()
        self.responses = []
        self.sent = {'joint_states': 0, 'joint_states_valid': 0,
                     'wrenches': 0, 'wrenches_valid': 0, 'requests': 0}
        self.fuzz_seconds = None

    def now_ns(self):
        return self.probe.node.get_clock().now().nanoseconds

    def call(self, request, timeout=10.0):
        future = self.client.call_async(request)
        self.probe.spin_until(future.done, timeout)
        return future.result() if future.done() else None

    def publish_state(self, names, position, velocity, stamp):
        msg = JointState()
        msg.header.stamp.sec, msg.header.stamp.nanosec = stamp
        msg.name = list(names)
        msg.position = list(position)
        msg.velocity = list(velocity)
        self.js.publish(msg)
        self.sent['joint_states'] += 1

    def publish_wrench(self, frame, values, stamp):
        from builtin_interfaces.msg import Time
        self.wr.publish(wrench(frame, values,
                               Time(sec=stamp[0], nanosec=stamp[1])))
        self.sent['wrenches'] += 1

    def counters(self):
        return self.probe.next_counters(self.diag)


@pytest.fixture(scope='module')
def graph(tmp_path_factory):
    g = Graph(str(tmp_path_factory.mktemp('fuzz')))
    yield g
    g.probe.close()
    g.node.stop()


@pytest.fixture(scope='module')
def model():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot('puma560')


def random_state(fz, now_ns):
    """One fuzzed joint state: (names, position, velocity, stamp, valid)."""
    if fz.rng.random() < 0.3:      # a VALID message
        names = fz.shuffled_joints()
        return (names, fz.values(N, 0.0), fz.values(N, 0.0)
                if fz.rng.random() < 0.8 else [],
                (int(now_ns // 10**9), int(now_ns % 10**9)), True)
    names = fz.names()
    position = fz.values(fz.length(len(names)))
    r = fz.rng.random()
    velocity = [] if r < 0.2 else fz.values(fz.length(len(names)))
    return names, position, velocity, fz.stamp(now_ns), False


def random_wrench(fz, now_ns):
    """One fuzzed wrench: (frame, values, stamp, valid)."""
    if fz.rng.random() < 0.3:      # a VALID, current wrench
        return (fz.pick(FRAMES_OK), fz.values(6, 0.0),
                (int(now_ns // 10**9), int(now_ns % 10**9)), True)
    frame = fz.pick(FRAMES_OK) if fz.rng.random() < 0.6 else \
        fz.pick(FRAMES_BAD)
    kind = int(fz.rng.integers(4))
    if kind == 0:                  # stale
        t = now_ns - int(fz.rng.uniform(TIMEOUT + 0.5, 1e4) * 1e9)
        stamp = (int(t // 10**9), int(t % 10**9))
    elif kind == 1:
        stamp = (0, 0)
    else:
        stamp = fz.stamp(now_ns)
        if stamp[0] == 2**31 - 1:  # see test_future_stamped_wrench_expires
            stamp = (0, 0)
    return frame, fz.values(6, 0.5), stamp, False


def random_request(fz):
    req = ComputeDynamics.Request()
    kind = int(fz.rng.integers(5))
    if kind == 0:                  # empty: latest state
        return req
    names = fz.shuffled_joints() if kind in (1, 2) else fz.names()
    req.name = names
    special = 0.0 if kind == 1 else 0.3
    req.position = fz.values(fz.length(len(names)), special)
    for field in ('velocity', 'acceleration'):
        count = 0 if fz.rng.random() < 0.3 else fz.length(len(names))
        setattr(req, field, fz.values(count, special))
    return req


def test_fuzz_inputs(graph):
    fz = Fuzzer(SEED)
    kinds = (['state'] * N_STATES + ['wrench'] * N_WRENCHES
             + ['request'] * N_REQUESTS)
    order = fz.rng.permutation(len(kinds))
    start = time.monotonic()
    for i in order:
        kind = kinds[i]
        if kind == 'state':
            names, pos, vel, stamp, valid = random_state(fz, graph.now_ns())
            graph.publish_state(names, pos, vel, stamp)
            graph.sent['joint_states_valid'] += valid
        elif kind == 'wrench':
            frame, values, stamp, valid = random_wrench(fz, graph.now_ns())
            graph.publish_wrench(frame, values, stamp)
            graph.sent['wrenches_valid'] += valid
        else:
            req = random_request(fz)
            res = graph.call(req)
            graph.sent['requests'] += 1
            assert res is not None, graph.node.log()[-3000:]
            graph.responses.append((req, res))
        graph.probe.spin_for(0.001)
        assert graph.node.alive(), graph.node.log()[-3000:]
    graph.probe.spin_for(1.0)
    graph.fuzz_seconds = time.monotonic() - start
    assert graph.node.alive(), graph.node.log()[-3000:]
    assert graph.cmds and graph.torques, 'no valid state got through'
    assert graph.sent['joint_states_valid'] > 0
    assert any(res.success for _, res in graph.responses)
    assert any(not res.success for _, res in graph.responses)


def test_published_values_are_finite(graph):
    bad = [list(m.data) for m in graph.cmds if not finite(m.data)]
    assert not bad, bad[:3]
    bad = [list(m.effort) for m in graph.torques if not finite(m.effort)]
    assert not bad, bad[:3]
    assert all(len(m.data) == N for m in graph.cmds)
    assert all(len(m.effort) == N and list(m.name) == JOINTS
               for m in graph.torques)


def test_successful_responses_are_finite_and_sized(graph):
    for req, res in graph.responses:
        if not res.success:
            assert res.message, req
            continue
        assert list(res.name) == JOINTS
        assert len(res.mass_matrix) == N * N, req
        assert len(res.coriolis_matrix) == N * N, req
        assert len(res.gravity) == N and len(res.torque) == N, req
        for field in ('mass_matrix', 'coriolis_matrix', 'gravity', 'torque'):
            assert finite(getattr(res, field)), (field, req, res)


def send_and_wait(graph, names, position, velocity, wait):
    """Publish a current-stamped state; return its torques msg or None."""
    now = graph.now_ns()
    stamp = (int(now // 10**9), int(now % 10**9))
    graph.publish_state(names, position, velocity, stamp)

    def mine():
        return [t for t in graph.torques
                if (t.header.stamp.sec, t.header.stamp.nanosec) == stamp]
    graph.probe.spin_until(mine, wait)
    found = mine()
    return found[-1] if found else None


@pytest.mark.parametrize('position, velocity', [
    ([0.3] * N, [1e308] * N),
    ([1e308] * N, [1e308] * N),
    ([0.3] * N, [1.7976931348623157e308, -1e308] * 3),
])
def test_huge_finite_input_is_not_published(graph, model, position,
                                            velocity):
    with pytest.raises(DynamicsInputError, match='overflows'):
        inverse_dynamics(model, np.array(position), np.array(velocity))
    # (the library refuses: the result really overflows float64)
    # the node now rejects such speeds as implausible before the dynamics
    # (beyond twice the velocity limit); either way nothing is published
    before = graph.counters()
    assert send_and_wait(graph, JOINTS, position, velocity, 1.0) is None
    after = graph.counters()
    assert after['non_finite'] + after['implausible'] > \
        before['non_finite'] + before['implausible']


def test_valid_input_still_correct_after_fuzz(graph, model):
    # no wrench may be active: the last fuzzed wrench has expired
    graph.probe.spin_for(TIMEOUT + 0.5)
    rng = np.random.default_rng(SEED + 1)
    q, qd = rng.uniform(-2.0, 2.0, (2, N))
    order = list(rng.permutation(N))
    names = ['gripper'] + [JOINTS[k] for k in order]
    out = send_and_wait(graph, names, [0.5] + [float(q[k]) for k in order],
                        [0.0] + [float(qd[k]) for k in order], 5.0)
    assert out is not None, graph.node.log()[-3000:]
    expected = inverse_dynamics(model, q, qd)
    np.testing.assert_allclose(out.effort, expected, rtol=0, atol=1e-12)
    assert graph.probe.spin_until(
        lambda: graph.cmds and np.allclose(graph.cmds[-1].data, expected,
                                           rtol=0, atol=1e-12), 2.0)
    req = ComputeDynamics.Request(name=names,
                                  position=[0.5] + [float(q[k])
                                                    for k in order],
                                  velocity=[0.0] + [float(qd[k])
                                                    for k in order])
    res = graph.call(req)
    assert res is not None and res.success, res
    np.testing.assert_allclose(res.torque, expected, rtol=0, atol=1e-12)
    assert len(res.mass_matrix) == N * N and finite(res.mass_matrix)


def test_counters_show_no_internal_error(graph):
    counts = graph.counters()
    print(f'\nfuzz: sent {graph.sent} in {graph.fuzz_seconds:.1f} s; '
          f'received {len(graph.cmds)} torque_command, '
          f'{len(graph.torques)} torques, '
          f'{sum(r.success for _, r in graph.responses)}/'
          f'{len(graph.responses)} successful responses; counters {counts}')
    assert counts['internal_error'] == 0, graph.node.log()[-5000:]
    assert counts['service_calls'] >= N_REQUESTS
    assert counts['malformed'] > 0 and counts['missing_joints'] > 0
    assert counts['non_finite'] > 0 and counts['unknown_frame'] > 0
    assert counts['stale'] > 0
    assert counts['published'] >= 1


def test_future_stamped_wrench_expires(graph, model):
    """A wrench from a clock running far ahead is never applied."""
    graph.publish_wrench('base_link', [0.0, 0.0, 50.0, 0.0, 0.0, 0.0],
                         (2**31 - 1, 0))
    graph.probe.spin_for(TIMEOUT + 0.5)
    q = np.full(N, 0.4)
    out = send_and_wait(graph, JOINTS, q.tolist(), [0.0] * N, 5.0)
    try:
        assert out is not None
        np.testing.assert_allclose(
            out.effort, inverse_dynamics(model, q, np.zeros(N)), rtol=0,
            atol=1e-12)
    finally:
        # clear it for later tests: a current wrench replaces it, expires
        now = graph.now_ns()
        graph.publish_wrench('base_link', [0.0] * 6,
                             (int(now // 10**9), int(now % 10**9)))
        graph.probe.spin_for(TIMEOUT + 0.3)


def test_stops_cleanly(graph):
    assert graph.node.alive(), graph.node.log()[-3000:]
    assert graph.node.stop() == 0
    log = graph.node.log()
    assert 'Traceback' not in log, log[-5000:]
