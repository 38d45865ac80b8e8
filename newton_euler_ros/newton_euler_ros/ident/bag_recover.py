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
Messages of a damaged rosbag2 recording, up to its last intact one.

A recorder that is killed (SIGKILL, a power cut) leaves a bag without
``metadata.yaml`` (rosbag2 writes it on close), and an MCAP file without
its summary and footer, or ended in the middle of a record; a copy cut
short leaves a truncated file.  ``rosbags`` opens none of these.  This
module reads them from the storage files alone:

- MCAP: the records in file order (the format's data section: a record
  is an opcode, a length and its content), schemas and channels as they
  come, messages from chunk records (uncompressed, zstd or lz4; their CRC
  checked when it is set) or outside chunks.  It stops at the first record
  that is not complete: a truncated uncompressed chunk gives the
  messages it holds up to the cut, a compressed one none.
- sqlite3: the ``topics`` table, then the ``messages`` rows in insertion
  order until one cannot be read.  The file is opened read-only and
  immutable (a killed writer's journal is left alone: what was committed
  is what is read); with a ``-wal`` file beside it, a temporary copy of
  both is opened instead so that its committed transactions count.

:func:`damage` says whether a bag needs this (no ``metadata.yaml``, an
MCAP file without its end magic, an sqlite3 file shorter than its header
says); a bag that is not damaged in these ways is read by ``rosbags`` as
before, and anything else wrong with it stays an error.
"""
from dataclasses import dataclass
import mmap
import os
import re
import shutil
import sqlite3
import struct
import tempfile
import zlib

MCAP_MAGIC = b'\x89MCAP0\r\n'
SQLITE_MAGIC = b'SQLite format 3\x00'
OP_HEADER, OP_FOOTER, OP_SCHEMA, OP_CHANNEL = 0x01, 0x02, 0x03, 0x04
OP_MESSAGE, OP_CHUNK, OP_DATA_END = 0x05, 0x06, 0x0F
MAX_RECORD = 1 << 32          # a length beyond this is garbage, not a record
# where a file cut short ends (not worth a word beyond "cut short")
CUT_RECORD = 'a record cut short'
CUT_PAGES = 'the end of the pages left'
PLAIN_CUTS = (CUT_RECORD, CUT_PAGES)


class Damaged(Exception):
    """The storage cannot be read at all (one line)."""


@dataclass
class Topic:
    """A topic of a recovered bag (as ``rosbags``' connections)."""

    key: int
    topic: str
    msgtype: str
    encoding: str
    msgcount: int = 0


def storage_files(path):
    """Return the storage files, in recording order (``X_0``, ``X_1``...)."""
    def key(name):
        m = re.search(r'_(\d+)\.(mcap|db3)$', name)
        return (int(m.group(1)) if m else -1, name)
    names = [n for n in os.listdir(path)
             if n.endswith(('.mcap', '.db3'))]
    return [os.path.join(path, n) for n in sorted(names, key=key)]


def _sqlite_short(path):
    """Return True if an sqlite3 file is shorter than its header says."""
    size = os.path.getsize(path)
    with open(path, 'rb') as fh:
        head = fh.read(100)
    if len(head) < 100 or not head.startswith(SQLITE_MAGIC):
        return True
    page = struct.unpack('>H', head[16:18])[0]
    page = 65536 if page == 1 else page
    pages = struct.unpack('>I', head[28:32])[0]
    return size < page * pages or size % page != 0


def damage(path):
    """
    Return why a rosbag2 directory must be recovered, or None if it need not.

    Reasons: no ``metadata.yaml``; an MCAP file without its end magic (cut
    before the footer); an sqlite3 file shorter than its header says.
    """
    if not os.path.isdir(path):
        return None
    files = storage_files(path)
    reasons = []
    if not os.path.exists(os.path.join(path, 'metadata.yaml')):
        if not files:
            return None         # not a bag at all: rosbags says so
        reasons.append('no metadata.yaml')
    for f in files:
        name = os.path.basename(f)
        size = os.path.getsize(f)
        if f.endswith('.mcap'):
            with open(f, 'rb') as fh:
                if size >= 8:
                    fh.seek(size - 8)
                tail = fh.read(8)
            if tail != MCAP_MAGIC or size < 16:
                reasons.append(f'{name} ends at byte {size} without its '
                               f'footer (cut short)')
        elif _sqlite_short(f):
            reasons.append(f'{name} is cut short ({size} bytes)')
    return '; '.join(reasons) or None


# ---- MCAP ------------------------------------------------------------------

def _string(buf, at):
    (n,) = struct.unpack_from('<I', buf, at)
    end = at + 4 + n
    if end > len(buf):
        raise ValueError('string past its record')
    return bytes(buf[at + 4:end]).decode('utf-8'), end


def _decompress(kind, data, size):
    if kind == '':
        return bytes(data)
    if kind == 'zstd':
        try:
            from compression import zstd
        except ImportError:
            from backports import zstd
        return zstd.decompress(bytes(data))
    if kind == 'lz4':
        from lz4.frame import decompress
        return decompress(bytes(data))
    raise ValueError(f'chunk compression {kind!r} is not supported')


class _Mcap:
    """Walks an MCAP file's records; ``self.cut`` is set where it stops."""

    def __init__(self, path):
        self.path = path
        self.schemas = {}          # id: (name, encoding)
        self.channels = {}         # id: Topic
        self.cut = None

    def _records(self, buf, at, end, inner):
        """Yield (opcode, content view, complete) of the records."""
        while at < end:
            if at + 9 > end:
                self.cut = self.cut or 'a record header cut short'
                return
            op = buf[at]
            (n,) = struct.unpack_from('<Q', buf, at + 1)
            if n > MAX_RECORD or at + 9 + n > end:
                self.cut = self.cut or CUT_RECORD
                if op == OP_CHUNK and not inner:
                    yield op, buf[at + 9:end], False  # a chunk cut short
                return
            yield op, buf[at + 9:at + 9 + n], True
            at += 9 + n
            if not inner and op == OP_DATA_END:
                return

    def _chunk(self, rec, complete):
        """Return a chunk's records (bytes), or None if none is trusted."""
        if len(rec) < 40:
            return None
        (usize,) = struct.unpack_from('<Q', rec, 16)
        (crc,) = struct.unpack_from('<I', rec, 24)
        kind, at = _string(rec, 28)
        if at + 8 > len(rec):
            return None
        (clen,) = struct.unpack_from('<Q', rec, at)
        data = rec[at + 8:at + 8 + clen]
        if len(data) < clen or not complete:
            if kind != '':
                return None
            return bytes(data)                     # up to the cut
        raw = _decompress(kind, data, usize)
        if len(raw) != usize or (crc and zlib.crc32(raw) != crc):
            self.cut = self.cut or 'a chunk whose checksum does not match'
            return None
        return raw

    def _inner(self, op, rec):
        """Yield (channel id, log time, data) of one record's messages."""
        if op == OP_SCHEMA:
            (sid,) = struct.unpack_from('<H', rec, 0)
            name, at = _string(rec, 2)
            enc, _ = _string(rec, at)
            self.schemas[sid] = (name, enc)
        elif op == OP_CHANNEL:
            cid, sid = struct.unpack_from('<HH', rec, 0)
            topic, at = _string(rec, 4)
            enc, _ = _string(rec, at)
            name = self.schemas.get(sid, ('', ''))[0]
            self.channels.setdefault(cid, Topic(cid, topic, name, enc))
        elif op == OP_MESSAGE:
            if len(rec) < 22:
                raise ValueError('a message record too short')
            cid, _, logtime, _ = struct.unpack_from('<HIQQ', rec, 0)
            yield cid, logtime, bytes(rec[22:])

    def messages(self):
        """Yield (channel id, log time ns, raw CDR) in file order."""
        with open(self.path, 'rb') as fh:
            if bytes(fh.read(8)) != MCAP_MAGIC:
                raise Damaged(f'{os.path.basename(self.path)}: not an MCAP '
                              f'file (empty, or its start is missing)')
            mm = mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ)
        try:
            yield from self._walk(memoryview(mm))
        finally:
            try:
                mm.close()
            except BufferError:    # a view still held by the caller
                pass

    def _walk(self, buf):
        self.cut = None
        try:
            for op, rec, full in self._records(buf, 8, len(buf), False):
                if op != OP_CHUNK:
                    yield from self._inner(op, rec)
                    continue
                raw = self._chunk(rec, full)
                if raw is not None:
                    mv = memoryview(raw)
                    for iop, irec, _ in self._records(mv, 0, len(mv), True):
                        yield from self._inner(iop, irec)
                if self.cut:
                    return
        except (ValueError, struct.error, UnicodeDecodeError) as err:
            self.cut = self.cut or f'a damaged record ({err})'


