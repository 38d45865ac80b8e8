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
Stress tests: float64 dynamics against a 50-digit reference at the edges.

Every float64 result is compared with
:class:`~newton_euler_ros.core.highprec.HighPrecisionModel`, the same
kernel source evaluated at 50 significant digits from the same float64
inputs, so the comparison measures round-off only.  ``relative_error`` is
max |float - exact| / max |exact| over the output.

Why a few ulp is the right size: each torque is a sum over the links
beyond the joint of products of rotations (entries <= 1), lever arms,
masses and rates; each product carries a few rounding errors and the
backward pass adds O(n) of them, so |error| <= c n eps max |term|.  As
long as the largest term is not much larger than the largest output
(no catastrophic cancellation), the relative error is c n eps with a
small c.  Each case states its c below; the measured errors are printed
as a table at the end of the module (run pytest with ``-s``).
"""
import math
import warnings

from hypothesis import given, HealthCheck, settings, strategies as st
import mpmath
from newton_euler_ros.core import (bundled_robots, coriolis_matrix,
                                   DynamicsInputError, forward_dynamics,
                                   gravity_torques, inverse_dynamics,
                                   jacobian, link_poses, load_robot,
                                   make_model, mass_matrix,
                                   mass_matrix_condition,
                                   NotPositiveDefiniteError, pose_matrix)
from newton_euler_ros.core.highprec import HighPrecisionModel, relative_error
from newton_euler_ros.core.model import convert_convention, rpy_matrix
from newton_euler_tools.accuracy.chains import random_chain, random_inertia
import numpy as np
import pytest

EPS = np.finfo(np.float64).eps
ERRORS = []


def _record(case, quantity, err, bound):
    ERRORS.append((case, quantity, err, bound))
    assert math.isfinite(err), f'{case} {quantity}: error is {err}'
    assert err <= bound, (
        f'{case} {quantity}: relative error {err:.3e} > bound {bound:.3e}')


@pytest.fixture(scope='module', autouse=True)
def error_table():
    """Print the measured errors after the module's tests."""
    yield
    if not ERRORS:
        return
    print('\n\nfloat64 vs 50-digit reference (relative error = '
          'max|diff| / max|exact|)')
    print(f'{"case":<44} {"quantity":<14} {"error":>10} {"in eps":>8} '
          f'{"bound":>10}')
    for case, quantity, err, bound in ERRORS:
        if quantity == 'cond(D)':
            print(f'{case:<44} {quantity:<14} {err:10.2e} {"-":>8} '
                  f'{"-":>10}')
            continue
        print(f'{case:<44} {quantity:<14} {err:10.2e} {err / EPS:8.1f} '
              f'{bound:10.2e}')


def _finite(*arrays):
    for x in arrays:
        assert np.all(np.isfinite(np.asarray(x, dtype=np.float64))), x


def _robot(name):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot(name)


def _random_chain(n, seed, convention='standard', prismatic=0.3,
                  masses=None, name='chain'):
    """Build a seeded random DH chain with mixed joints."""
    return random_chain(n, convention=convention, prismatic=prismatic,
                        masses=masses, name=name,
                        rng=np.random.default_rng(seed))


def _state(model, rng, scale=1.0):
    n = model.n
    return (rng.uniform(-2.0, 2.0, n), scale * rng.uniform(-1.0, 1.0, n),
            scale * rng.uniform(-1.0, 1.0, n))


def _check_tau(case, model, hp, q, qd, qdd, wrench=None, frame='base',
               bound=None):
    n = model.n
    bound = 10 * n * EPS if bound is None else bound
    tau = inverse_dynamics(model, q, qd, qdd, wrench, frame)
    _finite(tau)
    err = relative_error(tau, hp.inverse_dynamics(q, qd, qdd, wrench, frame))
    _record(case, 'tau', err, bound)
    return tau


