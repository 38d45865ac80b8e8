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
core.linearize.state_space: A, B and the zero-order-hold pair.

A and B against central differences of forward dynamics (with the drive
terms against the test's own solve of (D + I_a) qdd = ...), tau0 and qdd0
against each other, Ad and Bd against a closed form on a pendulum, the
first-order expansion for a tiny step, and an integration of the linear
system with the input held.
"""
import doctest
import warnings

from newton_euler_ros.core import (Drives, forward_dynamics, gravity_torques,
                                   inverse_dynamics, load_robot, mass_matrix,
                                   robot_from_dict)
from newton_euler_ros.core.linearize import state_space, zero_order_hold
import numpy as np
import pytest

RNG = np.random.default_rng(39)
H = 1e-5            # central-difference step (rad, rad/s, N m)


@pytest.fixture(scope='module')
def puma():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot('puma560')


def drives_of(n):
    return Drives(viscous=np.linspace(0.2, 1.0, n),
                  coulomb=np.linspace(0.5, 0.1, n),
                  offset=np.linspace(-0.1, 0.1, n),
                  armature=np.linspace(0.8, 0.1, n),
                  coulomb_width=np.full(n, 0.05))


def fd_with_drives(model, q, qd, tau, wrench, drives, gravity=True):
    """Solve (D + I_a) qdd = tau - bias - tau_drive densely (the test's own)."""
    n = model.n
    D = mass_matrix(model, q) + np.diag(drives.armature)
    bias = inverse_dynamics(model, q, qd, np.zeros(n), wrench,
                            gravity=gravity)
    return np.linalg.solve(D, tau - bias - drives.torques(qd, np.zeros(n)))


def torques_of_a_move(model, q, qd, wrench=None):
    """
    Torques that move the arm at a few rad/s^2.

    Not arbitrary torques: a few N m on the Puma's light wrist give
    accelerations of 1e5 rad/s^2, whose round-off would swamp the
    differences.
    """
    return inverse_dynamics(model, q, qd, RNG.uniform(-2.0, 2.0, model.n),
                            wrench)


def differences(f, q, qd, tau):
    """Central differences of qdd = f(q, qd, tau): d/dq, d/dqd, d/dtau."""
    n = len(q)
    out = np.zeros((3, n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = H
        out[0, :, j] = (f(q + e, qd, tau) - f(q - e, qd, tau)) / (2 * H)
        out[1, :, j] = (f(q, qd + e, tau) - f(q, qd - e, tau)) / (2 * H)
        out[2, :, j] = (f(q, qd, tau + e) - f(q, qd, tau - e)) / (2 * H)
    return out


def check_against(lin, ref, n):
    """Compare A and B of ``lin`` with the (3, n, n) differences ``ref``."""
    A, B = lin.A, lin.B
    np.testing.assert_array_equal(A[:n, :n], 0.0)
    np.testing.assert_array_equal(A[:n, n:], np.eye(n))
    np.testing.assert_array_equal(B[:n], 0.0)
    for got, want in ((A[n:, :n], ref[0]), (A[n:, n:], ref[1]),
                      (B[n:], ref[2])):
        scale = np.abs(want).max()
        assert np.abs(got - want).max() <= 1e-6 * scale, (got, want)


@pytest.mark.parametrize('wrench', [None, np.array([3.0, -2.0, 5.0, 0.4,
                                                    -0.3, 0.2])])
def test_a_and_b_are_the_derivatives_of_forward_dynamics(puma, wrench):
    q, qd = RNG.uniform(-1.5, 1.5, 6), RNG.uniform(-1.0, 1.0, 6)
    tau = torques_of_a_move(puma, q, qd, wrench)
    lin = state_space(puma, q, qd, tau=tau, wrench=wrench)
    assert lin.Ad is None and lin.Bd is None and lin.dt is None

    def f(q, qd, tau):
        return forward_dynamics(puma, q, qd, tau, wrench)
    check_against(lin, differences(f, q, qd, tau), 6)
    np.testing.assert_allclose(lin.qdd0, f(q, qd, tau), rtol=1e-12,
                               atol=1e-12)
    np.testing.assert_array_equal(lin.tau0, tau)


def test_drive_terms_join_the_dynamics(puma):
    drives = drives_of(6)
    wrench = np.array([1.0, 2.0, -3.0, 0.1, 0.0, -0.2])
    q, qd = RNG.uniform(-1.5, 1.5, 6), RNG.uniform(-0.2, 0.2, 6)
    tau = torques_of_a_move(puma, q, qd, wrench)
    lin = state_space(puma, q, qd, tau=tau, wrench=wrench, drives=drives)

    def f(q, qd, tau):
        return fd_with_drives(puma, q, qd, tau, wrench, drives)
    check_against(lin, differences(f, q, qd, tau), 6)
    np.testing.assert_allclose(lin.qdd0, f(q, qd, tau), rtol=1e-10,
                               atol=1e-10)
    # dqdd/dtau is (D + I_a)^-1
    np.testing.assert_allclose(
        lin.B[6:] @ (mass_matrix(puma, q) + np.diag(drives.armature)),
        np.eye(6), atol=1e-9)


def test_tau0_and_qdd0_agree_both_ways(puma):
    drives = drives_of(6)
    q, qd = RNG.uniform(-1.5, 1.5, 6), RNG.uniform(-1.0, 1.0, 6)
    qdd = RNG.uniform(-2.0, 2.0, 6)
    for d in (None, drives):
        from_qdd = state_space(puma, q, qd, qdd=qdd, drives=d)
        np.testing.assert_array_equal(from_qdd.qdd0, qdd)
        want = inverse_dynamics(puma, q, qd, qdd) + (
            0.0 if d is None else d.torques(qd, qdd))
        np.testing.assert_allclose(from_qdd.tau0, want, rtol=1e-12,
                                   atol=1e-12)
        from_tau = state_space(puma, q, qd, tau=from_qdd.tau0, drives=d)
        np.testing.assert_allclose(from_tau.qdd0, qdd, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(from_tau.A, from_qdd.A, rtol=1e-9,
                                   atol=1e-9 * np.abs(from_qdd.A).max())
    # neither: qdd0 = 0, tau0 holds the velocity unchanged
    rest = state_space(puma, q, qd)
    np.testing.assert_array_equal(rest.qdd0, 0.0)
    np.testing.assert_allclose(rest.tau0, inverse_dynamics(puma, q, qd),
                               rtol=1e-12, atol=1e-12)
    with pytest.raises(ValueError, match='not both'):
        state_space(puma, q, qd, tau=rest.tau0, qdd=qdd)
    with pytest.raises(ValueError, match='dt must be'):
        state_space(puma, q, qd, dt=float('nan'))


def test_a_robot_that_adds_gravity_itself(puma):
    """gravity=False: u is the torque sent; the robot adds g(q)."""
    q, qd = RNG.uniform(-1.5, 1.5, 6), RNG.uniform(-1.0, 1.0, 6)
    u = torques_of_a_move(puma, q, qd) - gravity_torques(puma, q)
    lin = state_space(puma, q, qd, tau=u, gravity=False)

    def f(q, qd, u):
        return forward_dynamics(puma, q, qd, u + gravity_torques(puma, q))
    check_against(lin, differences(f, q, qd, u), 6)
    held = state_space(puma, q, np.zeros(6), gravity=False)
    np.testing.assert_allclose(held.tau0, 0.0, atol=1e-12)


def pendulum():
    """One revolute link of 1 m, 2 kg at its middle, gravity along -y."""
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model, _ = robot_from_dict({
            'name': 'pendulum', 'convention': 'standard',
            'gravity': [0.0, -9.81, 0.0],
            'links': [{'name': 'joint1', 'type': 'revolute', 'a': 1.0,
                       'alpha': 0.0, 'd': 0.0, 'theta': 0.0, 'mass': 2.0,
                       'com': [-0.5, 0.0, 0.0],
                       'inertia': [1e-4, 1 / 6, 1 / 6, 0.0, 0.0, 0.0]}]})
    return model


def test_discrete_pair_of_a_pendulum_in_closed_form():
    """Hanging straight down: an undamped oscillator, omega^2 = m g l / I."""
    model = pendulum()
    inertia = 1 / 6 + 2.0 * 0.5 ** 2      # about the joint
    w2 = 2.0 * 9.81 * 0.5 / inertia
    w = np.sqrt(w2)
    dt = 0.05
    lin = state_space(model, [-np.pi / 2], [0.0], dt=dt)
    np.testing.assert_allclose(lin.tau0, 0.0, atol=1e-12)
    np.testing.assert_allclose(lin.A, [[0.0, 1.0], [-w2, 0.0]], rtol=1e-12)
    np.testing.assert_allclose(lin.B, [[0.0], [1 / inertia]], rtol=1e-12)
    c, s = np.cos(w * dt), np.sin(w * dt)
    np.testing.assert_allclose(lin.Ad, [[c, s / w], [-w * s, c]],
                               rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(
        lin.Bd, [[(1 - c) / w2 / inertia], [s / w / inertia]], rtol=1e-12)
    assert lin.dt == dt and lin.discretisation == 'zero-order hold'


def test_a_tiny_step_is_euler_and_a_long_one_integrates(puma):
    q, qd = RNG.uniform(-1.5, 1.5, 6), RNG.uniform(-1.0, 1.0, 6)
    dt = 1e-7
    lin = state_space(puma, q, qd, drives=drives_of(6), dt=dt)
    # Ad = I + A dt + A^2 dt^2 / 2 + O(dt^3), Bd = (dt + A dt^2 / 2) B + ...
    A, B = lin.A, lin.B
    np.testing.assert_allclose(lin.Ad, np.eye(12) + A * dt + A @ A * dt ** 2
                               / 2, rtol=0, atol=1e-9 * np.abs(A).max() * dt)
    np.testing.assert_allclose(lin.Bd, B * dt + A @ B * dt ** 2 / 2, rtol=0,
                               atol=1e-9 * np.abs(B).max() * dt)
    # one 10 ms step against RK4 of the linear system, input held
    dt = 0.01
    Ad, Bd = zero_order_hold(lin.A, lin.B, dt)
    x0, du = RNG.uniform(-0.1, 0.1, 12), RNG.uniform(-1.0, 1.0, 6)
    x, k = x0.copy(), 1000

    def rate(x):
        return lin.A @ x + lin.B @ du
    for _ in range(k):
        h = dt / k
        a = rate(x)
        b = rate(x + h / 2 * a)
        c = rate(x + h / 2 * b)
        x = x + h / 6 * (a + 2 * b + 2 * c + rate(x + h * c))
    np.testing.assert_allclose(Ad @ x0 + Bd @ du, x, rtol=1e-9, atol=1e-12)


def test_docstring_example_runs():
    from newton_euler_ros.core import linearize
    result = doctest.testmod(linearize)
    assert result.failed == 0 and result.attempted > 0