# ---- sqlite3 ---------------------------------------------------------------

def _varint(buf, at):
    """Read SQLite's big-endian varint at ``at``: (value, next offset)."""
    v = 0
    for i in range(8):
        byte = buf[at + i]
        v = (v << 7) | (byte & 0x7F)
        if byte < 0x80:
            return v, at + i + 1
    return (v << 8) | buf[at + 8], at + 9


def _record(payload):
    """Return an SQLite record's values (int, float, bytes, str, None)."""
    size, at = _varint(payload, 0)
    types = []
    while at < size:
        t, at = _varint(payload, at)
        types.append(t)
    out, at = [], size
    ints = {1: 1, 2: 2, 3: 3, 4: 4, 5: 6, 6: 8}
    for t in types:
        if t == 0:
            out.append(None)
        elif t in ints:
            n = ints[t]
            out.append(int.from_bytes(payload[at:at + n], 'big',
                                      signed=True))
            at += n
        elif t == 7:
            out.append(struct.unpack_from('>d', payload, at)[0])
            at += 8
        elif t in (8, 9):
            out.append(t - 8)
        elif t >= 12:
            n = (t - 12) // 2
            raw = bytes(payload[at:at + n])
            out.append(raw if t % 2 == 0
                       else raw.decode('utf-8', 'replace'))
            at += n
        else:
            raise ValueError(f'record serial type {t}')
    if at > len(payload):
        raise ValueError('record past its payload')
    return out


