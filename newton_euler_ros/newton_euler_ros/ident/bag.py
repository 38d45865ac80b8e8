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
Read ``sensor_msgs/JointState`` from a rosbag2 recording, without ROS.

The reader is ``rosbags.highlevel.AnyReader`` (pure Python): it opens
rosbag2 directories in either storage, MCAP (Jazzy's default) or sqlite3
(Humble's default).  Each JointState is read from its CDR bytes by
``cdr.JointStateReader`` (a few microseconds); a message that reader does
not expect goes to rosbags' deserialiser, with the type definitions
stored in the bag, or the Jazzy typestore when the bag has none.

What real recordings need, and what this module does about it:

- JointState lists every joint (fingers too) in any order, and the order
  may change between publishers: the chain's joints are picked by name in
  every message.
- Time is the message's ``header.stamp`` (never the message index: stamps
  jitter and messages get lost), kept as integer nanoseconds
  (``stamps_ns``); ``stamps`` is the float time in seconds since the first
  kept sample, which keeps nanosecond resolution for any realistic length.
  A bag whose header stamps are all zero falls back to the recording
  (log) time, with a note.
- Repeated samples (the same values with a later stamp, or the same stamp
  twice) and samples whose stamp goes backwards are dropped and counted.
- Messages without an effort (or position) for the chain are dropped and
  counted; velocity may be absent: ``qd`` is then None (differentiate).
- The bag is read in chunks (:func:`iter_joint_states`), and the reader
  over windows of recording time, so a long recording never has to be in
  memory at once.

A damaged recording (no ``metadata.yaml``, a storage file cut short: a
recorder killed, a power cut, a copy cut off) is read up to its last
intact message (``ident.bag_recover``), and one line on stderr says what
was recovered.  Every other problem with the file raises
:class:`BagError` with one line naming the bag and what is wrong
(missing, corrupt, no such topic, no effort, a chain joint missing, too
short).
"""
from dataclasses import dataclass, field
import os
from pathlib import Path
import sys

import numpy as np

from .cdr import JointStateReader
from ..core.errors import NewtonEulerError
from ..core.text import clip

DEFAULT_TOPIC = '/joint_states'
JOINT_STATE = 'sensor_msgs/msg/JointState'
# Fewer kept samples than this is "too short" to filter and fit.
MIN_SAMPLES = 50
DEFAULT_CHUNK = 65536
# recording time read per reader call (see _windowed)
WINDOW_NS = 30 * 1_000_000_000


class BagError(NewtonEulerError, ValueError):
    """A recording cannot be used; the message is one line naming the bag."""


@dataclass
class JointStates:
    """
    Samples of the chain's joints, in the order of ``names``.

    Unpacks as ``stamps, q, qd, effort``.  ``stamps`` are seconds since
    ``t0_ns`` (the first kept stamp of the recording); ``stamps_ns`` the
    absolute header stamps in integer nanoseconds.
    """

    stamps: np.ndarray
    q: np.ndarray
    qd: object
    effort: np.ndarray
    stamps_ns: np.ndarray
    names: tuple
    t0_ns: int = 0
    counts: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)

    def __iter__(self):
        """Unpack as (stamps, q, qd, effort)."""
        return iter((self.stamps, self.q, self.qd, self.effort))

    def __len__(self):
        """Return the number of samples."""
        return len(self.stamps_ns)


def _label(path):
    return str(path)


def _open(path):
    """Open the bag with AnyReader; BagError on any failure."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import get_typestore, Stores

    p = Path(path)
    label = _label(path)
    if not p.exists():
        raise BagError(f'{label}: no such bag (file or directory)')
    try:
        reader = AnyReader(
            [p], default_typestore=get_typestore(Stores.ROS2_JAZZY))
        reader.open()
    except Exception as err:  # noqa: BLE001 (rosbags raises many kinds)
        raise BagError(f'{label}: cannot open the bag (corrupt, truncated '
                       f'or not a rosbag2 recording): {_one_line(err)}'
                       ) from None
    return reader


def _one_line(err):
    text = ' '.join(str(err).split()) or type(err).__name__
    return text if len(text) <= 200 else text[:197] + '...'


def _decode_one(deserialize, raw, msgtype, label, topic, counts):
    """Decode one message (counted); BagError naming it if it cannot be."""
    try:
        msg = deserialize(raw, msgtype)
    except Exception as err:  # noqa: BLE001
        raise BagError(f'{label}: message {counts["messages"]} on '
                       f'{topic!r} cannot be decoded (corrupt '
                       f'bag?): {_one_line(err)}') from None
    counts['messages'] += 1
    return msg


def _decoder(deserialize, label, topic, counts):
    """
    Return decode(raw, msgtype): JointState's own reader, else rosbags'.

    ``cdr.JointStateReader`` reads a JointState in a few microseconds;
    a message it does not read (not little-endian CDR, a length that does
    not fit) goes to rosbags' ``deserialize``, which says what is wrong.
    """
    fast = JointStateReader()

    def decode(raw, msgtype):
        msg = fast(raw) if msgtype == JOINT_STATE else None
        if msg is None:
            return _decode_one(deserialize, raw, msgtype, label, topic,
                               counts)
        counts['messages'] += 1
        return msg
    return decode


def _connections(connections, label, topic):
    conns = [c for c in connections if c.topic == topic]
    if not conns:
        topics = sorted({c.topic for c in connections})
        shown = ', '.join(topics[:8]) + (' ...' if len(topics) > 8 else '')
        raise BagError(f'{label}: no topic {topic!r} in the bag (topics: '
                       f'{shown or "none"})')
    bad = [c.msgtype for c in conns if c.msgtype != JOINT_STATE]
    if bad:
        raise BagError(f'{label}: topic {topic!r} carries {bad[0]}, not '
                       f'{JOINT_STATE}')
    return conns


# ---- the reading layer: a bag, possibly damaged, as decoded messages ------

_REPORTED = set()


def _report(line):
    """Say once per process, on stderr, what was recovered of a bag."""
    if line not in _REPORTED:
        _REPORTED.add(line)
        print(f'warning: {line}', file=sys.stderr, flush=True)


def bag_messages(path, topic=DEFAULT_TOPIC, counts=None, notes=None):
    """
    Yield (log time ns, decoded message) of ``topic``, in recording order.

    An intact bag is read by ``rosbags``; a damaged one (see
    ``bag_recover.damage``) up to its last intact message, and one line
    on stderr (and in ``notes``) says what was recovered.  ``counts``
    ['messages'] counts the messages decoded.  Raises :class:`BagError`:
    no bag, no such topic, a topic of another type or without messages, a
    message that cannot be decoded, or a corrupt bag.
    """
    from .bag_recover import damage
    counts = {'messages': 0} if counts is None else counts
    label = _label(path)
    if not Path(path).exists():
        raise BagError(f'{label}: no such bag (file or directory)')
    why = damage(str(path))
    if why is None:
        reader = _open(path)
        try:
            conns = _connections(reader.connections, label, topic)
            if sum(c.msgcount for c in conns) == 0:
                raise BagError(f'{label}: topic {topic!r} has no messages')
            yield from _decoded(reader, conns, label, topic, counts)
        finally:
            try:
                reader.close()
            except Exception:  # noqa: BLE001, S110 (already failing)
                pass
        return
    yield from _recovered(path, label, topic, why, counts, notes)


def _scan(path, label):
    """Storage scanners of a damaged bag, with a first pass done."""
    from .bag_recover import Damaged, scanners
    scans = scanners(str(path))
    stats = {'first': None, 'last': None, 'count': {}}
    for scan in scans:
        try:
            for cid, logtime, _ in scan.messages():
                c = stats['count']
                c[(scan.path, cid)] = c.get((scan.path, cid), 0) + 1
                if stats['first'] is None:
                    stats['first'] = logtime
                stats['last'] = logtime
        except Damaged as err:
            raise BagError(f'{label}: cannot be recovered: {err}') from None
    return scans, stats


def _recovered(path, label, topic, why, counts, notes):
    """Messages of a damaged bag; one line says what was recovered."""
    from rosbags.typesys import get_typestore, Stores
    from .bag_recover import PLAIN_CUTS
    scans, stats = _scan(path, label)
    conns = []
    for scan in scans:
        for cid, conn in scan.channels.items():
            conn.msgcount = stats['count'].get((scan.path, cid), 0)
            conns.append(conn)
    files = ', '.join(os.path.basename(s.path) for s in scans)
    if not conns:
        raise BagError(f'{label}: {why}; nothing can be recovered from '
                       f'{files} (it ends before its first message)')
    conns = _connections(conns, label, topic)
    total = sum(c.msgcount for c in conns)
    cut = '; '.join(f'{os.path.basename(s.path)} stops at {s.cut}'
                    for s in scans if s.cut and s.cut not in PLAIN_CUTS)
    if total == 0:
        raise BagError(f'{label}: {why}; no message on {topic!r} can be '
                       f'recovered from {files}')
    seconds = (stats['last'] - stats['first']) * 1e-9
    line = (f'recording {label}: {why}; recovered {total} messages on '
            f'{topic} up to t = {seconds:.1f} s from {files}'
            + (f' ({cut})' if cut else ''))
    _report(line)
    if notes is not None:
        notes.append(line)
    decode = _decoder(get_typestore(Stores.ROS2_JAZZY).deserialize_cdr,
                      label, topic, counts)
    for scan in scans:
        wanted = {cid for cid, c in scan.channels.items() if c.topic == topic}
        for cid, logtime, raw in scan.messages():
            if cid not in wanted:
                continue
            yield logtime, decode(raw, JOINT_STATE)


def recovered_seconds(path):
    """Length (log time, s) of a damaged bag's readable part, or None."""
    from .bag_recover import damage
    if not Path(path).is_dir() or damage(str(path)) is None:
        return None
    _, stats = _scan(path, _label(path))
    if stats['first'] is None:
        return 0.0
    return (stats['last'] - stats['first']) * 1e-9


class _Selector:
    """Index of each chain joint in a message's name list (cached)."""

    def __init__(self, joint_names, label, topic):
        self.joint_names = tuple(joint_names)
        self.label = label
        self.topic = topic
        self.cache = {}

    def __call__(self, names):
        key = tuple(names)
        idx = self.cache.get(key)
        if idx is None:
            where = {name: i for i, name in enumerate(key)}
            missing = [j for j in self.joint_names if j not in where]
            if missing:
                idx = missing
            else:
                idx = np.array([where[j] for j in self.joint_names])
                idx = (idx, int(idx.max(initial=-1)))
            self.cache[key] = idx
        return idx

    def names_seen(self):
        """Every joint name the messages had, in order of appearance."""
        return list(dict.fromkeys(n if n.isprintable() else repr(n)
                                  for key in self.cache for n in key))


def _pick(values, idx, top):
    """values[idx] as float64, or None when ``values`` has no entry top."""
    if len(values) <= top:
        return None
    return np.asarray(values, dtype=np.float64)[idx]


def _decoded(reader, conns, label, topic, counts):
    """Yield (logtime, message) on ``conns`` in order; BagError if corrupt."""
    stream = _windowed(reader, conns)
    decode = _decoder(reader.deserialize, label, topic, counts)
    while True:
        try:
            conn, logtime, raw = next(stream)
        except StopIteration:
            return
        except Exception as err:  # noqa: BLE001
            raise BagError(f'{label}: the bag is corrupt or truncated '
                           f'after {counts["messages"]} messages: '
                           f'{_one_line(err)}') from None
        yield logtime, decode(raw, conn.msgtype)


class _Samples:
    """
    The chain's samples (t ns, q, qd or None, effort) of JointStates.

    ``take`` returns None for a message it drops, and counts why: a
    chain joint missing, no position or effort, a stamp going back, a
    duplicate.  Zero header stamps: the recording time is used instead.
    """

    def __init__(self, select, counts, notes):
        self.select, self.counts, self.notes = select, counts, notes
        self.last_t = self.last_vals = None
        self.have_qd = True
        self.use_logtime = None
        self.missing_seen = None

    def take(self, logtime, msg):
        idx = self.select(msg.name)
        if isinstance(idx, list):
            self.counts['missing_joint'] += 1
            self.missing_seen = idx
            return None
        idx, top = idx
        q = _pick(msg.position, idx, top)
        if q is None:
            self.counts['no_position'] += 1
            return None
        e = _pick(msg.effort, idx, top)
        if e is None:
            self.counts['no_effort'] += 1
            return None
        v = _pick(msg.velocity, idx, top)
        if v is None:
            self.have_qd = False
        t = self._time(logtime, msg.header.stamp)
        vals = (q.tobytes(), None if v is None else v.tobytes(), e.tobytes())
        if self.last_t is not None:
            if t < self.last_t:
                self.counts['backwards'] += 1
                return None
            if t == self.last_t or (vals == self.last_vals
                                    and not _has_nan(q, v, e)):
                self.counts['duplicates'] += 1
                return None
        self.last_t, self.last_vals = t, vals
        self.counts['kept'] += 1
        return t, q, v, e

    def _time(self, logtime, stamp):
        stamp = stamp.sec * 1_000_000_000 + stamp.nanosec
        if self.use_logtime is None:
            self.use_logtime = stamp == 0
            if self.use_logtime:
                self.notes.append('header stamps are zero: using the '
                                  'recording time')
        return int(logtime) if self.use_logtime else int(stamp)


class _Chunk:
    """Preallocated arrays filled with samples, emptied as JointStates."""

    def __init__(self, size, n):
        self.t = np.empty(size, dtype=np.int64)
        self.q, self.v, self.e = (np.empty((size, n)) for _ in range(3))
        self.k = 0
        self.t0 = None

    def add(self, t, q, v, e):
        """Store one sample; return True when the chunk is full."""
        if self.t0 is None:
            self.t0 = t
        k = self.k
        self.t[k], self.q[k], self.e[k] = t, q, e
        self.v[k] = v if v is not None else np.nan
        self.k += 1
        return self.k == len(self.t)

    def take(self, have_qd, names, counts, notes):
        """Return the samples stored as JointStates and empty the chunk."""
        k, self.k = self.k, 0
        t = self.t[:k].copy()
        return JointStates(
            stamps=(t - self.t0) * 1e-9, q=self.q[:k].copy(),
            qd=self.v[:k].copy() if have_qd else None,
            effort=self.e[:k].copy(), stamps_ns=t, names=names,
            t0_ns=self.t0, counts=dict(counts), notes=list(notes))


def iter_joint_states(path, joint_names, topic=DEFAULT_TOPIC,
                      chunk=DEFAULT_CHUNK, min_samples=MIN_SAMPLES):
    """
    Yield :class:`JointStates` chunks of at most ``chunk`` kept samples.

    Stamps are strictly increasing across chunks (duplicates and samples
    going back in time are dropped).  The last chunk's ``counts`` hold the
    totals for the whole bag: ``messages``, ``kept``, ``duplicates``,
    ``backwards``, ``no_effort``, ``no_position``, ``missing_joint``.
    Raises :class:`BagError` (before the first chunk when it can: missing
    bag, topic or joints; else when found, e.g. a truncated file).
    """
    label = _label(path)
    joint_names = tuple(joint_names)
    counts = {'messages': 0, 'kept': 0, 'duplicates': 0, 'backwards': 0,
              'no_effort': 0, 'no_position': 0, 'missing_joint': 0}
    notes = []
    samples = _Samples(_Selector(joint_names, label, topic), counts, notes)
    buf = _Chunk(chunk, len(joint_names))
    for logtime, msg in bag_messages(path, topic, counts, notes):
        sample = samples.take(logtime, msg)
        if sample is not None and buf.add(*sample):
            yield buf.take(samples.have_qd, joint_names, counts, notes)
    _check_totals(label, topic, counts, samples.missing_seen, min_samples,
                  samples.select.names_seen())
    if buf.k:
        yield buf.take(samples.have_qd, joint_names, counts, notes)


def _windowed(reader, conns, window_ns=WINDOW_NS):
    """
    Messages of ``conns`` in recording-time windows, in order.

    One ``messages()`` call over a whole MCAP file primes a reader for
    every chunk at once (memory grows with the recording); consecutive
    windows keep only the chunks of one window open.
    """
    start, end = reader.start_time, reader.end_time
    t = start
    while t < end:
        yield from reader.messages(connections=conns, start=t,
                                   stop=min(t + window_ns, end))
        t += window_ns


def _has_nan(*arrays):
    # a NaN is never the same value again (as np.array_equal has it)
    return any(a is not None and np.isnan(a).any() for a in arrays)


def _check_totals(label, topic, counts, missing_seen, min_samples,
                  names_seen=()):
    if counts['kept'] >= min_samples:
        return
    if counts['kept'] == 0 and counts['missing_joint'] and missing_seen:
        # every missing joint, and the names the messages do have
        raise BagError(
            f'{label}: chain joint(s) {clip(", ".join(missing_seen), 600)} '
            f'not in the JointState messages on {topic!r}; they name '
            f'{len(names_seen)} joint(s): '
            f'{clip(", ".join(names_seen), 600) or "none"}')
    if counts['kept'] == 0 and counts['no_effort']:
        raise BagError(f'{label}: the JointState messages on {topic!r} '
                       'have no effort field (this command needs '
                       'efforts)')
    if counts['kept'] == 0 and counts['no_position']:
        raise BagError(f'{label}: the JointState messages on {topic!r} '
                       'have no position field')
    raise BagError(f'{label}: too short: {counts["kept"]} usable samples '
                   f'on {topic!r}, need at least {min_samples}')


def read_joint_states(path, joint_names, topic=DEFAULT_TOPIC,
                      min_samples=MIN_SAMPLES, chunk=DEFAULT_CHUNK):
    """
    Read the whole recording of ``joint_names`` from ``topic``.

    Returns a :class:`JointStates`, which unpacks as
    ``stamps, q, qd, effort``: stamps (m,) float seconds since the first
    stamp (``t0_ns``), q (m, n), qd (m, n) or None when the messages carry
    no velocity, effort (m, n).  Raises :class:`BagError`.
    """
    parts = list(iter_joint_states(path, joint_names, topic, chunk=chunk,
                                   min_samples=min_samples))
    last = parts[-1]
    qd = None if any(p.qd is None for p in parts) else np.concatenate(
        [p.qd for p in parts])
    return JointStates(
        stamps=np.concatenate([p.stamps for p in parts]),
        q=np.concatenate([p.q for p in parts]), qd=qd,
        effort=np.concatenate([p.effort for p in parts]),
        stamps_ns=np.concatenate([p.stamps_ns for p in parts]),
        names=last.names, t0_ns=last.t0_ns, counts=last.counts,
        notes=last.notes)


def recording_seconds(path):
    """Return the recording's length in seconds (log time), or BagError."""
    seconds = recovered_seconds(path)
    if seconds is not None:
        return seconds
    reader = _open(path)
    try:
        return reader.duration * 1e-9
    except Exception:  # noqa: BLE001 (an empty bag has no times)
        return 0.0
    finally:
        reader.close()
