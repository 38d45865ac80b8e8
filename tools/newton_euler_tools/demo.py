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
Closed-loop demo: simulator, inverse dynamics and a tracking controller.

    python -m newton_euler_tools.demo [--scene NAME] [--duration T]
                                    [--out DIR] [--quick]

Runs the scene twice, each time as three ROS processes in a domain of
its own (ROS_DOMAIN_ID and the next id when it is set, else two ids from
1 + pid % 100; discovery on localhost): robot_sim_node, inverse_dynamics_node
(desired accelerations from the controller's reference) and
tracking_controller_node, once with the feedforward and once with PD
alone.  A probe in this process records joint states and commands.  The
simulator starts its clock only once every node has discovered its peers
(see :func:`run_graph`), so no command is lost at the start; the summary
says how many commands the controller sent, the plant received and the
probe recorded.  The children are stopped with SIGINT (the controller
first) and must exit 0.  Then plots (joint
tracking, torques split by term, tracking error) and ``summary.md`` are
written to DIR (default out/demo).
"""
import argparse
import os
import re
import sys
import time
import warnings

from newton_euler_ros.graph import (CONTROLLER_REMAPS, EFFORT_COMMANDS, ID,
                                    MUJOCO_CONTROLLER_REMAPS, MUJOCO_SIM,
                                    ros_args, SIM)
import numpy as np

from .demo_report import plots, summary, torque_terms
from .processes import ChildProcess, first_domain

# the plant: its node, its start and command topics, the controller's
# remaps, the default scene
PLANTS = {
    'mujoco': ('mujoco_sim_node', f'{MUJOCO_SIM}/start', EFFORT_COMMANDS,
               MUJOCO_CONTROLLER_REMAPS, 'panda_mujoco_full'),
    'newton_euler': ('robot_sim_node', f'{SIM}/start', f'{SIM}/commands',
                     CONTROLLER_REMAPS, 'puma_payload_press'),
}
PLANT = 'mujoco'
SCENE = PLANTS[PLANT][-1]
QUICK_DURATION = 1.0
STARTUP_TIMEOUT = 120.0     # first run may compile the numba kernels


class DemoError(Exception):
    """The demo could not run to completion."""


def stop_children(children, recorder, status):
    """Stop the children not stopped yet (last started first), close ``recorder``."""
    for child in reversed(children):
        if child.label not in status:
            status[child.label] = child.stop()
    recorder.close()


def check_exits(label, status, log_dir=None):
    """Raise DemoError when a child did not exit 0 (status: label -> code)."""
    bad = {k: v for k, v in status.items() if v != 0}
    if bad:
        where = f' (logs in {log_dir})' if log_dir else ''
        raise DemoError(f'[{label}] nodes did not exit cleanly: {bad}{where}')


def base_domain(count=2):
    """
    Return the first of ``count`` domain ids, one per run.

    ROS_DOMAIN_ID when set, else 1 + pid % 100 (runs started side by side
    rarely share a domain); ValueError for an unusable ROS_DOMAIN_ID.
    """
    return first_domain(1 + os.getpid() % 100, count)


def start_runs(out):
    """
    Make the folder ``out`` and its logs; pick the two runs' first domain.

    Return the absolute ``out``, its ``logs`` folder and the first domain
    id (:func:`base_domain`: ValueError for an unusable ROS_DOMAIN_ID).
    """
    out = os.path.abspath(out)
    log_dir = os.path.join(out, 'logs')
    os.makedirs(log_dir, exist_ok=True)
    return out, log_dir, base_domain()


class Child(ChildProcess):
    """A node run as ``python -m module --ros-args ...``."""

    def __init__(self, label, module, ros_args, domain, log_dir):
        super().__init__([sys.executable, '-m', module, '--ros-args',
                          *ros_args], domain,
                         os.path.join(log_dir, f'{label}.log'), label)

    def check_alive(self):
        """Raise DemoError when the process has already exited."""
        if not self.alive():
            raise DemoError(f'{self.label} exited early with status '
                            f'{self.proc.returncode}; see {self.log_path}')


class Recorder:
    """
    An rclpy node in its own context recording the demo's topics.

    With ``states_after_commands``, joint_states is subscribed only once
    the commands' subscription is matched with a publisher (the
    controller), so that a simulator counting this recorder among its
    joint_states subscribers starts only when this recorder hears the
    commands.
    """

    def __init__(self, domain, states_after_commands=False,
                 name='demo_recorder', start=f'{SIM}/start',
                 commands=f'{SIM}/commands'):
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.qos import (DurabilityPolicy, QoSProfile,
                               ReliabilityPolicy)
        from sensor_msgs.msg import JointState
        from std_msgs.msg import Float64MultiArray, Header
        self.rclpy = rclpy
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = rclpy.create_node(name, context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.t0 = None
        self.states = []
        self.commands = []
        latched = QoSProfile(depth=1,
                             reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.node.create_subscription(Header, start, self._on_start, latched)
        self.cmd_sub = self.node.create_subscription(
            Float64MultiArray, commands, self._on_command, 1000)
        self._state_type = JointState
        self.state_sub = None
        self._states_after_commands = states_after_commands
        self._subscribe_states()

    def _subscribe_states(self):
        # joint_states at once, or last: once the controller's commands
        # are matched (the simulator counts this subscriber before it
        # starts its clock)
        if self.state_sub is None and (
                not self._states_after_commands
                or self.cmd_sub.get_publisher_count()):
            self.state_sub = self.node.create_subscription(
                self._state_type, '/joint_states', self._on_state, 1000)

    def _on_start(self, msg):
        self.t0 = msg.stamp.sec + msg.stamp.nanosec * 1e-9

    def _on_state(self, msg):
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        self.states.append((stamp, list(msg.position), list(msg.velocity),
                            list(msg.effort), time.monotonic()))

    def _on_command(self, msg):
        self.commands.append((time.time(), list(msg.data)))

    def publishers(self, topic):
        return self.node.count_publishers(topic)

    def subscribers(self, topic):
        return self.node.count_subscribers(topic)

    def last_time(self):
        if self.t0 is None or not self.states:
            return None
        return self.states[-1][0] - self.t0

    def spin_once(self, timeout=0.02):
        self._subscribe_states()
        self.executor.spin_once(timeout_sec=timeout)

    def drain(self, quiet=0.3, limit=5.0):
        """Spin until no command arrived for ``quiet`` s (at most limit)."""
        end = time.monotonic() + limit
        count, since = len(self.commands), time.monotonic()
        while time.monotonic() - since < quiet and time.monotonic() < end:
            self.spin_once(0.02)
            if len(self.commands) != count:
                count, since = len(self.commands), time.monotonic()

    def close(self):
        self.executor.shutdown()
        self.node.destroy_node()
        self.rclpy.try_shutdown(context=self.context)


def poll(predicate, what, check, pause, timeout=STARTUP_TIMEOUT):
    """
    Call ``pause()`` until ``predicate()``, ``check()`` before each.

    ``check`` raises when a process has exited; DemoError after
    ``timeout`` seconds, naming ``what`` was awaited.
    """
    end = time.monotonic() + timeout
    while not predicate():
        check()
        if time.monotonic() > end:
            raise DemoError(f'timed out after {timeout:.0f} s waiting for '
                            f'{what}')
        pause()


def wait_for(recorder, children, predicate, what):
    """Spin until ``predicate()``; fail if a child exits or on timeout."""
    def check():
        for child in children:
            child.check_alive()
    poll(predicate, what, check, lambda: recorder.spin_once(0.05))


def start_controller(recorder, children, label, domain, log_dir, duration,
                     *, scene, feedforward, tail):
    """
    Start tracking_controller_node, the last node; wait for t = 0.

    It waits for two subscribers (the plant and ``recorder``) and takes
    ``scene``, ``feedforward`` ('true' or 'false') and then the arguments
    ``tail`` (clock, remaps); it is added to ``children`` and returned
    once the recorder has the plant's start time.
    """
    controller = Child(
        f'{label}_tracking_controller_node',
        'newton_euler_ros.nodes.tracking_controller_node',
        ['-p', f'scene:={scene}', '-p', f'feedforward:={feedforward}',
         '-p', 'wait_for_subscribers:=2', *tail], domain, log_dir)
    children.append(controller)
    wait_for(recorder, children, lambda: recorder.t0 is not None,
             'the simulation start')
    print(f'[{label}] nodes up in domain {domain}; simulating '
          f'{duration:g} s', flush=True)
    return controller


def run_to(recorder, children, duration, timeout, late, tick=None):
    """
    Spin until the recorder's last state is at t = ``duration``.

    Checks the children alive on every pass, calls ``tick(t)`` with each
    new last time, and raises DemoError(``late``) after ``timeout``
    seconds of wall clock.
    """
    end = time.monotonic() + timeout
    while True:
        recorder.spin_once()
        for child in children:
            child.check_alive()
        t = recorder.last_time()
        if t is not None:
            if tick is not None:
                tick(t)
            if t >= duration - 1e-9:
                return
        if time.monotonic() > end:
            raise DemoError(late)


COUNT = re.compile(r'commands (sent|received): (\d+)')


def logged_count(child, what):
    """Return the count a node logged on exit (``commands sent: N``)."""
    counts = dict(COUNT.findall(child.log()))
    if what not in counts:
        raise DemoError(f'{child.label} did not log its "commands {what}" '
                        f'count; see {child.log_path}')
    return int(counts[what])


def run_graph(scene_arg, label, feedforward, duration, domain, log_dir,
              plant=PLANT):
    """Run the three nodes once; return the recorded arrays."""
    ff = 'true' if feedforward else 'false'
    node, start, commands, remaps, _ = PLANTS[plant]
    # MuJoCo's plant stamps in simulated time and publishes /clock: the
    # others follow it (the library's own simulator stamps in wall time)
    sim_time = (['-p', 'use_sim_time:=true'] if plant == 'mujoco'
                else [])
    children = []
    recorder = Recorder(domain, states_after_commands=True, start=start,
                        commands=commands)
    status = {}
    try:
        # The simulator starts its clock once every node has discovered its
        # peers: it waits for its three joint_states subscribers (this
        # recorder, the controller, the ID node); the controller and this
        # recorder subscribe to joint_states only once the controller's
        # commands are matched with the simulator and this recorder (and,
        # with feedforward, its ~/feedforward and ~/reference with the ID
        # node); the simulator's GRACE second covers the ID node's side.
        # The controller starts last.
        sim = Child(
            f'{label}_{node}', f'newton_euler_ros.nodes.{node}',
            ['-p', f'scene:={scene_arg}', '-p', 'wait_for_subscribers:=3'],
            domain, log_dir)
        children.append(sim)
        children.append(Child(
            f'{label}_inverse_dynamics_node',
            'newton_euler_ros.nodes.inverse_dynamics_node',
            ['-p', f'scene:={scene_arg}',
             '-p', 'acceleration_source:=reference', *sim_time], domain,
            log_dir))
        wait_for(recorder, children,
                 lambda: recorder.publishers(f'{ID}/torques') >= 1
                 and recorder.subscribers(commands) >= 1,
                 f'{node} and inverse_dynamics_node')
        controller = start_controller(
            recorder, children, label, domain, log_dir, duration,
            scene=scene_arg, feedforward=ff,
            tail=[*sim_time, *ros_args(remaps)])
        next_report = [1.0]

        def report(t):
            while t >= next_report[0] - 1e-9 and next_report[0] <= duration:
                print(f'[{label}] t = {next_report[0]:4.1f} s simulated, '
                      f'{len(recorder.states)} joint states, '
                      f'{len(recorder.commands)} commands', flush=True)
                next_report[0] += 1.0
        run_to(recorder, children, duration, STARTUP_TIMEOUT + 10.0 * duration,
               f'[{label}] simulation did not reach t = {duration} s in time',
               report)
        # on a loaded machine the controller can lag the stream: give it
        # until as many commands as states up to t = duration are recorded
        # (the plant runs on meanwhile; with feedforward some states stay
        # unanswered, so this waits a few seconds at most)
        states_in = sum(1 for s in recorder.states
                        if -1e-9 <= s[0] - recorder.t0 <= duration + 1e-9)
        caught_up = time.monotonic() + 3.0
        while (len(recorder.commands) < states_in
               and time.monotonic() < caught_up):
            recorder.spin_once(0.05)
        # the controller first: then no command is in flight when the
        # recorder and the simulator give their counts
        status[controller.label] = controller.stop()
        recorder.drain()
        # the recorder has the last command; give the plant, a process of
        # its own, the moment it may still need to take it off its queue
        # (a SIGINT ends its spinning, and it counts only what it took)
        time.sleep(1.0)
    finally:
        stop_children(children, recorder, status)
    check_exits(label, status, log_dir)
    print(f'[{label}] stopped: all nodes exited 0', flush=True)
    if recorder.t0 is None:
        raise DemoError(f'[{label}] no start time received')
    stamps = np.array([s[0] for s in recorder.states]) - recorder.t0
    keep = (stamps >= -1e-9) & (stamps <= duration + 1e-9)
    order = np.argsort(stamps[keep], kind='stable')
    rows = [r for r, k in zip(recorder.states, keep) if k]
    rows = [rows[i] for i in order]
    arrived = np.array([r[4] for r in rows])
    span = arrived.max() - arrived.min() if len(rows) > 1 else 0.0
    run = {
        # simulated seconds per wall-clock second, as the states arrived
        'real_time_factor': (float(np.ptp(stamps[keep]) / span)
                             if span > 0 else float('nan')),
        't': stamps[keep][order],
        'q': np.array([r[1] for r in rows]),
        'qd': np.array([r[2] for r in rows]),
        'tau': np.array([r[3] for r in rows]),
        'commands': len(recorder.commands),
        'sent': logged_count(controller, 'sent'),
        'received': logged_count(sim, 'received'),
    }
    print(f'[{label}] commands: {run["sent"]} sent by the controller, '
          f'{run["received"]} received by the plant, {run["commands"]} '
          f'recorded; real-time factor {run["real_time_factor"]:.2f}',
          flush=True)
    return run


def tracking(scene, run):
    """Add the reference and tracking errors to a run; return its RMS."""
    ref = np.array([scene.reference.at(t)[0] for t in run['t']])
    run['q_ref'] = ref
    run['err'] = run['q'] - ref
    return float(np.sqrt(np.mean(run['err'] ** 2)))


def main(argv=None):
    """Run the closed-loop demo; return the exit status."""
    parser = argparse.ArgumentParser(
        prog='python -m newton_euler_tools.demo',
        description='Closed-loop ROS 2 demo: tracking with and without '
                    'Newton-Euler feedforward.')
    parser.add_argument('--plant', choices=sorted(PLANTS), default=PLANT,
                        help='the simulated robot: mujoco (mujoco_sim_node, '
                             "MuJoCo's physics; default) or newton_euler "
                             "(robot_sim_node, the library's own)")
    parser.add_argument('--scene', default=None,
                        help='scene name or file (default: '
                             + ', '.join(f'{v[-1]} on {k}'
                                         for k, v in PLANTS.items()) + ')')
    parser.add_argument('--duration', type=float, default=None,
                        help='seconds of simulated time (default: the '
                             "scene's duration)")
    parser.add_argument('--out', default=os.path.join('out', 'demo'),
                        help='output folder (default out/demo)')
    parser.add_argument('--quick', action='store_true',
                        help=f'{QUICK_DURATION:g} s runs, short benchmark')
    args = parser.parse_args(argv)
    args.scene = args.scene or PLANTS[args.plant][-1]
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

    from newton_euler_ros.core import NewtonEulerError
    from newton_euler_ros.sim.scene import load_scene
    try:
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            scene = load_scene(args.scene)
    except NewtonEulerError as exc:
        print(f'demo: {exc}', file=sys.stderr)
        return 2
    # children get an absolute path for a file, the name for a bundled one
    scene_arg = (os.path.abspath(args.scene) if os.path.isfile(args.scene)
                 else args.scene)
    duration = args.duration or (QUICK_DURATION if args.quick
                                 else scene.duration)
    duration = min(duration, scene.duration)
    try:
        out, log_dir, base = start_runs(args.out)
    except ValueError as exc:
        print(f'demo: {exc}', file=sys.stderr)
        return 2
    started = time.monotonic()
    runs, rms = {}, {}
    try:
        for k, (key, feedforward) in enumerate((('feedforward', True),
                                                ('pd', False))):
            domain = base + k
            runs[key] = run_graph(scene_arg, key, feedforward, duration,
                                  domain, log_dir, args.plant)
            if len(runs[key]['t']) < 2:
                raise DemoError(f'[{key}] too few joint states recorded')
            rms[key] = tracking(scene, runs[key])
            print(f'[{key}] tracking RMS error {rms[key]:.3e} rad',
                  flush=True)
    except DemoError as exc:
        print(f'demo: {exc}', file=sys.stderr)
        return 1
    wall = time.monotonic() - started
    costs = None
    if args.plant == 'mujoco':
        from .mujoco_costs import measure
        print('what accuracy costs: each effect left out of the '
              'feedforward, on MuJoCo (offline)', flush=True)
        costs = measure(scene, *((500, 3) if args.quick else (4000, 7)),
                        duration)
    terms = torque_terms(scene, runs['feedforward'])
    files = plots(scene, runs, terms, out)
    text = summary(scene, runs, rms, files, duration, wall, args.plant,
                   costs)
    with open(os.path.join(out, 'summary.md'), 'w') as fh:
        fh.write(text)
    np.savez(os.path.join(out, 'runs.npz'),
             **{f'{key}_{name}': run[name] for key, run in runs.items()
                for name in ('t', 'q', 'qd', 'tau', 'q_ref')})
    ratio = rms['pd'] / rms['feedforward'] if rms['feedforward'] else \
        float('inf')
    print(f'RMS with feedforward {rms["feedforward"]:.3e} rad, without '
          f'{rms["pd"]:.3e} rad (ratio {ratio:.1f}); wrote {out}',
          flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
