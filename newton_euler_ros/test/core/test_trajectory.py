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

"""Effort feedforward along trajectories: library and CLI."""
import json
import warnings

from newton_euler_ros.core import (DynamicsInputError, inverse_dynamics,
                                   jacobian, load_robot)
from newton_euler_ros.core.trajectory import (differentiate, fill_efforts,
                                              trajectory_efforts)
import numpy as np
import pytest
from cli_harness import newton_euler  # noqa: E402, I100


@pytest.fixture(scope='module')
def puma():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot('puma560')


def quadratic(model, times, order):
    """q(t) = a t^2 + b t + c per joint: exact derivatives known."""
    rng = np.random.default_rng(4)
    a, b, c = rng.uniform(-1, 1, size=(3, model.n))
    t = np.asarray(times)[:, None]
    Q = a * t ** 2 + b * t + c
    QD = 2 * a * t + b
    QDD = np.broadcast_to(2 * a, Q.shape)
    names = [model.joint_names[k] for k in order]
    return names, Q[:, order], QD[:, order], QDD[:, order]


def points(times, Q, QD=None, QDD=None):
    out = []
    for k, t in enumerate(times):
        p = {'time_from_start': float(t), 'positions': Q[k].tolist()}
        if QD is not None:
            p['velocities'] = QD[k].tolist()
        if QDD is not None:
            p['accelerations'] = QDD[k].tolist()
        out.append(p)
    return out


def test_differentiate_is_exact_for_quadratics_on_uneven_times():
    t = np.array([0.0, 0.1, 0.35, 0.4, 0.9, 1.0])
    x = np.stack([3 * t ** 2 - t + 2, -t ** 2 + 4 * t], axis=1)
    dx = np.stack([6 * t - 1, -2 * t + 4], axis=1)
    np.testing.assert_allclose(differentiate(t, x), dx, rtol=0, atol=1e-12)
    # two points: the slope; one point: zero
    np.testing.assert_allclose(differentiate(t[:2], x[:2]),
                               np.tile((x[1] - x[0]) / 0.1, (2, 1)))
    assert not differentiate(t[:1], x[:1]).any()


ORDER = [3, 0, 5, 1, 4, 2]       # the controller's order, not the robot's


def test_efforts_are_the_inverse_dynamics_of_each_point(puma):
    times = np.linspace(0.0, 2.0, 9)
    names, Q, QD, QDD = quadratic(puma, times, ORDER)
    eff = trajectory_efforts(puma, names, points(times, Q, QD, QDD))
    inv = np.argsort(ORDER)
    for k in range(len(times)):
        tau = inverse_dynamics(puma, Q[k][inv], QD[k][inv], QDD[k][inv])
        np.testing.assert_allclose(eff[k], tau[ORDER], rtol=1e-13,
                                   atol=1e-12)


def test_missing_derivatives_come_from_the_positions(puma):
    times = np.array([0.0, 0.2, 0.5, 0.6, 1.1, 1.5])
    names, Q, QD, QDD = quadratic(puma, times, ORDER)
    exact = trajectory_efforts(puma, names, points(times, Q, QD, QDD))
    derived = trajectory_efforts(puma, names, points(times, Q))
    np.testing.assert_allclose(derived, exact, rtol=1e-9, atol=1e-9)
    # velocities given, accelerations derived from them
    derived = trajectory_efforts(puma, names, points(times, Q, QD))
    np.testing.assert_allclose(derived, exact, rtol=1e-9, atol=1e-9)


def test_wrench_held_along_the_trajectory(puma):
    times = [0.0, 0.5]
    names, Q, QD, QDD = quadratic(puma, times, list(range(6)))
    F = np.array([5.0, -3.0, 10.0, 0.2, 0.1, -0.3])
    eff = trajectory_efforts(puma, names, points(times, Q, QD, QDD), F,
                             'end_effector')
    for k in range(2):
        expected = inverse_dynamics(puma, Q[k], QD[k], QDD[k]) + jacobian(
            puma, Q[k], 'end_effector').T @ F
        np.testing.assert_allclose(eff[k], expected, rtol=1e-13, atol=1e-12)


def good(puma):
    names = list(puma.joint_names)
    return names, [{'time_from_start': 0.0, 'positions': [0.0] * 6},
                   {'time_from_start': 0.5, 'positions': [0.1] * 6}]


