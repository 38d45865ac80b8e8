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
A recording survives its recorder: ``newton-euler record`` as processes.

A driver stand-in publishes JointState at 100 Hz over DDS while
``record`` writes them.  Closed by SIGHUP (a dropped ssh session) or
SIGTERM, the bag is complete.  Killed by SIGKILL (a crash, a power cut),
what it left has no metadata.yaml and an unfinished storage file, and
``replay``, ``observe`` and identify's reader read it, saying in one line
what they recovered: the messages published up to at most a second
before the kill.
"""
import os
import re
import signal
import subprocess
import sys
import time

from newton_euler_tools.processes import ros_env
import numpy as np
import pytest

pytest.importorskip('rclpy')

# After the skip: pytest must be imported first, hence E402 and I100.
from newton_euler_ros.ident.bag import read_joint_states  # noqa: E402, I100
from ros_harness import domain_id, Probe  # noqa: E402

pytestmark = pytest.mark.ros

NAMES = [f'joint{k}' for k in range(1, 7)]
RATE = 100.0
LOST_AT_MOST = 1.0          # s of recording a SIGKILL may cost


def _exe(name):
    return os.path.join(os.path.dirname(sys.executable), name)


def _cli(*args, domain):
    return subprocess.run([_exe('newton-euler'), *args], capture_output=True,
                          text=True, timeout=300, env=ros_env(domain))


class Driver:
    """Publishes a smooth motion on /joint_states; remembers what it sent."""

    def __init__(self, probe):
        from sensor_msgs.msg import JointState
        self.probe = probe
        self.pub = probe.node.create_publisher(JointState, 'joint_states',
                                               100)
        self.msg = JointState(name=NAMES)
        self.sent = []            # (stamp ns, wall time) of each message
        self.t0 = time.time_ns()
        self.next = time.monotonic()

    def step(self):
        # stamped at its control rate, as a driver's loop does
        stamp = self.t0 + len(self.sent) * int(1e9 / RATE)
        t = (stamp - self.t0) * 1e-9
        w = 2 * np.pi * 0.5
        phase = np.arange(6)
        self.msg.header.stamp.sec, self.msg.header.stamp.nanosec = divmod(
            stamp, 10 ** 9)
        self.msg.position = list(0.3 * np.sin(w * t + phase))
        self.msg.velocity = list(0.3 * w * np.cos(w * t + phase))
        self.msg.effort = list(np.sin(w * t + phase) + 0.1 * phase)
        self.pub.publish(self.msg)
        self.sent.append((stamp, time.monotonic()))
        self.next += 1.0 / RATE
        self.probe.spin_for(max(0.0, self.next - time.monotonic()))

    def run_until(self, predicate, timeout):
        end = time.monotonic() + timeout
        while not predicate():
            assert time.monotonic() < end, 'timed out'
            self.step()

    def run_for(self, seconds):
        end = time.monotonic() + seconds
        self.run_until(lambda: time.monotonic() >= end, seconds + 60)


def _record(tmp_path, domain, storage, seconds, sig):
    """Record while the driver publishes; end the recorder with ``sig``."""
    probe = Probe(domain, name='record_driver')
    driver = Driver(probe)
    bag = tmp_path / 'bag'
    rec = subprocess.Popen([_exe('newton-euler'), 'record', str(bag),
                            '--storage', storage],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           text=True, env=ros_env(domain),
                           start_new_session=True)
    try:
        driver.run_until(lambda: driver.pub.get_subscription_count() > 0
                         or rec.poll() is not None, 90.0)
        driver.run_for(seconds)
        rec.send_signal(sig)
        killed_at = time.monotonic()
        out, err = rec.communicate(timeout=60)
    finally:
        if rec.poll() is None:
            rec.kill()
        probe.close()
    sent = np.array([s for s, at in driver.sent if at < killed_at])
    # how long before the signal each message was published
    before = {s: killed_at - at for s, at in driver.sent}
    return bag, rec.returncode, out, err, sent, (driver.t0, before)


def _contiguous(recorded, sent):
    """Check that the recorded stamps are consecutive sent ones."""
    i0 = int(np.searchsorted(sent, recorded[0]))
    np.testing.assert_array_equal(recorded, sent[i0:i0 + len(recorded)])
    return i0


@pytest.mark.parametrize('sig', [signal.SIGHUP, signal.SIGTERM])
def test_sighup_and_sigterm_leave_a_complete_bag(tmp_path, sig):
    bag, code, out, err, sent, _ = _record(tmp_path, domain_id(41 + sig),
                                           'mcap', 2.0, sig)
    assert code == 0, out + err
    name = signal.Signals(sig).name
    match = re.search(r'recorded (\d+) messages .* \((\w+)\)', out)
    assert match and match.group(2) == name, out
    assert (bag / 'metadata.yaml').exists()
    states = read_joint_states(str(bag), NAMES)
    assert not states.notes, states.notes          # nothing to recover
    assert len(states) == int(match.group(1))
    _contiguous(states.stamps_ns, sent)
    # nothing lost but what was still on its way when the signal came
    assert (sent[-1] - states.stamps_ns[-1]) * 1e-9 < 0.2


# killed at different phases of record's quarter-second sync
@pytest.mark.parametrize('storage, seconds', [('mcap', 3.25),
                                              ('sqlite3', 3.45)])
def test_sigkill_loses_at_most_a_second(tmp_path, storage, seconds):
    domain = domain_id(51 + len(storage))
    bag, code, out, err, sent, (t0, before) = _record(
        tmp_path, domain, storage, seconds, signal.SIGKILL)
    assert code == -signal.SIGKILL
    assert not (bag / 'metadata.yaml').exists()
    # identify's reader: a run of what was published, up to at most a
    # second before the kill
    states = read_joint_states(str(bag), NAMES)
    assert len(states.notes) == 1 and 'no metadata.yaml' in states.notes[0]
    _contiguous(states.stamps_ns, sent)
    # the last message kept was published at most a second before the
    # kill (wall clock)
    lost = before[int(states.stamps_ns[-1])]
    print(f'{storage}: {len(states)} messages recovered, the last one '
          f'published {lost:.3f} s before the kill')
    assert 0.0 <= lost <= LOST_AT_MOST, lost
    assert len(states) > 1.5 * RATE        # over 1.5 s of 3 s kept
    np.testing.assert_allclose(
        states.q[:, 0], 0.3 * np.sin(np.pi * (states.stamps_ns - t0) * 1e-9),
        atol=1e-12)
    # replay and observe read it too, and say in one line what they read
    urdf = tmp_path / 'puma560.urdf'
    assert _cli('urdf', 'puma560', '-o', str(urdf), domain=domain) \
        .returncode == 0
    said = re.compile(rf'warning: recording {re.escape(str(bag))}: no '
                      rf'metadata.yaml; .*recovered {len(states)} messages '
                      rf'on /joint_states up to t = [0-9.]+ s from bag\.')
    replay = _cli('replay', str(urdf), str(bag), '--base', 'base_link',
                  '--tip', 'tool0', '--csv', str(tmp_path / 'r.csv'),
                  domain=domain)
    assert replay.returncode == 0, replay.stderr
    lines = [x for x in replay.stderr.splitlines() if 'recovered' in x]
    assert len(lines) == 1 and said.match(lines[0]), replay.stderr
    rows = (tmp_path / 'r.csv').read_text().splitlines()
    assert 0 < len(rows) - 1 <= len(states)
    observe = _cli('observe', 'puma560', str(bag), '--csv',
                   str(tmp_path / 'o.csv'), domain=domain)
    assert observe.returncode == 0, observe.stderr
    lines = [x for x in observe.stderr.splitlines() if 'recovered' in x]
    assert len(lines) == 1 and said.match(lines[0]), observe.stderr
