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
Every ``newton-euler`` command's exit status, as a process, per class.

docs/cli.md states one rule: 0 done; 1 the inputs were usable but the
work failed (the ROS graph did not answer); 2 an input is wrong (the
command line, or a file or value it names); 130 interrupted.  The
commands are read from the argument parser, so a new command without
cases here fails the test.  Success and bad input are run for every
command, a bad option for every command, the graph's silence for the
two that need it, and an interrupt for the long-running ones.
"""
import os
import signal
import subprocess
import sys
import threading
import time

from newton_euler_ros.cli import build_parser
from newton_euler_tools.ident_example import BASE, make_example, TIP
import pytest

pytest.importorskip('rclpy')

from ros_harness import (domain_id, interrupt, PACKAGE_DIR,  # noqa: E402
                         Probe, ros_env)

DOMAIN = domain_id(71)
CHAIN = ['--base', BASE, '--tip', TIP]
MOVE = os.path.join(PACKAGE_DIR, 'config', 'trajectories',
                    'puma560_move.json')
TRAJ_TOPIC = '/exit_status/trajectory'
STATE_TOPIC = '/exit_status/joint_states'
# excite starts where the arm is: the Panda's ready pose
START = ['--start', '0', '-0.785', '0', '-2.356', '0', '1.571', '0.785']


def commands():
    """Return the subcommands the parser knows."""
    parser = build_parser()
    sub = next(a for a in parser._actions
               if a.__class__.__name__ == '_SubParsersAction')
    return sorted(sub.choices)


def exe():
    return os.path.join(os.path.dirname(sys.executable), 'newton-euler')


def run(args, timeout=300):
    return subprocess.run([exe(), *map(str, args)], capture_output=True,
                          text=True, timeout=timeout, env=ros_env(DOMAIN))


@pytest.fixture(scope='module')
def files(tmp_path_factory):
    root = tmp_path_factory.mktemp('exit_status')
    example = make_example(str(root / 'loop'), seconds=12.0, rate=100.0,
                           seed=3, validation=False)
    return {'urdf': example['urdf'], 'bag': example['recording'],
            'root': root, 'missing': str(root / 'missing.file')}


# command -> success arguments and bad-input arguments ({name} from files;
# {out} a fresh output path); send and record run beside a probe
CASES = {
    'dynamics': (['puma560', '--q', *['0.1'] * 6],
                 ['{missing}', '--q', '0']),
    'check': (['puma560'], ['{missing}']),
    'urdf': (['puma560', '-o', '{out}.urdf'], ['{missing}']),
    'feedforward': (['puma560', MOVE], ['puma560', '{missing}']),
    'simulate': (['puma_payload_press', '--duration', '0.05'],
                 ['{missing}']),
    'robots': ([], None),
    'excite': (['{urdf}', *CHAIN, '-o', '{out}.json', '--budget', '1',
                '--period', '4', '--harmonics', '2', *START],
               ['{missing}', *CHAIN, '-o', '{out}.json', *START]),
    'identify': (['{urdf}', '{bag}', *CHAIN, '-o', '{out}.urdf'],
                 ['{urdf}', '{missing}', *CHAIN, '-o', '{out}.urdf']),
    'replay': (['{urdf}', '{bag}', *CHAIN, '--csv', '{out}.csv'],
               ['{urdf}', '{missing}', *CHAIN, '--csv', '{out}.csv']),
    'export': (['{urdf}', '--format', 'franka', '-o', '{out}.yaml'],
               ['{missing}', '--format', 'franka', '-o', '{out}.yaml']),
    'payload': (['{urdf}', '{bag}', *CHAIN],
                ['{urdf}', '{missing}', *CHAIN]),
    'observe': (['{urdf}', '{bag}', *CHAIN, '--csv', '{out}.csv'],
                ['{urdf}', '{missing}', *CHAIN, '--csv', '{out}.csv']),
    'send': ([MOVE, '--topic', TRAJ_TOPIC, '--no-follow', '--wait', '60',
              '--joint-states', STATE_TOPIC],
             ['{missing}', '--topic', TRAJ_TOPIC]),
    'record': (['{out}', '--topic', STATE_TOPIC, '--max-messages', '3',
                '--wait', '60'],
               ['{root}/no/such/dir/bag', '--topic', STATE_TOPIC]),
}
# the graph did not answer: exit status 1
SILENT_GRAPH = {
    'send': [MOVE, '--topic', '/exit_status/nobody', '--wait', '0.5'],
    'record': ['{out}', '--topic', '/exit_status/nobody', '--wait', '0.5'],
}
# interrupted while working: exit status 130
LONG_RUNNING = {
    'excite': ['{urdf}', *CHAIN, '-o', '{out}.json', '--budget', '600',
               *START],
    'simulate': ['puma_payload_press', '--duration', '100000'],
    'send': [MOVE, '--topic', '/exit_status/nobody', '--wait', '600'],
}


def fill(args, files, out):
    return [str(a).format(out=out, **files) for a in args]


def test_every_command_has_cases():
    assert sorted(CASES) == commands()
    assert set(SILENT_GRAPH) | set(LONG_RUNNING) <= set(CASES)


def beside_the_graph(command, args):
    """Run send or record while a probe subscribes or publishes."""
    import json
    from sensor_msgs.msg import JointState
    from trajectory_msgs.msg import JointTrajectory
    probe = Probe(DOMAIN, name='exit_status_probe')
    proc = None
    try:
        pub = probe.publisher(JointState, STATE_TOPIC)
        if command == 'send':
            got = probe.collect(JointTrajectory, TRAJ_TOPIC)
            # the robot at the trajectory's first point
            with open(MOVE, encoding='utf-8') as fh:
                move = json.load(fh)
            at_start = JointState(name=move['joint_names'],
                                  position=move['points'][0]['positions'])
        proc = subprocess.Popen([exe(), command, *args],
                                stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True,
                                env=ros_env(DOMAIN))
        end = time.monotonic() + 120.0
        stamp = 10 ** 9
        while proc.poll() is None and time.monotonic() < end:
            if command == 'record':
                stamp += 10 ** 7
                msg = JointState(name=['j'], position=[0.0], velocity=[0.0],
                                 effort=[0.0])
                msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(
                    stamp, 10 ** 9)
                pub.publish(msg)
            else:
                pub.publish(at_start)
            probe.spin_for(0.01)
        out, err = proc.communicate(timeout=30)
        if command == 'send':
            assert probe.spin_until(lambda: len(got) == 1, 10.0)
        return proc.returncode, err
    finally:
        if proc is not None and proc.poll() is None:
            proc.kill()
            proc.communicate()
        probe.close()


@pytest.mark.parametrize('command', sorted(CASES))
def test_done_is_0(command, files, tmp_path):
    args = fill(CASES[command][0], files, tmp_path / 'out')
    if command in ('send', 'record'):
        code, err = beside_the_graph(command, args)
    else:
        proc = run([command, *args])
        code, err = proc.returncode, proc.stderr
    assert code == 0, err


@pytest.mark.parametrize('command', sorted(CASES))
def test_a_wrong_command_line_is_2(command):
    proc = run([command, '--no-such-option'])
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith('newton-euler: error: ')
    assert len(proc.stderr.splitlines()) == 1, proc.stderr


@pytest.mark.parametrize('command', sorted(c for c in CASES if CASES[c][1]))
def test_a_wrong_input_file_is_2(command, files, tmp_path):
    proc = run([command, *fill(CASES[command][1], files, tmp_path / 'out')])
    assert proc.returncode == 2, proc.stderr
    lines = [x for x in proc.stderr.splitlines()
             if not x.startswith(('warning:', 'note:'))]
    assert len(lines) == 1 and lines[0].startswith('newton-euler: error: '), \
        proc.stderr
    assert 'Traceback' not in proc.stderr
    assert not [p for p in os.listdir(tmp_path) if p.startswith('out')]


@pytest.mark.parametrize('command', sorted(SILENT_GRAPH))
def test_a_silent_graph_is_1(command, files, tmp_path):
    proc = run([command, *fill(SILENT_GRAPH[command], files,
                               tmp_path / 'out')])
    assert proc.returncode == 1, proc.stderr
    assert 'after 0.5 s' in proc.stderr and len(
        proc.stderr.splitlines()) == 1, proc.stderr
    assert not (tmp_path / 'out').exists()


def test_record_that_hears_nothing_is_1(tmp_path):
    """A publisher that never publishes, then Ctrl-C: no bag, status 1."""
    from sensor_msgs.msg import JointState
    probe = Probe(DOMAIN, name='exit_status_quiet')
    try:
        probe.publisher(JointState, STATE_TOPIC)
        proc = subprocess.Popen(
            [exe(), 'record', str(tmp_path / 'bag'), '--topic', STATE_TOPIC,
             '--wait', '60'], stdout=subprocess.PIPE,
            stderr=subprocess.PIPE, text=True, env=ros_env(DOMAIN))
        lines = []
        reader = threading.Thread(target=lambda: lines.extend(proc.stdout),
                                  daemon=True)
        reader.start()
        end = time.monotonic() + 120.0
        while not lines and time.monotonic() < end:
            assert proc.poll() is None, proc.communicate()
            probe.spin_for(0.05)
        assert lines and lines[0].startswith('recording'), lines
        probe.spin_for(0.5)
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=30)
        reader.join(10)
        err = proc.stderr.read()
        out = ''.join(lines)
    finally:
        probe.close()
    assert proc.returncode == 1, out + err
    assert 'no message received' in err
    assert not (tmp_path / 'bag').exists()


@pytest.mark.parametrize('command', sorted(LONG_RUNNING))
def test_interrupted_is_130(command, files, tmp_path):
    args = fill(LONG_RUNNING[command], files, tmp_path / 'out')
    # a SIGINT before the command's main() (while Python imports the
    # package) ends Python itself (-SIGINT): wait longer and try again
    for delay in (3.0, 6.0, 12.0):
        proc = subprocess.Popen([exe(), command, *args],
                                stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True,
                                env=ros_env(DOMAIN))
        time.sleep(delay)
        assert proc.poll() is None, proc.communicate()
        _, err = interrupt(proc, 60)
        if proc.returncode != -signal.SIGINT:
            break
    assert proc.returncode == 130, err
    assert 'Traceback' not in err, err
    assert not [p for p in os.listdir(tmp_path) if p.startswith('out')]


# identify, replay and payload on the whole tree below the base (no --tip):
# the Panda with its hand and its two fingers (one a mimic joint), which
# the recording names at rest
TREE = ['--base', BASE]
TREE_CASES = {
    'identify': (['{urdf}', '{bag}', *TREE, '-o', '{out}.urdf'],
                 ['{urdf}', '{bag}', *TREE, '-o', '{out}.urdf',
                  '--known-mass-link', 'panda_hand']),
    'replay': (['{urdf}', '{bag}', *TREE, '--csv', '{out}.csv'],
               ['{urdf}', '{missing}', *TREE, '--csv', '{out}.csv']),
    # a tree with several tips: the payload's link must be named
    'payload': (['{urdf}', '{bag}', *TREE, '--link', 'panda_hand'],
                ['{urdf}', '{bag}', *TREE]),
}


@pytest.mark.parametrize('command', sorted(TREE_CASES))
def test_a_tree_done_is_0(command, files, tmp_path):
    proc = run([command, *fill(TREE_CASES[command][0], files,
                               tmp_path / 'out')])
    assert proc.returncode == 0, proc.stderr


@pytest.mark.parametrize('command', sorted(TREE_CASES))
def test_a_tree_wrong_input_is_2(command, files, tmp_path):
    proc = run([command, *fill(TREE_CASES[command][1], files,
                               tmp_path / 'out')])
    assert proc.returncode == 2, proc.stderr
    lines = [x for x in proc.stderr.splitlines()
             if not x.startswith(('warning:', 'note:'))]
    assert len(lines) == 1 and lines[0].startswith('newton-euler: error: '), \
        proc.stderr
    assert not [p for p in os.listdir(tmp_path) if p.startswith('out')]


def test_the_rule_is_stated_once_in_docs_cli():
    root = os.path.dirname(PACKAGE_DIR)
    with open(os.path.join(root, 'docs', 'cli.md'), encoding='utf-8') as fh:
        text = fh.read()
    assert text.count('## Exit status') == 1
    rule = text[text.index('## Exit status'):]
    for status in ('| 0 |', '| 1 |', '| 2 |', '| 130 |'):
        assert status in rule, status
