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
``newton-euler observe`` in the test process (cli_harness), on a real bag.

The bag is written by rosbags' Writer (``ident.bag.write_joint_states``);
its efforts come from the Euler-Lagrange oracle for a Puma 560 URDF that
moves slowly while the environment pushes on its tool from 1.0 s to
2.0 s.  The CSV must show the push as the external wrench and the
contact over that window; bad inputs are one line and exit status 2.
``--json`` prints one object, per joint in chain order; efforts in A
with the URDF's torque constants give the torques' results; the
threshold procedure holds on a current-sensing arm that stops.
"""
import csv
import json
import os
import subprocess
import sys
import warnings

from newton_euler_ros.core import load_robot
from newton_euler_ros.core.drives import DRIVES_NS
from newton_euler_ros.ident.bag_write import write_joint_states
import numpy as np
import pytest
import reference_dynamics as ref
from cli_harness import newton_euler  # noqa: E402, I100

pytest.importorskip('rosbags')

PUSH = np.array([15.0, 0.0, -25.0, 0.0, 0.0, 0.0])
CONSTANTS = np.array([11.0, 13.5, 9.0, 4.2, 3.9, 3.1])    # N m per A
T_ON, T_OFF = 1.0, 2.0


def run(*args):
    return newton_euler('observe', *args)


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
    # the same, the message's joints in another order
    reversed_bag = str(tmp / 'reversed')
    write_joint_states(reversed_bag, stamps, model.joint_names[::-1],
                       *(np.ascontiguousarray(X[:, ::-1])
                         for X in (Q, QD, TAU)))
    # the same arm reporting motor currents (A): effort = tau / K, and its
    # URDF with the torque constants K (N m per A)
    current_urdf = str(tmp / 'puma_current.urdf')
    with open(urdf, encoding='utf-8') as fh:
        text = fh.read()
    text = text.replace('<robot ', f'<robot xmlns:ne="{DRIVES_NS}" ', 1)
    for name, k in zip(model.joint_names, CONSTANTS):
        head = f'<joint name="{name}" type="revolute">'
        assert head in text
        text = text.replace(head, head + f'<ne:drive torque_constant="{k}"/>')
    with open(current_urdf, 'w', encoding='utf-8') as fh:
        fh.write(text)
    current = str(tmp / 'current')
    write_joint_states(current, stamps, model.joint_names, Q, QD,
                       TAU / CONSTANTS)
    return {'tmp': tmp, 'urdf': urdf, 'bag': bag, 't': t, 'model': model,
            'no_velocity': no_velocity, 'reversed': reversed_bag,
            'current_urdf': current_urdf, 'current': current}


def test_observe_recovers_the_push_from_a_bag(files):
    tmp = files['tmp']
    out_csv, out_png = str(tmp / 'out.csv'), str(tmp / 'out.png')
    code, out, err = run(files['urdf'], files['bag'], '--base', 'base_link',
                         '--tip', 'tool0', '--csv', out_csv, '--plot',
                         out_png, '--gain', '40', '--thresholds', '2.0')
    assert code == 0, err
    assert 'contacts: 1' in out and f'wrote {out_csv}' in out
    # the published Puma's odd inertias: notes, as check says them
    assert 'note:' in err and 'triangle' in err and 'warning' not in err, err
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
    lines = [x for x in err.splitlines()
             if not x.startswith(('warning:', 'note:'))]
    assert len(lines) == 1 and lines[0].startswith('newton-euler: error:')
    assert expect[-1] in lines[0], lines[0]
    assert 'Traceback' not in err
    assert not os.path.exists(tmp / 'bad.csv')


def observe_json(*args):
    code, out, err = run(*args, '--json')
    assert code == 0, err
    summary = json.loads(out)        # the whole output: one JSON object
    assert isinstance(summary, dict)
    return summary


def test_json_is_one_object_per_joint_in_chain_order(files):
    model, tmp = files['model'], files['tmp']
    before = set(os.listdir(tmp))
    args = ['--base', 'base_link', '--tip', 'tool0', '--gain', '40',
            '--thresholds', '2.0']
    s = observe_json(files['urdf'], files['bag'], *args)
    names = list(model.joint_names)
    assert s['joints'] == names
    for key in ('suggested_thresholds', 'thresholds', 'peak', 'rms',
                'peak_beyond_friction', 'friction_allowance'):
        assert len(s[key]) == model.n, key
    assert s['torque_constant'] is None       # the efforts are torques
    assert s['samples'] == files['t'].size and s['contacts'] == 1
    (start, end), = s['contact_intervals']
    assert T_ON <= start < T_ON + 0.1 and T_OFF <= end < T_OFF + 0.5
    # what the CSV holds, in the CSV's joint order
    assert not set(os.listdir(tmp)) - before          # no --csv: no file
    out_csv = str(tmp / 'json.csv')
    observe_json(files['urdf'], files['bag'], *args, '--csv', out_csv)
    with open(out_csv, newline='') as fh:
        rows = list(csv.DictReader(fh))
    peak = [max(abs(float(r[f'tau_ext_{j}'])) for r in rows) for j in names]
    np.testing.assert_allclose(s['peak'], peak, rtol=1e-5, atol=1e-6)
    # the joints in another order in the messages: the same, chain order
    r = observe_json(files['urdf'], files['reversed'], *args)
    assert r['joints'] == names
    np.testing.assert_allclose(r['peak'], s['peak'], rtol=1e-12)
    assert r['suggested_thresholds'] == s['suggested_thresholds']


def test_currents_with_torque_constants_give_the_torques_results(files):
    args = ['--base', 'base_link', '--tip', 'tool0', '--gain', '40',
            '--thresholds', '2.0']      # N m, whatever the effort's unit
    torque = observe_json(files['urdf'], files['bag'], *args)
    current = observe_json(files['current_urdf'], files['current'], *args)
    np.testing.assert_allclose(current['torque_constant'], CONSTANTS)
    np.testing.assert_allclose(current['peak'], torque['peak'], rtol=1e-6)
    assert current['contacts'] == 1
    assert current['contact_intervals'] == torque['contact_intervals']
    # the table says what it did
    code, out, err = run(files['current_urdf'], files['current'], *args)
    assert code == 0, err
    assert 'torque constants 11, 13.5, 9, 4.2, 3.9, 3.1' in out
    assert 'effort' not in err, err         # the units agree: no warning
    code, _, err = run(files['urdf'], files['bag'], *args)
    assert code == 0 and 'effort' not in err, err
    # read as N m, the currents are a wrong arm: contact all along, and
    # one line says why (the ratios it names are the torque constants)
    raw = observe_json(files['urdf'], files['current'], *args)
    assert raw['contact_fraction'] > 0.9
    code, _, err = run(files['urdf'], files['current'], *args, '--json')
    warned = [x for x in err.splitlines() if 'effort' in x]
    assert code == 0 and len(warned) == 1, err
    assert warned[0].startswith('warning: ') and \
        'not joint torques' in warned[0], warned[0]
    assert 'torque_constant' in warned[0], warned[0]
    named = dict(cell.rsplit(' ', 1) for cell in warned[0].split(
        'model torque / effort is ')[1].split(' (')[0].split(', '))
    # far from 1; where the push (not in the model) does not dominate,
    # the joint's torque constant
    assert named and all(float(r) > 2.5 for r in named.values()), named
    close = [name for name, r in named.items() if float(r) == pytest.approx(
        CONSTANTS[files['model'].joint_names.index(name)], rel=0.05)]
    assert len(close) >= 3, named


def test_thresholds_from_a_free_recording_with_stops(tmp_path):
    """
    The procedure on a current-sensing arm that stops and rests.

    Two free-motion recordings of the current-sensing example arm (a
    UR5, motor currents, stops of 0.3-2.5 s where static friction holds
    up to 1.2-1.5 x its Coulomb level): the thresholds suggested by the
    first give no contact on the second.  Without the static friction
    allowance, the stops alone would call for thresholds above the
    shoulder's Coulomb friction.
    """
    from newton_euler_tools import current_arm_example as arm_example
    from newton_euler_tools.current_arm_model import write_identified
    from newton_euler_tools.current_arm_motions import point_to_point
    arm = arm_example.real_arm(3)
    urdf = write_identified(tmp_path / 'arm.urdf', arm, 3)
    bags = []
    for k in (1, 2):
        bags.append(str(tmp_path / f'free_{k}'))
        arm_example.record(arm, bags[-1], point_to_point(
            300 + k, 30.0, dwell=(0.3, 2.5), few=0.3, reverse=0.7),
            seed=30 + k)
    chain = ['--base', 'base_link', '--tip', 'tool0']
    first = observe_json(urdf, bags[0], *chain)
    assert first['resting_fraction'] > 0.1         # it does stop
    suggested = first['suggested_thresholds']
    coulomb = np.asarray(arm.drives['coulomb'])
    assert np.all(np.asarray(suggested)[:3] < 0.6 * coulomb[:3]), suggested
    second = observe_json(urdf, bags[1], *chain, '--thresholds',
                          *map(str, suggested))
    assert second['contacts'] == 0, second
    assert second['contact_fraction_at_rest'] == 0.0
    # the same procedure with the allowance off: the held friction sets
    # the thresholds, above the shoulder's Coulomb friction
    bare = observe_json(urdf, bags[0], *chain, '--static-friction', '0')
    assert np.all(np.asarray(bare['suggested_thresholds'])[:2]
                  > coulomb[:2]), bare['suggested_thresholds']
