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
``newton-euler send`` and ``newton-euler record``: the loop on a live graph.

    newton-euler send TRAJECTORY.json [--topic T] [--start-in S] [--wait S]
                      [--no-follow] [--joint-states T] [--tolerance R]
                      [--move-to-start] [--move-speed V]
    newton-euler record BAG [--topic T] [--duration S] [--max-messages N]
                        [--storage mcap|sqlite3] [--wait S]

``send`` publishes a JointTrajectory JSON file (``excite``'s output, or
``feedforward``'s) once, as a ``trajectory_msgs/JointTrajectory``: to
inverse_dynamics_node's ``~/trajectory_in`` (efforts filled, passed on to
the controller) or straight to joint_trajectory_controller's
``~/joint_trajectory``.  It waits for a subscriber, for the message to be
acknowledged and (unless ``--no-follow``) for the trajectory to end.
Before it sends, it reads the robot's joint positions on
``/joint_states`` (``--joint-states``; the latest value of each joint,
whichever message carries it) and refuses, in one line giving each
joint's offset, unless every joint is within ``--tolerance`` of the
trajectory's first point.  With ``--move-to-start`` it first sends, the
same way, a rest-to-rest quintic from where the robot is to that point,
no joint faster than ``--move-speed``, and checks again once it has
ended.

``record`` writes ``sensor_msgs/JointState`` messages to a rosbag2 (MCAP
by default) as they arrive, raw (no decoding on the way), with the
arrival time as the recording time: what ``identify``, ``payload`` and
``observe`` read, without the ``ros2`` CLI.  Its subscription is reliable
unless a publisher on the topic is best effort.  It stops after
``--duration`` seconds of recording, ``--max-messages`` messages, or on
Ctrl-C (SIGINT), SIGTERM or SIGHUP (a closed terminal or ssh session);
the bag is complete in every case.  Its lag behind the stream is bounded
(messages it could not take in time are dropped and counted) and what
it has recorded reaches the disk four times a second, so a SIGKILL or a
power cut loses under a second: ``cli_record``.

