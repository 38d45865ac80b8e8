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
``newton-euler feedforward --gains Q R``: n x 2n gains in every point.

They equal core.lqr's, in the trajectory's joint order (a trajectory
whose joints are listed backwards gets its rows and columns backwards),
the efforts are unchanged, and bad weights exit 2 in one line.
"""
import json
import os
import subprocess
import sys
import warnings

from newton_euler_ros.core import load_robot
from newton_euler_ros.core.lqr import trajectory_gains
from newton_euler_ros.core.trajectory import trajectory_arrays
import numpy as np

MOVE = os.path.join(os.path.dirname(__file__), '..', '..', 'config',
                    'trajectories', 'puma560_move.json')


def run(*args):
    proc = subprocess.run(
        [sys.executable, '-m', 'newton_euler_ros.cli', *args],
        capture_output=True, text=True, timeout=300)
    return proc.returncode, proc.stdout, proc.stderr


def test_gains_beside_the_efforts_equal_the_librarys(tmp_path):
    with open(MOVE, encoding='utf-8') as fh:
        traj = json.load(fh)
    backwards = {'joint_names': traj['joint_names'][::-1],
                 'points': [{k: (v[::-1] if isinstance(v, list) else v)
                             for k, v in p.items()} for p in traj['points']]}
    path = tmp_path / 'backwards.json'
    path.write_text(json.dumps(backwards))
    # per-joint weights, in the file's (backwards) order
    q_text = ','.join(str(v) for v in [600, 500, 400, 300, 200, 100,
                                       6, 5, 4, 3, 2, 1])
    code, out, err = run('feedforward', 'puma560', str(path), '--gains',
                         q_text, '0.01')
    assert code == 0, err
    filled = json.loads(out)
    code, plain, err = run('feedforward', 'puma560', str(path))
    assert code == 0, err
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        puma = load_robot('puma560')
    times, Q, QD, QDD = trajectory_arrays(puma, traj['joint_names'],
                                          traj['points'])
    gains = trajectory_gains(puma, times, Q, QD, QDD,
                             [100, 200, 300, 400, 500, 600,
                              1, 2, 3, 4, 5, 6], 0.01)
    rev = np.arange(6)[::-1]
    for k, (point, bare) in enumerate(zip(filled['points'],
                                          json.loads(plain)['points'])):
        assert point['effort'] == bare['effort']
        K = np.array(point['gains'])
        assert K.shape == (6, 12)
        expected = gains.K[k][rev][:, np.concatenate([rev, 6 + rev])]
        np.testing.assert_allclose(K, expected, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(point['effort'], gains.tau0[k][rev],
                                   rtol=1e-12, atol=1e-12)


def test_bad_weights_exit_2_in_one_line():
    for gains, message in ((['100,1,3', '0.01'], '--gains Q: 3 values'),
                           (['100,1', '0'], '--gains R: must be positive '
                                            'definite'),
                           (['100,x', '0.01'], '--gains Q')):
        code, out, err = run('feedforward', 'puma560', MOVE, '--gains',
                             *gains)
        assert code == 2 and out == '', err
        assert message in err and err.count('\n') == 1, err


# per joint of the Puma: damping, friction, armature, offset, coulomb width
DRIVES = [(0.5, 1.2, 0.3, -0.1, 0.02), (0.7, 2.0, 0.4, 0.2, 0.05),
          (0.4, 0.9, 0.2, 0.0, 0.02), (0.1, 0.3, 0.05, 0.05, 0.02),
          (0.1, 0.2, 0.04, -0.02, 0.1), (0.05, 0.1, 0.02, 0.01, 0.02)]
NS = 'https://newton-euler-ros.github.io/ns/drives/1'


def puma_with_drives(tmp_path):
    """Write the Puma as a URDF whose joints carry DRIVES; return its path."""
    path = tmp_path / 'puma.urdf'
    code, _, err = run('urdf', 'puma560', '-o', str(path))
    assert code == 0, err
    text = path.read_text().replace('<robot ', f'<robot xmlns:ne="{NS}" ', 1)
    parts = text.split('</joint>')
    k = 0
    for i, part in enumerate(parts[:-1]):
        if 'type="fixed"' in part.rsplit('<joint ', 1)[-1]:
            continue
        b, f, a, o, w = DRIVES[k]
        parts[i] = (part + f'<dynamics damping="{b}" friction="{f}"/>'
                    f'<ne:drive armature="{a}" offset="{o}" '
                    f'coulomb_width="{w}"/>')
        k += 1
    assert k == 6
    path.write_text('</joint>'.join(parts))
    return str(path)


def test_drives_add_their_torques_and_join_the_gains(tmp_path):
    urdf = puma_with_drives(tmp_path)
    code, plain, err = run('feedforward', urdf, MOVE, '--tip', 'tool0')
    assert code == 0, err
    code, out, err = run('feedforward', urdf, MOVE, '--tip', 'tool0',
                         '--drives', '--gains', '100,10', '0.01')
    assert code == 0, err
    with open(MOVE, encoding='utf-8') as fh:
        traj = json.load(fh)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        from newton_euler_ros.core import load_urdf
        model = load_urdf(urdf, tip='tool0')
    times, Q, QD, QDD = trajectory_arrays(model, traj['joint_names'],
                                          traj['points'])
    b, f, a, o, w = np.array(DRIVES).T
    # each drive torque by hand: b qd + f tanh(qd / w) + offset + a qdd
    by_hand = b * QD + f * np.tanh(QD / w) + o + a * QDD
    filled = json.loads(out)
    for k, (point, bare) in enumerate(zip(filled['points'],
                                          json.loads(plain)['points'])):
        np.testing.assert_allclose(
            np.subtract(point['effort'], bare['effort']), by_hand[k],
            rtol=1e-12, atol=1e-12)
    gains = trajectory_gains(model, times, Q, QD, QDD, [100] * 6 + [10] * 6,
                             0.01, drives=model.info['drives'])
    bare = trajectory_gains(model, times, Q, QD, QDD, [100] * 6 + [10] * 6,
                            0.01)
    K = np.array([p['gains'] for p in filled['points']])
    np.testing.assert_allclose(K, gains.K, rtol=1e-12, atol=1e-12)
    # the drives change the gains: damping and rotor inertia slow the arm
    assert np.abs(K - bare.K).max() > 1e-3 * np.abs(bare.K).max()


def test_drives_on_a_robot_without_them_exit_2_in_one_line():
    code, out, err = run('feedforward', 'puma560', MOVE, '--drives')
    assert code == 2 and out == '', err
    assert '--drives: puma560 has no drive terms' in err, err
    assert err.count('\n') == 1, err
