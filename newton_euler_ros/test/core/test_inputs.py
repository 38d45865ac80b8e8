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
Bad input to the library raises DynamicsInputError naming argument and index.

Nothing non-finite comes out of finite input.
"""
import doctest
import math

from newton_euler_ros.core import (coriolis_matrix, DynamicsInputError,
                                   forward_dynamics, gravity_torques,
                                   inverse_dynamics, inverse_dynamics_batch,
                                   jacobian, load_robot, make_model,
                                   mass_matrix, NotPositiveDefiniteError,
                                   wrench_torques)
from newton_euler_ros.core import dynamics
import numpy as np
import pytest


@pytest.fixture(scope='module')
def arm():
    return load_robot('planar_2r')


@pytest.mark.parametrize('call, message', [
    (lambda m: inverse_dynamics(m, [0.0]), 'q must have 2 entries, got 1'),
    (lambda m: inverse_dynamics(m, [[0.0, 0.0]]), 'q must be a vector'),
    (lambda m: inverse_dynamics(m, ['a', 0.0]), 'q must be a sequence'),
    (lambda m: inverse_dynamics(m, [0.0, math.nan]), r'q\[1\] is nan'),
    (lambda m: inverse_dynamics(m, [0, 0], [0, math.inf]), r'qd\[1\] is inf'),
    (lambda m: inverse_dynamics(m, [0, 0], None, [-math.inf, 0]),
     r'qdd\[0\] is -inf'),
    (lambda m: inverse_dynamics(m, [0, 0], wrench=[0, 0, 0, 0, math.nan, 0]),
     r'wrench\[4\] is nan'),
    (lambda m: inverse_dynamics(m, [0, 0], wrench=[0, 0, 0]),
     'wrench must have 6 entries, got 3'),
    (lambda m: inverse_dynamics(m, [0, 0], wrench=[0] * 6,
                                wrench_frame='tool'),
     "wrench_frame must be 'base' or 'end_effector'"),
    (lambda m: mass_matrix(m, [math.nan, 0]), r'q\[0\] is nan'),
    (lambda m: coriolis_matrix(m, [0, 0], [0, math.nan]), r'qd\[1\] is nan'),
    (lambda m: gravity_torques(m, [0, 0, 0]), 'q must have 2 entries'),
    (lambda m: jacobian(m, [0, 0], frame='world'), "frame must be 'base'"),
    (lambda m: wrench_torques(m, [0, 0], [math.inf] + [0] * 5),
     r'wrench\[0\] is inf'),
    (lambda m: forward_dynamics(m, [0, 0], [0, 0], [0, math.nan]),
     r'tau\[1\] is nan'),
    (lambda m: inverse_dynamics_batch(m, np.zeros((3, 2)),
                                      np.full((3, 2), math.nan)),
     r'QD\[0, 0\] is nan'),
    (lambda m: inverse_dynamics_batch(m, np.zeros((3, 3))),
     r'Q must have shape \(m, 2\)'),
])
def test_bad_state_raises_named_error(arm, call, message):
    with pytest.raises(DynamicsInputError, match=message):
        call(arm)


def test_error_leaves_output_untouched(arm):
    out = np.array([7.0, 7.0])
    with pytest.raises(DynamicsInputError):
        inverse_dynamics(arm, [0.0, math.nan], out=out)
    assert out.tolist() == [7.0, 7.0]


def test_massless_tail_names_the_joint():
    # the second joint moves nothing: D is singular at joint index 1
    tail = make_model('tail', 'standard', ['j1', 'tip'],
                      ['revolute', 'revolute'], [1.0, 0.5], [0, 0], [0, 0],
                      [0, 0], [1.0, 0.0], np.zeros((2, 3)),
                      [np.eye(3) * 0.1, np.zeros((3, 3))])
    with pytest.raises(NotPositiveDefiniteError, match=r'joint 1 \(tip\)') \
            as info:
        forward_dynamics(tail, [0, 0], [0, 0], [1.0, 1.0])
    assert info.value.joint == 1


def test_docstring_examples_run():
    from newton_euler_ros.core import float32
    ran = 0
    for module in (dynamics, float32):     # the modules with examples
        result = doctest.testmod(module)
        assert result.failed == 0
        assert result.attempted > 0, f'{module.__name__} ran no example'
        ran += result.attempted
    assert ran >= 4


def test_condition_number_of_d(arm):
    """Check cond(D) against the 2x2 eigenvalues in closed form."""
    from newton_euler_ros.core import mass_matrix_condition
    q = [0.3, 1.1]
    D = mass_matrix(arm, q)
    a, b, c = D[0, 0], D[0, 1], D[1, 1]
    root = math.sqrt(((a - c) / 2) ** 2 + b * b)
    expected = ((a + c) / 2 + root) / ((a + c) / 2 - root)
    assert mass_matrix_condition(arm, q) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize('call', [
    lambda m: inverse_dynamics(m, [0.0, 0.0], [1e200, 1e200]),
    lambda m: inverse_dynamics_batch(m, np.zeros((2, 2)),
                                     np.full((2, 2), 1e200)),
    lambda m: forward_dynamics(m, [0.0, 0.0], [1e200, 1e200], [0.0, 0.0]),
])
def test_finite_input_that_overflows_raises(arm, call):
    """Finite input never yields NaN/Inf: an overflow is a clear error."""
    with pytest.raises(DynamicsInputError, match='overflows float64'):
        call(arm)


def _as(kind, x):
    """Return x (a float64 vector) as a list, tuple, int or float32 array."""
    if kind == 'list':
        return [float(v) for v in x]
    if kind == 'tuple':
        return tuple(x)
    return np.asarray(x).astype(kind)


@pytest.mark.parametrize('kind', ['list', 'tuple', np.int64, np.int32,
                                  np.float32])
def test_lists_and_other_dtypes_give_what_float64_arrays_give(kind):
    # integer-valued states, so that every kind holds the same numbers:
    # the result must be the float64 result to the last bit
    arm = load_robot('planar_2r')
    q = np.array([1.0, -2.0])
    qd = np.array([3.0, 1.0])
    qdd = np.array([-1.0, 2.0])
    w = np.array([0.0, 0.0, 10.0, 0.0, 1.0, 0.0])
    x = {name: _as(kind, v) for name, v in
         (('q', q), ('qd', qd), ('qdd', qdd), ('w', w))}
    pairs = [
        (inverse_dynamics(arm, q, qd, qdd, w),
         inverse_dynamics(arm, x['q'], x['qd'], x['qdd'], x['w'])),
        (inverse_dynamics(arm, q, qd, qdd, w, 'end_effector'),
         inverse_dynamics(arm, x['q'], qd, x['qdd'], x['w'],
                          'end_effector')),
        (gravity_torques(arm, q), gravity_torques(arm, x['q'])),
        (mass_matrix(arm, q), mass_matrix(arm, x['q'])),
        (coriolis_matrix(arm, q, qd), coriolis_matrix(arm, x['q'], x['qd'])),
        (forward_dynamics(arm, q, qd, qdd), forward_dynamics(
            arm, x['q'], x['qd'], x['qdd'])),
        (jacobian(arm, q), jacobian(arm, x['q'])),
    ]
    for expected, got in pairs:
        assert got.dtype == np.float64
        assert np.array_equal(got, expected)


def test_a_refused_call_leaves_the_fast_path_intact(arm):
    """After a list, a float64 array still takes the compiled entry."""
    q = np.array([0.3, -0.4])
    first = inverse_dynamics(arm, q)
    inverse_dynamics(arm, [0.3, -0.4])
    assert len(dynamics._tau.overloads) == 1    # no second compilation
    assert np.array_equal(inverse_dynamics(arm, q), first)


@pytest.mark.parametrize('call', [
    lambda m, ws: inverse_dynamics(m, [0.0, 0.0], ws=ws),
    lambda m, ws: gravity_torques(m, [0.0, 0.0], ws=ws),
    lambda m, ws: mass_matrix(m, [0.0, 0.0], ws=ws),
    lambda m, ws: coriolis_matrix(m, [0.0, 0.0], [0.0, 0.0], ws=ws),
    lambda m, ws: forward_dynamics(m, [0.0, 0.0], [0.0, 0.0], [0.0, 0.0],
                                   ws=ws),
])
def test_a_ws_that_is_no_workspace_is_one_clear_error(arm, call):
    with pytest.raises(DynamicsInputError, match='ws must be a float64 '
                                                 'Workspace'):
        call(arm, np.zeros((2, 21)))


def test_lists_copied_into_the_workspace_never_alias_a_result():
    """
    Lists are copied into rows of the workspace (calling.inputs).

    The next call overwrites those rows: a result handed back, or the
    Cholesky path a model with mimic joints takes from lists, must not
    read them afterwards.
    """
    from random_tree import random_tree_urdf
    arm = load_robot('puma560')
    rng = np.random.default_rng(5)
    a, b = rng.uniform(-1, 1, (2, 4, 6))
    w = rng.uniform(-5, 5, (2, 6))
    first = inverse_dynamics(arm, *a[:3].tolist(), w[0].tolist())
    second = forward_dynamics(arm, *b[:3].tolist(), w[1].tolist())
    assert np.array_equal(first, inverse_dynamics(arm, *a[:3], w[0]))
    assert np.array_equal(second, forward_dynamics(arm, *b[:3], w[1]))
    # a float64 q with a list wrench: the wrench converted, q as given
    assert np.array_equal(inverse_dynamics(arm, a[0], wrench=list(w[0])),
                          inverse_dynamics(arm, a[0], wrench=w[0]))
    # mimic joints: the articulated-body entry refuses, the Cholesky path
    # runs from the converted rows
    import warnings
    from newton_euler_ros.core import load_urdf
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        tree = load_urdf(random_tree_urdf(22, links=10)[0])
    assert tree.nb > tree.n
    q, qd, tau = rng.uniform(-1, 1, (3, tree.n))
    assert np.array_equal(
        forward_dynamics(tree, q.tolist(), qd.tolist(), tau.tolist()),
        forward_dynamics(tree, q, qd, tau))


@pytest.mark.parametrize('call, message', [
    (lambda m: forward_dynamics(m, [0, 0], None, [0, 0]),
     'qd must be a vector'),
    (lambda m: forward_dynamics(m, [0, 0], [0, 0], None),
     'tau must be a vector'),
    (lambda m: forward_dynamics(m, [0, 0], [0, 0], [0, 0], [0] * 5),
     'wrench must have 6 entries, got 5'),
    (lambda m: inverse_dynamics(m, np.zeros(2), wrench=(0, 0, 'x', 0, 0, 0)),
     'wrench must be a sequence'),
    (lambda m: inverse_dynamics(m, (0, 0), (0, [1, 2])),
     'qd must be a sequence'),
])
def test_bad_lists_name_the_argument(arm, call, message):
    with pytest.raises(DynamicsInputError, match=message):
        call(arm)


def test_lists_with_a_wrong_ws_or_out_name_it(arm):
    """The list path passes ws and out to the kernel unchecked, then says."""
    from newton_euler_ros.core import Workspace
    q = [0.1, 0.2]
    with pytest.raises(DynamicsInputError, match='ws must be a float64'):
        inverse_dynamics(arm, q, q, q, ws=Workspace(arm, np.float32))
    with pytest.raises(DynamicsInputError, match='ws must be a float64'):
        inverse_dynamics(arm, q, ws=Workspace(load_robot('puma560')))
    for out in (np.empty(3), np.empty(2, np.float32), np.empty((2, 2))):
        with pytest.raises(DynamicsInputError, match='out must be a '):
            inverse_dynamics(arm, q, q, q, [0.0] * 6, out=out)
    out = np.empty(2)
    assert inverse_dynamics(arm, q, q, q, out=out) is out
    assert np.array_equal(out, inverse_dynamics(arm, np.array(q),
                                                np.array(q), np.array(q)))