def _check_matrices(case, model, hp, q, qd, bound=None):
    """
    Check D and C (both algorithms) against 50 digits.

    The composite-body C sums products of moment arms about the origin of
    frame 0 that cancel, and where C vanishes exactly (a stretched planar
    arm) it returns round-off, not zeros: its error is measured against
    the scale C has, max|D| max|qd| (C = sum dD/dq_i qd_i / 2 and the
    derivatives of D are of the size of D on arms of metre scale).
    """
    n = model.n
    bound = 10 * n * EPS if bound is None else bound
    D = mass_matrix(model, q)
    C = coriolis_matrix(model, q, qd, method='newton_euler')
    Cc = coriolis_matrix(model, q, qd)
    _finite(D, C, Cc)
    D_exact = hp.mass_matrix(q)
    C_exact = hp.coriolis_matrix(q, qd)
    _record(case, 'D', relative_error(D, D_exact), bound)
    _record(case, 'C', relative_error(C, C_exact), bound)
    scale = (max(abs(x) for x in np.ravel(D_exact))
             * mpmath.mpf(float(np.max(np.abs(qd)))))
    diff = max(abs(mpmath.mpf(float(a)) - e)
               for a, e in zip(np.ravel(Cc), np.ravel(C_exact)))
    _record(case, 'C composite', float(diff / scale), bound)
    return D, C


# ---------------------------------------------------------------------------
# kinematic singularities
# ---------------------------------------------------------------------------

def _puma_elbow_stretched(puma):
    """Return q3 that puts the Puma wrist centre at full reach."""
    def reach(q3):
        T = link_poses(puma, [0.0, 0.3, q3, 0.0, 0.5, 0.0])
        return np.linalg.norm(T[4, :3, 3] - T[1, :3, 3])

    grid = np.linspace(-math.pi, math.pi, 721)
    lo = grid[int(np.argmax([reach(x) for x in grid]))] - 0.01
    hi = lo + 0.02
    for _ in range(80):
        m1, m2 = lo + (hi - lo) / 3, hi - (hi - lo) / 3
        if reach(m1) < reach(m2):
            lo = m1
        else:
            hi = m2
    return 0.5 * (lo + hi)


def _sigma_ratio(model, q):
    s = np.linalg.svd(jacobian(model, q), compute_uv=False)
    return s[-1] / s[0]


@pytest.mark.parametrize('wrench', [None, 'base', 'end_effector'])
def test_singular_configurations_match_high_precision(wrench):
    """
    Check Puma and planar 2R at singularities, with and without a wrench.

    The recursion never divides, so a singular Jacobian does not amplify
    round-off: the same c n eps bound (c = 10) as at a generic pose holds.
    """
    rng = np.random.default_rng(1)
    F = None if wrench is None else rng.normal(size=6) * 50.0
    frame = 'base' if wrench is None else wrench
    puma = _robot('puma560')
    hp = HighPrecisionModel(puma)
    q3 = _puma_elbow_stretched(puma)
    poses = {
        'puma q5=0 (wrist aligned)': [0.4, -0.7, 0.9, 1.1, 0.0, -0.3],
        'puma elbow stretched': [0.4, 0.3, q3, 0.0, 0.5, 0.0],
        'puma elbow folded': [0.4, 0.3, q3 + math.pi, 0.0, 0.5, 0.0],
        'puma stretched + q5=0': [0.0, 0.3, q3, 0.0, 0.0, 0.0],
    }
    for label, q in poses.items():
        q = np.array(q)
        assert _sigma_ratio(puma, q) < 1e-6, label
        qd, qdd = rng.uniform(-1.0, 1.0, (2, 6))
        _check_tau(f'{label} F={wrench}', puma, hp, q, qd, qdd, F, frame)
        if wrench is None:
            _check_matrices(label, puma, hp, q, qd)
            _finite(jacobian(puma, q), gravity_torques(puma, q))
    arm = _robot('planar_2r')
    hp2 = HighPrecisionModel(arm)
    for label, q2 in (('planar_2r stretched q2=0', 0.0),
                      ('planar_2r folded q2=pi', math.pi)):
        q = np.array([0.7, q2])
        J = jacobian(arm, q)
        assert abs(np.linalg.det(J[:2, :2])) < 1e-15
        qd, qdd = rng.uniform(-1.0, 1.0, (2, 2))
        _check_tau(f'{label} F={wrench}', arm, hp2, q, qd, qdd, F, frame)
        if wrench is None:
            _check_matrices(label, arm, hp2, q, qd)


# ---------------------------------------------------------------------------
# near-singular mass matrices
# ---------------------------------------------------------------------------

