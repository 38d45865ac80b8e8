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
The latency bench's own side of the graph: publish, pace, receive.

``BenchSide`` holds the bench's node, publisher and raw subscriptions
and spins them in a thread of their own; ``wait_ready`` waits for a
phase's node to answer; ``paced_send`` publishes at the rate on absolute
deadlines (see ``latency_bench``'s docstring for how it keeps out of its
own way).
"""
import array
import os
import sys
import threading
import time

import numpy as np

from .latency_report import BenchError
from .latency_traffic import _new_msg, _set_stamp, JOINTS, raw_stamp_ns
from .processes import prctl as _prctl


_PR_SET_TIMERSLACK = 29


def set_timer_slack(ns):
    """Set the timer slack of the calling thread (Linux); True when set."""
    if _prctl is None or not sys.platform.startswith('linux'):
        return False
    return _prctl(_PR_SET_TIMERSLACK, ns, 0, 0, 0) == 0


def _cpu_seconds(pid):
    """Return user + system CPU seconds of a process (None if unknown)."""
    try:
        with open(f'/proc/{pid}/stat') as fh:
            fields = fh.read().rsplit(')', 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')
    except (OSError, ValueError, IndexError):
        return None


class BenchSide:
    """
    The bench's node, in a context of its own.

    One publisher of joint states, one raw subscription (and optionally a
    second one, counted only, of the node's ~/torque_command), an executor
    spun by a thread of its own.
    """

    def __init__(self, domain, pub_topic, sub_topic, executor_kind,
                 command_topic=None, name='latency_bench', extra=()):
        import rclpy
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from rclpy.signals import SignalHandlerOptions
        from sensor_msgs.msg import JointState
        from std_msgs.msg import Float64MultiArray
        self.rclpy = rclpy
        self.context = rclpy.Context()
        # no rclpy signal handlers: Ctrl-C stays a KeyboardInterrupt here,
        # so the finally blocks stop the children
        rclpy.init(context=self.context, domain_id=domain,
                   signal_handler_options=SignalHandlerOptions.NO)
        self.node = None
        self.executor = None
        self._thread = None
        try:
            self.node = rclpy.create_node(name, context=self.context)
            # the node's QoS (reliable, depth 10) for the input, as a
            # driver would publish; a deep history on our side so that a
            # late receive thread here cannot lose messages and make the
            # node look bad
            self.pub = self.node.create_publisher(
                JointState, pub_topic,
                QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE))
            self.received = []
            self.sub = self.node.create_subscription(
                JointState, sub_topic, _recorder(self.received),
                QoSProfile(depth=1000,
                           reliability=ReliabilityPolicy.RELIABLE),
                raw=True)
            self.commands = []
            if command_topic:
                self.node.create_subscription(
                    Float64MultiArray, command_topic,
                    _recorder(self.commands),
                    QoSProfile(depth=1000,
                               reliability=ReliabilityPolicy.RELIABLE),
                    raw=True)
            # more raw subscriptions, kept like the answers: {topic: list}
            self.extra, self.extra_subs = {}, {}
            for topic, msg_type in extra:
                self.extra[topic] = []
                self.extra_subs[topic] = self.node.create_subscription(
                    msg_type, topic, _recorder(self.extra[topic]),
                    QoSProfile(depth=1000,
                               reliability=ReliabilityPolicy.RELIABLE),
                    raw=True)
            from newton_euler_ros.nodes.common import make_executor
            self.executor = make_executor(
                'events' if executor_kind == 'events' else 'single_threaded',
                self.context)
            self.executor_name = type(self.executor).__name__
            self.executor.add_node(self.node)
        except BaseException:
            self.close()
            raise
        self._stop = False
        self.spin_errors = []
        self._thread = threading.Thread(target=self._spin, daemon=True,
                                        name='latency_bench-receive')
        self._thread.start()

    def _spin(self):
        try:
            while not self._stop and self.context.ok():
                self.executor.spin_once(timeout_sec=0.05)
        except Exception as exc:   # reported by the main thread
            if not self._stop:
                self.spin_errors.append(repr(exc))

    def close(self):
        self._stop = True
        if self._thread is not None:
            self._thread.join(5.0)
        if self.executor is not None:
            self.executor.shutdown()
        if self.node is not None:
            self.node.destroy_node()
        self.rclpy.try_shutdown(context=self.context)


def _recorder(box):
    """Return the receive callback: it keeps the time and the raw bytes."""
    append = box.append
    now = time.time_ns

    def on_message(raw):
        append((now(), raw))
    return on_message


def wait_ready(bench, child, timeout, clock, walk):
    """
    Wait until matched both ways and a warm-up message is answered.

    Returns (seconds waited, the decoded answer, the message sent).
    """
    from rclpy.serialization import deserialize_message
    from sensor_msgs.msg import JointState
    t0 = time.monotonic()
    end = t0 + timeout

    def check_child():
        if child is not None and not child.alive():
            raise BenchError(f'{child.cmd[0]} exited with code '
                             f'{child.proc.returncode} during start-up:\n'
                             + child.tail())
        if bench.spin_errors:
            raise BenchError(f'receive thread failed: {bench.spin_errors}')

    while (bench.pub.get_subscription_count() < 1
           or bench.sub.get_publisher_count() < 1
           or any(sub.get_publisher_count() < 1
                  for sub in bench.extra_subs.values())):
        check_child()
        if time.monotonic() > end:
            raise BenchError(
                f'not matched after {timeout:.0f} s (subscribers of the '
                f'input: {bench.pub.get_subscription_count()}, publishers '
                f'of the output: {bench.sub.get_publisher_count()}'
                + ''.join(f', of {t}: {sub.get_publisher_count()}'
                          for t, sub in bench.extra_subs.items()) + ')'
                + (':\n' + child.tail() if child is not None else ''))
        time.sleep(0.02)
    msg = _new_msg()
    k = 0
    while True:
        check_child()
        i = k % len(walk)
        msg.position, msg.velocity, msg.effort = walk.positions[i], \
            walk.velocities[i], walk.efforts[i]
        stamp = clock()
        _set_stamp(msg, stamp)
        n = len(bench.received)
        bench.pub.publish(msg)
        k += 1
        retry = time.monotonic() + 0.1
        while time.monotonic() < retry:
            for _, raw in bench.received[n:]:
                if raw_stamp_ns(raw) == stamp:
                    return (time.monotonic() - t0,
                            deserialize_message(raw, JointState), msg)
            time.sleep(0.002)
        if time.monotonic() > end:
            raise BenchError(f'no answer to a warm-up message within '
                             f'{timeout:.0f} s'
                             + (':\n' + child.tail() if child else ''))


def check_answer(answer, sent, kind):
    """
    Return the problems with the warm-up answer (list of strings).

    ``kind`` is 'node', 'echo' (effort = position) or 'loop' (our own
    message).
    """
    problems = []
    if list(answer.name) != list(JOINTS):
        problems.append(f'names {list(answer.name)}')
    if kind == 'loop':
        return problems
    effort = list(answer.effort)
    if len(effort) != len(JOINTS) or not np.isfinite(effort).all():
        problems.append(f'effort {effort}')
    elif kind == 'echo' and effort != list(sent.position):
        problems.append('echo effort != position')
    return problems


def paced_send(bench, n_slots, rate, clock, walk, spin_s, record=True):
    """Publish at absolute perf_counter deadlines; returns the record."""
    perf = time.perf_counter
    perf_ns = time.perf_counter_ns
    sleep = time.sleep
    publish = bench.pub.publish
    positions, velocities, efforts = walk.positions, walk.velocities, \
        walk.efforts
    msg = _new_msg()
    stamp = msg.header.stamp
    period = 1.0 / rate
    stamps = array.array('q')
    pub_ns = array.array('q')
    late_ns = array.array('q')
    skipped = 0
    k = 0
    t0 = perf() + 0.01
    first = last = None
    while k < n_slots:
        deadline = t0 + k * period
        now = perf()
        if now > deadline + period:       # missed a whole slot: skip it
            missed = int((now - deadline) / period)
            skipped += min(missed, n_slots - k)
            k += missed
            continue
        wait = deadline - now
        if wait > spin_s:
            sleep(wait - spin_s)          # releases the GIL
        while perf() < deadline:          # short spin, holds the GIL
            pass
        msg.position = positions[k]
        msg.velocity = velocities[k]
        msg.effort = efforts[k]
        t = clock()
        stamp.sec = t // 1_000_000_000
        stamp.nanosec = t % 1_000_000_000
        a = perf_ns()
        publish(msg)
        b = perf_ns()
        if record:
            stamps.append(t)
            pub_ns.append(b - a)
            late_ns.append(a - int(deadline * 1e9))
        if first is None:
            first = a
        last = a
        k += 1
    span = (last - first) * 1e-9 if first is not None and last != first \
        else 0.0
    return {'stamps': stamps, 'publish_ns': pub_ns, 'late_ns': late_ns,
            'skipped': skipped, 'span_s': span}
