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

"""The observer's bench, example recording and targets run end to end."""
from newton_euler_tools import (bench_observer, observer_example,
                                observer_targets)
import numpy as np
import pytest


def test_bench_observer_runs(capsys):
    assert bench_observer.main(['--quick', '--robot', 'planar_2r']) == 0
    out = capsys.readouterr().out
    assert 'observer update' in out and 'us per JointState' in out
    assert 'with separate D, C, g, J calls' in out


@pytest.mark.parametrize('robot', ['panda', 'stanford', 'planar_rp'])
def test_bench_compares_like_with_like(robot):
    """The bench's separate-passes update is the observer's, to round-off."""
    import warnings
    from newton_euler_ros.core import load_robot
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot(robot)
    assert bench_observer.agreement(model, count=100) < 1e-12


def test_example_bag_holds_the_push(tmp_path):
    pytest.importorskip('rosbags')
    from newton_euler_ros.ident.bag import read_joint_states
    bag = str(tmp_path / 'bag')
    assert observer_example.main(['planar_2r', bag, '--duration', '1.0',
                                  '--rate', '200', '--push-at', '0.4',
                                  '0.6']) == 0
    rec = read_joint_states(bag, ['joint1', 'joint2'], min_samples=2)
    assert len(rec) == 200 and rec.qd is not None
    assert np.isfinite(rec.effort).all()
    # run again over it: an existing recording is replaced
    assert observer_example.main(['planar_2r', bag, '--duration', '0.5',
                                  '--rate', '200']) == 0
    assert len(read_joint_states(bag, ['joint1', 'joint2'],
                                 min_samples=2)) == 100
    # anything else at the path is left alone
    other = tmp_path / 'notes'
    other.mkdir()
    assert observer_example.main(['planar_2r', str(other)]) == 2
    assert observer_example.main(['no_such_robot', bag]) == 2


def test_targets_table_runs(tmp_path, capsys):
    """One seed, with and without the rest reference: the printed table."""
    assert observer_targets.main(['--seeds', '4', '--out',
                                  str(tmp_path)]) == 0
    out = capsys.readouterr().out.splitlines()
    row = out[2].split()
    assert row[0] == '4' and out[3].startswith('all'), out
    # pushes within 0.2 s, with / without: counts of 10
    assert 0 <= int(row[1]) <= 10 and 0 <= int(row[3]) <= 10, out
    # then one line for each of the others, with the arm at its onset
    late = [x for x in out if x.startswith('  seed 4: ')]
    assert len(late) == 10 - int(row[1]), out
    assert all('(onset: ' in x for x in late), out
    assert (tmp_path / 'seed_4' / 'pushed').is_dir()
