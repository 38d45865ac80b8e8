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

"""Reading JointState from real rosbag2 files (MCAP and sqlite3)."""
from newton_euler_ros.ident.bag import BagError, iter_joint_states, read_joint_states
from newton_euler_ros.ident.bag_write import write_joint_states
import numpy as np
import pytest

CHAIN = ('j1', 'j2', 'j3')
ALL = ('finger', 'j3', 'j1', 'j2')     # extra joint, other order


def _record(path, storage, m=200, velocity=True, effort=True,
            names=ALL, base_ns=1_700_000_000_123_456_789):
    rng = np.random.default_rng(1)
    t = base_ns + np.arange(m, dtype=np.int64) * 2_000_000 \
        + rng.integers(-200_000, 200_000, m)
    k = len(names)
    q = rng.normal(size=(m, k))
    qd = rng.normal(size=(m, k))
    e = rng.normal(size=(m, k))
    write_joint_states(path, t, names, q, qd if velocity else None,
                       e if effort else None, storage=storage)
    return t, q, qd, e


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_reads_chain_by_name_with_stamps(tmp_path, storage):
    bag = tmp_path / 'rec'
    t, q, qd, e = _record(bag, storage)
    js = read_joint_states(bag, CHAIN)
    cols = [ALL.index(j) for j in CHAIN]
    np.testing.assert_array_equal(js.stamps_ns, t)
    assert js.t0_ns == t[0]
    stamps, qq, vv, ee = js
    np.testing.assert_array_equal(qq, q[:, cols])
    np.testing.assert_array_equal(vv, qd[:, cols])
    np.testing.assert_array_equal(ee, e[:, cols])
    # nanosecond resolution of the differences survives the float seconds
    np.testing.assert_allclose(np.diff(stamps), np.diff(t) * 1e-9,
                               rtol=0, atol=1e-12)


def test_no_velocity_duplicates_and_backwards(tmp_path):
    bag = tmp_path / 'rec'
    rng = np.random.default_rng(2)
    m = 100
    t = 10**9 + np.arange(m, dtype=np.int64) * 10**6
    q = rng.normal(size=(m, 3))
    e = rng.normal(size=(m, 3))
    # a repeated sample with a later stamp, one with the same stamp, and
    # one going back in time
    t2 = np.concatenate([t[:10], [t[9] + 500_000], [t[10]], t[10:11],
                         [t[5]], t[11:]])
    q2 = np.concatenate([q[:10], q[9:10], q[10:11], q[10:11] + 1, q[5:6],
                         q[11:]])
    e2 = np.concatenate([e[:10], e[9:10], e[10:11], e[10:11], e[5:6],
                         e[11:]])
    # recorded in this order (the log time is monotonic)
    write_joint_states(bag, t2, CHAIN, q2, None, e2, storage='mcap',
                       logtimes_ns=10**9 + np.arange(len(t2)) * 10**6)
    js = read_joint_states(bag, CHAIN)
    assert js.qd is None
    np.testing.assert_array_equal(js.stamps_ns, t)
    np.testing.assert_array_equal(js.q, q)
    assert js.counts['duplicates'] == 2
    assert js.counts['backwards'] == 1


def test_chunks_cover_the_recording(tmp_path):
    bag = tmp_path / 'rec'
    t, q, _, _ = _record(bag, 'mcap', m=230)
    parts = list(iter_joint_states(bag, CHAIN, chunk=64))
    assert [len(p) for p in parts] == [64, 64, 64, 38]
    np.testing.assert_array_equal(
        np.concatenate([p.stamps_ns for p in parts]), t)


@pytest.mark.parametrize('case, match', [
    ('missing', 'no such bag'),
    ('corrupt', 'cannot open'),
    ('topic', "no topic '/other'"),
    ('effort', 'no effort'),
    ('joint', 'j9'),
    ('short', 'too short'),
])
def test_bad_bags_one_line(tmp_path, case, match):
    bag = tmp_path / 'rec'
    joints, topic = CHAIN, '/joint_states'
    if case == 'corrupt':
        bag.mkdir()
        (bag / 'metadata.yaml').write_text('not: [a, bag')
    elif case == 'effort':
        _record(bag, 'mcap', effort=False)
    elif case == 'short':
        _record(bag, 'sqlite3', m=10)
    elif case != 'missing':
        _record(bag, 'mcap')
        if case == 'topic':
            topic = '/other'
        else:
            joints = CHAIN + ('j9',)
    with pytest.raises(BagError, match=match) as info:
        read_joint_states(bag, joints, topic=topic)
    text = str(info.value)
    assert '\n' not in text and str(bag) in text


