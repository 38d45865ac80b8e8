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

"""EffectDynamics: exactly the chosen terms, the wrench an argument."""
import warnings

from newton_euler_ros.core import (EffectDynamics, Effects, inverse_dynamics,
                                   load_robot, mass_matrix)
import numpy as np
import pytest

RNG = np.random.default_rng(7)


@pytest.fixture(scope='module')
def puma():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot('puma560')


def state(n):
    return RNG.uniform(-1.0, 1.0, size=(3, n))


@pytest.mark.parametrize('frame', ['base', 'end_effector'])
def test_without_a_scene_it_is_the_whole_inverse_dynamics(puma, frame):
    q, qd, qdd = state(6)
    w = RNG.uniform(-5.0, 5.0, 6)
    got = EffectDynamics(puma).torques(q, qd, qdd, w, frame)
    assert np.array_equal(got, inverse_dynamics(puma, q, qd, qdd, w, frame))


def test_left_out_terms_are_left_out(puma):
    q, qd, qdd = state(6)
    w = RNG.uniform(-5.0, 5.0, 6)
    inertial = EffectDynamics(puma, Effects(gravity=False,
                                            velocity_products=False))
    # no gravity, no velocity products, the wrench ignored: D qdd
    np.testing.assert_allclose(inertial.torques(q, qd, qdd, w),
                               mass_matrix(puma, q) @ qdd, rtol=0,
                               atol=1e-12)
    assert np.all(inertial.torques(q, qd, None, w) == 0.0)


def test_friction_and_rotor_inertia_add_their_own_torques(puma):
    q, qd, qdd = state(6)
    qd[2] = 0.0                           # Coulomb's sign(0) = 0
    viscous, coulomb = RNG.uniform(0, 2, 6), RNG.uniform(0, 3, 6)
    armature = RNG.uniform(0, 1, 6)
    eff = Effects(friction=True, armature=True)
    dyn = EffectDynamics(puma, eff, viscous, coulomb, armature)
    expected = (inverse_dynamics(puma, q, qd, qdd) + viscous * qd
                + coulomb * np.sign(qd) + armature * qdd)
    np.testing.assert_allclose(dyn.torques(q, qd, qdd), expected, rtol=0,
                               atol=1e-12)
    D = dyn.mass_matrix(q)
    np.testing.assert_allclose(D - np.diag(armature), mass_matrix(puma, q),
                               rtol=0, atol=1e-15)


@pytest.mark.parametrize('frame', ['base', 'end_effector'])
def test_forward_dynamics_inverts_the_torques(puma, frame):
    q, qd, tau = state(6)
    w = RNG.uniform(-5.0, 5.0, 6)
    eff = Effects(wrench=True, friction=True, armature=True)
    dyn = EffectDynamics(puma, eff, np.full(6, 0.5), np.full(6, 0.2),
                         np.full(6, 0.1))
    qdd = dyn.accelerations(q, qd, tau, w, frame)
    np.testing.assert_allclose(dyn.torques(q, qd, qdd, w, frame), tau,
                               rtol=0, atol=1e-11)


def test_default_friction_arrays_are_not_shared(puma):
    dyn = EffectDynamics(puma)
    assert dyn.viscous is not dyn.coulomb
    assert dyn.viscous is not dyn.armature
