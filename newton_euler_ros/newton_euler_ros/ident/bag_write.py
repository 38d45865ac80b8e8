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
Write ``sensor_msgs/JointState`` to a rosbag2 recording, without ROS.

The writer is ``rosbags.rosbag2.Writer`` (MCAP or sqlite3).  ``record``
keeps what it has written on the disk as it goes (:func:`sync_writer`,
:func:`sync_directory`), so a recorder killed or a power cut loses at
most the last moments; :func:`write_joint_states` writes a whole
recording at once (the examples, benchmarks and tests).
"""
from pathlib import Path

import numpy as np

from .bag import DEFAULT_TOPIC, JOINT_STATE


def open_writer(path, topic=DEFAULT_TOPIC, storage='mcap'):
    """
    Open a rosbag2 recording of JointState on ``topic`` for writing.

    Return (writer, connection, typestore); ``writer.write(connection,
    logtime_ns, cdr_bytes)`` adds a message, ``writer.close()`` ends the
    bag.  ``storage`` is ``'mcap'`` or ``'sqlite3'``; ``path`` must not
    exist.
    """
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import get_typestore, Stores

    ts = get_typestore(Stores.ROS2_JAZZY)
    plugin = {'mcap': StoragePlugin.MCAP,
              'sqlite3': StoragePlugin.SQLITE3}[storage]
    writer = Writer(Path(path), version=9, storage_plugin=plugin)
    writer.open()
    try:
        conn = writer.add_connection(topic, JOINT_STATE, typestore=ts)
    except Exception:
        writer.close()
        raise
    return writer, conn, ts


def sync_writer(writer):
    """
    Put what ``writer`` (from :func:`open_writer`) has so far on the disk.

    MCAP: the pending chunk is closed (a complete chunk record, readable
    without the summary a close writes) and the file flushed and fsynced;
    sqlite3: the open transaction is committed (sqlite syncs on commit).
    After it, a killed process or a power cut loses nothing written
    before.  rosbags' writers keep the file and the pending chunk in
    ``writer.storage`` (rosbags 0.11).
    """
    import os
    storage = writer.storage
    if storage is None:
        return
    conn = getattr(storage, 'conn', None)
    if conn is not None:                            # sqlite3
        conn.commit()
        return
    if storage.chunk.msgs:                          # MCAP
        storage.close_chunk()
    storage.bio.flush()
    os.fsync(storage.bio.fileno())


def sync_directory(path):
    """Fsync a directory, so that the files just created in it survive."""
    import os
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def write_joint_states(path, stamps_ns, names, q, qd, effort,
                       topic=DEFAULT_TOPIC, storage='mcap',
                       logtimes_ns=None):
    """
    Write a rosbag2 recording of JointState messages (tests, examples).

    ``stamps_ns`` (m,) integer header stamps; ``q``, ``qd``, ``effort``
    (m, len(names)) arrays, ``qd`` or ``effort`` None to leave the field
    empty.  ``storage`` is ``'mcap'`` or ``'sqlite3'``; ``logtimes_ns``
    the recording times (default: the stamps).  ``path`` must not exist.
    """
    stamps_ns = np.asarray(stamps_ns, dtype=np.int64)
    logtimes = stamps_ns if logtimes_ns is None else np.asarray(
        logtimes_ns, dtype=np.int64)
    empty = np.zeros(0)
    names = list(names)
    writer, conn, ts = open_writer(path, topic, storage)
    JointState = ts.types['sensor_msgs/msg/JointState']
    Header = ts.types['std_msgs/msg/Header']
    Time = ts.types['builtin_interfaces/msg/Time']
    try:
        for i, t in enumerate(stamps_ns):
            t = int(t)
            msg = JointState(
                header=Header(stamp=Time(sec=t // 1_000_000_000,
                                         nanosec=t % 1_000_000_000),
                              frame_id=''),
                name=names,
                position=np.asarray(q[i], dtype=np.float64),
                velocity=(empty if qd is None
                          else np.asarray(qd[i], dtype=np.float64)),
                effort=(empty if effort is None
                        else np.asarray(effort[i], dtype=np.float64)))
            writer.write(conn, int(logtimes[i]),
                         ts.serialize_cdr(msg, JOINT_STATE))
    finally:
        writer.close()