class _Pages:
    """
    The table rows of an sqlite3 file cut short, read page by page.

    SQLite's own reader walks the b-tree from its root, and an interior
    page written late (when the tree grew a level) may be past the cut:
    then it finds nothing.  The leaf pages of a table hold its rows
    whole, so every leaf page still in the file is read, each row
    (following overflow pages while they are in the file) with its rowid.
    """

    def __init__(self, path):
        with open(path, 'rb') as fh:
            self.buf = fh.read()
        if not self.buf.startswith(SQLITE_MAGIC) or len(self.buf) < 100:
            raise Damaged(f'{os.path.basename(path)}: not an sqlite3 file '
                          f'(empty, or its start is missing)')
        page = struct.unpack('>H', self.buf[16:18])[0]
        self.page = 65536 if page == 1 else page
        if self.page < 512 or self.page & (self.page - 1):
            raise Damaged(f'{os.path.basename(path)}: page size {page} in '
                          f'its header')
        self.usable = self.page - self.buf[20]
        self.count = len(self.buf) // self.page

    def _payload(self, at, size):
        u = self.usable
        x = u - 35
        if size <= x:
            return self.buf[at:at + size]
        m = ((u - 12) * 32 // 255) - 23
        k = m + ((size - m) % (u - 4))
        local = k if k <= x else m
        out = bytearray(self.buf[at:at + local])
        (nxt,) = struct.unpack_from('>I', self.buf, at + local)
        while len(out) < size:
            if not 1 <= nxt <= self.count:
                raise ValueError('an overflow page past the cut')
            base = (nxt - 1) * self.page
            (after,) = struct.unpack_from('>I', self.buf, base)
            out += self.buf[base + 4:base + 4 + min(u - 4, size - len(out))]
            nxt = after
        return bytes(out)

    def rows(self):
        """Yield (rowid, values) of every row on a table leaf page."""
        for number in range(1, self.count + 1):
            base = (number - 1) * self.page
            head = base + (100 if number == 1 else 0)
            if self.buf[head] != 0x0D:          # a table leaf page
                continue
            (cells,) = struct.unpack_from('>H', self.buf, head + 3)
            for c in range(cells):
                try:
                    (ptr,) = struct.unpack_from('>H', self.buf,
                                                head + 8 + 2 * c)
                    size, at = _varint(self.buf, base + ptr)
                    rowid, at = _varint(self.buf, at)
                    yield rowid, _record(self._payload(at, size))
                except (ValueError, IndexError, struct.error):
                    continue


def _is_message(values):
    return (len(values) == 4 and isinstance(values[1], int)
            and isinstance(values[2], int) and isinstance(values[3], bytes))


def _is_topic(values):
    return len(values) >= 4 and all(isinstance(v, str) for v in values[1:4])


class _Sqlite:
    """Rows of a rosbag2 sqlite3 file, in insertion order."""

    def __init__(self, path):
        self.path = path
        self.channels = {}
        self.cut = None
        self._tmp = None

    def _connect(self):
        if os.path.exists(self.path + '-wal'):
            self._tmp = tempfile.mkdtemp(prefix='newton_euler_bag_')
            copy = os.path.join(self._tmp, os.path.basename(self.path))
            shutil.copyfile(self.path, copy)
            shutil.copyfile(self.path + '-wal', copy + '-wal')
            return sqlite3.connect(f'file:{copy}', uri=True)
        return sqlite3.connect(f'file:{self.path}?immutable=1', uri=True)

    def messages(self):
        """Yield (topic id, log time ns, raw CDR) in insertion order."""
        self.cut = None
        if _sqlite_short(self.path):
            yield from self._pages()
            return
        try:
            db = self._connect()
            # a file cut short has fewer pages than its header says:
            # sqlite refuses it as corrupt unless the schema is writable
            # (the connection is immutable: nothing is written)
            db.execute('PRAGMA writable_schema=ON')
        except sqlite3.Error as err:
            raise Damaged(f'{os.path.basename(self.path)}: cannot be '
                          f'opened: {err}') from None
        try:
            try:
                for tid, name, kind, enc in db.execute(
                        'SELECT id, name, type, serialization_format '
                        'FROM topics'):
                    self.channels[tid] = Topic(tid, name, kind, enc)
            except sqlite3.Error as err:
                raise Damaged(f'{os.path.basename(self.path)}: no readable '
                              f'topics table ({err})') from None
            try:
                rows = db.execute('SELECT topic_id, timestamp, data FROM '
                                  'messages ORDER BY id')
                for row in rows:
                    yield row[0], int(row[1]), bytes(row[2])
            except (sqlite3.Error, TypeError, ValueError) as err:
                self.cut = f'a row that cannot be read ({err})'
        finally:
            db.close()
            if self._tmp:
                shutil.rmtree(self._tmp, ignore_errors=True)

    def _pages(self):
        """Yield the rows of a file cut short, from its leaf pages."""
        try:
            pages = _Pages(self.path)
        except (OSError, struct.error) as err:
            raise Damaged(f'{os.path.basename(self.path)}: cannot be '
                          f'read: {err}') from None
        messages = {}
        for rowid, values in pages.rows():
            if _is_message(values):
                messages[rowid] = values
            elif _is_topic(values) and len(values) >= 4:
                self.channels.setdefault(rowid, Topic(
                    rowid, values[1], values[2], values[3]))
        # the rows in rowid order up to the first one missing: a row
        # after a gap was recorded after one that is lost
        rowid = min(messages, default=1)
        while rowid in messages:
            _, tid, stamp, data = messages.pop(rowid)
            yield tid, stamp, data
            rowid += 1
        if messages:
            self.cut = (f'row {rowid}: {len(messages)} later rows are kept '
                        f'out (recorded after one that is lost)')
        else:
            self.cut = CUT_PAGES


def scanners(path):
    """Return one reader per storage file of a bag directory, in order."""
    out = []
    for f in storage_files(path):
        out.append(_Mcap(f) if f.endswith('.mcap') else _Sqlite(f))
    return out
