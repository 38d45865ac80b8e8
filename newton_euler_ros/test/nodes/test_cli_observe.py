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
``newton-euler observe`` as a real process, on a real bag.

The bag is written by rosbags' Writer (``ident.bag.write_joint_states``);
its efforts come from the Euler-Lagrange oracle for a Puma 560 URDF that
moves slowly while the environment pushes on its tool from 1.0 s to
2.0 s.  The CSV must show the push as the external wrench and the
contact over that window; bad inputs are one line and exit status 2.
"""
import csv
import os
import subprocess
import sys
import warnings

from newton_euler_ros.core import load_robot
from newton_euler_ros.ident.bag import write_joint_states
import numpy as np
import pytest
import reference_dynamics as ref

pytest.importorskip('rosbags')

PUSH = np.array([15.0, 0.0, -25.0, 0.0, 0.0, 0.0])
T_ON, T_OFF = 1.0, 2.0


def run(*args):
    proc = subprocess.run(
        [sys.executable, '-m', 'newton_euler_ros.cli', 'observe', *args],
        capture_output=True, text=True, timeout=180, env=dict(os.environ))
    return proc.returncode, proc.stdout, proc.stderr


def motion(t, n):
    amp, w = 0.15, 0.8 + 0.3 * np.arange(n)
    ph = w * t[:, None] + np.arange(n)
    home = np.array([0.0, 0.5, -0.3, 0.1, 0.4, 0.2])
    return (home + amp * np.sin(ph), amp * w * np.cos(ph),
            -amp * w ** 2 * np.sin(ph))


@pytest.fixture(scope='module')
def files(tmp_path_factory):
    tmp = tmp_path_factory.mktemp('observe')
    urdf = str(tmp / 'puma.urdf')
    subprocess.run([sys.executable, '-m', 'newton_euler_ros.cli', 'urdf',
                    'puma560', '-o', urdf], check=True, timeout=120)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot(urdf)
    t = np.arange(0.0, 3.0, 2e-3)
    Q, QD, QDD = motion(t, model.n)
    TAU = np.array([
        ref.inverse_dynamics(model, Q[k], QD[k], QDD[k],
                             -PUSH if T_ON <= t[k] < T_OFF else None)
        for k in range(t.size)])
    stamps = (1_700_000_000 * 10**9 + np.round(t * 1e9)).astype(np.int64)
    bag = str(tmp / 'bag')
    write_joint_states(bag, stamps, model.joint_names, Q, QD, TAU)
    no_velocity = str(tmp / 'no_velocity')
    write_joint_states(no_velocity, stamps, model.joint_names, Q, None, TAU)
    return {'tmp': tmp, 'urdf': urdf, 'bag': bag, 't': t, 'model': model,
            'no_velocity': no_velocity}


def test_observe_recovers_the_push_from_a_bag(files):
    tmp = files['tmp']
    out_csv, out_png = str(tmp / 'out.csv'), str(tmp / 'out.png')
    code, out, err = run(files['urdf'], files['bag'], '--base', 'base_link',
                         '--tip', 'tool0', '--csv', out_csv, '--plot',
                         out_png, '--gain', '40', '--thresholds', '2.0')
    assert code == 0, err
    assert 'contacts: 1' in out and f'wrote {out_csv}' in out
    with open(out_csv, newline='') as fh:
        rows = list(csv.DictReader(fh))
    names = files['model'].joint_names
    assert list(rows[0]) == (['time', 'stamp_ns'] +
                             [f'tau_ext_{j}' for j in names] +
                             ['fx', 'fy', 'fz', 'mx', 'my', 'mz',
                              'contact'])
    assert len(rows) == files['t'].size
    t = np.array([float(r['time']) for r in rows])
    F = np.array([[float(r[c]) for c in ('fx', 'fy', 'fz', 'mx', 'my',
                                         'mz')] for r in rows])
    contact = np.array([r['contact'] == '1' for r in rows])
    settled = (t > T_ON + 0.15) & (t < T_OFF)
    err_f = np.linalg.norm(F[settled, :3] - PUSH[:3], axis=1).max()
    err_m = np.linalg.norm(F[settled, 3:] - PUSH[3:], axis=1).max()
    assert err_f <= 0.1 * np.linalg.norm(PUSH[:3]) + 1.0, err_f
    assert err_m <= 0.2, err_m
    assert contact[settled].all()
    assert not contact[t < T_ON].any() and not contact[t > T_OFF + 0.3].any()
    with open(out_png, 'rb') as fh:
        assert fh.read(8) == b'\x89PNG\r\n\x1a\n'
    assert not [f for f in os.listdir(tmp) if f.endswith('.tmp')]


@pytest.mark.parametrize('case', [
    'missing_bag', 'not_a_bag', 'no_velocity', 'thresholds', 'gain',
    'robot', 'csv_folder', 'topic'])
def test_bad_inputs_are_one_line_and_exit_2(files, case):
    tmp = files['tmp']
    args = [files['urdf'], files['bag'], '--csv', str(tmp / 'bad.csv')]
    expect = {
        'missing_bag': (1, str(tmp / 'nope'), 'no such bag'),
        'not_a_bag': (1, str(tmp), 'cannot open the bag'),
        'no_velocity': (1, files['no_velocity'], 'no velocity'),
        'thresholds': ('--thresholds', '1', '2', '--thresholds'),
        'gain': ('--gain', '-1', '--gain'),
        'robot': (0, str(tmp / 'missing.urdf'), 'missing.urdf'),
        'csv_folder': ('--csv', str(tmp / 'no' / 'x.csv'), 'does not exist'),
        'topic': ('--topic', '/other', '/other'),
    }[case]
    if isinstance(expect[0], int):
        args[expect[0]] = expect[1]
    else:
        args += list(expect[:-1])
    code, out, err = run(*args)
    assert code == 2, (out, err)
    lines = [x for x in err.splitlines() if not x.startswith('warning:')]
    assert len(lines) == 1 and lines[0].startswith('newton-euler: error:')
    assert expect[-1] in lines[0], lines[0]
    assert 'Traceback' not in err
    assert not os.path.exists(tmp / 'bad.csv')