def _spread_chain(n=8, seed=5):
    """Masses and inertias spanning 1e-9 .. 1e3 kg in one chain."""
    rng = np.random.default_rng(seed)
    masses = np.logspace(-9, 3, n)
    rng.shuffle(masses)
    return _random_chain(n, seed, masses=masses, name='spread')


def _point_and_zero_mass_chain():
    """Link 0 a point mass, link 1 massless with inertia, etc."""
    rng = np.random.default_rng(8)
    base = _random_chain(5, 8, prismatic=0.0)
    mass = np.array(base.mass)
    inertia = np.array(base.inertia)
    com = np.array(base.com)
    mass[1] = 0.0                                  # massless, inertia only
    inertia[0] = inertia[2] = inertia[4] = 0.0     # point masses
    com[4] = rng.uniform(0.2, 0.4, 3)              # off every joint axis
    return base.replace(mass=mass, inertia=inertia, com=com)


def _check_forward(case, model, q, qd):
    n = model.n
    rng = np.random.default_rng(2)
    D = mass_matrix(model, q)
    tau = rng.normal(size=n) * np.sqrt(np.diag(D))
    rhs = tau - inverse_dynamics(model, q, qd)
    # Cholesky is backward stable: (D + dD) qdd = rhs with
    # ||dD|| <= gamma_{3n+1} n ||D|| (Higham, Thm 10.4 + Lemma 10.5), so the
    # scaled residual is at most about 3 n^2 eps.  The articulated-body
    # algorithm (the default) factorizes D too, from the tip (a reverse
    # LDL^T, never forming D); the same bound holds for it, measured.
    for method in ('aba', 'cholesky'):
        qdd = forward_dynamics(model, q, qd, tau, method=method)
        _finite(qdd)
        res = np.linalg.norm(D @ qdd - rhs) / (
            np.linalg.norm(D, 2) * np.linalg.norm(qdd) + np.linalg.norm(rhs))
        _record(case, f'fd residual ({method})', res, 3 * n * n * EPS)
    cond = mass_matrix_condition(model, q)
    assert math.isfinite(cond) and cond >= 1.0
    return cond


@pytest.mark.parametrize('kind', ['spread 1e-9..1e3 kg', 'point/zero mass'])
def test_near_singular_mass_matrix(kind):
    """
    Check D, its symmetry, Cholesky and the forward-dynamics residual.

    D is checked entrywise against its own diagonal: every entry is a sum
    over links of J_k^T M_k J_k contributions, so by Cauchy-Schwarz
    |D_ij| <= sqrt(D_ii D_jj) and round-off on D_ij is c n eps of that
    scale (not of max |D|, which would hide the light links).
    """
    model = (_spread_chain() if kind.startswith('spread')
             else _point_and_zero_mass_chain())
    hp = HighPrecisionModel(model)
    rng = np.random.default_rng(3)
    n = model.n
    for trial in range(3):
        q, qd, qdd = _state(model, rng)
        D = mass_matrix(model, q)
        Dx = hp.mass_matrix(q)
        diag = np.sqrt(np.array([float(Dx[i, i]) for i in range(n)]))
        scaled = max(float(abs(mpmath.mpf(float(D[i, j])) - Dx[i, j]))
                     / (diag[i] * diag[j])
                     for i in range(n) for j in range(n))
        _record(f'{kind} #{trial}', 'D scaled', scaled, 10 * n * EPS)
        # D is assembled column by column, so it is symmetric to round-off
        # only; the same diagonal scaling applies.
        asym = np.max(np.abs(D - D.T) / np.outer(diag, diag))
        _record(f'{kind} #{trial}', 'D asym', asym, 20 * n * EPS)
        _check_tau(f'{kind} #{trial}', model, hp, q, qd, qdd)
        cond = _check_forward(f'{kind} #{trial}', model, q, qd)
        ERRORS.append((f'{kind} #{trial}', 'cond(D)', cond, math.inf))


def test_massless_tail_raises_naming_the_joint():
    """Check a chain whose last two links carry nothing is refused."""
    model = _random_chain(6, 21, prismatic=0.0)
    mass = np.array(model.mass)
    inertia = np.array(model.inertia)
    mass[4:] = 0.0
    inertia[4:] = 0.0
    tail = model.replace(mass=mass, inertia=inertia)
    q = np.linspace(0.2, 1.2, 6)
    with pytest.raises(NotPositiveDefiniteError) as info:
        forward_dynamics(tail, q, np.zeros(6), np.ones(6))
    assert info.value.joint == 4
    assert 'joint 4' in str(info.value) and 'j4' in str(info.value)
    assert mass_matrix_condition(tail, q) == math.inf
    _finite(mass_matrix(tail, q), inverse_dynamics(tail, q, q, q))


