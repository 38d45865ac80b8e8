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
JointState read from its CDR bytes (``ident.cdr``) as rosbags reads it.

The bytes come from the real serialisers: rclpy's (the middleware's, what
``ros2 bag record`` and ``newton-euler record`` store) and rosbags' (what
``ident.bag_write`` stores).  Every field must equal what rosbags'
deserialiser gives; bytes the reader does not expect give None (the bag
layer then asks rosbags, which names what is wrong).
"""
from newton_euler_ros.ident.cdr import JointStateReader
import numpy as np
import pytest

TYPE = 'sensor_msgs/msg/JointState'

CASES = [
    # (frame, names, position, velocity, effort)
    ('base', ['a', 'b', 'c'], [0.1, -2.0, 3.5], [1.0, 2.0, 3.0],
     [0.5, 0.25, -0.125]),
    ('', ['joint_1'], [np.pi], [], [2.0]),
    ('x' * 7, ['wheel', 'arm_1', 'arm_2'], [1.0, 2.0], [], []),
    ('odom', [], [], [], []),
    ('ünïcode', ['gelenk_ä', 'ß'], [1e300, -0.0], [np.inf, -np.inf],
     [np.nan, 5e-324]),
    ('f', [f'panda_finger_joint{k}' * (k + 1) for k in range(9)],
     list(np.linspace(-3, 3, 9)), list(np.linspace(0, 1, 9)),
     list(np.linspace(5, 6, 9))),
]


def _rclpy_bytes(frame, names, pos, vel, eff, sec=17, nanosec=999999999):
    """
    Return the middleware's bytes of the message (serialize_message).

    rmw_fastrtps returns a buffer of its estimated size, up to 12 bytes
    past the message's end (left uninitialised); what DDS carries and a
    recorder stores ends with the message, as rosbags' serialiser ends it.
    """
    pytest.importorskip('rclpy')
    from rclpy.serialization import serialize_message
    from sensor_msgs.msg import JointState
    msg = JointState()
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, nanosec
    msg.header.frame_id = frame
    msg.name, msg.position, msg.velocity, msg.effort = (
        names, [float(x) for x in pos], [float(x) for x in vel],
        [float(x) for x in eff])
    size = len(_rosbags_bytes(frame, names, pos, vel, eff, sec, nanosec))
    return serialize_message(msg)[:size]


def _typestore():
    from rosbags.typesys import get_typestore, Stores
    return get_typestore(Stores.ROS2_JAZZY)


def _rosbags_bytes(frame, names, pos, vel, eff, sec=-3, nanosec=5):
    ts = _typestore()
    JS = ts.types[TYPE]
    Header = ts.types['std_msgs/msg/Header']
    Time = ts.types['builtin_interfaces/msg/Time']
    msg = JS(header=Header(stamp=Time(sec=sec, nanosec=nanosec),
                           frame_id=frame), name=list(names),
             position=np.array(pos, dtype=np.float64),
             velocity=np.array(vel, dtype=np.float64),
             effort=np.array(eff, dtype=np.float64))
    return bytes(ts.serialize_cdr(msg, TYPE))


def _same_as_rosbags(raw, got):
    ref = _typestore().deserialize_cdr(raw, TYPE)
    assert got is not None
    assert (got.header.stamp.sec, got.header.stamp.nanosec) == (
        ref.header.stamp.sec, ref.header.stamp.nanosec)
    assert got.header.frame_id == ref.header.frame_id
    assert list(got.name) == list(ref.name)
    for field in ('position', 'velocity', 'effort'):
        a, b = getattr(got, field), getattr(ref, field)
        assert a.dtype == np.float64 and a.tobytes() == b.tobytes(), field


@pytest.mark.parametrize('serialise', [_rclpy_bytes, _rosbags_bytes])
@pytest.mark.parametrize('case', range(len(CASES)))
def test_every_field_is_what_rosbags_reads(serialise, case):
    raw = serialise(*CASES[case])
    _same_as_rosbags(raw, JointStateReader()(raw))


def test_one_reader_follows_names_that_change_between_messages():
    read = JointStateReader()
    for case in (0, 0, 5, 0, 2, 2, 1, 5):
        raw = _rclpy_bytes(*CASES[case], sec=case)
        _same_as_rosbags(raw, read(raw))


def test_bytes_it_does_not_expect_give_none():
    raw = _rclpy_bytes(*CASES[0])
    read = JointStateReader()
    assert read(raw[:-8]) is None                 # cut short
    assert read(raw[:30]) is None
    assert read(raw + bytes(4)) is None           # bytes left over
    assert read(b'\x00\x00' + raw[2:]) is None    # big-endian CDR
    # a name's length past the end of the message
    bad = bytearray(raw)
    bad[20:24] = (10 ** 6).to_bytes(4, 'little')
    assert read(bytes(bad)) is None
    # and the reader still reads a good message after those
    _same_as_rosbags(raw, read(raw))


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
@pytest.mark.parametrize('with_qd', [True, False])
def test_a_bag_reads_the_same_as_through_rosbags(tmp_path, storage, with_qd):
    from newton_euler_ros.ident.bag import read_joint_states
    from newton_euler_ros.ident.bag_write import write_joint_states
    from rosbags.highlevel import AnyReader
    from pathlib import Path
    rng = np.random.default_rng(5)
    names = ('j1', 'j2', 'j3')
    m = 400
    stamps_ns = (1_500_000_000 + np.arange(m) * 2_000_000
                 + rng.integers(0, 100_000, m))
    q, qd, e = (rng.normal(size=(m, 3)) for _ in range(3))
    bag = tmp_path / 'bag'
    write_joint_states(str(bag), stamps_ns, names, q, qd if with_qd else None,
                       e, storage=storage)
    js = read_joint_states(str(bag), names)
    stamps = []
    with AnyReader([Path(bag)]) as reader:
        for conn, _, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            stamps.append(msg.header.stamp.sec * 10 ** 9
                          + msg.header.stamp.nanosec)
    assert js.stamps_ns.tolist() == stamps
    np.testing.assert_array_equal(js.q, q)
    if with_qd:
        np.testing.assert_array_equal(js.qd, qd)
    else:
        assert js.qd is None
    np.testing.assert_array_equal(js.effort, e)
