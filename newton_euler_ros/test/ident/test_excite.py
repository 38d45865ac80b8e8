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

"""Excitation trajectories: limits, rest at both ends, conditioning."""
import json
import warnings

from newton_euler_ros.core import load_robot
from newton_euler_ros.core.regressor import regressor_batch
from newton_euler_ros.core.trajectory import differentiate
from newton_euler_ros.ident.base import base_parameters, structural_base
from newton_euler_ros.ident.excite import (ExcitationError, excite, MARGIN,
                                           model_limits, trajectory_json)
from newton_euler_tools.ident_example import BASE, panda_path, TIP
import numpy as np
import pytest
from cli_harness import newton_euler  # noqa: E402, I100

# the Panda's ready pose: where excite starts (the arm's pose now)
START = ['--start', '0', '-0.785', '0', '-2.356', '0', '1.571', '0.785']


def run_cli(*args):
    return newton_euler(*args)


@pytest.fixture(scope='module')
def panda():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot(panda_path(), base=BASE, tip=TIP)


@pytest.fixture(scope='module')
def excitation(panda):
    # a count of evaluations, not seconds: the same motion however loaded
    return excite(panda, period=8.0, harmonics=4, seed=1, budget=120.0,
                  evaluations=150)


def test_a_count_of_evaluations_gives_the_same_motion(panda, excitation):
    again = excite(panda, period=8.0, harmonics=4, seed=1, budget=120.0,
                   evaluations=150)
    assert excitation.evaluations == again.evaluations == 150
    np.testing.assert_array_equal(again.a, excitation.a)
    np.testing.assert_array_equal(again.b, excitation.b)
    assert again.condition < excitation.condition_random


def test_rest_at_both_ends_at_the_start(panda, excitation):
    traj = trajectory_json(excitation, seconds=16.0, rate=50.0)
    pts = traj['points']
    assert traj['joint_names'] == list(panda.joint_names)
    assert pts[-1]['time_from_start'] == pytest.approx(16.0)
    for p in (pts[0], pts[-1]):
        np.testing.assert_allclose(p['positions'], excitation.start,
                                   atol=1e-9)
        np.testing.assert_allclose(p['velocities'], 0.0, atol=1e-9)
        np.testing.assert_allclose(p['accelerations'], 0.0, atol=1e-9)
    # rest also in the continuous series (not only in the written points)
    q, qd, qdd = excitation.sample(np.array([0.0, 8.0, 16.0]))
    np.testing.assert_allclose(qd, 0.0, atol=1e-9)
    np.testing.assert_allclose(qdd, 0.0, atol=1e-9)
    np.testing.assert_allclose(q, np.tile(excitation.start, (3, 1)),
                               atol=1e-9)


def test_velocities_and_accelerations_are_the_positions_derivatives(
        excitation):
    t = np.linspace(0.0, 8.0, 4001)
    q, qd, qdd = excitation.sample(t)
    np.testing.assert_allclose(differentiate(t, q)[1:-1], qd[1:-1],
                               atol=2e-3)
    np.testing.assert_allclose(differentiate(t, qd)[1:-1], qdd[1:-1],
                               atol=2e-2)


def test_limits_with_margin(panda, excitation):
    t = np.linspace(0.0, 8.0, 20001)
    q, qd, qdd = excitation.sample(t)
    lim = model_limits(panda)
    rng = lim.upper - lim.lower
    tol = 1e-3
    assert (q.min(axis=0) >= lim.lower + (MARGIN - tol) * rng).all()
    assert (q.max(axis=0) <= lim.upper - (MARGIN - tol) * rng).all()
    assert (np.abs(qd).max(axis=0)
            <= (1 - MARGIN + tol) * lim.velocity).all()
    assert (np.abs(qdd).max(axis=0)
            <= (1 - MARGIN + tol) * lim.acceleration).all()
    # the URDF's velocity limits are used (the Panda has them)
    assert lim.velocity[0] == pytest.approx(2.175)
    # every joint uses its range: one of the limits binds
    m = excitation.margins
    binding = np.minimum.reduce([m['position'] - MARGIN,
                                 1 - MARGIN - m['velocity'],
                                 1 - MARGIN - m['acceleration']])
    assert (np.abs(binding) < 0.02).all(), binding