# ---------------------------------------------------------------------------
# long chains
# ---------------------------------------------------------------------------

def test_long_chains_error_growth():
    """
    Check tau for n = 50, 100, 200 (D and C for n = 50) against 50 digits.

    Forward dynamics (both methods) is checked by its residual, as for
    the near-singular chains below.

    Each frame's rotation is a product of j rotations, so its error grows
    like j eps (worst case; sqrt(j) eps for random rounding), and the
    backward pass sums n link forces.  Bound: c n eps with c = 4, a
    worst-case constant over the few flops per link of the forward and
    backward passes (measured errors are well below, growing slower than
    n because the roundings are random).
    """
    rows = []
    for n in (50, 100, 200):
        model = _random_chain(n, 100 + n)
        hp = HighPrecisionModel(model)
        rng = np.random.default_rng(n)
        worst = 0.0
        for _ in range(2):
            q, qd, qdd = _state(model, rng)
            tau = _check_tau(f'random chain n={n}', model, hp, q, qd, qdd,
                             bound=4 * n * EPS)
            worst = max(worst, ERRORS[-1][2])
            assert np.all(np.isfinite(tau))
        if n == 50:
            _check_matrices(f'random chain n={n}', model, hp, q, qd,
                            bound=4 * n * EPS)
        _check_forward(f'random chain n={n}', model, q, qd)
        rows.append((n, worst))
    print('\nlong chains: n, max tau error, error / (n eps)')
    for n, worst in rows:
        print(f'  {n:4d} {worst:10.2e} {worst / (n * EPS):8.3f}')


# ---------------------------------------------------------------------------
# high rates, large joint values, scale
# ---------------------------------------------------------------------------

def test_high_speed_and_acceleration():
    """
    Check qd ~ 1e3 rad/s and qdd ~ 1e4 rad/s^2 on Puma and Stanford.

    tau is then dominated by the velocity and acceleration terms (1e6
    times gravity), homogeneous in the rates, so the relative error is the
    same c n eps (c = 10) as at ordinary rates.
    """
    rng = np.random.default_rng(4)
    for name in ('puma560', 'stanford', 'panda'):
        model = _robot(name)
        hp = HighPrecisionModel(model)
        n = model.n
        q = rng.uniform(-2.0, 2.0, n)
        qd = rng.choice([-1.0, 1.0], n) * 1e3
        qdd = rng.choice([-1.0, 1.0], n) * 1e4
        _check_tau(f'{name} qd=1e3 qdd=1e4', model, hp, q, qd, qdd,
                   rng.normal(size=6) * 100.0)
        _check_matrices(f'{name} qd=1e3', model, hp, q, qd)


def test_large_joint_values_and_long_extension():
    """
    Check |q| up to 1e6 rad and prismatic joints at 1e3 m extension.

    Fair comparison: float64 cos and sin of a float64 q are correctly
    rounded (to within 1 ulp) even at 1e6 rad, and the reference takes the
    same float64 q as exact, so no argument-reduction error is charged to
    either side.  With a 1e3 m lever arm the revolute torques are ~1e3
    times the prismatic forces; the error is still c n eps (c = 10) of
    the largest torque because each lever-arm product is rounded
    relatively.

    A revolute joint with a theta offset (planar_rp has theta_1 = pi/2)
    does not round q + offset: the kernel uses the angle-addition formulas
    with the offset's cosine and sine (before that fix this case measured
    4.7e-12).  A prismatic joint with a d offset still forms d + q in
    float64, rounded to |q| eps / 2 absolute (backward stable: exact for q
    moved by one relative eps); the bound adds twice
    |q_i| eps |dtau/dq_i| / max|tau| for such joints.
    """
    rng = np.random.default_rng(6)
    puma = _robot('puma560')
    hp = HighPrecisionModel(puma)
    for scale in (1e3, 1e6):
        q = rng.uniform(-1.0, 1.0, 6) * scale
        qd, qdd = rng.uniform(-1.0, 1.0, (2, 6))
        _check_tau(f'puma |q|~{scale:.0e} rad', puma, hp, q, qd, qdd)
        _check_matrices(f'puma |q|~{scale:.0e} rad', puma, hp, q, qd)
    for name, qp in (('stanford', 2), ('scara', 2), ('planar_rp', 1)):
        model = _robot(name)
        hp = HighPrecisionModel(model)
        q = rng.uniform(-1.0, 1.0, model.n) * 1e6
        q[qp] = 1e3
        qd, qdd = rng.uniform(-1.0, 1.0, (2, model.n))
        F = rng.normal(size=6)
        bound = (10 * model.n * EPS
                 + 2 * _offset_rounding(model, q, qd, qdd, F))
        _check_tau(f'{name} prismatic 1e3 m, |q|~1e6', model, hp, q, qd, qdd,
                   F, bound=bound)
        _check_matrices(f'{name} prismatic 1e3 m', model, hp, q, qd)
        _finite(jacobian(model, q), gravity_torques(model, q))


