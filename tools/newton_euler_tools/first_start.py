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
Time from starting inverse_dynamics_node to its first torques, then latency.

    python -m newton_euler_tools.first_start [--robot URDF] [--observer]
        [--cold] [--rate HZ] [--seconds S]

The node is started as a user starts it (its console script) on a whole
robot (default: example-robot-data's TIAGo Pro) from ``robot_file``;
joint states of every moving joint are published at 100 Hz from the
moment the process starts, and the time to the first ``~/torques`` is
printed, with how many states were sent before it, how many of the next
second's were answered, and the node's own 'kernels ready' line.
``--cold`` gives the node an empty numba cache (as after a fresh install
that skipped ``python -m newton_euler_ros.precompile``): the time then
includes compiling.  Then, at ``--rate`` Hz (500) for ``--seconds`` s
(3): the round trip from publishing a state to receiving its torques
(median, 99th percentile) and the node's own time per update from
``/diagnostics``.
"""
import argparse
import os
import re
import sys
import tempfile
import time

from newton_euler_tools.processes import ChildProcess, first_domain

DEFAULT = 'tiago_pro_description/robots/tiago_pro.urdf'


def node_cmd(path, observer):
    """Return the node's command line on ``path``'s whole tree."""
    script = os.path.join(os.path.dirname(sys.executable),
                          'inverse_dynamics_node')
    return [script, '--ros-args', '-p', f'robot_file:={path}',
            '-p', f'observer.enabled:={"true" if observer else "false"}']


def measure(path, observer=False, cold=False, rate=500.0, seconds=3.0,
            timeout=600.0):
    """Start the node, publish states; return the figures as a dict."""
    import warnings

    from newton_euler_ros.core import load_urdf
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    import numpy as np
    from rclpy.executors import SingleThreadedExecutor
    from sensor_msgs.msg import JointState

    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_urdf(path)
    names = [model.moving_joints[b] for b in range(model.nb)]
    domain = first_domain(71)
    os.environ['ROS_DOMAIN_ID'] = str(domain)
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    scratch = tempfile.mkdtemp(prefix='first_start_')
    env = {'NUMBA_CACHE_DIR': os.path.join(scratch, 'numba')} if cold \
        else None
    rclpy.init()
    probe = rclpy.create_node('first_start_probe')
    executor = SingleThreadedExecutor()
    executor.add_node(probe)
    got = []
    probe.create_subscription(JointState, '/inverse_dynamics_node/torques',
                              lambda m: got.append((
                                  time.monotonic(), m.header.stamp.sec,
                                  m.header.stamp.nanosec)), 10)
    pub = probe.create_publisher(JointState, 'joint_states', 10)
    diag = []
    probe.create_subscription(DiagnosticArray, '/diagnostics',
                              diag.append, 10)
    msg = JointState()
    msg.name = names
    msg.position = [0.0] * len(names)
    msg.velocity = [0.0] * len(names)
    start = time.monotonic()
    node = ChildProcess(node_cmd(path, observer), domain,
                        os.path.join(scratch, 'node.log'), env=env)
    tick = [start]
    sent_at = {}

    def publish_at(period):
        # one state per tick; spin in between; True when sent
        now = time.monotonic()
        if now < tick[0]:
            executor.spin_once(timeout_sec=tick[0] - now)
            return False
        tick[0] += period
        msg.header.stamp = probe.get_clock().now().to_msg()
        key = (msg.header.stamp.sec, msg.header.stamp.nanosec)
        sent_at[key] = time.monotonic()
        pub.publish(msg)
        stamps.append(key)
        return True

    def publish_at_100_hz():
        return publish_at(0.01)

    stamps = []
    sent = 0
    try:
        while not got and time.monotonic() - start < timeout:
            if not node.alive():
                raise SystemExit(f'the node exited:\n{node.tail()}')
            sent += publish_at_100_hz()
        first = got[0][0] - start if got else None
        # a second of states after the first torques: none unanswered
        end = time.monotonic() + 1.0
        del stamps[:]
        after_sent = 0
        while time.monotonic() < end:
            after_sent += publish_at_100_hz()
        stop = time.monotonic() + 0.3
        while time.monotonic() < stop:
            executor.spin_once(timeout_sec=0.05)
        answered = len(set(stamps) & {g[1:] for g in got})
        # latency at the rate asked
        del stamps[:]
        tick[0] = time.monotonic()
        end = tick[0] + seconds
        while time.monotonic() < end:
            publish_at(1.0 / rate)
        count = len(diag)
        stop = time.monotonic() + 3.0
        while time.monotonic() < stop and len(diag) <= count + 1:
            executor.spin_once(timeout_sec=0.05)
        arrived = {g[1:]: g[0] for g in got}
        trips = np.array([arrived[k] - sent_at[k] for k in stamps
                          if k in arrived]) * 1e3
        update = next((
            {kv.key: kv.value for kv in st.values} for st in
            (diag[-1].status if diag else [])
            if st.name.endswith(': update time')), {})
    finally:
        node.stop()
        probe.destroy_node()
        rclpy.shutdown()
    ready = re.search(r'kernels ready in ([0-9.]+) s \(([^)]*)\)',
                      node.log())
    return {'robot': model.name, 'joints': model.nb, 'first': first,
            'sent_before': sent, 'sent_after': after_sent,
            'answered_after': answered,
            'kernels': (float(ready.group(1)), ready.group(2)) if ready
            else None,
            'warned': 'not compiled ahead' in node.log(),
            'rate': rate, 'latency_sent': len(stamps),
            'latency_answered': len(trips),
            'round_trip_ms': (np.percentile(trips, [50, 99]).tolist()
                              if len(trips) else None),
            'update_us': (float(update['median_us']),
                          float(update['p99_us'])) if update else None}


def main(argv=None):
    """Print the time to the first torques."""
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[1])
    ap.add_argument('--robot', help='URDF path (default: TIAGo Pro from '
                    'example-robot-data)')
    ap.add_argument('--observer', action='store_true',
                    help='with observer.enabled')
    ap.add_argument('--cold', action='store_true',
                    help='an empty numba cache (includes compiling)')
    ap.add_argument('--rate', type=float, default=500.0, metavar='HZ',
                    help="the latency phase's publishing rate (500)")
    ap.add_argument('--seconds', type=float, default=3.0, metavar='S',
                    help="the latency phase's length (3 s)")
    args = ap.parse_args(argv)
    if args.robot:
        path = args.robot
    else:
        from newton_euler_tools.peers import example_robot_urdf
        path = example_robot_urdf(DEFAULT)
    r = measure(path, args.observer, args.cold, args.rate, args.seconds)
    kernels = ('no "kernels ready" line' if r['kernels'] is None else
               f'kernels ready in {r["kernels"][0]:.1f} s '
               f'({r["kernels"][1]})')
    first = ('none' if r['first'] is None else f'{r["first"]:.1f} s')
    print(f'{r["robot"]} ({r["joints"]} moving joints), observer '
          f'{"on" if args.observer else "off"}, '
          f'{"cold" if args.cold else "precompiled"} cache: first torques '
          f'{first} after the process started; {kernels}; '
          f'{r["sent_before"]} states sent before them; then '
          f'{r["answered_after"]} of {r["sent_after"]} answered in 1 s'
          + ('; the node warned that nothing was compiled ahead'
             if r['warned'] else ''))
    trip = r['round_trip_ms']
    update = r['update_us']
    print(f'at {r["rate"]:g} Hz: {r["latency_answered"]} of '
          f'{r["latency_sent"]} states answered; round trip '
          + ('-' if trip is None else
             f'median {trip[0]:.2f} ms, 99th percentile {trip[1]:.2f} ms')
          + "; the node's time per update (/diagnostics) "
          + ('-' if update is None else
             f'median {update[0] / 1e3:.2f} ms, 99th percentile '
             f'{update[1] / 1e3:.2f} ms'))
    return 0 if r['first'] is not None else 1


if __name__ == '__main__':
    sys.exit(main())