@pytest.mark.parametrize('change, message', [
    (lambda n, p: (n[:5] + ['elbow'], p), r"unknown joints \['elbow'\]"),
    (lambda n, p: (n[:5], [dict(x, positions=x['positions'][:5])
                           for x in p]), r"missing joints \['joint6'\]"),
    (lambda n, p: (n, [p[0], dict(p[1], time_from_start=0.0)]),
     r'points\[1\].time_from_start: 0.0 s is not after'),
    (lambda n, p: (n, [p[0], dict(p[1], time_from_start=float('nan'))]),
     r'points\[1\].time_from_start: must be finite'),
    (lambda n, p: (n, [p[0], dict(p[1], positions=[0.1] * 5 + [
        float('inf')])]), r'points\[1\].positions\[5\]: must be finite'),
    (lambda n, p: (n, [dict(p[0], velocities=[0.0] * 6), p[1]]),
     r'velocities given in 1 of 2 points'),
    (lambda n, p: (n, [dict(p[0], accelerations=[0.0] * 4), p[1]]),
     r'points\[0\].accelerations: 4 values for 6 joints'),
    (lambda n, p: (n, []), r'the trajectory has no points'),
    (lambda n, p: (n + [n[0]], p), r"'joint1' appears twice"),
])
def test_bad_trajectories_are_one_line(puma, change, message):
    names, pts = change(*good(puma))
    with pytest.raises(DynamicsInputError, match=message) as info:
        trajectory_efforts(puma, names, pts, where='traj.json: ')
    assert '\n' not in str(info.value)
    assert str(info.value).startswith('traj.json: ')


def test_fill_efforts_keeps_the_object(puma):
    names, pts = good(puma)
    traj = {'joint_names': names, 'points': pts, 'header': {'x': 1}}
    out = fill_efforts(puma, traj)
    assert out['header'] == {'x': 1} and out['joint_names'] == names
    assert all(len(p['effort']) == 6 and p['positions'] == q['positions']
               for p, q in zip(out['points'], pts))
    with pytest.raises(DynamicsInputError, match=r"unknown key 'effrot'"):
        fill_efforts(puma, {'joint_names': names,
                            'points': [dict(pts[0], effrot=[])]})


def run_cli(*args):
    return newton_euler(*args)


def test_cli_feedforward(tmp_path, puma):
    times = np.linspace(0.0, 1.0, 5)
    names, Q, QD, QDD = quadratic(puma, times, ORDER)
    path = tmp_path / 'traj.json'
    path.write_text(json.dumps({'joint_names': names,
                                'points': points(times, Q, QD, QDD)}))
    code, out, err = run_cli('feedforward', 'puma560', str(path))
    assert code == 0, err
    result = json.loads(out)
    np.testing.assert_allclose(
        [p['effort'] for p in result['points']],
        trajectory_efforts(puma, names, points(times, Q, QD, QDD)),
        rtol=0, atol=0)
    # a bad file: one line naming it
    path.write_text(json.dumps({'joint_names': names, 'points': points(
        times[::-1], Q)}))
    code, out, err = run_cli('feedforward', 'puma560', str(path))
    assert code != 0 and out == '' and 'Traceback' not in err
    last = err.strip().splitlines()[-1]      # after the puma's warnings
    assert last.startswith('newton-euler: error: ') and \
        'traj.json: points[1].time_from_start' in last


def test_a_trajectory_of_some_joints_of_a_tree_holds_the_others():
    """The named joints move, the others stay at ``hold``, at rest."""
    from newton_euler_ros.core import load_urdf, wrench_torques
    from random_tree import random_tree_urdf
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        tree = load_urdf(random_tree_urdf(7, links=9)[0])
    rng = np.random.default_rng(7)
    hold = rng.uniform(-1, 1, tree.n)
    # the joints of the deepest branch: their ancestors are held, and so
    # change their torques
    names = list(tree.joint_names[tree.n // 2:])[::-1]
    named = [tree.joint_names.index(j) for j in names]
    times = np.arange(4) * 0.1
    Q, QD, QDD = rng.uniform(-1, 1, (3, 4, len(names)))
    pts = [{'time_from_start': t, 'positions': q.tolist(),
            'velocities': qd.tolist(), 'accelerations': qdd.tolist()}
           for t, q, qd, qdd in zip(times, Q, QD, QDD)]
    F = {'l03': np.array([1.0, -2.0, 3.0, 0.1, 0.2, 0.3])}   # a wrench
    got = trajectory_efforts(tree, names, pts, F, 'base', hold=hold)
    for k in range(4):
        x, v, a = hold.copy(), np.zeros(tree.n), np.zeros(tree.n)
        x[named], v[named], a[named] = Q[k], QD[k], QDD[k]
        full = inverse_dynamics(tree, x, v, a) + wrench_torques(
            tree, x, F, 'base')
        np.testing.assert_allclose(got[k], full[named], rtol=1e-12,
                                   atol=1e-12)
        x0 = np.where(np.isin(np.arange(tree.n), named), x, 0.0)
        other = inverse_dynamics(tree, x0, v, a) + wrench_torques(
            tree, x0, F, 'base')      # held at zero instead: not the same
        assert np.abs(other[named] - full[named]).max() > 1e-6
    with pytest.raises(DynamicsInputError, match='missing joints'):
        trajectory_efforts(tree, names, pts)