def _offset_rounding(model, q, qd, qdd, F):
    """Return sum_i |q_i| eps |dtau/dq_i| / max|tau| over d-offset joints."""
    tau = inverse_dynamics(model, q, qd, qdd, F)
    total = 0.0
    for i in range(model.n):
        if model.joint_types[i] == 'revolute' or model.d[i] == 0.0:
            continue
        h = np.zeros(model.n)
        h[i] = 1e-3
        slope = (inverse_dynamics(model, q + h, qd, qdd, F)
                 - inverse_dynamics(model, q - h, qd, qdd, F)) / 2e-3
        total += abs(q[i]) * EPS * np.max(np.abs(slope))
    return total / np.max(np.abs(tau))


def _scaled(model, length, mass):
    return model.replace(
        a=np.array(model.a) * length, d=np.array(model.d) * length,
        com=np.array(model.com) * length, mass=np.array(model.mass) * mass,
        inertia=np.array(model.inertia) * mass * length ** 2,
        name=model.name + '_small')


def test_millimetre_gram_robot():
    """
    Check planar 2R scaled by 1e-3 m and 1e-3 kg: scaling law and accuracy.

    For revolute joints D and C scale as M L^2 and gravity torques as
    M L (gravity itself is not scaled).  The scaled parameters are each
    rounded once (1e-3 is not a binary number), so the scaling law holds
    to a few eps relative; the comparison with 50 digits is scale-free.
    """
    arm = _robot('planar_2r')
    small = _scaled(arm, 1e-3, 1e-3)
    hp = HighPrecisionModel(small)
    rng = np.random.default_rng(7)
    for _ in range(3):
        q, qd, qdd = _state(arm, rng)
        tau_s = _check_tau('planar_2r mm/g', small, hp, q, qd, qdd)
        _check_matrices('planar_2r mm/g', small, hp, q, qd)
        dyn = inverse_dynamics(arm, q, qd, qdd, gravity=False)
        dyn_s = inverse_dynamics(small, q, qd, qdd, gravity=False)
        np.testing.assert_allclose(dyn_s, 1e-9 * dyn, rtol=0,
                                   atol=20 * EPS * 1e-9 * np.abs(dyn).max())
        g = gravity_torques(arm, q)
        g_s = gravity_torques(small, q)
        np.testing.assert_allclose(g_s, 1e-6 * g, rtol=0,
                                   atol=20 * EPS * 1e-6 * np.abs(g).max())
        np.testing.assert_allclose(mass_matrix(small, q),
                                   1e-9 * mass_matrix(arm, q), rtol=20 * EPS)
        assert np.abs(tau_s).max() < 1e-3


def test_gravity_off_and_tilted():
    """
    Check gravity off (exact zero) and a tilted gravity vector.

    Tilted gravity only changes the constant base acceleration of the
    recursion, so the c n eps bound (c = 10) is unchanged.
    """
    rng = np.random.default_rng(9)
    for name in ('puma560', 'planar_2r', 'stanford'):
        model = _robot(name)
        q, qd, qdd = _state(model, rng)
        off = model.replace(gravity=[0.0, 0.0, 0.0])
        assert np.all(gravity_torques(off, q) == 0.0)
        np.testing.assert_array_equal(
            inverse_dynamics(off, q, qd, qdd),
            inverse_dynamics(model, q, qd, qdd, gravity=False))
        g = 9.81 * rpy_matrix(0.3, -0.7, 1.1) @ np.array([0.0, 0.0, -1.0])
        tilted = model.replace(gravity=g)
        hp = HighPrecisionModel(tilted)
        _check_tau(f'{name} tilted gravity', tilted, hp, q, qd, qdd)
        _check_tau(f'{name} tilted gravity, static', tilted, hp, q,
                   np.zeros(model.n), np.zeros(model.n))


