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
Helpers for tests that run real ROS 2 processes on loopback DDS.

Each test module takes its own ROS_DOMAIN_ID; discovery stays on
localhost.  The node under test runs as its own process through its
console script; the test talks to it from a separate rclpy context.
"""
import os
import signal
import sys
import time

from newton_euler_tools.processes import ChildProcess, ros_env  # noqa: F401

PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PARAMS_DIR = os.path.join(PACKAGE_DIR, 'config', 'params')


def interrupt(proc, timeout):
    """
    Ctrl-C a command started with pipes; return its (stdout, stderr).

    A command that has not stopped when this returns or raises (a timeout)
    is killed: it must not outlive the test, a core busy for the rest of
    the run.
    """
    try:
        proc.send_signal(signal.SIGINT)
        return proc.communicate(timeout=timeout)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()


def domain_id(offset):
    """
    Return a domain id unique to this test run and module (1..100).

    Under pytest-xdist (``make test`` runs two workers) worker k of K
    takes ids from its own slice of 100 // K, the top ten of each left
    for the tools that use consecutive ids (demos, latency phases), so two
    workers never share a domain.
    """
    worker = os.environ.get('PYTEST_XDIST_WORKER', '')
    count = os.environ.get('PYTEST_XDIST_WORKER_COUNT', '')
    if worker[2:].isdigit() and count.isdigit() and int(count) > 1:
        size = 100 // min(int(count), 5)
        k = int(worker[2:]) % min(int(count), 5)
        return 1 + size * k + (os.getpid() * 7 + offset) % (size - 10)
    return 1 + (os.getpid() * 7 + offset) % 100


# the node under test runs as a child process; stop() sends SIGINT
NodeProcess = ChildProcess


# tests that read the node's input counters (next_counters) ask for them
# ten times a second rather than once (the default): each read waits for
# the next message
FAST_DIAGNOSTICS = ('-p', 'diagnostics_period:=0.1')


def id_node_cmd(params='puma560.yaml', *extra):
    """
    Command line of inverse_dynamics_node, as a user starts it.

    Its console script (the entry point users run), else ``python -m``;
    ``params`` is a bundled parameter file name, or None for none.
    """
    script = os.path.join(os.path.dirname(sys.executable),
                          'inverse_dynamics_node')
    base = [script] if os.path.exists(script) else [
        sys.executable, '-m', 'newton_euler_ros.nodes.inverse_dynamics_node']
    files = (['--params-file', os.path.join(PARAMS_DIR, params)]
             if params else [])
    return base + ['--ros-args', *files, *extra]


def joint_state(names, position, velocity, stamp):
    """Return a sensor_msgs/JointState of these values."""
    from sensor_msgs.msg import JointState
    msg = JointState()
    msg.header.stamp = stamp
    msg.name = list(names)
    msg.position = [float(x) for x in position]
    msg.velocity = [float(x) for x in velocity]
    return msg


def wrench(frame_id, values, stamp):
    """Return a geometry_msgs/WrenchStamped: force, then torque."""
    from geometry_msgs.msg import WrenchStamped
    msg = WrenchStamped()
    msg.header.frame_id = frame_id
    msg.header.stamp = stamp
    f, n = msg.wrench.force, msg.wrench.torque
    f.x, f.y, f.z, n.x, n.y, n.z = (float(v) for v in values)
    return msg


class Probe:
    """A test-side rclpy node in its own context: publish, collect, call."""

    def __init__(self, domain, name='probe'):
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        self.rclpy = rclpy
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = rclpy.create_node(name, context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.inbox = {}

    def collect(self, msg_type, topic, depth=100):
        box = self.inbox.setdefault(topic, [])
        self.node.create_subscription(msg_type, topic, box.append, depth)
        return box

    def publisher(self, msg_type, topic, depth=100):
        return self.node.create_publisher(msg_type, topic, depth)

    def spin_until(self, predicate, timeout):
        # each wait is bounded by the time left, so spin_for(0.004) takes
        # 4 ms, not the 20 ms of an idle spin_once
        end = time.monotonic() + timeout
        while not predicate():
            left = end - time.monotonic()
            if left <= 0.0:
                return predicate()
            self.executor.spin_once(timeout_sec=min(0.02, left))
        return True

    def spin_for(self, seconds):
        self.spin_until(lambda: False, seconds)

    def call(self, srv_type, name, request, timeout=10.0, resend=5.0):
        """
        Call ``name`` and return the response, or raise TimeoutError.

        A request that gets no answer within ``resend`` seconds is sent
        again: DDS can drop the first response of a fresh client when the
        server's response writer has not yet matched the client's reader
        (the client-service discovery race of ros2/rmw_fastrtps#418), and
        the services under test are idempotent.
        """
        client = self.node.create_client(srv_type, name)
        end = time.monotonic() + timeout
        if not client.wait_for_service(timeout_sec=timeout):
            raise TimeoutError(f'service {name} not available')
        while True:
            future = client.call_async(request)
            left = end - time.monotonic()
            if self.spin_until(future.done, max(0.0, min(resend, left))):
                return future.result()
            client.remove_pending_request(future)
            if time.monotonic() >= end:
                raise TimeoutError(f'service {name} did not answer')

    def handshake(self, publisher, message, answers, timeout=60.0,
                  resend=0.5, settle=1.0):
        """
        Publish ``message`` until ``answers`` holds a reply with its stamp.

        A subscription count above zero says only that the publisher has
        matched the node's reader; until the node's reader has matched
        the publisher too, what is published is lost (volatile, and the
        reader does not know the writer yet).  One answered message
        proves both directions, so a test's timed stream starts only
        after it.  The message is sent again every ``resend`` seconds
        with the same stamp; once one reply is in, the probe spins
        ``settle`` seconds more so replies to the resends arrive too.
        Returns the stamp, for the caller to leave those replies out.
        """
        stamp = message.header.stamp
        end = time.monotonic() + timeout

        def replied():
            return any(m.header.stamp == stamp for m in answers)
        while time.monotonic() < end:
            publisher.publish(message)
            if self.spin_until(replied, resend):
                self.spin_for(settle)
                return stamp
        raise TimeoutError(f'no reply to the handshake on '
                           f'{publisher.topic_name} within {timeout} s')

    def close(self):
        self.executor.shutdown()
        self.node.destroy_node()
        self.rclpy.try_shutdown(context=self.context)

    def keyed_stamp(self, seq, offset_s=0.0):
        """
        Return a stamp ``offset_s`` from now that ends in ``seq % 1000`` ns.

        The node copies a joint state's stamp onto its torques, so the
        stamp is the key that finds the answer to one message.
        """
        from builtin_interfaces.msg import Time
        ns = self.node.get_clock().now().nanoseconds + int(offset_s * 1e9)
        ns = (ns // 1000) * 1000 + seq % 1000
        return Time(sec=ns // 10**9, nanosec=ns % 10**9)

    def answer(self, torques, stamp, wait):
        """Return the message of ``torques`` stamped ``stamp``, or None."""
        def match():
            return next((t for t in torques if t.header.stamp == stamp),
                        None)
        self.spin_until(lambda: match() is not None, wait)
        return match()

    def next_counters(self, diagnostics, timeout=5.0):
        """
        Return the node's input counters from a message published from now.

        ``diagnostics`` is the list a ``collect(DiagnosticArray, ...)``
        fills.  Messages waiting in the reader's queue (the probe did not
        spin for a while) were published before this call: their stamps
        say so, and they are passed over.  A node on a simulated clock
        (stamps an hour or more before this clock's) gets the next message
        taken, whatever its stamp.
        """
        since = self.node.get_clock().now().nanoseconds
        count = len(diagnostics)

        def fresh():
            for msg in diagnostics[count:]:
                t = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
                if t >= since or since - t > 3600 * 10**9:
                    return msg
            return None
        assert self.spin_until(lambda: fresh() is not None, timeout)
        return {kv.key: int(kv.value) for kv in fresh().status[0].values}
