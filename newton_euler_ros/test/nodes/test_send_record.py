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
``newton-euler send`` and ``record`` as a user runs them, over real DDS.

The robot is robot_sim_node (a Puma 560 standing in for a driver and
joint_trajectory_controller); inverse_dynamics_node fills the efforts of
the trajectory ``send`` publishes on its ``~/trajectory_in`` and passes
it on to the simulator; ``record`` writes ``/joint_states`` to a rosbag2
that the identification commands read.
"""
import json
import os
import subprocess
import sys

from newton_euler_tools.processes import ros_env
import numpy as np
import pytest

pytest.importorskip('rclpy')

# After the skip: pytest must be imported first, hence E402 and I100.
from newton_euler_ros.ident.bag import read_joint_states  # noqa: E402, I100
from ros_harness import (domain_id, id_node_cmd, interrupt,  # noqa: E402
                         NodeProcess, Probe)

pytestmark = pytest.mark.ros

NAMES = [f'joint{k}' for k in range(1, 7)]
Q0 = [0.0, 0.3, -0.4, 0.0, 0.3, 0.0]     # puma_pick_and_place's start
STEP = 0.2          # rad: every joint moves this much
MOVE = 2.0          # s


def cli(*args, domain=None, timeout=60):
    exe = os.path.join(os.path.dirname(sys.executable), 'newton-euler')
    base = [exe] if os.path.exists(exe) else [
        sys.executable, '-m', 'newton_euler_ros.cli']
    return subprocess.run(base + list(args), capture_output=True, text=True,
                          timeout=timeout,
                          env=ros_env(domain if domain is not None
                                      else domain_id(3)))


def write_move(path):
    """Write a rest-to-rest quintic of every joint by STEP, no efforts."""
    points = []
    for t in np.arange(0.0, MOVE + 1e-9, 0.01):
        s = t / MOVE
        p = 10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5
        dp = (30 * s ** 2 - 60 * s ** 3 + 30 * s ** 4) / MOVE
        points.append({'time_from_start': float(t),
                       'positions': [q + STEP * p for q in Q0],
                       'velocities': [STEP * dp] * 6})
    path.write_text(json.dumps({'joint_names': NAMES, 'points': points}))
    return path


def _stamp_ns(msg):
    return msg.header.stamp.sec * 10 ** 9 + msg.header.stamp.nanosec


def test_send_through_the_node_and_record_a_bag(tmp_path):
    """Send through the node into the simulator; record; stop on Ctrl-C."""
    import re
    from sensor_msgs.msg import JointState
    from newton_euler_ros.sim.scene import scene_dirs
    domain = domain_id(11)
    # the bundled pick-and-place scene, long enough for a loaded machine
    bundled = next(path for path in (
        os.path.join(d, 'puma_pick_and_place.yaml') for d in scene_dirs())
        if os.path.isfile(path))
    with open(bundled, encoding='utf-8') as fh:
        scene = fh.read().replace('duration: 5.0', 'duration: 60.0')
    assert 'duration: 60.0' in scene
    (tmp_path / 'scene.yaml').write_text(scene)
    sim_cmd = [os.path.join(os.path.dirname(sys.executable),
                            'robot_sim_node'), '--ros-args',
               '-p', f'scene:={tmp_path / "scene.yaml"}',
               # the recorder, the inverse-dynamics node and the probe
               '-p', 'wait_for_subscribers:=3']
    node_cmd = id_node_cmd(None, '-p', 'robot_file:=puma560',
                           '-p', 'mode:=gravity', '-r',
                           '~/trajectory_out:=/robot_sim_node/'
                           'joint_trajectory')
    sim = NodeProcess(sim_cmd, domain, str(tmp_path / 'sim.log'))
    node = NodeProcess(node_cmd, domain, str(tmp_path / 'node.log'))
    probe = Probe(domain, name='send_record_probe')
    live = probe.collect(JointState, 'joint_states')
    bag = tmp_path / 'recording'
    recorder = subprocess.Popen(
        [os.path.join(os.path.dirname(sys.executable), 'newton-euler'),
         'record', str(bag)], stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True, env=ros_env(domain))
    try:
        # the robot is up: the simulator has started (it holds t = 0 for
        # the first command)
        assert probe.spin_until(lambda: live, 90.0), sim.log() + node.log()
        sent = cli('send', str(write_move(tmp_path / 'move.json')),
                   '--wait', '60', domain=domain, timeout=120)
        assert sent.returncode == 0, sent.stdout + sent.stderr + node.log()
        assert 'sent 201 points for 6 joints to /inverse_dynamics_node/' \
            'trajectory_in' in sent.stdout
        # the recording goes on until the simulator's stamps are 0.5 s
        # past the trajectory's end (they lag the wall clock: t = 0 was
        # held for the first command, and a loaded machine slows it)
        sec, nanosec = re.search(r'\(stamp (\d+)\.(\d{9})\)',
                                 sent.stdout).groups()
        after = int(sec) * 10 ** 9 + int(nanosec) \
            + int((MOVE + 0.5) * 1e9)
        assert probe.spin_until(
            lambda: live and _stamp_ns(live[-1]) >= after, 60.0), sim.log()
        out, err = interrupt(recorder, 30)
    finally:
        if recorder.poll() is None:
            recorder.kill()
            recorder.communicate()
        probe.close()
        status = [node.stop(), sim.stop()]
    assert recorder.returncode == 0, out + err
    assert 'recording /joint_states into' in out and '(reliable)' in out
    assert status == [0, 0], node.log() + sim.log()
    # the bag is a complete rosbag2 the identification commands read,
    # with every joint state the simulator published while it recorded
    # (its stamps are t0 + k 4 ms), but for those the recorder says it
    # dropped (a machine too busy to keep its lag under MAX_LAG_S)
    states = read_joint_states(str(bag), NAMES)
    # from t = 0 to 0.5 s past the trajectory's end: over 3 s at 250 Hz
    assert states.counts['messages'] == states.counts['kept'] >= 700
    steps = np.diff(states.stamps_ns)
    assert np.all(steps % 4_000_000 == 0) and np.all(steps > 0), steps
    missing = int((steps // 4_000_000 - 1).sum())
    said = re.search(r'recorded (\d+) messages .*, (none|\d+) dropped', out)
    assert said and int(said.group(1)) == len(states.stamps_ns), out
    dropped = 0 if said.group(2) == 'none' else int(said.group(2))
    assert missing <= dropped, f'{missing} states lost, {dropped} said: {out}'
    np.testing.assert_allclose(states.q[0], Q0, atol=1e-12)
    # the node filled the efforts (gravity): sent straight to the
    # simulator, the scene's soft PD alone leaves joint 2 about 0.3 rad
    # below the goal
    goal = np.array(Q0) + STEP
    assert np.abs(states.q[-1] - goal).max() < 0.01, states.q[-1] - goal


def test_send_errors_are_one_line(tmp_path):
    good = write_move(tmp_path / 'move.json')
    points = json.loads(good.read_text())['points']
    cases = {
        'not json': ('{', 'not valid JSON'),
        'names': (json.dumps({'joint_names': ['a', 'a'], 'points': points}),
                  'joint_names: must be a list of distinct'),
        'time': (json.dumps({'joint_names': NAMES, 'points': [
            points[1], points[0]]}), 'points[1].time_from_start'),
        'nan': (json.dumps({'joint_names': NAMES, 'points': [
            dict(points[0], positions=[0.0] * 5 + ['x'])]}),
            'points[0].positions: must be finite numbers'),
        'size': (json.dumps({'joint_names': NAMES, 'points': [
            dict(points[0], velocities=[0.0] * 5)]}),
            'points[0].velocities: must be a list of 6 numbers'),
    }
    for label, (text, expected) in cases.items():
        path = tmp_path / f'{label.replace(" ", "_")}.json'
        path.write_text(text)
        proc = cli('send', str(path), '--wait', '0')
        assert proc.returncode == 2, (label, proc.stderr)
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and str(path) in lines[0] \
            and expected in lines[0], (label, proc.stderr)
    # a well-formed file and nobody listening: said, and nothing hangs
    proc = cli('send', str(good), '--topic', '/nobody_here', '--wait', '0.5')
    assert proc.returncode == 1         # the graph did not answer
    assert 'no subscriber on /nobody_here after 0.5 s' in proc.stderr


def test_record_errors_are_one_line(tmp_path):
    existing = tmp_path / 'existing'
    existing.mkdir()
    for args, expected in (
            ([str(existing)], 'already exists'),
            ([str(tmp_path / 'no' / 'bag')], 'no such directory'),
            ([str(tmp_path / 'bag'), '--duration', '0'],
             '--duration: must be a finite number > 0'),
            ([str(tmp_path / 'bag'), '--max-messages', '0'],
             '--max-messages: must be >= 1'),
            ([str(tmp_path / 'bag'), '--topic', '/nobody_here', '--wait',
              '0.5'], 'no publisher on /nobody_here after 0.5 s')):
        proc = cli('record', *args)
        # 1: the graph did not answer; 2: the command line is wrong
        assert proc.returncode == (1 if 'nobody' in expected else 2), \
            (args, proc.stderr)
        assert len(proc.stderr.strip().splitlines()) == 1 \
            and expected in proc.stderr, (args, proc.stderr)
    # nothing was written where nothing could be
    assert not (tmp_path / 'bag').exists()
    assert list(existing.iterdir()) == []


def test_record_adapts_to_a_best_effort_driver(tmp_path):
    """A best-effort publisher is recorded; a wrong type is refused."""
    import time
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import JointState
    from std_msgs.msg import String
    domain = domain_id(29)
    probe = Probe(domain, name='best_effort_driver')
    pub = probe.node.create_publisher(
        JointState, 'joint_states',
        QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
    wrong = probe.node.create_publisher(String, 'not_joint_states', 10)
    bag = tmp_path / 'best_effort'
    exe = os.path.join(os.path.dirname(sys.executable), 'newton-euler')
    recorder = subprocess.Popen(
        [exe, 'record', str(bag), '--max-messages', '20'],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env=ros_env(domain))
    try:
        msg = JointState(name=NAMES, position=Q0, velocity=[0.0] * 6,
                         effort=[1.0] * 6)
        stamp = 1_000_000_000
        end = time.monotonic() + 60.0
        while recorder.poll() is None and time.monotonic() < end:
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(
                stamp, 10 ** 9)
            msg.position[0] = stamp * 1e-9
            pub.publish(msg)
            stamp += 10_000_000
            probe.spin_for(0.01)
        out, err = recorder.communicate(timeout=10)
        refused = cli('record', str(tmp_path / 'wrong'), '--topic',
                      '/not_joint_states', '--wait', '20', domain=domain)
    finally:
        if recorder.poll() is None:
            recorder.kill()
        probe.close()
    assert recorder.returncode == 0, out + err
    assert '(best effort)' in out and 'recorded 20 messages' in out, out
    states = read_joint_states(str(bag), NAMES, min_samples=1)
    assert states.counts['messages'] == 20
    assert refused.returncode == 2
    assert 'carries std_msgs/msg/String, not sensor_msgs/msg/JointState' \
        in refused.stderr
    assert not (tmp_path / 'wrong').exists()
    del wrong


def _write(path, points):
    path.write_text(json.dumps({'joint_names': NAMES, 'points': points}))
    return path


def test_send_checks_the_start_and_moves_there_slowly(tmp_path):
    """Refused off the start (offsets in one line); --move-to-start goes."""
    import re
    from sensor_msgs.msg import JointState
    from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint
    from newton_euler_ros.sim.scene import scene_dirs
    domain = domain_id(17)
    bundled = next(path for path in (
        os.path.join(d, 'puma_pick_and_place.yaml') for d in scene_dirs())
        if os.path.isfile(path))
    with open(bundled, encoding='utf-8') as fh:
        scene = fh.read().replace('duration: 5.0', 'duration: 120.0')
    (tmp_path / 'scene.yaml').write_text(scene)
    sim = NodeProcess([os.path.join(os.path.dirname(sys.executable),
                                    'robot_sim_node'), '--ros-args',
                       '-p', f'scene:={tmp_path / "scene.yaml"}',
                       '-p', 'wait_for_subscribers:=2'],
                      domain, str(tmp_path / 'sim.log'))
    node = NodeProcess(id_node_cmd(None, '-p', 'robot_file:=puma560',
                                   '-p', 'mode:=gravity', '-r',
                                   '~/trajectory_out:=/robot_sim_node/'
                                   'joint_trajectory'),
                       domain, str(tmp_path / 'node.log'))
    probe = Probe(domain, name='start_check_probe')
    live = probe.collect(JointState, 'joint_states')
    to_robot = probe.collect(JointTrajectory, '/robot_sim_node/'
                             'joint_trajectory')
    offset = np.array([0.25, 0.0, -0.15, 0.0, 0.0, 0.0])
    start = np.array(Q0) + offset
    away = [{'time_from_start': t,
             'positions': list(start + STEP * t / MOVE)}
            for t in np.arange(0.0, MOVE + 1e-9, 0.05)]
    off = _write(tmp_path / 'off.json', away)
    hold = _write(tmp_path / 'hold.json', [
        {'time_from_start': t, 'positions': list(Q0)} for t in (0.0, 1.0)])
    hold_now = probe.node.create_publisher(
        JointTrajectory, '/inverse_dynamics_node/trajectory_in', 10)
    try:
        assert probe.spin_until(lambda: live, 90.0), sim.log() + node.log()
        # the node's trajectory input and output both matched with the
        # probe, or the first command may be published to nobody
        assert probe.spin_until(
            lambda: hold_now.get_subscription_count() >= 1
            and probe.node.count_publishers(
                '/robot_sim_node/joint_trajectory') >= 1, 90.0), node.log()
        # the robot holds Q0 at once (the simulator holds t = 0 only until
        # its first command): stamped on the simulator's own timeline
        first = JointTrajectory(joint_names=NAMES)
        first.header.stamp = live[-1].header.stamp
        first.points = [JointTrajectoryPoint(positions=Q0,
                                             velocities=[0.0] * 6)]
        hold_now.publish(first)
        assert probe.spin_until(lambda: len(to_robot) == 1, 10.0)
        # at the start: sent
        held = cli('send', str(hold), '--start-in', '0', '--wait', '60',
                   domain=domain, timeout=120)
        assert held.returncode == 0, held.stdout + held.stderr
        assert "at the trajectory's first point" in held.stdout
        assert probe.spin_until(lambda: len(to_robot) == 2, 10.0)
        # off the start: refused, each joint's offset in one line, and
        # nothing reaches the robot
        refused = cli('send', str(off), '--start-in', '0', '--wait', '30',
                      domain=domain, timeout=120)
        # the inputs are good, the robot is elsewhere: status 1
        assert refused.returncode == 1, refused.stdout + refused.stderr
        lines = refused.stderr.strip().splitlines()
        assert len(lines) == 1 and 'not at the trajectory' in lines[0] \
            and '--move-to-start' in lines[0], refused.stderr
        said = dict(re.findall(r'(joint\d) ([+-]\d+\.\d+)', lines[0]))
        assert sorted(said) == NAMES, lines[0]
        np.testing.assert_allclose([float(said[n]) for n in NAMES],
                                   -offset, atol=0.01)
        probe.spin_for(1.0)
        assert len(to_robot) == 2
        # --move-to-start: a slow move there, checked, then the trajectory
        moved = cli('send', str(off), '--start-in', '0', '--wait', '30',
                    '--move-to-start', '--move-speed', '0.3',
                    domain=domain, timeout=120)
        assert moved.returncode == 0, moved.stdout + moved.stderr
        assert 'moving to the start at 0.3 rad/s' in moved.stdout
        assert 'trajectory ended' in moved.stdout
        assert probe.spin_until(lambda: len(to_robot) == 4, 10.0), \
            len(to_robot)
        # the move: rest to rest, from where the robot was, at 0.3 rad/s
        move = to_robot[2]
        first = np.array(move.points[0].positions)
        np.testing.assert_allclose(first, Q0, atol=0.01)
        np.testing.assert_allclose(move.points[-1].positions, start,
                                   atol=1e-12)
        peak = max(max(abs(v) for v in p.velocities) for p in move.points)
        assert 0.25 < peak <= 0.3 + 1e-9
        goal = start + STEP
        assert probe.spin_until(lambda: np.abs(
            np.array(live[-1].position) - goal).max() < 0.01, 20.0), \
            np.array(live[-1].position) - goal
    finally:
        probe.close()
        status = [node.stop(), sim.stop()]
    assert status == [0, 0], node.log() + sim.log()
