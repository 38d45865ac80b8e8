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
from newton_euler_ros.ident.bag import (BagError, iter_joint_states,
                                        read_joint_states,
                                        write_joint_states)
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


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_truncated_file(tmp_path, storage):
    bag = tmp_path / 'rec'
    _record(bag, storage, m=400)
    data = next(p for p in bag.iterdir() if p.suffix in ('.mcap', '.db3'))
    raw = data.read_bytes()
    data.write_bytes(raw[:len(raw) // 2])
    with pytest.raises(BagError) as info:
        read_joint_states(bag, CHAIN)
    assert str(bag) in str(info.value) and '\n' not in str(info.value)