# ---------------------------------------------------------------------------
# standard vs modified DH
# ---------------------------------------------------------------------------

def _max_rel(a, b):
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


@pytest.mark.parametrize('name', sorted(bundled_robots()))
def test_standard_and_modified_dh_agree(name):
    """
    Check the robot in both DH conventions gives the same dynamics.

    convert_convention re-expresses com and inertia through one rotation
    (a few roundings each) and the two recursions round differently, so
    the results agree to c n eps of the largest entry with c = 20 (two
    independent float64 evaluations, each within 10 n eps).
    """
    model = _robot(name)
    other = convert_convention(
        model, 'modified' if model.convention == 'standard' else 'standard')
    back = convert_convention(other, model.convention)
    n = model.n
    bound = 20 * n * EPS
    rng = np.random.default_rng(10)
    for _ in range(3):
        q, qd, qdd = _state(model, rng)
        F = rng.normal(size=6) * 10.0
        for m in (other, back):
            for frame in ('base', 'end_effector'):
                assert _max_rel(
                    inverse_dynamics(m, q, qd, qdd, F, frame),
                    inverse_dynamics(model, q, qd, qdd, F, frame)) < bound
                assert _max_rel(jacobian(m, q, frame),
                                jacobian(model, q, frame)) < bound
            assert _max_rel(mass_matrix(m, q), mass_matrix(model, q)) < bound
            assert _max_rel(coriolis_matrix(m, q, qd),
                            coriolis_matrix(model, q, qd)) < bound
            assert _max_rel(gravity_torques(m, q),
                            gravity_torques(model, q)) < bound
        err = _max_rel(inverse_dynamics(other, q, qd, qdd, F),
                       inverse_dynamics(model, q, qd, qdd, F))
        ERRORS.append((f'{name} std vs mod DH', 'tau diff', err, bound))


def test_non_finite_input_still_refused():
    """Check the stress helpers did not weaken input validation."""
    model = _robot('puma560')
    with pytest.raises(DynamicsInputError):
        inverse_dynamics(model, [0.0] * 5 + [math.inf])


# ---------------------------------------------------------------------------
# property tests over random robots
# ---------------------------------------------------------------------------

@st.composite
def robots_and_states(draw):
    """Draw a random robot (both conventions, mixed joints) and a state."""
    n = draw(st.integers(1, 6))
    convention = draw(st.sampled_from(['standard', 'modified']))
    types = draw(st.lists(st.sampled_from(['revolute', 'prismatic']),
                          min_size=n, max_size=n))
    angle = st.floats(-math.pi, math.pi, allow_nan=False)
    tool = pose_matrix(
        draw(st.tuples(*[st.floats(-0.2, 0.2)] * 3)),
        draw(st.tuples(angle, angle, angle)))
    seed = draw(st.integers(0, 2 ** 32 - 1))
    rng = np.random.default_rng(seed)
    mass = rng.uniform(0.1, 10.0, n)
    size = rng.uniform(0.02, 0.3, n)
    model = make_model(
        'hyp', convention, [f'j{k}' for k in range(n)], types,
        a=rng.uniform(-0.5, 0.5, n), alpha=rng.uniform(-math.pi, math.pi, n),
        d=rng.uniform(-0.5, 0.5, n), theta=rng.uniform(-math.pi, math.pi, n),
        mass=mass, com=rng.uniform(-0.2, 0.2, (n, 3)),
        inertia=np.array([random_inertia(rng, m, s) for m, s in zip(mass, size)]),
        gravity=rng.normal(size=3) * 5.0, tool=tool,
        base=pose_matrix(rng.uniform(-0.5, 0.5, 3),
                         rng.uniform(-math.pi, math.pi, 3)))
    q, qd, qdd = rng.uniform(-2.0, 2.0, (3, n))
    return model, q, qd, qdd


