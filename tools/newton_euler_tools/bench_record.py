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
``newton-euler record`` under load: its CPU per message, its lag, a crash.

    python -m newton_euler_tools.bench_record [--rate HZ] [--seconds S]
                                              [--load N] [--storage S]

A publisher process sends 7-joint JointState messages at ``--rate``
(default 500 Hz), each stamped with the wall clock when it is sent.
``newton-euler record`` records them while ``--load`` processes (default
2, one per core here) spin in busy loops; after ``--seconds`` (default
15) the recorder is killed with SIGKILL, as a crash would, and what it
left on the disk is read back (the project's reader, which recovers a
bag without metadata.yaml).  It prints:

- the recorder's CPU time per message received (user + system, from
  /proc, over the recording; the executor's wake-ups included);
- its lag behind the stream: the arrival time it logged minus the stamp,
  median, 99th percentile and largest, over the messages kept;
- what the crash lost: the time from the last message kept to the kill
  (the issue's bound: under a second), and how many messages were sent,
  kept and reported dropped by the recorder.

:func:`run` is what the load test of ``record`` calls
(``newton_euler_ros/test/nodes/test_record_load.py``).
"""
import argparse
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np

from .processes import first_domain, ros_env

MODULE = 'newton_euler_tools.bench_record'
NAMES = [f'joint{k}' for k in range(1, 8)]
BUSY = ('import time\nend = time.monotonic() + {seconds}\n'
        'while time.monotonic() < end:\n    pass\n')


def _exe(name):
    return os.path.join(os.path.dirname(sys.executable), name)


def publish(rate, seconds):
    """Publish JointState at ``rate`` Hz, stamped when sent, ``seconds`` s."""
    import rclpy
    from sensor_msgs.msg import JointState
    rclpy.init()
    node = rclpy.create_node('bench_record_driver')
    pub = node.create_publisher(JointState, 'joint_states', 100)
    msg = JointState(name=NAMES)
    msg.velocity = msg.effort = [0.0] * len(NAMES)
    sent, stop, period = [], [], 1.0 / rate
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    nxt = start = time.monotonic()
    while time.monotonic() - start < seconds and not stop:
        now = time.time_ns()
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(now, 10 ** 9)
        msg.position = [1e-9 * (now % 10 ** 9)] * len(NAMES)
        pub.publish(msg)
        sent.append(now)
        nxt += period
        delay = nxt - time.monotonic()
        if delay > 0:
            time.sleep(delay)
    print('\n'.join(f'sent {t}' for t in sent), flush=True)
    node.destroy_node()
    rclpy.shutdown()


def _renice(pid, nice):
    """Lower the priority of ``pid``: its own and its session's (autogroup)."""
    os.setpriority(os.PRIO_PROCESS, pid, nice)
    try:
        with open(f'/proc/{pid}/autogroup', 'w') as fh:
            fh.write(str(nice))
    except OSError:
        pass


def _cpu_seconds(pid):
    """User + system CPU time of process ``pid`` (s)."""
    with open(f'/proc/{pid}/stat') as fh:
        fields = fh.read().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def _logtimes(bag):
    """Log times (ns) of every message in the bag, intact or recovered."""
    from newton_euler_ros.ident.bag_recover import scanners
    out = []
    for scanner in scanners(bag):
        out.extend(logtime for _, logtime, _ in scanner.messages())
    return np.array(out, dtype=np.int64)


def _wait_line(proc, pattern, timeout):
    """Read ``proc``'s stdout until a line matches; return it (or None)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        line = proc.stdout.readline()
        if not line:
            return None
        if re.search(pattern, line):
            return line
    return None


def run(bag, domain, rate=500.0, seconds=15.0, load=2, storage='mcap',
        nice=0):
    """
    Record ``seconds`` under ``load`` busy processes, SIGKILL, measure.

    Return a dict: sent, kept, dropped (what the recorder reported, None
    when it reports nothing), cpu_per_msg_us, lag_ms (median, p99, max of
    log time - stamp), lost_s (kill time - the last kept message's stamp),
    kept_stamps_ns and sent_stamps_ns, lines (the recorder's output).
    """
    env = ros_env(domain)
    pub = subprocess.Popen(
        [sys.executable, '-m', MODULE, '--publish', '--rate', str(rate),
         '--seconds', str(seconds + 60)], stdout=subprocess.PIPE, text=True,
        env=env, start_new_session=True)
    rec = busy = None
    try:
        rec = subprocess.Popen(
            [_exe('newton-euler'), 'record', str(bag), '--storage', storage],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
            env=env, start_new_session=True)
        if _wait_line(rec, r'^recording ', 90.0) is None:
            raise RuntimeError('the recorder did not start')
        time.sleep(0.5)                 # its first messages
        if nice:
            _renice(rec.pid, nice)
        busy = [subprocess.Popen([sys.executable, '-c',
                                  BUSY.format(seconds=seconds + 5)],
                                 start_new_session=True)
                for _ in range(load)]
        cpu0, t0 = _cpu_seconds(rec.pid), time.time_ns()
        time.sleep(seconds)
        cpu1 = _cpu_seconds(rec.pid)
        killed_ns = time.time_ns()
        rec.kill()
        lines = rec.communicate(timeout=30)[0].splitlines()
    finally:
        for proc in [rec] + (busy or []):
            if proc is not None and proc.poll() is None:
                proc.kill()
        pub.terminate()
        out = pub.communicate(timeout=30)[0]
    sent = np.array([int(m) for m in re.findall(r'^sent (\d+)$', out,
                                                re.M)], dtype=np.int64)
    from newton_euler_ros.ident.bag import read_joint_states
    states = read_joint_states(str(bag), NAMES)
    stamps = states.stamps_ns
    logtimes = _logtimes(str(bag))
    lag = (logtimes - stamps) * 1e-6
    during = (stamps >= t0) & (stamps <= killed_ns)
    dropped = [int(m) for line in lines for m in re.findall(
        r'(\d+) dropped', line)]
    return {
        'sent': int(np.sum((sent >= t0) & (sent <= killed_ns))),
        'kept': int(np.sum(during)),
        'dropped': max(dropped) if dropped else None,
        'cpu_per_msg_us': 1e6 * (cpu1 - cpu0) / max(1, int(np.sum(during))),
        'lag_ms': (float(np.median(lag)), float(np.percentile(lag, 99)),
                   float(lag.max())),
        'lost_s': (killed_ns - int(stamps[-1])) * 1e-9,
        'killed_ns': killed_ns,
        'kept_stamps_ns': stamps, 'sent_stamps_ns': sent,
        'lines': lines}


def report(r, rate, seconds, load, storage, nice=0):
    """Print one run's figures."""
    print(f'{storage}, {rate:g} Hz, {load} busy process(es), recorder at '
          f'nice {nice}, SIGKILL after {seconds:g} s:')
    print(f'  while loaded: sent {r["sent"]}, kept {r["kept"]}, '
          f'reported dropped '
          f'{"nothing" if r["dropped"] is None else r["dropped"]}')
    print(f'  recorder CPU per message received: '
          f'{r["cpu_per_msg_us"]:.0f} us')
    med, p99, top = r['lag_ms']
    print(f'  lag (log time - stamp): median {med:.1f} ms, 99th '
          f'percentile {p99:.1f} ms, largest {top:.1f} ms')
    print(f'  lost to the SIGKILL: the last message kept was sent '
          f'{r["lost_s"]:.3f} s before the kill', flush=True)
    said = [x for x in r['lines'] if 'dropped' in x]
    if said:
        print(f'  the recorder said last: {said[-1]}', flush=True)


def main(argv=None):
    """Run the benchmark (or, with --publish, its publisher)."""
    parser = argparse.ArgumentParser(prog=MODULE, description=__doc__.split(
        '\n\n')[0].strip())
    parser.add_argument('--rate', type=float, default=500.0)
    parser.add_argument('--seconds', type=float, default=15.0)
    parser.add_argument('--load', type=int, default=2)
    parser.add_argument('--storage', choices=('mcap', 'sqlite3'),
                        default='mcap')
    parser.add_argument('--nice', type=int, default=0,
                        help="the recorder's niceness (10: it gets a tenth "
                             'of a core shared with a busy process)')
    parser.add_argument('--publish', action='store_true',
                        help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.publish:
        publish(args.rate, args.seconds)
        return 0
    domain = first_domain(87)
    with tempfile.TemporaryDirectory() as tmp:
        r = run(os.path.join(tmp, 'bag'), domain, args.rate, args.seconds,
                args.load, args.storage, args.nice)
    report(r, args.rate, args.seconds, args.load, args.storage, args.nice)
    return 0


if __name__ == '__main__':
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        sys.exit(130)