def _synced(path, storage, m, every):
    """Write as ``newton-euler record`` does: on the disk every few."""
    from newton_euler_ros.ident.bag_write import open_writer, sync_writer
    rng = np.random.default_rng(4)
    t = 1_700_000_000_000_000_000 + np.arange(m, dtype=np.int64) * 10 ** 7
    q = rng.normal(size=(m, len(ALL)))
    writer, conn, ts = open_writer(path, '/joint_states', storage)
    JointState = ts.types['sensor_msgs/msg/JointState']
    Header = ts.types['std_msgs/msg/Header']
    Time = ts.types['builtin_interfaces/msg/Time']
    for i in range(m):
        msg = JointState(
            header=Header(stamp=Time(sec=int(t[i]) // 10 ** 9,
                                     nanosec=int(t[i]) % 10 ** 9),
                          frame_id=''),
            name=list(ALL), position=q[i], velocity=q[i], effort=q[i])
        writer.write(conn, int(t[i]), ts.serialize_cdr(
            msg, 'sensor_msgs/msg/JointState'))
        if (i + 1) % every == 0:
            sync_writer(writer)
    writer.close()
    return t, q


def _cut(src, dst, fraction, keep_metadata):
    import shutil
    shutil.copytree(src, dst)
    data = next(p for p in dst.iterdir() if p.suffix in ('.mcap', '.db3'))
    size = data.stat().st_size
    with open(data, 'r+b') as fh:
        fh.truncate(int(size * fraction))
    if not keep_metadata:
        (dst / 'metadata.yaml').unlink()


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
@pytest.mark.parametrize('writer', ['one chunk', 'synced'])
def test_a_damaged_bag_reads_as_a_prefix(tmp_path, capsys, storage, writer):
    """
    Cut short (mid-chunk too) and without metadata.yaml: a prefix.

    The messages read equal the first ones written, as many as the
    bytes left hold (within the storage's overhead), and one line on
    stderr says how many were recovered.
    """
    m = 3000
    src = tmp_path / 'rec'
    if writer == 'synced':
        # many small MCAP chunks / sqlite3 transactions, as record writes
        t, q = _synced(src, storage, m, every=137)
    else:
        t, q, _, _ = _record(src, storage, m=m)
        q = q[:, [ALL.index(j) for j in ALL]]
    capsys.readouterr()
    cols = [ALL.index(j) for j in CHAIN]
    for i, (fraction, keep) in enumerate([
            (1.0, False), (0.93, True), (0.71, False), (0.5, True),
            (0.377, False), (0.2, False)]):
        bag = tmp_path / f'cut{i}'
        _cut(src, bag, fraction, keep)
        js = read_joint_states(bag, CHAIN, min_samples=1)
        k = len(js)
        assert (1.0 if fraction == 1.0 else fraction - 0.12) * m <= k <= m, \
            (fraction, k)
        np.testing.assert_array_equal(js.stamps_ns, t[:k])
        np.testing.assert_array_equal(js.q, q[:k][:, cols])
        lines = capsys.readouterr().err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith(
            f'warning: recording {bag}: ') and \
            f'recovered {k} messages on /joint_states' in lines[0], lines
        assert ('no metadata.yaml' in lines[0]) == (not keep)
        assert ('cut short' in lines[0]) == (fraction < 1.0)


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_what_cannot_be_recovered_stays_an_error(tmp_path, storage):
    bag = tmp_path / 'rec'
    _record(bag, storage, m=300)
    # cut before any message: nothing to recover
    empty = tmp_path / 'empty'
    _cut(bag, empty, 0.002, False)
    with pytest.raises(BagError, match='nothing can be recovered') \
            as info:
        read_joint_states(empty, CHAIN)
    assert str(empty) in str(info.value) and '\n' not in str(info.value)
    # a damaged bag without the topic: the same error as an intact one
    cut = tmp_path / 'cut'
    _cut(bag, cut, 0.6, False)
    with pytest.raises(BagError, match="no topic '/other'"):
        read_joint_states(cut, CHAIN, topic='/other')
    # a storage file that is not one
    junk = tmp_path / 'junk'
    junk.mkdir()
    (junk / f'junk.{"mcap" if storage == "mcap" else "db3"}').write_bytes(
        b'\x00' * 4096)
    with pytest.raises(BagError, match='cannot be recovered') as info:
        read_joint_states(junk, CHAIN)
    assert '\n' not in str(info.value)
