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
float64 results against the same recursion evaluated at 50 digits.

The high-precision run executes the same kernel source, so it measures
round-off, not correctness (the Euler-Lagrange tests establish that).
Bound: every output is a sum of O(n) well-scaled products per joint, so
the float64 relative error should be a few ulp; we assert 1e-14 (about
45 ulp) and measure <= 1e-15 on the bundled robots.
"""
import warnings

import mpmath
from newton_euler_ros.core import (bundled_robots, coriolis_matrix,
                                   inverse_dynamics, load_robot, mass_matrix)
from newton_euler_ros.core.highprec import HighPrecisionModel, relative_error
import numpy as np
import pytest

BOUND = 1e-14
# The O(n^2) composite-body C works with inertias and moment arms about
# the origin of frame 0, where products of arm lengths cancel: on the
# planar 2R arm C[1, 1] = 0 exactly comes out as 5e-17, 72 eps of max|C|.
# The n-recursion C keeps BOUND; `make accuracy` tabulates both.
COMPOSITE_BOUND = 1e-13


@pytest.fixture(scope='module', params=sorted(bundled_robots()))
def robot(request):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot(request.param)
    return model, HighPrecisionModel(model, dps=50)


def test_tau_d_c_within_a_few_ulp(robot):
    model, hp = robot
    rng = np.random.default_rng(11)
    for _ in range(3):
        q, qd, qdd = rng.uniform(-2.0, 2.0, size=(3, model.n))
        F = rng.normal(size=6) * 10.0
        for frame in ('base', 'end_effector'):
            assert relative_error(
                inverse_dynamics(model, q, qd, qdd, F, frame),
                hp.inverse_dynamics(q, qd, qdd, F, frame)) < BOUND
        assert relative_error(mass_matrix(model, q),
                              hp.mass_matrix(q)) < BOUND
        exact = hp.coriolis_matrix(q, qd)
        assert relative_error(
            coriolis_matrix(model, q, qd, method='newton_euler'),
            exact) < BOUND
        assert relative_error(coriolis_matrix(model, q, qd),
                              exact) < COMPOSITE_BOUND


def test_reference_really_is_high_precision(robot):
    model, hp = robot
    q = np.linspace(0.1, 0.9, model.n)
    tau = hp.inverse_dynamics(q, q, q)
    assert all(isinstance(x, mpmath.mpf) for x in tau)
    # at 50 digits the exact results are not float64 numbers
    assert any(mpmath.mpf(float(x)) != x for x in tau)