PROPERTY = settings(max_examples=25, deadline=None, database=None,
                    suppress_health_check=[HealthCheck.too_slow])


@PROPERTY
@given(robots_and_states())
def test_property_mass_matrix_symmetric_positive_definite(case):
    """
    Check D is symmetric and positive definite for physical links.

    Every link has m > 0 and a positive definite inertia, so zero kinetic
    energy forces each link, from the base out, to stand still: D is PD.
    Asymmetry is round-off of two differently computed sums: <= 20 n eps
    of max |D|.
    """
    model, q, _, _ = case
    D = mass_matrix(model, q)
    _finite(D)
    assert np.max(np.abs(D - D.T)) <= 20 * model.n * EPS * np.max(np.abs(D))
    assert np.linalg.eigvalsh(0.5 * (D + D.T))[0] > 0.0
    assert math.isfinite(mass_matrix_condition(model, q))


@PROPERTY
@given(robots_and_states())
def test_property_ddot_equals_c_plus_ct(case):
    """
    Check dD/dt = C + C^T, dD/dt by central difference along qd.

    With h = 1e-6 the truncation error is h^2 |D'''| |qd|^3 / 6 ~ 1e-11
    of |D| (|qd| <= 2, lengths ~ 0.1 m), and round-off is about
    10 n eps |D| / h ~ 1.3e-8 |D| for n = 6; the tolerance 1e-6 of
    max(|D|, |C|) leaves a margin of about 100.
    """
    model, q, qd, _ = case
    h = 1e-6
    Ddot = (mass_matrix(model, q + h * qd)
            - mass_matrix(model, q - h * qd)) / (2.0 * h)
    C = coriolis_matrix(model, q, qd)
    _finite(Ddot, C)
    scale = max(np.max(np.abs(mass_matrix(model, q))), np.max(np.abs(C)))
    assert np.max(np.abs(Ddot - (C + C.T))) <= 1e-6 * scale


@PROPERTY
@given(robots_and_states())
def test_property_coriolis_times_qd_is_velocity_torque(case):
    """
    Check C qd = tau(q, qd, 0) - g(q) with gravity on and no wrench.

    Both sides are sums of O(n) terms of size <= |C| |qd| + |g|; the
    subtraction cancels g, so the tolerance is 100 n eps of that scale.
    """
    model, q, qd, _ = case
    C = coriolis_matrix(model, q, qd)
    lhs = C @ qd
    g = gravity_torques(model, q)
    rhs = inverse_dynamics(model, q, qd) - g
    _finite(lhs, rhs)
    scale = np.max(np.abs(C) @ np.abs(qd)) + np.max(np.abs(g)) + 1e-300
    assert np.max(np.abs(lhs - rhs)) <= 100 * model.n * EPS * scale


def _energy(model, q, qd):
    D = mass_matrix(model, q)
    T = link_poses(model, q)
    U = 0.0
    for j in range(model.n):
        p = T[j + 1, :3, :3] @ model.com[j] + T[j + 1, :3, 3]
        U -= model.mass[j] * model.gravity @ p
    return 0.5 * qd @ D @ qd + U


@PROPERTY
@given(robots_and_states())
def test_property_power_balance(case):
    """
    Check d/dt (qd^T D qd / 2 + U) = qd^T tau along q(t) = q + t qd + t^2 qdd / 2.

    On that quadratic trajectory (q, qd, qdd) at t = 0 are exact, so the
    identity holds exactly.  dE/dt by the fourth-order central stencil with
    h = 1e-3: truncation h^4 |E^(5)| / 30 ~ 1e-12 of the power scale and
    round-off ~ 2 eps |E| / h ~ 1e-12 |E|; tolerance 1e-8 of the scale.
    """
    model, q, qd, qdd = case
    tau = inverse_dynamics(model, q, qd, qdd)
    _finite(tau)
    h = 1e-3

    def energy_at(t):
        return _energy(model, q + t * qd + 0.5 * t * t * qdd, qd + t * qdd)

    dE = (-energy_at(2 * h) + 8 * energy_at(h) - 8 * energy_at(-h)
          + energy_at(-2 * h)) / (12 * h)
    power = qd @ tau
    scale = np.abs(qd) @ np.abs(tau) + abs(energy_at(0.0)) + 1e-300
    assert abs(dE - power) <= 1e-8 * scale