Both need rclpy (the ROS 2 wheels of ``make setup``); every other command
of ``newton-euler`` runs without it.
"""
import math
import os
import signal
import sys
import time

from .cli_options import topic_option
from .core.text import read_text

MAX_TRAJECTORY_BYTES = 64 * 1024 * 1024
MAX_POINTS = 1_000_000
FIELDS = ('positions', 'velocities', 'accelerations', 'effort')
JOINT_STATE = 'sensor_msgs/msg/JointState'


class RosCliError(Exception):
    """A bad input: one line, exit status 2."""


class RosGraphError(RosCliError):
    """The ROS graph did not answer in time: one line, exit status 1."""


def register(subparsers):
    """Add the ``send`` and ``record`` commands to ``subparsers``."""
    snd = subparsers.add_parser(
        'send', help='publish a JointTrajectory JSON file once (to the '
                     "node's ~/trajectory_in or a controller)")
    snd.add_argument('trajectory', metavar='TRAJECTORY.json',
                     help='JointTrajectory JSON file')
    snd.add_argument('--topic', default='/inverse_dynamics_node/'
                     'trajectory_in', help='where to publish (default: '
                     '%(default)s)')
    snd.add_argument('--start-in', type=float, default=0.5, metavar='S',
                     help='stamp the trajectory to start S seconds from '
                          'now (0: a zero stamp, "start on receipt"; '
                          'default %(default)s)')
    snd.add_argument('--wait', type=float, default=10.0, metavar='S',
                     help="seconds to wait for a subscriber, the robot's "
                          'joint states and its arrival at the start '
                          '(default %(default)s)')
    snd.add_argument('--no-follow', action='store_true',
                     help='return once the message is acknowledged, not '
                          'when the trajectory ends')
    snd.add_argument('--joint-states', default='/joint_states', metavar='T',
                     help="where the robot's joint positions are read "
                          '(default: %(default)s)')
    snd.add_argument('--tolerance', type=float, default=0.02, metavar='R',
                     help='how far (rad or m) a joint may be from the '
                          "trajectory's first point (default %(default)s)")
    snd.add_argument('--move-to-start', action='store_true',
                     help="first move the arm to the trajectory's first "
                          'point, slowly, if it is not there')
    snd.add_argument('--move-speed', type=float, default=0.2, metavar='V',
                     help='top joint speed of that move, rad/s or m/s '
                          '(default %(default)s)')
    snd.set_defaults(func=cmd_send)
    rec = subparsers.add_parser(
        'record', help='record sensor_msgs/JointState to a rosbag2 (MCAP)')
    rec.add_argument('bag', metavar='BAG',
                     help='rosbag2 directory to create (must not exist)')
    topic_option(rec)
    rec.add_argument('--duration', type=float, metavar='S',
                     help='stop after S seconds from the first message')
    rec.add_argument('--max-messages', type=int, metavar='N',
                     help='stop after N messages')
    rec.add_argument('--storage', choices=('mcap', 'sqlite3'),
                     default='mcap', help='bag storage (default: '
                                          '%(default)s)')
    rec.add_argument('--wait', type=float, default=30.0, metavar='S',
                     help='seconds to wait for a publisher (default '
                          '%(default)s)')
    rec.set_defaults(func=_record)


# ---- the trajectory file -------------------------------------------------

def _finite_list(value, n, where):
    if not isinstance(value, list) or len(value) != n:
        raise RosCliError(f'{where}: must be a list of {n} numbers')
    out = []
    for x in value:
        if isinstance(x, bool) or not isinstance(x, (int, float)) \
                or not math.isfinite(x):
            raise RosCliError(f'{where}: must be finite numbers, got '
                              f'{str(x)[:40]!r}')
        out.append(float(x))
    return out


def read_trajectory(path):
    """
    Return (joint_names, points) of a JointTrajectory JSON file.

    ``points`` are dicts with ``time_from_start`` (s, strictly
    increasing) and any of positions, velocities, accelerations, effort
    (one number per joint).  Every error is one line naming the file, the
    point and the field.
    """
    import json
    text = read_text(path, MAX_TRAJECTORY_BYTES, 'trajectory JSON file')
    try:
        data = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        raise RosCliError(f'{path}: not valid JSON: '
                          f'{str(exc)[:200]}') from None
    if not isinstance(data, dict):
        raise RosCliError(f'{path}: must hold a JSON object with '
                          f'"joint_names" and "points"')
    names, points = data.get('joint_names'), data.get('points')
    if not isinstance(names, list) or not names or not all(
            isinstance(x, str) and x for x in names) \
            or len(set(names)) != len(names):
        raise RosCliError(f'{path}: joint_names: must be a list of distinct '
                          f'non-empty names')
    if not isinstance(points, list) or not points:
        raise RosCliError(f'{path}: points: must be a non-empty list')
    if len(points) > MAX_POINTS:
        raise RosCliError(f'{path}: points: {len(points)} points, at most '
                          f'{MAX_POINTS}')
    out, last = [], -math.inf
    for i, point in enumerate(points):
        where = f'{path}: points[{i}]'
        if not isinstance(point, dict):
            raise RosCliError(f'{where}: must be an object')
        t = point.get('time_from_start')
        if isinstance(t, bool) or not isinstance(t, (int, float)) \
                or not math.isfinite(t) or t < 0.0 or not t > last:
            raise RosCliError(f'{where}.time_from_start: must be a finite '
                              f'number >= 0, larger than the previous '
                              f"point's, got {str(t)[:40]!r}")
        last = t
        fields = {f: _finite_list(point[f], len(names), f'{where}.{f}')
                  for f in FIELDS if point.get(f) not in (None, [])}
        out.append(dict(fields, time_from_start=float(t)))
    return names, out


def trajectory_message(names, points, stamp_ns):
    """Return the JointTrajectory of ``points``, stamped ``stamp_ns`` (0: now)."""
    from builtin_interfaces.msg import Duration
    from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint
    msg = JointTrajectory(joint_names=list(names))
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp_ns,
                                                            10 ** 9)
    for point in points:
        sec, nanosec = divmod(int(round(point['time_from_start'] * 1e9)),
                              10 ** 9)
        msg.points.append(JointTrajectoryPoint(
            time_from_start=Duration(sec=sec, nanosec=nanosec),
            **{f: point[f] for f in FIELDS if f in point}))
    return msg


# ---- running on a graph ----------------------------------------------------

class _Ros:
    """rclpy in a context of its own, stopped by SIGINT, SIGTERM, SIGHUP."""

    def __init__(self, name):
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.signals import SignalHandlerOptions
        self.stop = []
        self._old = {}
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
            self._old[sig] = signal.signal(
                sig, lambda signum, frame: self.stop.append(signum))
        self.rclpy = rclpy
        self.context = rclpy.Context()
        rclpy.init(context=self.context,
                   signal_handler_options=SignalHandlerOptions.NO)
        self.node = rclpy.create_node(name, context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)

    def spin_until(self, predicate, timeout):
        """Spin until ``predicate()``, a stop, or ``timeout`` s (None: never)."""
        end = None if timeout is None else time.monotonic() + timeout
        while not predicate() and not self.stop:
            if end is not None and time.monotonic() >= end:
                return False
            self.executor.spin_once(timeout_sec=0.05)
        return predicate()

    def close(self):
        self.executor.shutdown()
        self.node.destroy_node()
        self.rclpy.try_shutdown(context=self.context)
        for sig, handler in self._old.items():
            signal.signal(sig, handler)


def _check_seconds(value, option, allow_zero=True):
    if not math.isfinite(value) or value < 0.0 or (
            not allow_zero and value == 0.0):
        raise RosCliError(f'{option}: must be a finite number '
                          f'{">=" if allow_zero else ">"} 0, got {value}')


class _Positions:
    """The latest position of each named joint on a JointState topic."""

    def __init__(self, names):
        self.names = list(names)
        self.latest = {}

    def __call__(self, msg):
        for name, q in zip(msg.name, msg.position):
            if name in self.names and math.isfinite(q):
                self.latest[name] = float(q)

    def complete(self):
        return all(n in self.latest for n in self.names)

    def vector(self):
        return [self.latest[n] for n in self.names]


def approach(names, here, goal, speed, rate=50.0):
    """
    Points of a rest-to-rest quintic from ``here`` to ``goal``.

    Its duration makes the fastest joint peak at ``speed`` (the quintic's
    peak speed is 1.875 times the mean), at least one second.
    """
    here, goal = (list(map(float, v)) for v in (here, goal))
    dist = max(abs(g - h) for g, h in zip(goal, here))
    total = max(1.0, 1.875 * dist / speed)
    count = max(2, int(math.ceil(total * rate)))
    points = []
    for i in range(count + 1):
        t = total * i / count
        s = t / total
        p = 10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5
        dp = (30 * s ** 2 - 60 * s ** 3 + 30 * s ** 4) / total
        ddp = (60 * s - 180 * s ** 2 + 120 * s ** 3) / total ** 2
        points.append({
            'time_from_start': t,
            'positions': [h + (g - h) * p for g, h in zip(goal, here)],
            'velocities': [(g - h) * dp for g, h in zip(goal, here)],
            'accelerations': [(g - h) * ddp for g, h in zip(goal, here)]})
    return points


def _offsets(names, here, goal):
    return [h - g for h, g in zip(here, goal)]


def _off_text(names, off):
    return ', '.join(f'{n} {d:+.4f}' for n, d in zip(names, off))


class _Sender:
    """Publishes trajectories on one topic and follows them."""

    def __init__(self, ros, args):
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from sensor_msgs.msg import JointState
        from trajectory_msgs.msg import JointTrajectory
        self.ros, self.args = ros, args
        self.pub = ros.node.create_publisher(
            JointTrajectory, args.topic,
            QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE))
        self.state = None
        self._joint_state = JointState

    def watch(self, names):
        """Subscribe to the robot's joint positions."""
        self.state = _Positions(names)
        self.ros.node.create_subscription(
            self._joint_state, self.args.joint_states, self.state, 100)

    def wait_ready(self):
        """Wait for a subscriber and every joint's position; or refuse."""
        args, ros = self.args, self.ros
        if not ros.spin_until(lambda: self.pub.get_subscription_count() > 0,
                              args.wait):
            if not ros.stop:
                raise RosGraphError(
                    f'no subscriber on {args.topic} after {args.wait:g} s '
                    f'(is the node or the controller running, in this '
                    f'ROS_DOMAIN_ID?)')
            return False
        if self.state is None:
            return True
        if not ros.spin_until(self.state.complete, args.wait):
            if not ros.stop:
                missing = [n for n in self.state.names
                           if n not in self.state.latest]
                raise RosGraphError(
                    f'no position of {", ".join(missing[:6])} on '
                    f'{args.joint_states} after {args.wait:g} s (is the '
                    f'robot driver running? --joint-states names the '
                    f'topic)')
            return False
        return True

    def send(self, names, points, what='sent', follow=True):
        """Publish once (and follow); return False if stopped."""
        from rclpy.duration import Duration
        args = self.args
        now = self.ros.node.get_clock().now().nanoseconds
        start = now + int(args.start_in * 1e9) if args.start_in > 0 else 0
        self.pub.publish(trajectory_message(names, points, start))
        if not self.pub.wait_for_all_acked(Duration(seconds=5.0)):
            print(f'newton-euler: warning: {args.topic}: not acknowledged '
                  f'within 5 s', file=sys.stderr)
        end_s = args.start_in + points[-1]['time_from_start']
        print(f'{what} {len(points)} points for {len(names)} joints to '
              f'{args.topic}, starting in {args.start_in:g} s (stamp '
              f'{start // 10 ** 9}.{start % 10 ** 9:09d}), '
              f'{points[-1]["time_from_start"]:g} s long', flush=True)
        return self.follow(end_s) if follow else True

    def follow(self, seconds):
        """Spin for ``seconds``; False if stopped."""
        done = time.monotonic() + seconds
        self.ros.spin_until(lambda: time.monotonic() >= done, None)
        return not self.ros.stop

    def offsets(self, names, goal):
        return _offsets(names, self.state.vector(), goal)


