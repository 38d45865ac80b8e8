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
The momentum observer's combined pass: D qd, C^T qd and g in one recursion.

``kernels.run_momentum_terms`` against the same three terms computed
separately (``mass_matrix``, ``coriolis_matrix``, ``gravity_torques``),
against the Euler-Lagrange oracle of ``reference_dynamics`` (its D, the
Christoffel C of its D and dU/dq, with Ddot = C + C^T checked on the
way), and against Pinocchio's reading of the Panda URDF.
"""
import math
import warnings

from newton_euler_ros.core import (coriolis_matrix, gravity_torques,
                                   load_robot, mass_matrix, RobotFileWarning,
                                   velocity_products, Workspace)
from newton_euler_ros.core import kernels as K
from newton_euler_ros.core.model import make_chain, rpy_matrix
import numpy as np
import pytest
import reference_dynamics as ref

EPS = np.finfo(np.float64).eps


def _quiet_load(*args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        return load_robot(*args, **kw)


def terms(model, q, qd, ws=None):
    """Return the rows D qd, C^T qd, g of the combined pass."""
    ws = Workspace(model) if ws is None else ws
    out = np.full((3, model.n), np.nan)
    code = K.run_momentum_terms(model.packed, np.asarray(q, float),
                                np.asarray(qd, float), ws.ws, ws.cw, out)
    assert code == -1, code
    return out


def separate(model, q, qd):
    """Return the same three from the matrices."""
    return np.array([mass_matrix(model, q) @ qd,
                     coriolis_matrix(model, q, qd).T @ qd,
                     gravity_torques(model, q)])


def random_chain(seed, n):
    """URDF-style chain, both joint types, arbitrary axes and placements."""
    rng = np.random.default_rng(seed)
    types = ['revolute' if rng.random() < 0.6 else 'prismatic'
             for _ in range(n)]
    pre = [(('xyz', *rng.uniform(-0.4, 0.4, 3)),
            ('rpy', *rng.uniform(-math.pi, math.pi, 3))) for _ in range(n)]
    inertia = []
    for _ in range(n):
        R = rpy_matrix(*rng.uniform(-math.pi, math.pi, 3))
        p = rng.uniform(0.01, 0.2, 3)
        inertia.append(R @ np.diag([p[1] + p[2], p[0] + p[2], p[0] + p[1]])
                       @ R.T)
    g = rng.normal(size=3)
    return make_chain(f'chain{seed}', [f'j{k}' for k in range(n)], types,
                      pre, rng.normal(size=(n, 3)), rng.uniform(0.2, 3.0, n),
                      rng.uniform(-0.3, 0.3, (n, 3)), inertia,
                      gravity=9.81 * g / np.linalg.norm(g)), rng


@pytest.mark.parametrize('name', ['panda', 'puma560', 'stanford', 'scara',
                                  'planar_rp', 'planar_2r'])
def test_combined_pass_equals_the_separate_terms(name):
    """Bundled robots (revolute and prismatic, DH and URDF): to round-off."""
    model = _quiet_load(name)
    rng = np.random.default_rng(7)
    ws = Workspace(model)
    for _ in range(25):
        q, qd = rng.uniform(-2.0, 2.0, (2, model.n))
        got = terms(model, q, qd, ws)
        want = separate(model, q, qd)
        scale = max(1.0, float(np.abs(want).max()))
        assert np.abs(got - want).max() < 100 * model.n * EPS * scale


@pytest.mark.parametrize('seed', range(6))
def test_combined_pass_on_random_chains_against_the_oracle(seed):
    """Mixed joints: the separate terms and the Euler-Lagrange oracle."""
    model, rng = random_chain(seed, 3 + seed % 4)
    q, qd = rng.uniform(-1.5, 1.5, (2, model.n))
    got = terms(model, q, qd)
    want = separate(model, q, qd)
    scale = max(1.0, float(np.abs(want).max()))
    assert np.abs(got - want).max() < 100 * model.n * EPS * scale
    # the oracle: its D, the Christoffel C of its D, dU/dq
    D = ref.mass_matrix(model, q)
    C = ref.christoffel_coriolis(model, q, qd)
    np.testing.assert_allclose(got[0], D @ qd, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(got[1], C.T @ qd, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(got[2], ref.gravity_vector(model, q), rtol=0,
                               atol=1e-9 * scale)
    # C^T qd is what the momentum's rate leaves after C qd: Ddot = C + C^T
    Ddot = ref.mass_matrix_rate(model, q, qd)
    np.testing.assert_allclose(
        got[1] + velocity_products(model, q, qd), Ddot @ qd, rtol=0,
        atol=1e-9 * scale)


def test_combined_pass_against_pinocchio_on_the_panda_urdf():
    import pinocchio  # noqa: F401 (a test dependency: make setup installs it)
    from newton_euler_tools.peers import example_robot_urdf, PinocchioUrdf
    try:
        path = example_robot_urdf('panda_description/urdf/panda.urdf')
    except ImportError:
        pytest.skip('example-robot-data is not installed')
    model = _quiet_load(path, tip='panda_hand_tcp')
    peer = PinocchioUrdf(path, model.joint_names, model.info['urdf']['tip'])
    rng = np.random.default_rng(3)
    for _ in range(10):
        q, qd = rng.uniform(-1.5, 1.5, (2, model.n))
        got = terms(model, q, qd)
        pin = peer.terms(q, qd, np.zeros(model.n), np.zeros(6))
        np.testing.assert_allclose(got[0], pin['D'] @ qd, rtol=0, atol=1e-9)
        np.testing.assert_allclose(got[1], pin['C'].T @ qd, rtol=0,
                                   atol=1e-9)
        np.testing.assert_allclose(got[2], pin['g'], rtol=0, atol=1e-9)


def test_combined_pass_status_codes():
    """Non-finite input and wrong sizes come back as the kernels' codes."""
    model = _quiet_load('panda')
    ws = Workspace(model)
    n = model.n
    q, qd, out = np.zeros(n), np.zeros(n), np.zeros((3, n))
    P = model.packed
    q[3] = np.nan
    assert K.run_momentum_terms(P, q, qd, ws.ws, ws.cw, out) == 3
    q[3] = 0.0
    qd[5] = np.inf
    assert K.run_momentum_terms(P, q, qd, ws.ws, ws.cw, out) == \
        K.NONFINITE + 5
    qd[5] = 0.0
    assert K.run_momentum_terms(P, q[:5], qd, ws.ws, ws.cw, out) == K.SIZE
    assert K.run_momentum_terms(P, q, qd, ws.ws, ws.cw, out[:2]) == \
        K.SIZE + 4
    assert K.run_momentum_terms(P, q, qd, ws.ws, ws.cw[:n], out) == \
        K.SIZE + 5
    qd[0] = 1e300
    assert K.run_momentum_terms(P, q, qd, ws.ws, ws.cw, out) == K.OVERFLOW
