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
import gc
import os
import shlex
import signal
import sys
import time


from .latency_driver import (_cpu_seconds, BenchSide, check_answer,
                             paced_send, set_timer_slack, wait_ready)
from .latency_report import (_fmt_load, _loadavg, BenchError, log,
                             observer_check, print_header, report, summarize,
                             write_json)
from .latency_traffic import (_StampClock, CONTACT_TOPIC, ECHO_TOPIC,
                              INPUT_TOPIC, joint_limits, LOOP_TOPIC,
                              NODE_NAME, NODE_TOPIC, puma_model, random_walk,
                              raw_stamp_ns, WRENCH_TOPIC)
from .processes import ChildProcess, first_domain
from .timing import tool_parser

PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
REPO_DIR = os.path.dirname(os.path.dirname(PACKAGE_DIR))


DEFAULT_DOMAIN = 64             # phases use DOMAIN .. DOMAIN + 4
DOMAINS = 5
OBSERVER_PARAMS = ('# written by newton_euler_tools.latency_bench: the observer '
                   'phase\ninverse_dynamics_node:\n  ros__parameters:\n'
                   '    observer:\n      enabled: true\n')


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


# --------------------------------------------------------------------------
# the bench's ROS side


# --------------------------------------------------------------------------
# input: a random walk within the joint limits


# --------------------------------------------------------------------------
# one phase


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
    clock = _StampClock()
    child = bench = None
    try:
        if cmd:
            child = ChildProcess(cmd, domain,
                                 os.path.join(logs_dir, f'{key}.log'),
                                 env=env, die_with_parent=True)
            result['log'] = child.log_path
        bench, command_topic = _bench_side(key, domain, cmd, sub_topic,
                                           args)
        result['bench_executor'] = bench.executor_name
        _get_ready(key, bench, child, args, clock, walk, result)
        timed = _timed(bench, child, args, clock, walk, n_slots)
        if bench.spin_errors:
            raise BenchError(f'receive thread failed: {bench.spin_errors}')
    finally:
        _stop(label, bench, child, args)
    return _phase_result(key, result, timed, child, args, command_topic)


def _bench_side(key, domain, cmd, sub_topic, args):
    """Return the bench's node of this phase and its command topic."""
    extra = ()
    if key == 'observer':
        from geometry_msgs.msg import WrenchStamped
        from std_msgs.msg import Bool
        extra = ((WRENCH_TOPIC, WrenchStamped), (CONTACT_TOPIC, Bool))
    command_topic = (sub_topic.rsplit('/', 1)[0] + '/torque_command'
                     if cmd and args.also_command else None)
    bench = BenchSide(domain, LOOP_TOPIC if cmd is None else INPUT_TOPIC,
                      sub_topic, args.bench_executor, command_topic,
                      extra=extra)
    return bench, command_topic


def _get_ready(key, bench, child, args, clock, walk, result):
    """Wait for the peer's first well-formed answer, then pre-roll."""
    waited, answer, sent = wait_ready(bench, child, args.startup_timeout,
                                      clock, walk)
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
        paced_send(bench, int(args.preroll * args.rate), args.rate, clock,
                   walk, args.spin_us * 1e-6, record=False)


def _drain(bench, stamps, seconds):
    """Wait until every answer (and observer wrench) is in, or seconds."""
    end = time.monotonic() + seconds
    want = set(stamps)
    wrenches = bench.extra.get(WRENCH_TOPIC)
    while time.monotonic() < end:
        got = sum(1 for _, raw in bench.received if raw_stamp_ns(raw) in want)
        if wrenches is not None:
            got = min(got, sum(1 for _, raw in wrenches
                               if raw_stamp_ns(raw) in want))
        if got >= len(want):
            return
        time.sleep(0.02)


def _timed(bench, child, args, clock, walk, n_slots):
    """Send n_slots paced states, drain; return what was measured."""
    commands0 = len(bench.commands)
    extra0 = {t: len(box) for t, box in bench.extra.items()}
    t = {'cpu0': _cpu_seconds(child.pid) if child else None,
         'own0': time.process_time()}
    t0 = time.monotonic()
    old_switch = sys.getswitchinterval()
    sys.setswitchinterval(args.switch_us * 1e-6)
    gc_was_enabled = gc.isenabled()
    if not args.keep_gc:
        gc.disable()   # no collector pauses in the bench while timing
    try:
        t['send'] = paced_send(bench, n_slots, args.rate, clock, walk,
                               args.spin_us * 1e-6)
        t['wall'] = time.monotonic() - t0
        t['cpu1'] = _cpu_seconds(child.pid) if child else None
        t['own1'] = time.process_time()
        _drain(bench, t['send']['stamps'], args.drain)
        t['received'] = list(bench.received)
        t['commands'] = len(bench.commands) - commands0
        t['extras'] = {k: list(box[extra0[k]:])
                       for k, box in bench.extra.items()}
    finally:
        sys.setswitchinterval(old_switch)
        if gc_was_enabled:
            gc.enable()
    return t


def _stop(label, bench, child, args):
    """Close the bench's node, then stop the peer."""
    try:
        if bench is not None:
            bench.close()
    finally:
        if child is not None:
            child.stop(args.stop_timeout)
            log(f'stopped {label}: exit code {child.exit_code} '
                f'({child.stop_how}); log {child.log_path}')


def _phase_result(key, result, t, child, args, command_topic):
    """Return (the phase's figures, its latencies in us)."""
    stats, lat_us = summarize(t['send'], t['received'], args.rate)
    result.update(stats)
    if command_topic:
        # not matched by stamp (Float64MultiArray has none): a count of
        # what arrived from the timed start to the end of the drain
        result['torque_command_received'] = t['commands']
    wall = t['wall']
    if child is not None:
        result['exit_code'] = child.exit_code
        result['stopped_by'] = child.stop_how
        result['node_cpu_percent'] = (
            100.0 * (t['cpu1'] - t['cpu0']) / wall
            if t['cpu0'] is not None and t['cpu1'] is not None else None)
    result['bench_cpu_percent'] = 100.0 * (t['own1'] - t['own0']) / wall
    result['load_average_end'] = _loadavg()
    L = stats['latency_us']
    log(f'latency us: p50 {L["p50"]:.0f}  p99 {L["p99"]:.0f}  p99.9 '
        f'{L["p99.9"]:.0f}  max {L["max"]:.0f};  sent {stats["sent"]}  '
        f'received {stats["received"]}  dropped {stats["dropped"]}')
    if key == 'observer':
        result['observer'] = observer_check(t['send'], t['received'],
                                            t['extras'])
    return result, lat_us


# --------------------------------------------------------------------------
# report


def parse_args(argv=None):
    """Return the command line's options (``--quick`` applied)."""
    parser = tool_parser(
        'latency_bench', 'Latency of inverse_dynamics_node (joint state in, '
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
