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
The ROS-free layer behind the node.

Joint mapping, wrench handling, reference sampling, and the torques it
asks the library for.
"""
import math
import re
import warnings

from newton_euler_ros.core import inverse_dynamics, load_robot, mass_matrix
from newton_euler_ros.feedforward import FeedforwardComputer
from newton_euler_ros.joint_inputs import (InputRejected, JointOrder,
                                           ReferenceTrajectory)
from newton_euler_ros.wrenches import APPLIED_TO_ROBOT, WrenchInput
import numpy as np
import pytest


@pytest.fixture(scope='module')
def puma():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot('puma560')


def names6():
    return [f'joint{k}' for k in range(1, 7)]


def test_joint_order_gathers_any_order_and_ignores_extras():
    order = JointOrder(['a', 'b', 'c'], ['c', 'a', 'b'])
    x = order.gather(['x', 'b', 'c', 'a'], 'position', [9.0, 2.0, 3.0, 1.0])
    assert x.tolist() == [1.0, 2.0, 3.0]
    assert order.to_output_order(x).tolist() == [3.0, 1.0, 2.0]
    M = np.arange(9.0).reshape(3, 3)
    assert order.matrix_to_output_order(M)[0, 1] == M[2, 0]


@pytest.mark.parametrize('names, values, kind, text', [
    (['a', 'b'], [1.0, 2.0], 'missing_joints', "missing joints ['c']"),
    (['a', 'b', 'c'], [1.0, 2.0], 'malformed', 'position has 2 entries '
                                               'for 3 names'),
    (['a', 'b', 'c', 'a'], [1.0] * 4, 'malformed', "'a' appears twice"),
    (['a', 'b', 'c'], [1.0, math.nan, 2.0], 'non_finite',
     "position of 'b' is nan"),
])
def test_joint_order_rejects(names, values, kind, text):
    order = JointOrder(['a', 'b', 'c'])
    with pytest.raises(InputRejected, match=re.escape(text)) as info:
        order.gather(names, 'position', values)
    assert info.value.kind == kind


@pytest.mark.parametrize('output, text', [
    (['a', 'b'], "missing \\['c'\\]"),
    (['a', 'b', 'c', 'd'], "not in the robot: \\['d'\\]"),
    (['a', 'a', 'b'], "'a' is listed twice"),
])
def test_joint_order_validates_output(output, text):
    with pytest.raises(ValueError, match=text):
        JointOrder(['a', 'b', 'c'], output)


def test_wrench_sign_frames_and_staleness():
    w = WrenchInput(['base_link'], ['tool0'], APPLIED_TO_ROBOT, timeout=0.5)
    w.update('tool0', [1, 2, 3, 4, 5, 6], stamp=10.0, now=10.1)
    wrench, frame = w.current(now=10.2)
    assert frame == 'end_effector' and wrench.tolist() == [-1, -2, -3, -4,
                                                           -5, -6]
    assert w.current(now=10.6) == (None, 'end_effector')   # expired
    assert w.expired == 0 and w.current(now=10.2)[0] is not None  # a read
    assert w.expire(now=10.2) is False and w.expire(now=10.6) is True
    assert w.expired == 1
    assert w.expire(now=10.7) is False and w.expired == 1   # counted once
    assert w.current(now=10.2) == (None, 'end_effector')    # dropped
    with pytest.raises(InputRejected, match='is not one of') as info:
        w.update('camera', [0] * 6, 10.0, 10.0)
    assert info.value.kind == 'unknown_frame'
    with pytest.raises(InputRejected) as info:
        w.update('base_link', [0] * 6, stamp=1.0, now=10.0)
    assert info.value.kind == 'stale'
    with pytest.raises(InputRejected) as info:
        w.update('base_link', [0, 0, math.inf, 0, 0, 0], 10.0, 10.0)
    assert info.value.kind == 'non_finite'
    w.update('base_link', [1] * 6, stamp=0.0, now=20.0)  # unstamped: now
    assert w.current(now=20.1)[1] == 'base'


@pytest.mark.parametrize('kwargs, text', [
    ({'base_frames': ['x'], 'end_effector_frames': ['x']}, 'both a base'),
    ({'base_frames': [], 'end_effector_frames': [], 'convention': 'push'},
     'convention must be'),
    ({'base_frames': [], 'end_effector_frames': [], 'timeout': -1.0},
     'timeout must be >= 0'),
])
def test_wrench_input_validates(kwargs, text):
    with pytest.raises(ValueError, match=text):
        WrenchInput(**kwargs)


def test_reference_interpolates_linearly_in_time():
    ref = ReferenceTrajectory(JointOrder(['a', 'b']))
    assert ref.acceleration(0.0) is None
    ref.set(['b', 'a'], start=100.0, points=[(0.0, [0.0, 1.0]),
                                             (2.0, [4.0, 3.0]),
                                             (3.0, [])], now=0.0)
    assert ref.acceleration(99.0).tolist() == [1.0, 0.0]   # before: first
    assert ref.acceleration(101.0).tolist() == [2.0, 2.0]  # halfway
    assert ref.acceleration(102.5).tolist() == [1.5, 2.0]  # toward zeros
    assert ref.acceleration(200.0).tolist() == [0.0, 0.0]  # after: last
    with pytest.raises(InputRejected, match='non-decreasing'):
        ref.set(['a', 'b'], 0.0, [(1.0, []), (0.5, [])], now=0.0)


def test_computer_matches_library_with_reference_and_wrench(puma):
    order = JointOrder(puma.joint_names, list(reversed(puma.joint_names)))
    ref = ReferenceTrajectory(order)
    wrench = WrenchInput(['base_link'], ['tool0'], timeout=0.0)
    ff = FeedforwardComputer(puma, order, wrench, ref)
    rng = np.random.default_rng(3)
    q, qd, qdd = rng.normal(size=(3, 6))
    F = rng.normal(size=6)
    ref.set(names6(), 0.0, [(0.0, qdd.tolist())], now=5.0)
    wrench.update('tool0', F, 5.0, 5.0)
    tau = ff.torques(names6(), q, qd, stamp=5.0, now=5.0)
    expected = inverse_dynamics(puma, q, qd, qdd, F, 'end_effector')
    assert np.abs(tau - expected[::-1]).max() < 1e-12
    D, C, g, t = ff.terms(names6(), [], [], qdd.tolist(), now=5.0)  # latest
    assert np.abs(D - mass_matrix(puma, q)[::-1, ::-1]).max() < 1e-12
    assert np.abs(t - expected[::-1]).max() < 1e-12


def test_scene_selects_the_nodes_effects():
    from newton_euler_ros.sim.scene import load_scene
    from newton_euler_ros.sim.simulate import SceneDynamics
    orbit = load_scene('panda_orbit_slow')       # no gravity
    order = JointOrder(orbit.model.joint_names)
    ff = FeedforwardComputer(None, order, WrenchInput([], []), None, orbit)
    names = list(orbit.model.joint_names)
    q = orbit.q0
    tau = ff.torques(names, q, np.zeros(7), stamp=0.0, now=0.0)
    assert np.all(tau == 0.0)                    # at rest in orbit: nothing
    D, C, g, t = ff.terms(names, q, np.full(7, 0.5), np.ones(7), now=0.0)
    assert np.all(g == 0.0) and np.abs(C).max() > 0.0
    np.testing.assert_allclose(t, D @ np.ones(7) + C @ np.full(7, 0.5),
                               rtol=0, atol=1e-12)
    slow = load_scene('panda_slow_earth')        # no velocity products
    ff = FeedforwardComputer(None, order, WrenchInput([], []), None, slow)
    D, C, g, t = ff.terms(names, q, np.full(7, 0.5), np.ones(7), now=0.0)
    assert np.all(C == 0.0) and np.abs(g).max() > 1.0
    np.testing.assert_allclose(t, D @ np.ones(7) + g, rtol=0, atol=1e-12)
    press = load_scene('puma_payload_press')     # every effect
    order = JointOrder(press.model.joint_names)
    ff = FeedforwardComputer(None, order, WrenchInput([], []), None, press)
    rng = np.random.default_rng(5)
    q, qd = rng.normal(size=(2, 6))
    expected = SceneDynamics(press).torques(q, qd, None, None)
    got = ff.torques(names6(), q, qd, stamp=0.0, now=0.0)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        bare = inverse_dynamics(load_robot('puma560'), q, qd)
    assert np.abs(got - bare).max() > 0.1        # payload + friction count


def test_future_wrench_rejected_and_bad_state_not_remembered(puma):
    w = WrenchInput(['base_link'], [], timeout=0.5)
    with pytest.raises(InputRejected, match='in the future') as info:
        w.update('base_link', [1.0] * 6, stamp=100.0, now=10.0)
    assert info.value.kind == 'stale' and w.current(10.0)[0] is None
    order = JointOrder(puma.joint_names)
    ff = FeedforwardComputer(puma, order, WrenchInput([], []))
    with pytest.raises(InputRejected, match='overflows float64'):
        ff.torques(names6(), np.zeros(6), np.full(6, 1e308), 0.0, 0.0)
    assert ff.last_q is None          # a rejected state is not "latest"


def test_computer_built_in_one_call_from_parameters(puma):
    from newton_euler_ros.safety import effort_bounds, velocity_bounds
    order = JointOrder(puma.joint_names, list(reversed(puma.joint_names)))
    params = {'limits.action': 'clamp', 'limits.velocity_factor': 2.0,
              'limits.max_velocity': 20.0, 'joint_states.max_future': 0.5,
              'joint_states.max_age': 2.0}
    bounds, sources = effort_bounds(puma)
    ff = FeedforwardComputer.from_parameters(
        params, puma, order, WrenchInput([], []), bounds, sources)
    assert ff.mode == 'gravity_coriolis' and ff.model is puma
    assert ff.output_names == list(reversed(puma.joint_names))
    assert ff.guard.action == 'clamp'
    assert ff.guard.bounds.tolist() == bounds[::-1].tolist()
    assert ff.bound_sources == sources[::-1]
    np.testing.assert_array_equal(ff.velocity_bounds,
                                  velocity_bounds(puma, 2.0, 20.0))
    assert (ff.max_future, ff.max_age) == (0.5, 2.0)
    assert ff.bare_model is puma and ff.bare_scene is None
    with pytest.raises(InputRejected, match='in the future'):
        ff.torques(names6(), np.zeros(6), np.zeros(6), stamp=1.0, now=0.0)
    # a computer built without parameters guards nothing and accepts any
    # plausible stamp, as before
    plain = FeedforwardComputer(puma, order, WrenchInput([], []))
    assert plain.guard is None and plain.velocity_bounds is None
    assert (plain.max_future, plain.max_age) == (1.0, 0.0)


def test_a_trajectorys_efforts_are_guarded_by_its_joints_bounds(puma):
    from newton_euler_ros.safety import effort_bounds
    order = JointOrder(puma.joint_names, list(reversed(puma.joint_names)))
    params = {'limits.action': 'clamp', 'limits.velocity_factor': 2.0,
              'limits.max_velocity': 20.0, 'joint_states.max_future': 0.5,
              'joint_states.max_age': 0.0}
    names = names6()[2:] + names6()[:2]         # its own order
    rng = np.random.default_rng(11)
    Q, QD, QDD = rng.normal(size=(3, 3, 6))
    points = [{'time_from_start': 0.1 * k, 'positions': Q[k],
               'velocities': QD[k], 'accelerations': QDD[k]}
              for k in range(3)]
    at = [puma.joint_names.index(j) for j in names]
    expected = np.array([inverse_dynamics(puma, Q[k][np.argsort(at)],
                                          QD[k][np.argsort(at)],
                                          QDD[k][np.argsort(at)])[at]
                         for k in range(3)])
    # one joint's bound (model order) below what the trajectory asks
    bounds, sources = effort_bounds(puma)
    j = int(np.argmax(np.abs(expected).max(axis=0)))
    low = bounds.copy()
    low[at[j]] = 0.5 * np.abs(expected[:, j]).max()
    for action in ('clamp', 'drop', 'publish'):
        params['limits.action'] = action
        ff = FeedforwardComputer.from_parameters(
            params, puma, order, WrenchInput([], []), low, sources)
        efforts, exceeded = ff.trajectory(names, points, 0.0)
        # the one joint over, with the largest torque asked and its bound
        k = int(np.abs(expected[:, j]).argmax())
        assert exceeded == {names[j]: (expected[k, j], low[at[j]], 'N m')}
        if action == 'drop':
            assert efforts is None
            continue
        want = expected.copy()
        if action == 'clamp':
            want[:, j] = np.clip(want[:, j], -low[at[j]], low[at[j]])
        np.testing.assert_allclose(efforts, want, rtol=0, atol=1e-9)
    # within its bounds: the inverse dynamics at every point, unguarded
    ff = FeedforwardComputer.from_parameters(
        params, puma, order, WrenchInput([], []), bounds * 1e3, sources)
    efforts, exceeded = ff.trajectory(names, points, 0.0)
    assert not exceeded
    np.testing.assert_allclose(efforts, expected, rtol=0, atol=1e-9)
    with pytest.raises(InputRejected, match='trajectory: ') as info:
        ff.trajectory(names, [{'time_from_start': 0.0,
                               'positions': [0.0]}], 0.0)
    assert info.value.kind == 'malformed'


def test_the_torque_bound_warning_names_the_joints_once_per_change(puma):
    """
    Only the joints over, with the torque asked and the bound.

    Said again only when another set of joints goes over, not at every
    message.
    """
    from newton_euler_ros.safety import (joint_units, over_text,
                                         OverLimitLog, TorqueGuard)
    guard = TorqueGuard([10.0, 20.0, 5.0], 'clamp', ['a', 'b', 'c'],
                        ['N m', 'N m', 'N'])
    over = guard.over([12.0, -1.0, -7.5])
    assert over == {'a': (12.0, 10.0, 'N m'), 'c': (-7.5, 5.0, 'N')}
    assert over_text(over) == ('a asked 12 N m, bound 10; '
                               'c asked -7.5 N, bound 5')
    assert guard.over([1.0, 1.0, 1.0]) == {}
    log = OverLimitLog()
    said = [log.news(guard.over(tau)) for tau in (
        [12.0, 0, 0], [13.0, 0, 0], [0, 0, 0], [12.5, 0, 0],
        [12.0, 0, 9.0], [12.0, 0, 9.0], [0, 30.0, 0])]
    assert said == [True, False, False, False, True, False, True]
    assert joint_units(puma) == ['N m'] * 6


def test_every_rejection_kind_raised_is_one_the_node_counts():
    """Each InputRejected kind in the sources is in REJECTIONS, counted."""
    import ast
    import os
    from newton_euler_ros import joint_inputs
    from newton_euler_ros.nodes.inverse_dynamics_node import COUNTERS
    package = os.path.dirname(joint_inputs.__file__)
    raised = {}
    for folder, _, files in os.walk(package):
        for name in files:
            if not name.endswith('.py'):
                continue
            path = os.path.join(folder, name)
            with open(path, encoding='utf-8') as fh:
                tree = ast.parse(fh.read())
            for node in ast.walk(tree):
                if isinstance(node, ast.Call) and getattr(
                        node.func, 'id', None) == 'InputRejected':
                    kind = node.args[0]
                    kinds = [kind.body, kind.orelse] if isinstance(
                        kind, ast.IfExp) else [kind]
                    for k in kinds:
                        assert isinstance(k, ast.Constant), (
                            f'{path}:{node.lineno}: the kind must be a '
                            f'literal (or a choice of two)')
                        raised.setdefault(k.value, f'{path}:{node.lineno}')
    assert len(raised) >= 8, raised         # the walk sees the raises
    unknown = {k: where for k, where in raised.items()
               if k not in joint_inputs.REJECTIONS}
    assert not unknown, f'kinds not in joint_inputs.REJECTIONS: {unknown}'
    assert set(joint_inputs.REJECTIONS) <= set(COUNTERS)
    assert len(set(COUNTERS)) == len(COUNTERS)
    with pytest.raises(ValueError, match='unknown kind'):
        InputRejected('no_such_kind', 'text')
