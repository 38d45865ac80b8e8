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
``sensor_msgs/JointState`` read straight from its CDR bytes.

rosbags' deserialiser reads any type from its definition, in Python, at
about 70 us a message: two thirds of the time ``identify`` spent on a
long recording.  A JointState's layout is fixed, and a recording's
messages repeat their frame and joint names, so :class:`JointStateReader`
reads the stamp with one struct call, compares the frame and names with
the last message's bytes (decoding them only when they change), and
takes the three arrays as views of the bytes.

Only what it knows is read here: little-endian CDR (what every ROS 2
middleware writes), every length inside the message, at most three
bytes of padding left over (as rosbags).  Anything else gives None, and the caller
deserialises the message with rosbags, which reads what it can and says
what is wrong with the rest.
"""
import struct

import numpy as np

_U32 = struct.Struct('<I')
_STAMP = struct.Struct('<iI')
_CDR_LE = b'\x00\x01'
_F8 = np.dtype('<f8')
_EMPTY = np.zeros(0)
_EMPTY.flags.writeable = False


class Stamp:
    """builtin_interfaces/Time: ``sec``, ``nanosec``."""

    __slots__ = ('sec', 'nanosec')

    def __init__(self, sec, nanosec):
        self.sec, self.nanosec = sec, nanosec


class Header:
    """std_msgs/Header: ``stamp``, ``frame_id``."""

    __slots__ = ('stamp', 'frame_id')

    def __init__(self, stamp, frame_id):
        self.stamp, self.frame_id = stamp, frame_id


class JointState:
    """sensor_msgs/JointState: names a tuple, arrays read-only views."""

    __slots__ = ('header', 'name', 'position', 'velocity', 'effort')

    def __init__(self, header, name, position, velocity, effort):
        self.header, self.name = header, name
        self.position, self.velocity, self.effort = (position, velocity,
                                                     effort)


def _align(offset, size):
    # CDR aligns to the size of the value, counted from the data's start
    # (after the 4-byte encapsulation header)
    return 4 + -(-(offset - 4) // size) * size


def _string(raw, o, end):
    """Return (text, next offset) of the CDR string at ``o``."""
    o = _align(o, 4)
    (size,) = _U32.unpack_from(raw, o)
    stop = o + 4 + size
    if size == 0 or stop > end or raw[stop - 1] != 0:
        raise ValueError('bad string')
    return bytes(raw[o + 4:stop - 1]).decode('utf-8'), stop


class JointStateReader:
    """Read JointState messages of one recording; None where it cannot."""

    def __init__(self):
        self._prefix = b''      # the frame and names of the last message
        self._frame = ''
        self._names = ()

    def __call__(self, raw):
        """Return a :class:`JointState` of the CDR bytes ``raw``, or None."""
        try:
            return self._read(raw)
        except (struct.error, ValueError, UnicodeDecodeError):
            return None

    def _read(self, raw):
        end = len(raw)
        if end < 24 or raw[:2] != _CDR_LE:
            return None
        sec, nanosec = _STAMP.unpack_from(raw, 4)
        start = 12
        size = len(self._prefix)
        if size and raw[start:start + size] == self._prefix:
            o, frame, names = start + size, self._frame, self._names
        else:
            frame, o = _string(raw, start, end)
            o = _align(o, 4)
            (count,) = _U32.unpack_from(raw, o)
            if 4 * count > end - o:
                return None
            o += 4
            names = []
            for _ in range(count):
                name, o = _string(raw, o, end)
                names.append(name)
            names = tuple(names)
            self._prefix = bytes(raw[start:o])
            self._frame, self._names = frame, names
        arrays = []
        for _ in range(3):
            o = (o + 3) & ~3
            (count,) = _U32.unpack_from(raw, o)
            o += 4
            if count == 0:
                arrays.append(_EMPTY)
                continue
            o = 4 + ((o + 3) & ~7)      # 8-aligned from the data's start
            if 8 * count > end - o:
                return None
            arrays.append(np.frombuffer(raw, _F8, count, o))
            o += 8 * count
        if not 0 <= end - o < 4:       # as rosbags: padding to 4 at most
            return None
        return JointState(Header(Stamp(sec, nanosec), frame), names,
                          *arrays)
