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
Measure latency: joint state in, torques out, through the real ROS graph.

    python -m newton_euler_tools.latency_bench [--duration S] [--quick]
                                             [--json PATH] [--rate HZ]

Five phases, each in a ROS domain of its own (``--domain`` and the next
four ids; default ROS_DOMAIN_ID when set, else 64), on loopback
discovery:

1. **inverse_dynamics_node** (the node under test) is started as its own
   process (``inverse_dynamics_node --ros-args --params-file
   config/params/puma560.yaml``).  Once its ``joint_states`` subscription
   is matched and it has answered one warm-up message (it loads or compiles
   its numba kernels at start; up to ``--startup-timeout`` s), a driver in
   this process publishes ``sensor_msgs/JointState`` for the 6 Puma joints
   (a seeded random walk of positions and velocities within the joint
   limits, with efforts: the Puma model's own torques for that motion)
   at ``--rate`` Hz for ``--duration`` s, with header.stamp = the
   send time (this process's ``time.time_ns()``, the clock ROS's system
   time uses).  Every ``/inverse_dynamics_node/torques`` message is matched
   to its input by stamp: latency = receive time - header.stamp; dropped =
   sent - received after a short drain.  The node spins its default
   SingleThreadedExecutor.
2. **observer on** (domain + 4): the same node with
   ``observer.enabled: true`` (a second ``--params-file``, written to
   ``build/latency_bench/observer_params.yaml``), fed the same states:
   the observer's cost in the node, side by side with phase 1.  The
   bench also takes ``~/external_wrench`` and ``~/contact``: the phase
   fails (exit 2) when fewer than half of the answered JointStates came
   with their wrench, i.e. when the observer did not run.  The efforts
   are the model's torques, so the residual stays small (only the send
   jitter against the walk's 1 ms steps) and no contact fires.
3. A second run of phase 1 with ``NEWTON_EULER_EXECUTOR=events`` (the
   EventsExecutor) shows the trade-off between the two executors: CPU
   and p99 against memory that stays bounded under a flood.
4. **echo_node** (:mod:`newton_euler_tools.echo_node`), the same
   message work with no dynamics, measured the same way: the floor.
5. **self-loop**: the bench publishes to a subscription of its own, no
   other process: what the bench's own send and receive paths cost (no
   transport: FastDDS delivers within a process directly).

The child is stopped with SIGINT (killed after a timeout) and its exit code
reported; no process is left behind (try/finally, and the children get
SIGKILL from the kernel if this process dies first).

How the bench keeps out of its own way
--------------------------------------
- Pacing: absolute ``time.perf_counter`` deadlines; ``time.sleep`` (which
  releases the GIL) until ``--spin-us`` before the deadline, then a short
  busy spin.  The timer slack of the sending thread is set to 1 ns
  (``prctl(PR_SET_TIMERSLACK)``, Linux) so the sleep wakes within a few us
  and the spin, which holds the GIL, stays short.  A slot missed by more
  than one period is skipped (counted), never sent in a burst.
- Receiving: a separate thread spins the executor (``spin_once`` with a
  timeout in a loop); the sender releases the GIL whenever it sleeps, and
  ``sys.setswitchinterval`` is lowered to ``--switch-us`` for the run so a
  message arriving during the spin waits at most that long for the GIL.
- The receive callback takes the message raw (serialized CDR, no Python
  message built) and appends ``(time.time_ns(), bytes)`` to a list; the
  stamp is parsed after the run.
- Executor: ``rclpy.experimental.EventsExecutor`` when it is available
  (rclpy 7.1 in Jazzy has it), else ``SingleThreadedExecutor``
  (``--bench-executor``).  Its ``spin()`` is not used: in this rclpy
  (7.1.5 wheels) it busy-polls a whole core, stops dispatching callbacks
  and does not return on shutdown; a ``spin_once(timeout_sec)`` loop
  does none of that.
- The bench's garbage collector is off while timing (``--keep-gc``).

``--also-command`` also subscribes ``~/torque_command`` (counted, not
timed), as a controller would: a matched reader makes that publish, which
the node does before ``~/torques``, dearer.