def _check_send_args(args):
    for option in ('start_in', 'wait'):
        _check_seconds(getattr(args, option), '--' + option.replace('_', '-'))
    _check_seconds(args.tolerance, '--tolerance')
    _check_seconds(args.move_speed, '--move-speed', allow_zero=False)


def _at_start(sender, names, goal, tol):
    """Return True if at the start; else move or refuse (RosGraphError)."""
    args = sender.args
    off = sender.offsets(names, goal)
    worst = max(abs(d) for d in off)
    if worst <= tol:
        print(f"the robot is at the trajectory's first point (largest "
              f'offset {worst:.4f}, tolerance {tol:g})', flush=True)
        return True
    if not args.move_to_start:
        raise RosGraphError(
            f"the robot is not at the trajectory's first point (tolerance "
            f'{tol:g}; robot - start: {_off_text(names, off)}): move it '
            f'there, or add --move-to-start')
    move = approach(names, sender.state.vector(), goal, args.move_speed)
    print(f'moving to the start at {args.move_speed:g} rad/s at most '
          f'(largest offset {worst:.4f})', flush=True)
    if not sender.send(names, move, what='moving:'):
        return False
    # the controller may lag the wall clock: give it --wait s to arrive
    if not sender.ros.spin_until(
            lambda: max(map(abs, sender.offsets(names, goal))) <= tol,
            args.wait):
        if sender.ros.stop:
            return False
        off = sender.offsets(names, goal)
        raise RosGraphError(
            f"the robot did not reach the trajectory's first point within "
            f'{args.wait:g} s of the move (tolerance {tol:g}; robot - '
            f'start: {_off_text(names, off)}); nothing else sent')
    return _at_start(sender, names, goal, tol)


def cmd_send(args):
    """Check the start, publish a trajectory file once, follow it."""
    _check_send_args(args)
    names, points = read_trajectory(args.trajectory)
    if 'positions' not in points[0]:
        raise RosCliError(f'{args.trajectory}: points[0] has no positions: '
                          f'the start cannot be checked')
    ros = _Ros('newton_euler_send')
    try:
        sender = _Sender(ros, args)
        sender.watch(names)
        if not sender.wait_ready():
            return 130
        if not _at_start(sender, names, points[0]['positions'],
                         args.tolerance):
            return 130
        if not sender.send(names, points, follow=not args.no_follow):
            return 130
        if args.no_follow:
            return 0
        print('trajectory ended', flush=True)
    finally:
        ros.close()
    return 0


def _record(args):
    """``record`` (cli_record: the recorder, its lag and its drops)."""
    from .cli_record import cmd_record
    return cmd_record(args)


def _say(text, stream=None):
    """Print a line; a terminal gone (SIGHUP) is no error: drop it."""
    stream = sys.stdout if stream is None else stream
    try:
        print(text, file=stream, flush=True)
    except OSError:
        # stdout and stderr to /dev/null, so that the exit flush cannot
        # fail either
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, 1)
        os.dup2(null, 2)
