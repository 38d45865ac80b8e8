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
``newton-euler record``: JointState to a rosbag2 that survives a crash.

Each message is written raw (no decoding), with the time it arrived
(the middleware's reception time) as its recording time.  The recorder
wakes every ``POLL_S`` seconds and takes every message waiting, with no
executor (which woke for each message and cost about 0.6 ms of Python a
message: a third of a core at 500 Hz), and keeps its lag bounded:

- a message taken more than ``MAX_LAG_S`` after it was published is
  dropped and counted, so that the recorder catches up rather than
  lagging without bound on a machine too busy to give it the CPU it
  needs (the lag: the time since the middleware received it, plus its
  delivery delay beyond the least seen lately, which cancels an offset
  between the publisher's clock and this one);
- a gap in the publisher's sequence numbers (the middleware discarded
  messages before the recorder took them) is counted as dropped too,
  when one publisher is on the topic (several publishers' numbers
  interleave);
- what is written reaches the disk every ``SYNC_S`` seconds (a closed
  MCAP chunk, fsynced; a committed sqlite3 transaction), checked at
  each wake-up and every 50 messages of a long batch.

So a SIGKILL or a power cut loses at most ``MAX_LAG_S + SYNC_S`` of
recording, and the reading commands recover the rest.  Drops are
reported on stderr at once, then every ``REPORT_S`` seconds while they
happen, and in the final line.
"""
import os
import shutil
import signal
import sys
import time

from .cli_ros import (_check_seconds, _Ros, _say, JOINT_STATE, RosCliError,
                      RosGraphError)

MAX_LAG_S = 0.5       # a message taken later than this is dropped, counted
SYNC_S = 0.25         # what is recorded is on the disk this often
REPORT_S = 5.0        # drops are reported this often while they happen
POLL_S = 0.02         # the waiting messages are taken this often
DRAIN = 1000          # messages taken at one wake-up at most
SKEW_WINDOW_S = 2.0   # the middleware's least delay is taken over this
CLOCK_SANITY_NS = 3600 * 10 ** 9   # a reception time this far off: unusable


class Recorder:
    """Writes raw JointState messages to the bag, in batches, lag bounded."""

    def __init__(self, args, max_lag_s=MAX_LAG_S, sync_s=SYNC_S,
                 report_s=REPORT_S):
        """Record as ``args`` (the command line) say; nothing open yet."""
        self.args = args
        self.writer = self.conn = self.sub = self.msg_type = None
        self.count = self.late = self.missed = 0
        self.first = self.last = None
        self.lag_ns = 0                   # the largest lag of a kept message
        self._max_lag = int(max_lag_s * 1e9)
        self._sync_s, self._report_s = sync_s, report_s
        self._seq = None
        self._skews, self._window_at = [None, None], time.monotonic()
        self._synced = 0
        self._sync_at = self._report_at = time.monotonic()
        self._reported = 0

    @property
    def dropped(self):
        """Messages not recorded: taken too late, or never received."""
        return self.late + self.missed

    def start(self):
        """Create the bag and put its start on the disk."""
        from .ident.bag_write import open_writer, sync_directory, sync_writer
        self.writer, self.conn, _ = open_writer(self.args.bag,
                                                self.args.topic,
                                                self.args.storage)
        self._sync_writer = sync_writer
        sync_writer(self.writer)
        sync_directory(self.args.bag)
        sync_directory(os.path.dirname(os.path.abspath(self.args.bag)))

    def attach(self, sub, msg_type):
        """Take the waiting messages of ``sub`` at each wake-up."""
        self.sub, self.msg_type = sub, msg_type

    def sync(self):
        """Put what is recorded on the disk (after a batch, and a timer)."""
        self._sync_at = time.monotonic()
        if self.writer is not None and self.count != self._synced:
            self._sync_writer(self.writer)
            self._synced = self.count

    def __call__(self, raw, info):
        """Write this message, then every one waiting (:meth:`poll`)."""
        self._one(raw, info)
        self.poll()

    def poll(self):
        """Write every message waiting; sync and report when due."""
        if self.sub is not None:
            handle = self.sub.handle
            with handle:
                for k in range(1, DRAIN):
                    if self.done():
                        break
                    taken = handle.take_message(self.msg_type, True)
                    if taken is None:
                        break
                    self._one(*taken)
                    if k % 50 == 0:       # a long batch on a starved CPU
                        self._due()
        self._due()

    def _due(self):
        """Sync and report when their time has come."""
        now = time.monotonic()
        if now - self._sync_at >= self._sync_s:
            self.sync()
        if now - self._report_at >= self._report_s or (
                self.dropped and not self._reported):      # the first at once
            self._report(now)

    def _one(self, raw, info):
        if self.done():
            return
        now = time.time_ns()
        arrived = info.get('received_timestamp') or 0
        if abs(now - arrived) > CLOCK_SANITY_NS:
            arrived = now                 # no usable reception time
        self._sequence(info.get('publication_sequence_number'))
        lag = now - arrived + self._delivery(arrived,
                                             info.get('source_timestamp'))
        if lag > self._max_lag:
            self.late += 1
            return
        self.writer.write(self.conn, arrived, raw)
        self.count += 1
        self.lag_ns = max(self.lag_ns, lag)
        self.first = arrived if self.first is None else self.first
        self.last = arrived if self.last is None else max(self.last, arrived)

    def _delivery(self, arrived, sent):
        """
        Return the middleware's delay of this message beyond its least.

        Reception minus publication times, less their least over the
        last one to two ``SKEW_WINDOW_S``: the publisher's clock may be
        offset from this one (another computer), and a step of either
        clock is forgotten within that window.  The middleware's threads
        in this process starve as the recorder does, so their delay is
        part of the lag.
        """
        if not sent:
            return 0
        skew = arrived - sent
        now = time.monotonic()
        if now - self._window_at >= SKEW_WINDOW_S:
            self._window_at, self._skews = now, [self._skews[1], None]
        low = self._skews[1]
        self._skews[1] = skew if low is None else min(low, skew)
        least = min(x for x in self._skews if x is not None)
        return skew - least

    def _sequence(self, seq):
        """Count a gap in one publisher's sequence numbers as dropped."""
        if not seq:
            return
        last, self._seq = self._seq, seq
        if last is not None and seq > last + 1 and self.sub is not None \
                and self.sub.handle.get_publisher_count() == 1:
            self.missed += seq - last - 1

    def _report(self, now):
        if self.dropped > self._reported:
            _say(f'newton-euler: record: {self.dropped - self._reported} '
                 f'messages dropped in the last {now - self._report_at:.1f} s '
                 f'({self.dropped} dropped so far: {self.why()})',
                 sys.stderr)
            self._reported = self.dropped
        self._report_at = now

    def why(self):
        """Return what the drops were, in words."""
        parts = []
        if self.late:
            parts.append(f'{self.late} more than {self._max_lag * 1e-9:g} s '
                         f'behind the stream, the machine too busy to keep '
                         f'up')
        if self.missed:
            parts.append(f'{self.missed} never received (gaps in the '
                         f"publisher's sequence numbers)")
        return '; '.join(parts)

    def done(self):
        """Return whether --max-messages or --duration is reached."""
        a = self.args
        return ((a.max_messages is not None and self.count >= a.max_messages)
                or (a.duration is not None and self.first is not None
                    and self.last - self.first >= a.duration * 1e9))

    def close(self):
        """End the bag (metadata.yaml, the MCAP summary)."""
        if self.writer is not None:
            self.writer.close()


def check_record_args(args):
    """Refuse a bad command line in one line (RosCliError)."""
    bag = args.bag
    if os.path.lexists(bag):
        raise RosCliError(f'{bag}: already exists (a recording is never '
                          f'overwritten)')
    parent = os.path.dirname(os.path.abspath(bag))
    if not os.path.isdir(parent):
        raise RosCliError(f'{bag}: no such directory {parent}')
    _check_seconds(args.wait, '--wait')
    if args.duration is not None:
        _check_seconds(args.duration, '--duration', allow_zero=False)
    if args.max_messages is not None and args.max_messages < 1:
        raise RosCliError(f'--max-messages: must be >= 1, got '
                          f'{args.max_messages}')


def _publishers(ros, topic):
    """(types, any best effort) of the publishers on ``topic``."""
    from rclpy.qos import ReliabilityPolicy
    infos = ros.node.get_publishers_info_by_topic(topic)
    return ({i.topic_type for i in infos},
            any(i.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT
                for i in infos))


def cmd_record(args):
    """Record JointState messages into a new rosbag2."""
    check_record_args(args)
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import JointState
    ros = _Ros('newton_euler_record')
    rec = Recorder(args)
    try:
        topic = ros.node.resolve_topic_name(args.topic)
        if not ros.spin_until(lambda: _publishers(ros, topic)[0],
                              args.wait):
            if ros.stop:
                return 130
            raise RosGraphError(f'no publisher on {topic} after '
                                f'{args.wait:g} s (is the robot driver '
                                f'running, in this ROS_DOMAIN_ID?)')
        types, best_effort = _publishers(ros, topic)
        if types != {JOINT_STATE}:
            raise RosCliError(f'{topic} carries {", ".join(sorted(types))}, '
                              f'not {JOINT_STATE}')
        rec.start()
        rec.attach(ros.node.create_subscription(
            JointState, topic, rec, QoSProfile(
                depth=1000, reliability=ReliabilityPolicy.BEST_EFFORT
                if best_effort else ReliabilityPolicy.RELIABLE), raw=True),
            JointState)
        _say(f'recording {topic} into {args.bag} '
             f'({"best effort" if best_effort else "reliable"}); Ctrl-C '
             f'stops')
        # no executor: it would wake for each message (0.6 ms of Python
        # each); the middleware's threads fill the subscription's queue
        while not rec.done() and not ros.stop:
            rec.poll()
            time.sleep(POLL_S)
        rec.poll()                        # what came before the signal
    finally:
        rec.close()
        ros.close()
    if not rec.count:
        if rec.writer is not None:
            shutil.rmtree(args.bag, ignore_errors=True)
        more = f' ({rec.dropped} dropped: {rec.why()})' if rec.dropped else ''
        _say(f'newton-euler: no message received on {args.topic}; no bag '
             f'written{more}', sys.stderr)
        return 1
    seconds = (rec.last - rec.first) * 1e-9
    how = {signal.SIGINT: ' (Ctrl-C)', signal.SIGTERM: ' (SIGTERM)',
           signal.SIGHUP: ' (SIGHUP)'}.get(ros.stop[0] if ros.stop else None,
                                           '')
    drops = (f'{rec.dropped} dropped: {rec.why()}' if rec.dropped
             else 'none dropped')
    _say(f'recorded {rec.count} messages on {topic} over {seconds:.1f} s '
         f'into {args.bag}; largest lag behind the stream '
         f'{rec.lag_ns * 1e-9:.3f} s, {drops}{how}')
    return 0