def test_optimised_series_is_better_conditioned(panda, excitation):
    assert excitation.condition < 0.7 * excitation.condition_random
    # the figure is the condition number of the base regressor: check it
    # independently, on a finer sampling, with the identification's QR
    t = np.linspace(0.0, 8.0, 400, endpoint=False)
    q, qd, qdd = excitation.sample(t)
    Y = regressor_batch(panda, q, qd, qdd, drives=True)
    cols = structural_base(panda, drives=True).columns
    info = base_parameters(Y.reshape(-1, Y.shape[2])[:, cols])
    assert info.rank == len(cols)
    assert info.condition == pytest.approx(excitation.condition, rel=0.25)


def test_period_too_short_is_refused(panda):
    with pytest.raises(ExcitationError, match='too short'):
        excite(panda, period=0.2, harmonics=5, budget=1.0)


def test_cli_writes_what_feedforward_reads(tmp_path):
    out = tmp_path / 'excite.json'
    code, text, err = run_cli('excite', panda_path(), '--base', BASE,
                              '--tip', TIP, '-o', str(out), *START,
                              '--period', '6',
                              '--harmonics', '3', '--seconds', '12',
                              '--budget', '3')
    assert code == 0, err
    assert 'condition number' in text and 'random series' in text
    assert 'pos margin' in text
    traj = json.loads(out.read_text())
    assert traj['points'][-1]['time_from_start'] == pytest.approx(12.0)
    code, text, err = run_cli('feedforward', panda_path(), '--base', BASE,
                              '--tip', TIP, str(out))
    assert code == 0, err
    filled = json.loads(text)
    efforts = np.array([p['effort'] for p in filled['points']])
    assert efforts.shape == (len(traj['points']), 7)
    assert np.isfinite(efforts).all()


@pytest.mark.parametrize('args, words', [
    (['--period', '0.3'], 'too short'),
    (['--harmonics', '1'], 'harmonics'),
    (['--period', '-1'], 'period'),
    (['--seconds', '0'], '--seconds'),
    (['--start', '0', '0'], 'start'),
    (['--start', '0', '0', '0', '-0.01', '0', '1', '0'], 'panda_joint4'),
])
def test_cli_bad_requests_one_line_exit_2(tmp_path, args, words):
    out = tmp_path / 'x.json'
    code, text, err = run_cli('excite', panda_path(), '--base', BASE,
                              '--tip', TIP, '-o', str(out), '--budget', '1',
                              *START, *args)
    assert code == 2, (text, err)
    lines = [x for x in err.splitlines() if not x.startswith(('note',
                                                              'warning'))]
    assert len(lines) == 1 and words in lines[0], err
    assert 'Traceback' not in err
    assert not out.exists()


def test_cli_missing_urdf_and_directory(tmp_path):
    code, _, err = run_cli('excite', str(tmp_path / 'no.urdf'), '--base',
                           BASE, '--tip', TIP, '-o', str(tmp_path / 'x.json'),
                           *START)
    assert code == 2 and 'no.urdf' in err and len(err.splitlines()) == 1
    code, _, err = run_cli('excite', panda_path(), '--base', BASE, '--tip',
                           TIP, '-o', str(tmp_path / 'nodir' / 'x.json'),
                           *START)
    assert code == 2 and 'nodir' in err and len(err.splitlines()) == 1


def test_trajectory_efforts_add_the_drive_terms(panda, excitation):
    # what the node fills in on ~/trajectory_in with drives.compensate on
    from newton_euler_ros.core import inverse_dynamics_batch
    from newton_euler_ros.core.drives import Drives
    from newton_euler_ros.core.trajectory import trajectory_efforts
    traj = trajectory_json(excitation, rate=20.0)
    names = list(reversed(traj['joint_names']))
    points = [{'time_from_start': p['time_from_start'],
               **{k: list(reversed(p[k])) for k in
                  ('positions', 'velocities', 'accelerations')}}
              for p in traj['points']]
    rng = np.random.default_rng(3)
    drives = Drives.from_parameters(rng.uniform(0.05, 0.5, 28))
    got = trajectory_efforts(panda, names, points, drives=drives)
    Q, QD, QDD = (np.array([p[k] for p in traj['points']]) for k in
                  ('positions', 'velocities', 'accelerations'))
    want = (inverse_dynamics_batch(panda, Q, QD, QDD)
            + drives.torques(QD, QDD))[:, ::-1]
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-9)
    assert not np.allclose(got, trajectory_efforts(panda, names, points))