Targets (PASS/MISS, from this run's numbers): node p99 < 1 ms; nothing
dropped; overhead over the echo floor, (node - echo) / echo, < 50% on p50
and on p99; with the observer on, p99 < 1 ms and nothing dropped.  The
exit code is 0 when the run completed (1 with ``--strict`` and a MISS),
2 when it could not run.
"""
import argparse
import array
import gc
import json
import os
import platform
import shlex
import signal
import struct
import sys
import threading
import time

import numpy as np

from .processes import ChildProcess, first_domain, prctl as _prctl

PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
REPO_DIR = os.path.dirname(os.path.dirname(PACKAGE_DIR))

NODE_NAME = 'inverse_dynamics_node'
NODE_TOPIC = '/inverse_dynamics_node/torques'
WRENCH_TOPIC = '/inverse_dynamics_node/external_wrench'
CONTACT_TOPIC = '/inverse_dynamics_node/contact'
ECHO_TOPIC = '/echo_node/torques'
LOOP_TOPIC = '/latency_bench/loop'
INPUT_TOPIC = '/joint_states'
JOINTS = ('joint1', 'joint2', 'joint3', 'joint4', 'joint5', 'joint6')
# used when the robot file cannot be read: the puma560's limits (rad)
FALLBACK_LIMITS = ((-2.7925, 2.7925), (-0.7854, 3.9270), (-3.9270, 0.7854),
                   (-1.9199, 2.9671), (-1.7453, 1.7453), (-4.6426, 4.6426))

TARGET_P99_US = 1000.0
WALL_STIFFNESS = 400.0          # 1/s^2: the walk's turn-back spring
TARGET_OVERHEAD = 0.50          # (node - echo) / echo, on p50 and on p99
DEFAULT_DOMAIN = 64             # phases use DOMAIN .. DOMAIN + 4
DOMAINS = 5
# the observer phase fails when fewer answered JointStates than this share
# came with their ~/external_wrench (the observer did not run)
MIN_OBSERVED = 0.5
OBSERVER_PARAMS = ('# written by newton_euler_tools.latency_bench: the observer '
                   'phase\ninverse_dynamics_node:\n  ros__parameters:\n'
                   '    observer:\n      enabled: true\n')

_CDR_LE = b'\x00\x01'
_STAMP = struct.Struct('<iI')   # header.stamp.sec, .nanosec after the
_STAMP_BE = struct.Struct('>iI')  # 4-byte CDR encapsulation header


class BenchError(Exception):
    """The benchmark could not run (node did not start, ...)."""


def log(line=''):
    print(line, flush=True)


# --------------------------------------------------------------------------
# environment and child processes


def _default_dirs():
    """Return build/ of the repository when run from it, else of the cwd."""
    root = REPO_DIR if os.path.isfile(os.path.join(REPO_DIR, 'Makefile')) \
        else os.getcwd()
    return os.path.join(root, 'build')


def prepare_environment(build_dir):
    """
    Set this process's environment before rclpy starts.

    Loopback discovery; logs under build/ unless set (the numba cache
    is where the package keeps it).
    """
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    os.environ.setdefault('ROS_LOG_DIR', os.path.join(build_dir, 'ros_log'))
    os.makedirs(os.environ['ROS_LOG_DIR'], exist_ok=True)


def _params_file():
    path = os.path.join(REPO_DIR, 'newton_euler_ros', 'config', 'params',
                        'puma560.yaml')
    if os.path.isfile(path):
        return os.path.normpath(path)
    from ament_index_python.packages import get_package_share_directory
    return os.path.join(get_package_share_directory('newton_euler_ros'),
                        'config', 'params', 'puma560.yaml')


def node_command():
    """Return the node's console script beside this interpreter, else -m."""
    script = os.path.join(os.path.dirname(sys.executable), NODE_NAME)
    cmd = ([script] if os.access(script, os.X_OK) else
           [sys.executable, '-m',
            'newton_euler_ros.nodes.inverse_dynamics_node'])
    return cmd + ['--ros-args', '--params-file', _params_file()]


def echo_command():
    return [sys.executable, '-m', 'newton_euler_tools.echo_node']


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


# --------------------------------------------------------------------------
# the bench's ROS side


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


def raw_stamp_ns(raw):
    """Return header.stamp of a serialized JointState, in ns."""
    st = _STAMP if raw[:2] == _CDR_LE else _STAMP_BE
    sec, nsec = st.unpack_from(raw, 4)
    return sec * 1_000_000_000 + nsec


# --------------------------------------------------------------------------
# input: a random walk within the joint limits


def puma_model():
    """Return the bundled puma560 model (None if it cannot be read)."""
    try:
        import warnings
        from newton_euler_ros.core import load_robot
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            model = load_robot('puma560')
        return model if model.n == len(JOINTS) else None
    except Exception:
        return None


def joint_limits(model=None):
    if model is not None:
        return tuple((lim['lower'], lim['upper']) for lim in model.limits)
    return FALLBACK_LIMITS


class Walk:
    """The joint states of a phase: positions, velocities, efforts."""

    def __init__(self, positions, velocities, efforts):
        self.positions = positions
        self.velocities = velocities
        self.efforts = efforts

    def __len__(self):
        return len(self.positions)


def random_walk(n, rate, seed, limits, model=None):
    """
    Return a :class:`Walk` of n states 1/rate s apart, as array('d').

    The accelerations are a random walk (smooth, bounded motion),
    velocities are capped at 2 rad/s, and a joint beyond 90% of its
    range is turned back by a stiff spring (velocities stay continuous;
    it stays within its limits).  The efforts are ``model``'s own
    torques for the motion, tau(q, qd, qdd) with qdd the acceleration
    the walk integrated: what the drives of that arm would report, so a
    momentum observer on the same model sees no external torque (empty
    without a model).
    """
    rng = np.random.default_rng(seed)
    lo = np.array([a for a, _ in limits])
    hi = np.array([b for _, b in limits])
    mid, half = (lo + hi) / 2, 0.9 * (hi - lo) / 2
    lo, hi = mid - half, mid + half
    dt = 1.0 / rate
    q = mid + rng.uniform(-0.5, 0.5, 6) * half
    qd = rng.uniform(-0.5, 0.5, 6)
    qdd = np.zeros(6)
    pos = np.empty((n, 6))
    vel = np.empty((n, 6))
    acc = np.empty((n, 6))
    for k in range(n):
        qdd = 0.995 * qdd + rng.normal(0.0, 0.5, 6)
        # the wall: zero at 90% of the range, so no jump in acceleration
        wall = WALL_STIFFNESS * (np.minimum(hi - q, 0.0)
                                 + np.maximum(lo - q, 0.0))
        new_qd = np.clip(qd + (qdd + wall) * dt, -2.0, 2.0)
        acc[k] = (new_qd - qd) / dt
        qd = new_qd
        q = q + qd * dt
        pos[k], vel[k] = q, qd
    if model is not None:
        from newton_euler_ros.core import inverse_dynamics_batch
        eff = inverse_dynamics_batch(model, pos, vel, acc)
        efforts = [array.array('d', e) for e in eff]
    else:
        efforts = [array.array('d')] * n
    return Walk([array.array('d', p) for p in pos],
                [array.array('d', v) for v in vel], efforts)


# --------------------------------------------------------------------------
# one phase


def _new_msg():
    from sensor_msgs.msg import JointState
    msg = JointState()
    msg.name = list(JOINTS)
    return msg


class _StampClock:
    """Strictly increasing time.time_ns() stamps (the matching key)."""

    def __init__(self):
        self.last = 0

    def __call__(self):
        t = time.time_ns()
        if t <= self.last:
            t = self.last + 1
        self.last = t
        return t


def _set_stamp(msg, t):
    msg.header.stamp.sec = t // 1_000_000_000
    msg.header.stamp.nanosec = t % 1_000_000_000


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


def _pct(x, q):
    return float(np.percentile(x, q)) if len(x) else float('nan')


def summarize(send, received, rate):
    """Return the latency statistics of one phase (matched by stamp)."""
    sent = set(send['stamps'])
    seen = set()
    lat = []
    first = last = None
    duplicates = unknown = 0
    for recv_ns, raw in received:
        s = raw_stamp_ns(raw)
        if s not in sent:
            unknown += 1                  # warm-up / pre-roll answers
        elif s in seen:
            duplicates += 1
        else:
            seen.add(s)
            lat.append(recv_ns - s)
            first = recv_ns if first is None else min(first, recv_ns)
            last = recv_ns if last is None else max(last, recv_ns)
    lat_us = np.array(lat, dtype=np.float64) / 1e3
    n_sent = len(send['stamps'])
    pub_us = np.frombuffer(send['publish_ns'], dtype=np.int64) / 1e3
    late_us = np.frombuffer(send['late_ns'], dtype=np.int64) / 1e3
    out = {
        'sent': n_sent, 'received': len(lat), 'dropped': n_sent - len(lat),
        'duplicates': duplicates, 'skipped_slots': send['skipped'],
        'send_rate_hz': ((n_sent - 1) / send['span_s']
                         if send['span_s'] > 0 else float('nan')),
        'target_rate_hz': rate,
        # answers per second, from the first answer's arrival to the last
        'answer_rate_hz': ((len(lat) - 1) / ((last - first) * 1e-9)
                           if len(lat) > 1 and last > first
                           else float('nan')),
        'latency_us': {
            'p50': _pct(lat_us, 50), 'p90': _pct(lat_us, 90),
            'p99': _pct(lat_us, 99), 'p99.9': _pct(lat_us, 99.9),
            'max': float(lat_us.max()) if len(lat_us) else float('nan'),
            'min': float(lat_us.min()) if len(lat_us) else float('nan'),
            'mean': float(lat_us.mean()) if len(lat_us) else float('nan'),
            'over_1ms': int((lat_us >= 1000.0).sum()),
        },
        'publish_call_us': {'p50': _pct(pub_us, 50), 'p99': _pct(pub_us, 99),
                            'max': float(pub_us.max()) if len(pub_us)
                            else float('nan')},
        'send_lateness_us': {'p50': _pct(late_us, 50),
                             'p99': _pct(late_us, 99),
                             'max': float(late_us.max()) if len(late_us)
                             else float('nan')},
    }
    return out, lat_us


def run_phase(key, label, domain, cmd, sub_topic, args, logs_dir, env=None):
    """Start ``cmd`` (None: self-loop) with ``env`` added, time it, stop it."""
    log(f'\n--- {label}: domain {domain}'
        + ''.join(f', {k}={v}' for k, v in (env or {}).items())
        + (f', {" ".join(shlex.quote(c) for c in cmd)}' if cmd else ''))
    result = {'label': label, 'domain': domain,
              'command': cmd, 'load_average_start': _loadavg()}
    n_slots = int(round(args.duration * args.rate))
    walk = random_walk(n_slots, args.rate, args.seed, args.limits,
                       args.model)
    extra = ()
    if key == 'observer':
        from geometry_msgs.msg import WrenchStamped
        from std_msgs.msg import Bool
        extra = ((WRENCH_TOPIC, WrenchStamped), (CONTACT_TOPIC, Bool))
    clock = _StampClock()
    child = None
    bench = None
    try:
        if cmd:
            child = ChildProcess(cmd, domain,
                                 os.path.join(logs_dir, f'{key}.log'),
                                 env=env, die_with_parent=True)
            result['log'] = child.log_path
        command_topic = (sub_topic.rsplit('/', 1)[0] + '/torque_command'
                         if cmd and args.also_command else None)
        bench = BenchSide(domain, LOOP_TOPIC if cmd is None else
                          INPUT_TOPIC, sub_topic, args.bench_executor,
                          command_topic, extra=extra)
        result['bench_executor'] = bench.executor_name
        waited, answer, sent = wait_ready(
            bench, child, args.startup_timeout, clock, walk)
        problems = check_answer(answer, sent, key)
        result['startup_s'] = waited
        result['answer_problems'] = problems
        log(f'ready after {waited:.2f} s (matched, warm-up answered'
            + (f'; PROBLEMS: {"; ".join(problems)}' if problems else
               ', answer well-formed') + ')')
        foreign = (bench.pub.get_subscription_count() > 1
                   or bench.sub.get_publisher_count() > 1)
        result['foreign_endpoints'] = foreign
        if foreign:
            log('WARNING: other participants in this domain also use these '
                'topics; choose another --domain')
        if args.preroll > 0:
            paced_send(bench, int(args.preroll * args.rate), args.rate,
                       clock, walk, args.spin_us * 1e-6, record=False)
        commands0 = len(bench.commands)
        extra0 = {t: len(box) for t, box in bench.extra.items()}
        cpu0 = _cpu_seconds(child.pid) if child else None
        own0 = time.process_time()
        t0 = time.monotonic()
        old_switch = sys.getswitchinterval()
        sys.setswitchinterval(args.switch_us * 1e-6)
        gc_was_enabled = gc.isenabled()
        if not args.keep_gc:
            gc.disable()   # no collector pauses in the bench while timing
        try:
            send = paced_send(bench, n_slots, args.rate, clock, walk,
                              args.spin_us * 1e-6)
            wall = time.monotonic() - t0
            cpu1 = _cpu_seconds(child.pid) if child else None
            own1 = time.process_time()
            # drain: until every answer is in, or --drain s
            end = time.monotonic() + args.drain
            want = set(send['stamps'])
            wrenches = bench.extra.get(WRENCH_TOPIC)
            while time.monotonic() < end:
                got = sum(1 for _, raw in bench.received
                          if raw_stamp_ns(raw) in want)
                if wrenches is not None:    # and every wrench
                    got = min(got, sum(1 for _, raw in wrenches
                                       if raw_stamp_ns(raw) in want))
                if got >= len(want):
                    break
                time.sleep(0.02)
            received = list(bench.received)
            commands = len(bench.commands) - commands0
            extras = {t: list(box[extra0[t]:])
                      for t, box in bench.extra.items()}
        finally:
            sys.setswitchinterval(old_switch)
            if gc_was_enabled:
                gc.enable()
        if bench.spin_errors:
            raise BenchError(f'receive thread failed: {bench.spin_errors}')
    finally:
        try:
            if bench is not None:
                bench.close()
        finally:
            if child is not None:
                child.stop(args.stop_timeout)
                log(f'stopped {label}: exit code {child.exit_code} '
                    f'({child.stop_how}); log {child.log_path}')
    stats, lat_us = summarize(send, received, args.rate)
    result.update(stats)
    if command_topic:
        # not matched by stamp (Float64MultiArray has none): a count of
        # what arrived from the timed start to the end of the drain
        result['torque_command_received'] = commands
    if child is not None:
        result['exit_code'] = child.exit_code
        result['stopped_by'] = child.stop_how
        result['node_cpu_percent'] = (100.0 * (cpu1 - cpu0) / wall
                                      if cpu0 is not None and cpu1 is not None
                                      else None)
    result['bench_cpu_percent'] = 100.0 * (own1 - own0) / wall
    result['load_average_end'] = _loadavg()
    L = stats['latency_us']
    log(f'latency us: p50 {L["p50"]:.0f}  p99 {L["p99"]:.0f}  p99.9 '
        f'{L["p99.9"]:.0f}  max {L["max"]:.0f};  sent {stats["sent"]}  '
        f'received {stats["received"]}  dropped {stats["dropped"]}')
    if key == 'observer':
        result['observer'] = observer_check(send, received, extras)
    return result, lat_us


def observer_check(send, received, extras):
    """
    Return what the node's observer published in the timed run, or raise.

    Every answered JointState should come with its ``~/external_wrench``
    (stamped with the JointState's stamp); fewer than ``MIN_OBSERVED`` of
    them means the observer did not run and the phase measured the node
    without it: BenchError.  Also the wrench's latency (receive time -
    stamp), its largest force and moment, and whether ``~/contact`` was
    ever true (the efforts are the model's own torques: it should not).
    """
    from geometry_msgs.msg import WrenchStamped
    from rclpy.serialization import deserialize_message
    sent = set(send['stamps'])
    answered = {raw_stamp_ns(raw) for _, raw in received} & sent
    lat, seen, f_max, m_max, finite = [], set(), 0.0, 0.0, True
    for recv_ns, raw in extras.get(WRENCH_TOPIC, []):
        s = raw_stamp_ns(raw)
        if s not in sent or s in seen:
            continue
        seen.add(s)
        lat.append((recv_ns - s) / 1e3)
        w = deserialize_message(raw, WrenchStamped).wrench
        f = (w.force.x, w.force.y, w.force.z)
        m = (w.torque.x, w.torque.y, w.torque.z)
        finite &= bool(np.isfinite(f + m).all())
        f_max = max(f_max, float(np.linalg.norm(f)))
        m_max = max(m_max, float(np.linalg.norm(m)))
    contacts = extras.get(CONTACT_TOPIC, [])
    out = {'answered': len(answered), 'wrenches': len(seen),
           'wrench_latency_us': {'p50': _pct(lat, 50), 'p99': _pct(lat, 99)},
           'max_force_n': f_max, 'max_moment_nm': m_max,
           'wrench_finite': finite,
           'contact_messages': len(contacts),
           'contact_true': sum(1 for _, raw in contacts
                               if len(raw) > 4 and raw[4] != 0)}
    log(f'observer: {out["wrenches"]} ~/external_wrench for '
        f'{out["answered"]} answered JointStates (latency p50 '
        f'{out["wrench_latency_us"]["p50"]:.0f} / p99 '
        f'{out["wrench_latency_us"]["p99"]:.0f} us); largest |f| '
        f'{f_max:.2f} N, |m| {m_max:.2f} N m; ~/contact true in '
        f'{out["contact_true"]} of {out["contact_messages"]} messages')
    if not answered or len(seen) < MIN_OBSERVED * len(answered):
        raise BenchError(
            f'observer phase: {len(seen)} ~/external_wrench for '
            f'{len(answered)} answered JointStates: the observer did not '
            f'run (see the node log), so this phase measured nothing')
    if not finite:
        raise BenchError('observer phase: a non-finite ~/external_wrench')
    return out


# --------------------------------------------------------------------------
# report


def _loadavg():
    try:
        return list(os.getloadavg())
    except (AttributeError, OSError):
        return None


def _fmt_load(la):
    return ' '.join(f'{x:.2f}' for x in la) if la else 'n/a'


def verdicts(node, echo):
    nl, el = node['latency_us'], echo['latency_us']
    over50 = (nl['p50'] - el['p50']) / el['p50']
    over99 = (nl['p99'] - el['p99']) / el['p99']
    return {
        'ratio_p50': nl['p50'] / el['p50'],
        'ratio_p99': nl['p99'] / el['p99'],
        'overhead_p50': over50, 'overhead_p99': over99,
        'targets': {
            'p99 < 1 ms': {'value': nl['p99'], 'unit': 'us',
                           'pass': bool(nl['p99'] < TARGET_P99_US)},
            'nothing dropped': {'value': node['dropped'], 'unit': 'messages',
                                'pass': node['dropped'] == 0},
            'overhead over echo floor < 50% (p50)': {
                'value': 100 * over50, 'unit': '%',
                'pass': bool(over50 < TARGET_OVERHEAD)},
            'overhead over echo floor < 50% (p99)': {
                'value': 100 * over99, 'unit': '%',
                'pass': bool(over99 < TARGET_OVERHEAD)},
        },
    }


def print_table(phases):
    head = (f'{"":36s}{"p50":>7s}{"p99":>8s}{"p99.9":>8s}{"max":>8s}'
            f'{"sent":>8s}{"recv":>8s}{"drop":>6s}{"sent Hz":>9s}'
            f'{"ans Hz":>8s}{"cpu%":>6s}')
    log('latency = receive time - header.stamp, in us')
    log(head)
    log('-' * len(head))
    for r in phases:
        L = r['latency_us']
        cpu = r.get('node_cpu_percent')
        log(f'{r["label"]:36s}{L["p50"]:7.0f}{L["p99"]:8.0f}'
            f'{L["p99.9"]:8.0f}{L["max"]:8.0f}{r["sent"]:8d}'
            f'{r["received"]:8d}{r["dropped"]:6d}{r["send_rate_hz"]:9.1f}'
            f'{r["answer_rate_hz"]:8.1f}'
            + (f'{cpu:6.0f}' if cpu is not None else f'{"-":>6s}'))
    log('(sent Hz / ans Hz = joint states sent / answers received per '
        'second; cpu% = the node process, % of one core, during the timed '
        'run)')
    for r in phases:
        P, S = r['publish_call_us'], r['send_lateness_us']
        log(f'  {r["label"]}: publish() call p50 {P["p50"]:.1f} / p99 '
            f'{P["p99"]:.1f} us; send lateness p50 {S["p50"]:.1f} / p99 '
            f'{S["p99"]:.1f} / max {S["max"]:.0f} us; skipped slots '
            f'{r["skipped_slots"]}; bench cpu {r["bench_cpu_percent"]:.0f}%'
            + (f'; duplicates {r["duplicates"]}' if r['duplicates'] else '')
            + (f'; torque_command received {r["torque_command_received"]}'
               if 'torque_command_received' in r else ''))


def parse_args(argv=None):
    """Return the command line's options (``--quick`` applied)."""
    parser = argparse.ArgumentParser(
        prog='python -m newton_euler_tools.latency_bench',
        description='Latency of inverse_dynamics_node (joint state in, '
                    'torques out) at 1 kHz, against an echo node floor.')
    parser.add_argument('--duration', type=float, default=10.0,
                        help='seconds of timed publishing per phase '
                             '(default 10)')
    parser.add_argument('--quick', action='store_true',
                        help='2 s per phase (smoke test)')
    parser.add_argument('--json', metavar='PATH',
                        help='write every figure to this JSON file')
    parser.add_argument('--rate', type=float, default=1000.0,
                        help='publishing rate, Hz (default 1000)')
    parser.add_argument('--domain', type=int, default=None,
                        help='ROS domain of the first phase; the others '
                             f'use the next {DOMAINS - 1} ids (default '
                             'ROS_DOMAIN_ID when set, else '
                             f'{DEFAULT_DOMAIN})')
    parser.add_argument('--seed', type=int, default=1,
                        help='seed of the random walk (default 1)')
    parser.add_argument('--startup-timeout', type=float, default=60.0,
                        help='seconds allowed for a node to start and answer '
                             'a warm-up message (default 60)')
    parser.add_argument('--drain', type=float, default=1.0,
                        help='seconds to wait for late answers (default 1)')
    parser.add_argument('--preroll', type=float, default=0.0,
                        help='untimed seconds at the rate before timing '
                             '(default 0)')
    parser.add_argument('--stop-timeout', type=float, default=10.0,
                        help='seconds from SIGINT to SIGKILL (default 10)')
    parser.add_argument('--bench-executor', choices=('events', 'single'),
                        default='events',
                        help="the bench's receive executor (default events: "
                             'rclpy.experimental.EventsExecutor)')
    parser.add_argument('--spin-us', type=float, default=50.0,
                        help='busy-wait the last N us before each deadline '
                             '(default 50)')
    parser.add_argument('--switch-us', type=float, default=50.0,
                        help='sys.setswitchinterval during the run, us '
                             '(default 50; Python default 5000)')
    parser.add_argument('--keep-gc', action='store_true',
                        help="leave the bench's garbage collector on while "
                             'timing (default: off while timing)')
    parser.add_argument('--no-timer-slack', action='store_true',
                        help="keep the sending thread's default timer slack")
    parser.add_argument('--skip', action='append', default=[],
                        choices=('node', 'observer', 'events', 'echo',
                                 'loop'),
                        help='leave a phase out (repeatable)')
    parser.add_argument('--also-command', action='store_true',
                        help='also subscribe ~/torque_command (counted, not '
                             'timed), as a controller would')
    parser.add_argument('--node-cmd', metavar='CMD',
                        help='command of the node under test (shell words; '
                             'default: the inverse_dynamics_node console '
                             'script with the puma560 params)')
    parser.add_argument('--echo-cmd', metavar='CMD',
                        help='command of the floor node (default: python -m '
                             'newton_euler_tools.echo_node)')
    parser.add_argument('--strict', action='store_true',
                        help='exit code 1 when a target is missed')
    args = parser.parse_args(argv)
    if args.quick:
        args.duration = 2.0
    if args.duration <= 0 or args.rate <= 0:
        parser.error('--duration and --rate must be > 0')
    if args.domain is None:
        try:
            args.domain = first_domain(DEFAULT_DOMAIN, DOMAINS)
        except ValueError as exc:
            parser.error(str(exc))
    if not 0 <= args.domain <= 232 - (DOMAINS - 1):
        parser.error(f'--domain must be in 0..{232 - (DOMAINS - 1)}')
    return args


def print_header(args, rclpy_version, slack, load_start):
    """Log the set-up: rate, versions, machine load, the bench's timing."""
    log(f'newton_euler_ros latency benchmark: {args.rate:.0f} Hz x '
        f'{args.duration:g} s per phase; python '
        f'{platform.python_version()}, rclpy {rclpy_version}, '
        f'{os.environ.get("RMW_IMPLEMENTATION", "rmw default (FastDDS)")}')
    log(f'machine: {os.cpu_count()} cpus; load average at start '
        f'{_fmt_load(load_start)}'
        + ('  (WARNING: other work is running; figures will be noisy)'
           if load_start and load_start[0] > 0.5 * (os.cpu_count() or 1)
           else ''))
    log(f'bench: sender = main thread, absolute perf_counter deadlines, '
        f'sleep then spin the last {args.spin_us:g} us, timer slack '
        f'{"1 ns" if slack else "default"}; receiver = its own thread '
        f'spinning the {args.bench_executor} executor; switch interval '
        f'{args.switch_us:g} us during timing')


def phase_plan(args, observer_params):
    """(key, label, domain, command, topic, env) of each phase to run."""
    node_cmd = (shlex.split(args.node_cmd) if args.node_cmd
                else node_command())
    # the observer on: the same command, one more parameters file
    observer_cmd = node_cmd + ['--ros-args', '--params-file',
                               observer_params]
    return [('node', f'{NODE_NAME}', args.domain, node_cmd, NODE_TOPIC, None),
            ('observer', f'{NODE_NAME}, observer on', args.domain + 4,
             observer_cmd, NODE_TOPIC, None),
            ('events', f'{NODE_NAME}, events', args.domain + 3, node_cmd,
             NODE_TOPIC, {'NEWTON_EULER_EXECUTOR': 'events'}),
            ('echo', 'echo_node (floor)', args.domain + 1,
             shlex.split(args.echo_cmd) if args.echo_cmd else echo_command(),
             ECHO_TOPIC, None),
            ('loop', 'bench self-loop', args.domain + 2, None, LOOP_TOPIC,
             None)]


def observer_verdicts(off, on):
    """Targets of the observer phase (and its figures beside ``off``)."""
    L = on['latency_us']
    out = {'targets': {
        'observer on: p99 < 1 ms': {'value': L['p99'], 'unit': 'us',
                                    'pass': bool(L['p99'] < TARGET_P99_US)},
        'observer on: nothing dropped': {'value': on['dropped'],
                                         'unit': 'messages',
                                         'pass': on['dropped'] == 0}}}
    if off is not None:
        out['added_p50_us'] = L['p50'] - off['latency_us']['p50']
        out['added_p99_us'] = L['p99'] - off['latency_us']['p99']
    return out


def _side_by_side(off, on):
    """Log the observer off / on figures on one line each."""
    def pair(key):
        return (f'{off["latency_us"][key]:.0f} / '
                f'{on["latency_us"][key]:.0f}')
    cpu = [r.get('node_cpu_percent') for r in (off, on)]
    log(f'\nobserver off / on ({NODE_NAME}, SingleThreadedExecutor): p50 '
        f'{pair("p50")} us, p99 {pair("p99")} us, max {pair("max")} us; '
        f'answered {off["answer_rate_hz"]:.1f} / {on["answer_rate_hz"]:.1f}'
        f' Hz of {on["target_rate_hz"]:.0f}; dropped {off["dropped"]} / '
        f'{on["dropped"]}'
        + (f'; node cpu {cpu[0]:.0f}% / {cpu[1]:.0f}%'
           if None not in cpu else ''))


def report(phases, by_key):
    """Log the table, the node/echo verdicts; return (summary, missed)."""
    print_table(phases)
    summary = None
    missed = False
    targets = {}
    if 'node' in by_key and 'echo' in by_key:
        summary = verdicts(by_key['node'], by_key['echo'])
        targets.update(summary['targets'])
        log(f'\nnode / echo: p50 {summary["ratio_p50"]:.2f}x, p99 '
            f'{summary["ratio_p99"]:.2f}x;  overhead over the echo floor: '
            f'p50 {100 * summary["overhead_p50"]:+.0f}%, p99 '
            f'{100 * summary["overhead_p99"]:+.0f}%')
        if 'loop' in by_key:
            lp, ep = by_key['loop']['latency_us'], by_key['echo']['latency_us']
            log(f'bench itself (self-loop, no transport): p50 '
                f'{lp["p50"]:.0f} us = {100 * lp["p50"] / ep["p50"]:.0f}% of '
                f'the echo floor p50 ({ep["p50"]:.0f} us), p99 '
                f'{lp["p99"]:.0f} us')
    if 'observer' in by_key:
        on = by_key['observer']
        ov = observer_verdicts(by_key.get('node'), on)
        summary = dict(summary or {}, observer=ov)
        targets.update(ov['targets'])
        if 'node' in by_key:
            _side_by_side(by_key['node'], on)
        o = on['observer']
        log(f'the observer ran: {o["wrenches"]} ~/external_wrench for '
            f'{o["answered"]} answered JointStates; largest |f| '
            f'{o["max_force_n"]:.2f} N, |m| {o["max_moment_nm"]:.2f} N m; '
            f'~/contact true in {o["contact_true"]} of '
            f'{o["contact_messages"]} messages')
    if targets:
        summary['targets'] = targets
        log('\ntargets:')
        for name, t in targets.items():
            value = ('no answers' if t['value'] != t['value'] else
                     f'{t["value"]:.0f} {t["unit"]}' if t['unit'] != '%'
                     else f'{t["value"]:+.0f}%')
            log(f'  {name:40s} {"PASS" if t["pass"] else "MISS"}  ({value})')
            missed |= not t['pass']
    if 'node' in by_key and 'events' in by_key:
        ev, nd = by_key['events'], by_key['node']
        log(f'executor trade-off: the default SingleThreadedExecutor p50 '
            f'{nd["latency_us"]["p50"]:.0f} / p99 '
            f'{nd["latency_us"]["p99"]:.0f} us at '
            f'{nd.get("node_cpu_percent", float("nan")):.0f}% CPU; '
            f'NEWTON_EULER_EXECUTOR=events p50 '
            f'{ev["latency_us"]["p50"]:.0f} / p99 '
            f'{ev["latency_us"]["p99"]:.0f} us at '
            f'{ev.get("node_cpu_percent", float("nan")):.0f}% CPU, but '
            f'memory unbounded under a flood (test_load_node.py)')
    codes = ', '.join(f'{r["label"]} {r["exit_code"]}'
                      for r in phases if 'exit_code' in r)
    if codes:
        log(f'child exit codes after SIGINT: {codes}')
    return summary, missed


def write_json(args, rclpy_version, slack, load_start, load_end, phases,
               summary):
    """Write every figure of the run to ``args.json``."""
    payload = {
        'rate_hz': args.rate, 'duration_s': args.duration,
        'seed': args.seed, 'domain': args.domain,
        'python': platform.python_version(), 'rclpy': rclpy_version,
        'cpus': os.cpu_count(), 'load_average_start': load_start,
        'load_average_end': load_end,
        'bench': {'executor': args.bench_executor,
                  'spin_us': args.spin_us, 'switch_us': args.switch_us,
                  'timer_slack_1ns': slack, 'preroll_s': args.preroll,
                  'drain_s': args.drain},
        'targets': {'p99_us': TARGET_P99_US,
                    'overhead_over_echo': TARGET_OVERHEAD},
        'phases': phases, 'summary': summary,
    }
    os.makedirs(os.path.dirname(os.path.abspath(args.json)),
                exist_ok=True)
    with open(args.json, 'w') as fh:
        json.dump(payload, fh, indent=1)
    log(f'wrote {args.json}')


def main(argv=None):
    args = parse_args(argv)
    build_dir = _default_dirs()
    prepare_environment(build_dir)
    logs_dir = os.path.join(build_dir, 'latency_bench')
    # SIGTERM: unwind through the finally blocks that stop the children
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))

    from importlib import metadata
    try:
        rclpy_version = metadata.version('rclpy')
    except metadata.PackageNotFoundError:
        rclpy_version = '?'
    args.model = puma_model()
    args.limits = joint_limits(args.model)
    os.makedirs(logs_dir, exist_ok=True)
    observer_params = os.path.join(logs_dir, 'observer_params.yaml')
    with open(observer_params, 'w') as fh:
        fh.write(OBSERVER_PARAMS)
    slack = False if args.no_timer_slack else set_timer_slack(1)
    load_start = _loadavg()
    print_header(args, rclpy_version, slack, load_start)

    phases = []
    by_key = {}
    t_start = time.monotonic()
    try:
        for key, label, domain, cmd, topic, env in phase_plan(
                args, observer_params):
            if key in args.skip:
                continue
            result, _ = run_phase(key, label, domain, cmd, topic, args,
                                  logs_dir, env)
            result['key'] = key
            phases.append(result)
            by_key[key] = result
    except BenchError as exc:
        print(f'latency_bench: {exc}', file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print('latency_bench: interrupted', file=sys.stderr)
        return 130

    load_end = _loadavg()
    log('\n' + '=' * 78)
    log('RESULTS')
    log('=' * 78)
    summary, missed = report(phases, by_key)
    log(f'load average at end: {_fmt_load(load_end)} (includes this '
        f'benchmark); took {time.monotonic() - t_start:.0f} s')
    if args.json:
        write_json(args, rclpy_version, slack, load_start, load_end, phases,
                   summary)
    return 1 if (args.strict and missed) else 0


if __name__ == '__main__':
    sys.exit(main())
