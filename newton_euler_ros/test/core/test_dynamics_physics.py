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
Dynamics checked by physics, not by snapshots of the library's output.

Three kinds of evidence:

1. closed forms derived by hand (Spong's planar elbow arm, a planar RP
   arm, the 2 m r rdot thetadot Coriolis force of a sliding joint);
2. an independent Euler-Lagrange oracle (``reference_dynamics.py``: its
   own forward kinematics, D from com Jacobians, C from Christoffel
   symbols of D, g = dU/dq, derivatives by complex step) for every bundled
   robot in both DH conventions and for random chains;
3. identities that relate *different* library functions (Ddot = C + C^T,
   C(q, x) y = C(q, y) x, g = tau(q, 0, 0), forward o inverse = id, ...)
   and conservation of energy along simulated motions, with the energy
   computed by the oracle.

Tolerances are relative to the size of the compared quantity (max-norm):
``err = max|actual - expected| / max(max|expected|, floor)``.  The oracle's
complex-step derivatives are exact to round-off, so library-vs-oracle
checks use 1e-12 (no derivative involved: D, J, poses) or 1e-11 (C, g,
tau); the observed errors are ~1e-15.  Set NE_PHYSICS_ERRORS=path to dump
the largest error seen per check as JSON.
"""
import atexit
import json
import math
import os
import warnings

from hypothesis import given, settings
from hypothesis import strategies as st
from newton_euler_ros.core import (bundled_robots, coriolis_matrix,
                                   end_effector_pose, forward_dynamics,
                                   gravity_torques, inverse_dynamics,
                                   inverse_dynamics_batch, jacobian,
                                   link_poses, load_robot, make_model,
                                   mass_matrix, velocity_products,
                                   wrench_torques)
from newton_euler_ros.core.model import convert_convention
import numpy as np
import pytest
import reference_dynamics as ref    # test/, on sys.path (conftest.py)

BUNDLED = ['panda', 'planar_2r', 'planar_rp', 'puma560', 'scara', 'stanford']
CONVENTIONS = ['standard', 'modified']
R, P = 'revolute', 'prismatic'

# tolerances (relative, see the module docstring)
RTOL_CLOSED = 1e-12     # closed forms: a handful of flops, round-off ~1e-16
RTOL_KIN = 1e-12        # oracle quantities with no derivative (D, J, poses)
RTOL_DERIV = 1e-11      # oracle quantities from complex-step derivatives
RTOL_IDENTITY = 1e-12   # identities between library functions


# ---------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------
MAX_ERR = {}


def _dump_errors():
    path = os.environ.get('NE_PHYSICS_ERRORS')
    if path and MAX_ERR:
        with open(path, 'w') as fh:
            json.dump(dict(sorted(MAX_ERR.items())), fh, indent=1)


atexit.register(_dump_errors)


def check(name, actual, expected, rtol, scale=None, floor=1e-300):
    """Assert max|actual - expected| <= rtol * max(max|expected|, scale)."""
    actual = np.asarray(actual, dtype=float)
    expected = np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, (name, actual.shape,
                                            expected.shape)
    size = np.abs(expected).max() if expected.size else 0.0
    if scale is not None:
        size = max(size, scale)
    size = max(size, floor)
    err = float(np.abs(actual - expected).max()) / size
    MAX_ERR[name] = max(MAX_ERR.get(name, 0.0), err)
    assert err <= rtol, (
        f'{name}: relative error {err:.3e} > {rtol:.1e}\n'
        f'actual   = {actual!r}\nexpected = {expected!r}')
    return err


def load(name):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot(name)


_MODELS = {}


def bundled(name, convention):
    key = (name, convention)
    if key not in _MODELS:
        _MODELS[key] = convert_convention(load(name), convention)
    return _MODELS[key]


def random_state(rng, n, scale=1.0):
    return (rng.uniform(-1.5, 1.5, n), scale * rng.normal(size=n),
            scale * rng.normal(size=n), 5.0 * rng.normal(size=6))


def rot_x(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])


def random_rotation(rng):
    Q, Rr = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q @ np.diag(np.sign(np.diag(Rr)))
    if np.linalg.det(Q) < 0:
        Q[:, 0] = -Q[:, 0]
    return Q


def random_pose(rng, reach=0.5):
    T = np.eye(4)
    T[:3, :3] = random_rotation(rng)
    T[:3, 3] = rng.uniform(-reach, reach, 3)
    return T


def random_inertia(rng):
    """
    Return a random positive semidefinite inertia about the com.

    About a third are rod-like, with a zero principal moment.
    """
    if rng.uniform() < 0.3:
        p = rng.uniform(0.01, 0.2)
        moments = np.array([0.0, p, p])
    else:
        moments = rng.uniform(0.005, 0.2, 3)
    Q = random_rotation(rng)
    return Q @ np.diag(moments) @ Q.T


def random_chain(rng, n, convention, joint_types=None):
    if joint_types is None:
        joint_types = [R if rng.uniform() < 0.6 else P for _ in range(n)]
        if n >= 2 and len(set(joint_types)) == 1:
            joint_types[rng.integers(n)] = P if joint_types[0] == R else R
    g = rng.normal(size=3)
    g *= 9.81 / np.linalg.norm(g)
    return make_model(
        name=f'random{n}', convention=convention,
        joint_names=[f'j{k}' for k in range(n)], joint_types=joint_types,
        a=rng.uniform(-0.5, 0.5, n), alpha=rng.uniform(-math.pi, math.pi, n),
        d=rng.uniform(-0.4, 0.4, n), theta=rng.uniform(-math.pi, math.pi, n),
        mass=rng.uniform(0.3, 3.0, n), com=rng.uniform(-0.3, 0.3, (n, 3)),
        inertia=[random_inertia(rng) for _ in range(n)], gravity=g,
        base=random_pose(rng), tool=random_pose(rng, 0.2))


# 14 random chains: 7 seeds x 2 conventions, n = 1..7 (mixed joints)
CHAINS = [(seed, conv) for seed in range(7) for conv in CONVENTIONS]


def chain(seed, conv):
    key = ('random', seed, conv)
    if key not in _MODELS:
        rng = np.random.default_rng(1000 + seed)
        _MODELS[key] = random_chain(rng, 1 + seed, conv)
    return _MODELS[key]


def chain_states(seed, count=3):
    rng = np.random.default_rng(2000 + seed)
    return [random_state(rng, 1 + seed) for _ in range(count)]


# ---------------------------------------------------------------------------
# 1. closed forms: Spong's planar elbow arm
# ---------------------------------------------------------------------------
def spong_2r(p, q, qd, qdd):
    """
    Spong, Hutchinson & Vidyasagar, planar elbow arm, gravity -g y0.

    d11 = m1 lc1^2 + m2 (l1^2 + lc2^2 + 2 l1 lc2 c2) + I1 + I2
    d12 = m2 (lc2^2 + l1 lc2 c2) + I2,  d22 = m2 lc2^2 + I2
    h = -m2 l1 lc2 s2;  c121 = c211 = c221 = h, c112 = -h, others 0, so
    C = [[h qd2, h (qd1 + qd2)], [-h qd1, 0]]
    phi1 = (m1 lc1 + m2 l1) g c1 + m2 lc2 g c12,  phi2 = m2 lc2 g c12
    J (tip, frame-0 axes) = [[-l1 s1 - l2 s12, -l2 s12],
                             [ l1 c1 + l2 c12,  l2 c12], [0, 0], [0, 0],
                             [0, 0], [1, 1]]
    """
    m1, m2, l1, l2, lc1, lc2, I1, I2, g = (
        p[k] for k in ('m1', 'm2', 'l1', 'l2', 'lc1', 'lc2', 'I1', 'I2', 'g'))
    q1, q2 = q
    c1, c2, s1, s2 = math.cos(q1), math.cos(q2), math.sin(q1), math.sin(q2)
    c12, s12 = math.cos(q1 + q2), math.sin(q1 + q2)
    d11 = m1 * lc1 ** 2 + m2 * (l1 ** 2 + lc2 ** 2 + 2 * l1 * lc2 * c2) \
        + I1 + I2
    d12 = m2 * (lc2 ** 2 + l1 * lc2 * c2) + I2
    d22 = m2 * lc2 ** 2 + I2
    D = np.array([[d11, d12], [d12, d22]])
    h = -m2 * l1 * lc2 * s2
    C = np.array([[h * qd[1], h * (qd[0] + qd[1])], [-h * qd[0], 0.0]])
    G = np.array([(m1 * lc1 + m2 * l1) * g * c1 + m2 * lc2 * g * c12,
                  m2 * lc2 * g * c12])
    J = np.zeros((6, 2))
    J[0] = [-l1 * s1 - l2 * s12, -l2 * s12]
    J[1] = [l1 * c1 + l2 * c12, l2 * c12]
    J[5] = [1.0, 1.0]
    # tau written out term by term (not as D qdd + C qd) as in the book
    tau = np.array([
        d11 * qdd[0] + d12 * qdd[1] + 2 * h * qd[0] * qd[1]
        + h * qd[1] ** 2 + G[0],
        d12 * qdd[0] + d22 * qdd[1] - h * qd[0] ** 2 + G[1]])
    return D, C, G, J, tau


SPONG = {'m1': 1.7, 'm2': 0.9, 'l1': 0.75, 'l2': 0.55, 'lc1': 0.31,
         'lc2': 0.26, 'I1': 0.041, 'I2': 0.017, 'g': 9.81}


def two_r_standard(p):
    """
    Build Spong's elbow arm with parameters ``p`` in standard DH.

    Frame j is at the distal end of link j, so the com at distance lc from
    joint j is at x = lc - l in frame j.
    """
    return make_model(
        'elbow', 'standard', ['j1', 'j2'], [R, R], a=[p['l1'], p['l2']],
        alpha=[0, 0], d=[0, 0], theta=[0, 0], mass=[p['m1'], p['m2']],
        com=[[p['lc1'] - p['l1'], 0, 0], [p['lc2'] - p['l2'], 0, 0]],
        inertia=[np.diag([0.003, 0.5 * p['I1'], p['I1']]),
                 np.diag([0.002, 0.7 * p['I2'], p['I2']])],
        gravity=[0.0, -p['g'], 0.0])


def two_r_modified(p):
    """
    Build Spong's elbow arm with parameters ``p`` in modified DH.

    Frame j at joint j (com at x = lc), tip in the tool.  Mounted with the
    plane of motion vertical: base = Tz(0.4) Rx(pi/2), so y0 is the base's
    z and gravity (0, 0, -g) is -g y0.
    """
    base = np.eye(4)
    base[:3, :3] = rot_x(math.pi / 2)
    base[:3, 3] = [0.1, -0.2, 0.4]
    tool = np.eye(4)
    tool[0, 3] = p['l2']
    return make_model(
        'elbow_mdh', 'modified', ['j1', 'j2'], [R, R], a=[0, p['l1']],
        alpha=[0, 0], d=[0, 0], theta=[0, 0], mass=[p['m1'], p['m2']],
        com=[[p['lc1'], 0, 0], [p['lc2'], 0, 0]],
        inertia=[np.diag([0.003, 0.5 * p['I1'], p['I1']]),
                 np.diag([0.002, 0.7 * p['I2'], p['I2']])],
        gravity=[0.0, 0.0, -p['g']], base=base, tool=tool)


def params_of_bundled_2r(model):
    """
    Read Spong's parameters from the model of planar_2r.yaml.

    Asserts the layout they assume: standard DH, frames at the distal ends,
    com on the x axis, gravity along -y0.
    """
    assert model.convention == 'standard'
    assert model.joint_types == (R, R)
    assert np.all(model.alpha == 0) and np.all(model.d == 0)
    assert np.all(model.theta == 0)
    assert np.all(model.com[:, 1:] == 0)
    assert model.gravity[0] == 0 and model.gravity[2] == 0
    assert np.array_equal(model.base, np.eye(4))
    assert np.array_equal(model.tool, np.eye(4))
    l1, l2 = model.a
    return {'m1': model.mass[0], 'm2': model.mass[1], 'l1': l1, 'l2': l2,
            'lc1': l1 + model.com[0, 0], 'lc2': l2 + model.com[1, 0],
            'I1': model.inertia[0][2, 2], 'I2': model.inertia[1][2, 2],
            'g': -model.gravity[1]}


TWO_R = {
    'make_model_standard': lambda: (two_r_standard(SPONG), SPONG, np.eye(3)),
    'make_model_modified_mounted': lambda: (two_r_modified(SPONG), SPONG,
                                            rot_x(math.pi / 2)),
    'bundled_standard': lambda: (
        bundled('planar_2r', 'standard'),
        params_of_bundled_2r(bundled('planar_2r', 'standard')), np.eye(3)),
    'bundled_converted_to_modified': lambda: (
        bundled('planar_2r', 'modified'),
        params_of_bundled_2r(bundled('planar_2r', 'standard')), np.eye(3)),
}


def test_bundled_planar_2r_has_the_documented_numbers():
    p = params_of_bundled_2r(bundled('planar_2r', 'standard'))
    assert (p['l1'], p['l2'], p['m1'], p['m2']) == (1.0, 0.8, 2.0, 1.5)
    assert (p['lc1'], p['lc2']) == (0.5, 0.4)
    assert p['I1'] == pytest.approx(2.0 / 12) and p['I2'] == pytest.approx(
        1.5 * 0.64 / 12)


@pytest.mark.parametrize('variant', sorted(TWO_R))
def test_planar_2r_closed_form(variant):
    model, p, R0 = TWO_R[variant]()
    rng = np.random.default_rng(7)
    for _ in range(6):
        q, qd, qdd, _ = random_state(rng, 2, scale=2.0)
        D, C, G, J0, tau = spong_2r(p, q, qd, qdd)
        # Jacobian: closed form in frame-0 axes, R0 = base rotation
        J = np.vstack([R0 @ J0[:3], R0 @ J0[3:]])
        check('2R closed form: D', mass_matrix(model, q), D, RTOL_CLOSED)
        check('2R closed form: C', coriolis_matrix(model, q, qd), C,
              RTOL_CLOSED, scale=np.abs(D).max() * np.abs(qd).max())
        check('2R closed form: g', gravity_torques(model, q), G, RTOL_CLOSED)
        check('2R closed form: J', jacobian(model, q), J, RTOL_CLOSED)
        check('2R closed form: tau', inverse_dynamics(model, q, qd, qdd),
              tau, RTOL_CLOSED)
        # the oracle agrees with the closed form too (it is what the other
        # tests trust)
        check('2R closed form: oracle D', ref.mass_matrix(model, q), D,
              RTOL_CLOSED)
        check('2R closed form: oracle C',
              ref.christoffel_coriolis(model, q, qd), C, RTOL_CLOSED,
              scale=np.abs(D).max() * np.abs(qd).max())
        check('2R closed form: oracle g', ref.gravity_vector(model, q), G,
              RTOL_CLOSED)
        check('2R closed form: oracle tau',
              ref.inverse_dynamics(model, q, qd, qdd), tau, RTOL_CLOSED)


# ---------------------------------------------------------------------------
# 1b. closed forms: planar RP (polar) arm
# ---------------------------------------------------------------------------
def rp_closed_form(p, q, qd, qdd):
    """
    Planar RP arm, derived by hand with Euler-Lagrange.

    Joint 1: angle th about the normal to the plane; joint 2: radial
    extension r.  Link 1 (mass m1, planar inertia I1 about its com) has its
    com on the radial line at distance lc1 from the axis.  Link 2 (m2, I2)
    has its com on the radial line at rho = r + e (e: offset of the com
    from the joint-2 frame origin, along the slide).  With u = (cos th,
    sin th), n = (-sin th, cos th):

        p1 = lc1 u,  p2 = rho u
        v1 = lc1 thd n,  v2 = rd u + rho thd n,  w1 = w2 = thd
        T  = 1/2 (I1 + I2 + m1 lc1^2 + m2 rho^2) thd^2 + 1/2 m2 rd^2
        U  = g (m1 lc1 + m2 rho) sin th          (gravity -g y0)

    so D = diag(I1 + I2 + m1 lc1^2 + m2 rho^2, m2).  Euler-Lagrange:

        tau1 = d/dt(D11 thd) + dU/dth
             = D11 thdd + 2 m2 rho rd thd + g (m1 lc1 + m2 rho) cos th
        tau2 = m2 rdd - 1/2 dD11/dr thd^2 + dU/dr
             = m2 rdd - m2 rho thd^2 + m2 g sin th

    Christoffel symbols: only dD11/dr = 2 m2 rho is non-zero, giving
    c121 = c211 = m2 rho, c112 = -m2 rho, i.e.
        C = [[m2 rho rd, m2 rho thd], [-m2 rho thd, 0]].
    The tip (the joint-2 frame origin, at r) has the Jacobian
        J = [[-r sin th, cos th], [r cos th, sin th], 0, 0, 0, [1, 0]].
    """
    m1, m2, lc1, e, I1, I2, g = (
        p[k] for k in ('m1', 'm2', 'lc1', 'e', 'I1', 'I2', 'g'))
    th, r = q
    thd, rd = qd
    rho = r + e
    d11 = I1 + I2 + m1 * lc1 ** 2 + m2 * rho ** 2
    D = np.diag([d11, m2])
    C = np.array([[m2 * rho * rd, m2 * rho * thd], [-m2 * rho * thd, 0.0]])
    G = np.array([g * (m1 * lc1 + m2 * rho) * math.cos(th),
                  m2 * g * math.sin(th)])
    tau = np.array([
        d11 * qdd[0] + 2 * m2 * rho * rd * thd + G[0],
        m2 * qdd[1] - m2 * rho * thd ** 2 + G[1]])
    J = np.zeros((6, 2))
    J[0] = [-r * math.sin(th), math.cos(th)]
    J[1] = [r * math.cos(th), math.sin(th)]
    J[5] = [1.0, 0.0]
    return D, C, G, J, tau


RP = {'m1': 2.3, 'm2': 1.1, 'lc1': 0.27, 'e': -0.35, 'I1': 0.07, 'I2': 0.05,
      'g': 9.81}


def rp_standard(p):
    """
    Build the planar RP arm with parameters ``p`` in standard DH.

    As in planar_rp.yaml: alpha1 = pi/2 and theta offset pi/2 make z1
    radial; frame 2 = frame 1 moved q2 along z1.  The normal to the plane
    is y1 = y2 = z0, so the planar inertia is Iyy.
    """
    return make_model(
        'rp', 'standard', ['th', 'r'], [R, P], a=[0, 0],
        alpha=[math.pi / 2, 0], d=[0, 0], theta=[math.pi / 2, 0],
        mass=[p['m1'], p['m2']], com=[[0, 0, p['lc1']], [0, 0, p['e']]],
        inertia=[np.diag([0.09, p['I1'], 0.004]),
                 np.diag([0.08, p['I2'], 0.003])],
        gravity=[0.0, -p['g'], 0.0])


def rp_modified(p):
    """
    Build the planar RP arm with parameters ``p`` in modified DH, by hand.

    Joint 1 (theta offset pi/2) about z0, so x1 = (-sin th, cos th),
    y1 = -(cos th, sin th), z1 = z0; joint 2 has alpha2 = pi/2, so
    z2 = Rx(pi/2) z = -y1 is radial and y2 = z1.  Link 1's com (radial,
    lc1) is at -lc1 y1; the planar inertias are Izz of link 1 and Iyy of
    link 2.
    """
    return make_model(
        'rp_mdh', 'modified', ['th', 'r'], [R, P], a=[0, 0],
        alpha=[0, math.pi / 2], d=[0, 0], theta=[math.pi / 2, 0],
        mass=[p['m1'], p['m2']], com=[[0, -p['lc1'], 0], [0, 0, p['e']]],
        inertia=[np.diag([0.09, 0.004, p['I1']]),
                 np.diag([0.08, p['I2'], 0.003])],
        gravity=[0.0, -p['g'], 0.0])


def params_of_bundled_rp(model):
    """Read the RP parameters from the model of planar_rp.yaml (see its header)."""
    assert model.convention == 'standard'
    assert model.joint_types == (R, P)
    assert model.alpha[0] == pytest.approx(math.pi / 2, abs=1e-15)
    assert model.theta[0] == pytest.approx(math.pi / 2, abs=1e-15)
    assert np.all(model.a == 0) and np.all(model.d == 0)
    assert model.alpha[1] == 0 and model.theta[1] == 0
    assert np.all(model.com[:, :2] == 0)
    assert model.gravity[0] == 0 and model.gravity[2] == 0
    return {'m1': model.mass[0], 'm2': model.mass[1], 'lc1': model.com[0, 2],
            'e': model.com[1, 2], 'I1': model.inertia[0][1, 1],
            'I2': model.inertia[1][1, 1], 'g': -model.gravity[1]}


RP_VARIANTS = {
    'make_model_standard': lambda: (rp_standard(RP), RP),
    'make_model_modified': lambda: (rp_modified(RP), RP),
    'make_model_standard_converted': lambda: (
        convert_convention(rp_standard(RP), 'modified'), RP),
    'bundled_standard': lambda: (
        bundled('planar_rp', 'standard'),
        params_of_bundled_rp(bundled('planar_rp', 'standard'))),
    'bundled_converted_to_modified': lambda: (
        bundled('planar_rp', 'modified'),
        params_of_bundled_rp(bundled('planar_rp', 'standard'))),
}


@pytest.mark.parametrize('variant', sorted(RP_VARIANTS))
def test_planar_rp_closed_form(variant):
    model, p = RP_VARIANTS[variant]()
    rng = np.random.default_rng(11)
    for _ in range(6):
        _, qd, qdd, _ = random_state(rng, 2, scale=2.0)
        q = np.array([rng.uniform(-3, 3), rng.uniform(0.4, 1.2)])
        D, C, G, J, tau = rp_closed_form(p, q, qd, qdd)
        check('RP closed form: D', mass_matrix(model, q), D, RTOL_CLOSED)
        check('RP closed form: C', coriolis_matrix(model, q, qd), C,
              RTOL_CLOSED, scale=np.abs(D).max() * np.abs(qd).max())
        check('RP closed form: g', gravity_torques(model, q), G, RTOL_CLOSED)
        check('RP closed form: J', jacobian(model, q), J, RTOL_CLOSED)
        check('RP closed form: tau', inverse_dynamics(model, q, qd, qdd),
              tau, RTOL_CLOSED)
        check('RP closed form: oracle C',
              ref.christoffel_coriolis(model, q, qd), C, RTOL_CLOSED,
              scale=np.abs(D).max() * np.abs(qd).max())
        check('RP closed form: oracle tau',
              ref.inverse_dynamics(model, q, qd, qdd), tau, RTOL_CLOSED)


def test_bundled_planar_rp_tip_is_at_r_along_the_link():
    """The header of planar_rp.yaml: the tip is at (q2 cos q1, q2 sin q1)."""
    model = bundled('planar_rp', 'standard')
    for q in ([0.3, 0.5], [-2.0, 1.1], [2.9, 0.7]):
        expected = [q[1] * math.cos(q[0]), q[1] * math.sin(q[0]), 0.0]
        check('RP tip position', end_effector_pose(model, q)[:3, 3],
              expected, RTOL_CLOSED)
        check('RP tip position (oracle)', ref.ee_pose(model, q)[:3, 3],
              expected, RTOL_CLOSED)


# ---------------------------------------------------------------------------
# 1c. the Coriolis force of a sliding joint on a rotating arm
# ---------------------------------------------------------------------------
@pytest.mark.parametrize('convention', ['standard', 'modified_by_hand',
                                        'converted'])
def test_prismatic_coriolis_is_2_m_r_rdot_thetadot(convention):
    """
    A point mass m sliding outwards (rd) on an arm turning at thd.

    In the rotating frame the mass has radial velocity rd, so it needs the
    tangential Coriolis force 2 m rd thd (half from the change of direction
    of the radial velocity, half from the growth of the tangential velocity
    r thd); its moment about the axis is tau1 = 2 m r rd thd.  A recursion
    that keeps only one ``w x z qd`` term gets m r rd thd, half of it.  The
    radial joint must pull inwards with the centripetal force, tau2 =
    -m r thd^2.  No gravity, no acceleration.
    """
    m, I_hub = 1.3, 0.2
    p = {'m1': 0.0, 'm2': m, 'lc1': 0.0, 'e': 0.0, 'I1': I_hub, 'I2': 0.0,
         'g': 0.0}
    base = {'standard': rp_standard, 'modified_by_hand': rp_modified,
            'converted': lambda p: convert_convention(rp_standard(p),
                                                      'modified')}
    model = base[convention](p)
    # a point mass: no rotational inertia on link 2
    model = model.replace(inertia=[model.inertia[0], np.zeros((3, 3))],
                          gravity=[0.0, 0.0, 0.0])
    for r, rd, thd in ((0.8, 0.5, 2.0), (1.2, -0.3, 1.5), (0.4, 2.0, -3.0)):
        q, qd = [0.7, r], [thd, rd]
        tau = inverse_dynamics(model, q, qd, [0.0, 0.0])
        coriolis = 2 * m * r * rd * thd
        check('prismatic Coriolis 2 m r rd thd', tau[0], coriolis,
              RTOL_CLOSED)
        assert abs(tau[0] - coriolis / 2) > 0.4 * abs(coriolis)
        check('prismatic centripetal -m r thd^2', tau[1], -m * r * thd ** 2,
              RTOL_CLOSED)
        # the same through the Coriolis matrix and velocity_products
        check('prismatic Coriolis via C qd',
              coriolis_matrix(model, q, qd) @ qd,
              [coriolis, -m * r * thd ** 2], RTOL_CLOSED)
        check('prismatic Coriolis via velocity_products',
              velocity_products(model, q, qd),
              [coriolis, -m * r * thd ** 2], RTOL_CLOSED)


# ---------------------------------------------------------------------------
# 2. every bundled robot, both conventions, against the oracle
# ---------------------------------------------------------------------------
@pytest.mark.parametrize('convention', CONVENTIONS)
@pytest.mark.parametrize('name', BUNDLED)
def test_bundled_robot_against_euler_lagrange(name, convention):
    assert name in bundled_robots()
    model = bundled(name, convention)
    rng = np.random.default_rng(10 * BUNDLED.index(name)
                                + CONVENTIONS.index(convention))
    for _ in range(4):
        q, qd, qdd, F = random_state(rng, model.n)
        D = ref.mass_matrix(model, q)
        C = ref.christoffel_coriolis(model, q, qd)
        G = ref.gravity_vector(model, q)
        J = ref.ee_jacobian(model, q)
        check('bundled: D', mass_matrix(model, q), D, RTOL_KIN)
        check('bundled: C', coriolis_matrix(model, q, qd), C, RTOL_DERIV,
              scale=np.abs(D).max() * np.abs(qd).max())
        check('bundled: g', gravity_torques(model, q), G, RTOL_DERIV,
              scale=model.total_mass * 9.81 * 1e-3)
        check('bundled: J', jacobian(model, q), J, RTOL_KIN)
        check('bundled: J (EE axes)', jacobian(model, q, 'end_effector'),
              ref.ee_jacobian(model, q, 'end_effector'), RTOL_KIN)
        tau_ref = ref.inverse_dynamics(model, q, qd, qdd, F)
        check('bundled: tau with wrench',
              inverse_dynamics(model, q, qd, qdd, F), tau_ref, RTOL_DERIV)
        check('bundled: tau with EE-axes wrench',
              inverse_dynamics(model, q, qd, qdd, F, 'end_effector'),
              ref.inverse_dynamics(model, q, qd, qdd, F, 'end_effector'),
              RTOL_DERIV)
        check('bundled: tau without wrench', inverse_dynamics(model, q, qd,
                                                              qdd),
              D @ qdd + C @ qd + G, RTOL_DERIV)
        Ts, _ = ref.forward_kinematics(model, q)
        check('bundled: link poses', link_poses(model, q), np.array(Ts),
              RTOL_KIN)


@pytest.mark.parametrize('name', BUNDLED)
def test_convention_conversion_preserves_the_robot(name):
    """
    Same end-effector pose and the same physics in both conventions.

    Judged by the oracle, so a conversion that produced a different but
    self-consistent robot would fail here.
    """
    std, mod = bundled(name, 'standard'), bundled(name, 'modified')
    rng = np.random.default_rng(31 + BUNDLED.index(name))
    for _ in range(3):
        q, qd, qdd, F = random_state(rng, std.n)
        check('conversion: EE pose (oracle)', ref.ee_pose(mod, q),
              ref.ee_pose(std, q), RTOL_KIN, scale=1.0)
        check('conversion: com positions (oracle)',
              ref.com_positions(mod, q)[std.mass > 0],
              ref.com_positions(std, q)[std.mass > 0], RTOL_KIN, scale=1.0)
        check('conversion: tau (oracle)',
              ref.inverse_dynamics(mod, q, qd, qdd, F),
              ref.inverse_dynamics(std, q, qd, qdd, F), RTOL_DERIV)
        check('conversion: tau (library)',
              inverse_dynamics(mod, q, qd, qdd, F),
              inverse_dynamics(std, q, qd, qdd, F), RTOL_DERIV)


@pytest.mark.parametrize('seed,convention', CHAINS)
def test_random_chain_against_euler_lagrange(seed, convention):
    model = chain(seed, convention)
    for q, qd, qdd, F in chain_states(seed):
        D = ref.mass_matrix(model, q)
        check('random: D', mass_matrix(model, q), D, RTOL_KIN)
        check('random: C', coriolis_matrix(model, q, qd),
              ref.christoffel_coriolis(model, q, qd), RTOL_DERIV,
              scale=np.abs(D).max() * np.abs(qd).max())
        check('random: g', gravity_torques(model, q),
              ref.gravity_vector(model, q), RTOL_DERIV,
              scale=model.total_mass * 9.81 * 1e-3)
        check('random: J', jacobian(model, q), ref.ee_jacobian(model, q),
              RTOL_KIN)
        for frame in ('base', 'end_effector'):
            check('random: tau with wrench',
                  inverse_dynamics(model, q, qd, qdd, F, frame),
                  ref.inverse_dynamics(model, q, qd, qdd, F, frame),
                  RTOL_DERIV)
        check('random: EE pose', end_effector_pose(model, q),
              ref.ee_pose(model, q), RTOL_KIN, scale=1.0)
        # round trip through the other convention
        other = convert_convention(
            model, 'modified' if convention == 'standard' else 'standard')
        check('random: conversion tau (oracle)',
              ref.inverse_dynamics(other, q, qd, qdd, F),
              ref.inverse_dynamics(model, q, qd, qdd, F), RTOL_DERIV)
        check('random: conversion EE pose (oracle)', ref.ee_pose(other, q),
              ref.ee_pose(model, q), RTOL_KIN, scale=1.0)
        back = convert_convention(other, convention)
        check('random: conversion round trip tau (oracle)',
              ref.inverse_dynamics(back, q, qd, qdd, F),
              ref.inverse_dynamics(model, q, qd, qdd, F), RTOL_DERIV)


# ---------------------------------------------------------------------------
# the oracle itself: its parts are consistent, and its derivative methods
# are as accurate as documented
# ---------------------------------------------------------------------------
@pytest.mark.parametrize('name', ['stanford', 'panda', 'scara'])
def test_oracle_self_consistency(name):
    model = bundled(name, 'standard')
    rng = np.random.default_rng(5)
    q, qd, _, _ = random_state(rng, model.n)
    D = ref.mass_matrix(model, q)
    T = ref.kinetic_energy(model, q, qd)
    # T from time derivatives of the FK vs 1/2 qd^T D qd from Jacobians
    check('oracle: T vs 1/2 qd D qd', T, 0.5 * qd @ D @ qd, RTOL_DERIV)
    # the linear rows of J are the derivative of the EE position
    Jp = np.array(ref.partials(lambda x: ref.ee_pose(model, x)[:3, 3], q))
    check('oracle: J linear = dp/dq', ref.ee_jacobian(model, q)[:3], Jp.T,
          RTOL_DERIV)
    Cx = ref.christoffel_coriolis(model, q, qd)
    for method, rtol in ref.METHOD_RTOL.items():
        scale = np.abs(D).max() * np.abs(qd).max()
        check(f'oracle: C by {method}',
              ref.christoffel_coriolis(model, q, qd, method), Cx, rtol,
              scale=scale)
        check(f'oracle: g by {method}', ref.gravity_vector(model, q, method),
              ref.gravity_vector(model, q), rtol,
              scale=model.total_mass * 9.81)


# ---------------------------------------------------------------------------
# 3. identities between library functions, random chains
# ---------------------------------------------------------------------------
def richardson_rate(fun, h=1e-3):
    """d/dt fun(t) at 0 from central differences at h and h/2."""
    def cd(s):
        return (np.asarray(fun(s)) - np.asarray(fun(-s))) / (2 * s)
    return (4 * cd(h / 2) - cd(h)) / 3


@pytest.mark.parametrize('seed,convention', CHAINS)
def test_random_chain_identities(seed, convention):
    model = chain(seed, convention)
    n = model.n
    for q, qd, qdd, F in chain_states(seed):
        D = mass_matrix(model, q)
        C = coriolis_matrix(model, q, qd)
        g = gravity_torques(model, q)
        J = jacobian(model, q)
        Dscale = np.abs(D).max()
        Cscale = Dscale * np.abs(qd).max()
        # D symmetric (to the last bit, as documented) and positive definite
        assert np.array_equal(D, D.T)
        np.linalg.cholesky(D)
        assert np.linalg.eigvalsh(D)[0] > 0
        # Ddot = C + C^T, Ddot by Richardson-extrapolated central
        # differences of the library's D along qd (error ~1e-12 relative)
        Ddot = richardson_rate(lambda t: mass_matrix(model, q + t * qd))
        check('identity: Ddot = C + C^T', C + C.T, Ddot, 1e-9, scale=Cscale)
        N = Ddot - 2 * C
        check('identity: Ddot - 2C skew', N + N.T, np.zeros((n, n)), 1e-9,
              scale=Cscale)
        # C(q, 0) = 0
        check('identity: C(q, 0) = 0', coriolis_matrix(model, q, np.zeros(n)),
              np.zeros((n, n)), 0.0, scale=1.0)
        # C qd = tau(q, qd, 0) - g = velocity_products
        tau_v = inverse_dynamics(model, q, qd, np.zeros(n))
        check('identity: C qd = tau(q,qd,0) - g', C @ qd, tau_v - g,
              RTOL_IDENTITY, scale=Cscale * np.abs(qd).max() + np.abs(g).max())
        check('identity: C qd = velocity_products', C @ qd,
              velocity_products(model, q, qd), RTOL_IDENTITY,
              scale=Cscale * np.abs(qd).max())
        # Christoffel symmetry C(q, x) y = C(q, y) x
        x, y = qdd, qd
        check('identity: C(q,x)y = C(q,y)x',
              coriolis_matrix(model, q, x) @ y,
              coriolis_matrix(model, q, y) @ x, RTOL_IDENTITY,
              scale=Dscale * np.abs(x).max() * np.abs(y).max())
        # g = tau(q, 0, 0); D e_k = tau(q, 0, e_k) - g
        check('identity: g = tau(q,0,0)', g,
              inverse_dynamics(model, q, np.zeros(n), np.zeros(n)), 0.0,
              scale=1.0)
        for k in range(n):
            e = np.eye(n)[k]
            check('identity: D e_k = tau(q,0,e_k) - g', D[:, k],
                  inverse_dynamics(model, q, np.zeros(n), e) - g,
                  RTOL_IDENTITY, scale=Dscale + np.abs(g).max())
        # the decomposition
        tau = inverse_dynamics(model, q, qd, qdd, F)
        check('identity: tau = D qdd + C qd + g + J^T F', tau,
              D @ qdd + C @ qd + g + J.T @ F, RTOL_IDENTITY)
        # the switches leave out exactly their term
        check('identity: gravity=False drops g',
              inverse_dynamics(model, q, qd, qdd, F, gravity=False),
              D @ qdd + C @ qd + J.T @ F, RTOL_IDENTITY,
              scale=np.abs(tau).max())
        check('identity: velocity_products=False drops C qd',
              inverse_dynamics(model, q, qd, qdd, F,
                               velocity_products=False),
              D @ qdd + g + J.T @ F, RTOL_IDENTITY, scale=np.abs(tau).max())
        # g holds the arm still
        check('identity: forward_dynamics(q, 0, g) = 0',
              forward_dynamics(model, q, np.zeros(n), g), np.zeros(n),
              1e-14 * np.linalg.cond(D) + 1e-13,
              scale=np.abs(np.linalg.solve(D, g)).max())
        # the two wrench paths, in both frames
        for frame in ('base', 'end_effector'):
            check('identity: wrench paths agree',
                  inverse_dynamics(model, q, qd, qdd, F, frame)
                  - inverse_dynamics(model, q, qd, qdd),
                  wrench_torques(model, q, F, frame), RTOL_IDENTITY,
                  scale=np.abs(tau).max())
        # a base-axes wrench re-expressed in EE axes (oracle's rotation)
        Re = ref.ee_pose(model, q)[:3, :3]
        F_ee = np.concatenate([Re.T @ F[:3], Re.T @ F[3:]])
        check('identity: base wrench = rotated EE wrench',
              inverse_dynamics(model, q, qd, qdd, F_ee, 'end_effector'),
              tau, RTOL_IDENTITY)
        check('identity: J in EE axes = R^T J',
              jacobian(model, q, 'end_effector'),
              np.vstack([Re.T @ J[:3], Re.T @ J[3:]]), RTOL_IDENTITY)
        # forward o inverse = identity (with a wrench)
        qdd_back = forward_dynamics(model, q, qd, tau, F)
        cond = np.linalg.cond(D)
        check('identity: forward(inverse(qdd)) = qdd', qdd_back, qdd,
              1e-14 * cond + 1e-13)


@pytest.mark.parametrize('convention', CONVENTIONS)
def test_batch_equals_single(convention):
    rng = np.random.default_rng(77)
    model = random_chain(rng, 6, convention)
    m = 9
    Q = rng.uniform(-2, 2, (m, 6))
    QD, QDD = rng.normal(size=(m, 6)), rng.normal(size=(m, 6))
    W = rng.normal(size=(m, 6))
    for kwargs in ({}, {'gravity': False}, {'velocity_products': False}):
        for frame in ('base', 'end_effector'):
            TAU = inverse_dynamics_batch(model, Q, QD, QDD, W, frame,
                                         **kwargs)
            for k in range(m):
                check('batch == single', TAU[k],
                      inverse_dynamics(model, Q[k], QD[k], QDD[k], W[k],
                                       frame, **kwargs), 1e-15)
        TAU = inverse_dynamics_batch(model, Q, QD, QDD, **kwargs)
        for k in range(m):
            check('batch == single', TAU[k],
                  inverse_dynamics(model, Q[k], QD[k], QDD[k], **kwargs),
                  1e-15)


# hypothesis: a couple of properties over random chains
CHAIN_ARGS = {'seed': st.integers(0, 2 ** 31 - 1), 'n': st.integers(1, 6),
              'convention': st.sampled_from(CONVENTIONS)}


@settings(max_examples=15, deadline=None, database=None, derandomize=True)
@given(**CHAIN_ARGS)
def test_property_passivity_and_christoffel_symmetry(seed, n, convention):
    """x^T (Ddot - 2C) x = 0 for every x and C(q, x) y = C(q, y) x."""
    rng = np.random.default_rng(seed)
    model = random_chain(rng, n, convention)
    q, qd, x, _ = random_state(rng, n)
    y = rng.normal(size=n)
    C = coriolis_matrix(model, q, qd)
    Ddot = ref.mass_matrix_rate(model, q, qd)     # oracle, complex step
    scale = np.abs(ref.mass_matrix(model, q)).max() * np.abs(qd).max()
    check('property: x (Ddot - 2C) x = 0', x @ (Ddot - 2 * C) @ x, 0.0,
          RTOL_DERIV, scale=scale * np.abs(x).max() ** 2)
    check('property: C(q,x)y = C(q,y)x', coriolis_matrix(model, q, x) @ y,
          coriolis_matrix(model, q, y) @ x, RTOL_IDENTITY,
          scale=scale / np.abs(qd).max() * np.abs(x).max() * np.abs(y).max())


@settings(max_examples=15, deadline=None, database=None, derandomize=True)
@given(**CHAIN_ARGS)
def test_property_kinetic_energy_and_positive_definiteness(seed, n,
                                                           convention):
    """
    1/2 qd^T D qd equals the oracle's kinetic energy; D is positive definite.

    The oracle takes the kinetic energy from the time derivative of its FK.
    """
    rng = np.random.default_rng(seed)
    model = random_chain(rng, n, convention)
    q, qd, _, _ = random_state(rng, n)
    D = mass_matrix(model, q)
    np.linalg.cholesky(D)
    T = ref.kinetic_energy(model, q, qd)
    check('property: 1/2 qd D qd = T', 0.5 * qd @ D @ qd, T, RTOL_DERIV)
    assert T > 0


# ---------------------------------------------------------------------------
# 4. energy: free motion conserves T + U, driven motion obeys the power law
# ---------------------------------------------------------------------------
def rk4(f, x, t0, dt, steps, every, observe):
    """Classical RK4; observe(t, x) every ``every`` steps (and at t0)."""
    t = t0
    observe(t, x)
    for i in range(1, steps + 1):
        k1 = f(t, x)
        k2 = f(t + dt / 2, x + dt / 2 * k1)
        k3 = f(t + dt / 2, x + dt / 2 * k2)
        k4 = f(t + dt, x + dt * k3)
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        t = t0 + i * dt
        if i % every == 0:
            observe(t, x)
    return x


def simulate(model, q0, qd0, seconds, dt, torque=None, every=100):
    """
    Integrate a motion by RK4 and record its energy balance.

    Integrates (q, qd, W) with qdd = forward_dynamics(q, qd, tau(t)) and
    W' = qd^T tau(t) (the work of the actuators).  Returns the observed
    (t, E(t) - E(0) - W(t), energy scale) from the oracle's energies.
    """
    n = model.n
    zero = np.zeros(n)

    def f(t, x):
        q, qd = x[:n], x[n:2 * n]
        tau = zero if torque is None else torque(t)
        qdd = forward_dynamics(model, q, qd, tau)
        return np.concatenate([qd, qdd, [qd @ tau]])

    E0 = ref.total_energy(model, q0, qd0)
    record = []

    def observe(t, x):
        q, qd, W = x[:n], x[n:2 * n], x[-1]
        T = ref.kinetic_energy(model, q, qd)
        U = float(ref.potential_energy(model, q))
        record.append((t, T + U - E0 - W, T, U))

    rk4(f, np.concatenate([q0, qd0, [0.0]]), 0.0, dt,
        int(round(seconds / dt)), every, observe)
    rec = np.array(record)
    # energy scale: the largest kinetic energy and the swing of U
    scale = rec[:, 2].max() + (rec[:, 3].max() - rec[:, 3].min())
    return rec, scale


ENERGY_CASES = {
    'puma560': lambda: (bundled('puma560', 'standard'),
                        np.array([0.3, -0.6, 0.4, 0.2, -0.5, 0.1]),
                        np.array([0.8, -0.5, 0.6, 1.0, -0.7, 1.2])),
    'stanford': lambda: (bundled('stanford', 'standard'),
                         np.array([0.2, 0.9, 0.6, -0.4, 0.7, 0.3]),
                         np.array([0.4, -0.3, 0.1, 0.8, -0.6, 0.9])),
    'random5_modified': lambda: (
        random_chain(np.random.default_rng(555), 5, 'modified',
                     [R, P, R, R, P]),
        np.array([0.4, 0.1, -0.7, 0.5, -0.1]),
        np.array([0.7, 0.2, -0.9, 1.1, 0.3])),
}

# RK4: local error O(dt^5), global O(dt^4); with dt = 1e-3 and motions of
# frequency ~1-10 rad/s the relative energy drift after 1 s is expected far
# below 1e-9.  An error in the dynamics (e.g. half the prismatic Coriolis
# force, a wrong C, a g that is not dU/dq) breaks conservation at O(1).
ENERGY_RTOL = 1e-9


@pytest.mark.parametrize('case', sorted(ENERGY_CASES))
def test_free_motion_conserves_energy(case):
    model, q0, qd0 = ENERGY_CASES[case]()
    rec, scale = simulate(model, q0, qd0, seconds=1.0, dt=1e-3)
    drift = np.abs(rec[:, 1]).max() / scale
    MAX_ERR[f'energy drift / scale ({case})'] = max(
        MAX_ERR.get(f'energy drift / scale ({case})', 0.0), drift)
    assert scale > 1.0           # the arm really moved
    assert drift < ENERGY_RTOL, (case, drift, scale)


def test_energy_drift_shrinks_like_dt4():
    """
    The drift is integration error, not a modelling error.

    Halving dt divides it by ~16 (RK4).  Coarse steps so the drift is well
    above round-off.
    """
    model, q0, qd0 = ENERGY_CASES['random5_modified']()
    drifts = []
    for dt in (2e-2, 1e-2):
        rec, scale = simulate(model, q0, 2 * qd0, seconds=1.0, dt=dt,
                              every=1)
        drifts.append(np.abs(rec[:, 1]).max() / scale)
    ratio = drifts[0] / drifts[1]
    MAX_ERR['energy drift ratio dt/(dt/2)'] = ratio
    assert drifts[1] > 1e-12
    assert 8 < ratio < 32, drifts


def test_driven_motion_power_identity_integrated():
    """
    d/dt (T + U) = qd^T tau, integrated along a driven motion.

    E(t) - E(0) = integral of qd^T tau dt for a smooth torque, with the
    work integrated alongside the state.
    """
    model = random_chain(np.random.default_rng(808), 4, 'standard',
                         [R, P, R, P])
    amp = np.array([6.0, 15.0, 3.0, 10.0])
    omega = np.array([3.0, 2.0, 5.0, 4.0])
    phase = np.array([0.1, 1.0, -0.5, 0.3])
    g0 = gravity_torques(model, np.zeros(4))

    def torque(t):
        return g0 + amp * np.sin(omega * t + phase)

    rec, scale = simulate(model, np.zeros(4), np.array([0.5, 0.1, -0.4, 0.2]),
                          seconds=1.0, dt=1e-3, torque=torque)
    work_scale = scale + np.abs(rec[:, 1]).max()
    drift = np.abs(rec[:, 1]).max() / work_scale
    MAX_ERR['power identity integrated / scale'] = drift
    assert scale > 1.0
    assert drift < ENERGY_RTOL


@pytest.mark.parametrize('name', ['puma560', 'stanford', 'scara', 'panda'])
def test_power_identity_pointwise(name):
    """
    At a state, dE/dt = qd^T tau - (J qd)^T F.

    dE/dt along (qd, qdd), with qdd from forward_dynamics, is the actuator
    power minus the power the end effector delivers to the environment (F
    is exerted BY the end effector).  dE/dt by a complex step of the
    oracle's energy (exact to round-off; the accelerations reach 1e5
    rad/s^2 on the Puma's light wrist, where finite differences would need
    a step ~1e-5).
    """
    model = bundled(name, 'standard')
    rng = np.random.default_rng(99 + BUNDLED.index(name))
    for _ in range(3):
        q, qd, _, F = random_state(rng, model.n)
        tau = 20 * rng.normal(size=model.n)
        qdd = forward_dynamics(model, q, qd, tau, F)
        dE = ref.energy_rate(model, q, qd, qdd)
        power = qd @ tau - (ref.ee_jacobian(model, q) @ qd) @ F
        # the terms of dE/dt are as large as |qd| |D qdd|
        scale = np.abs(qd).max() * np.abs(
            ref.mass_matrix(model, q) @ qdd).max()
        check('power identity pointwise', dE, power, RTOL_DERIV, scale=scale)
        # with the wrench's sign flipped the identity must fail
        assert abs(dE - (qd @ tau + (ref.ee_jacobian(model, q) @ qd) @ F)) \
            > 1e-6 * scale
