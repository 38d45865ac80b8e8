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
The O(n) forward dynamics and the O(n^2) Coriolis matrix, by identities.

- The articulated-body algorithm (ABA) equals the Cholesky solve of
  D qdd = tau - bias to round-off (scaled by cond D) and inverts inverse
  dynamics: FD(q, qd, ID(q, qd, qdd)) = qdd, with wrenches in both frames
  and each term switched off.
- The composite-body C equals the n-recursion C to round-off, and
  satisfies C qd = tau(q, qd, 0) - g and Ddot = C + C^T (Ddot by central
  differences of D along qd, checked at two steps for its h^2 error).
- Batches equal loops of single calls bit for bit (the same kernels).
- Random chains: both DH conventions and general (URDF-style) joints.
- A warm call of every entry point allocates nothing (numba's allocator
  statistics), and a workspace of another size is refused.
"""
import math

from hypothesis import given, settings, strategies as st
from newton_euler_ros.core import (coriolis_matrix, coriolis_matrix_batch,
                                   DynamicsInputError, forward_dynamics,
                                   forward_dynamics_batch, gravity_torques,
                                   gravity_torques_batch, inverse_dynamics,
                                   load_robot, make_model, mass_matrix,
                                   mass_matrix_batch,
                                   mass_matrix_condition,
                                   NotPositiveDefiniteError, Workspace)
from newton_euler_ros.core import kernels as K
from newton_euler_ros.core.model import make_chain, rpy_matrix
import numpy as np
import pytest

EPS = np.finfo(np.float64).eps


def _inertia(rng):
    R = rpy_matrix(*rng.uniform(-math.pi, math.pi, 3))
    p = rng.uniform(0.01, 0.2, 3)
    moments = np.array([p[1] + p[2], p[0] + p[2], p[0] + p[1]])
    return R @ np.diag(moments) @ R.T


def dh_chain(rng, n, convention):
    types = ['revolute' if rng.random() < 0.7 else 'prismatic'
             for _ in range(n)]
    g = rng.normal(size=3)
    return make_model(
        f'dh{n}', convention, [f'j{k}' for k in range(n)], types,
        rng.uniform(-0.5, 0.5, n), rng.uniform(-math.pi, math.pi, n),
        rng.uniform(-0.4, 0.4, n), rng.uniform(-math.pi, math.pi, n),
        rng.uniform(0.2, 3.0, n), rng.uniform(-0.3, 0.3, (n, 3)),
        [_inertia(rng) for _ in range(n)], gravity=9.81 * g / np.linalg.norm(g))


def general_chain(rng, n):
    """URDF-style joints: arbitrary axes, placements as xyz + rpy."""
    types = ['revolute' if rng.random() < 0.7 else 'prismatic'
             for _ in range(n)]
    pre = [(('xyz', *rng.uniform(-0.4, 0.4, 3)),
            ('rpy', *rng.uniform(-math.pi, math.pi, 3))) for _ in range(n)]
    return make_chain(
        f'urdf{n}', [f'j{k}' for k in range(n)], types, pre,
        rng.normal(size=(n, 3)), rng.uniform(0.2, 3.0, n),
        rng.uniform(-0.3, 0.3, (n, 3)), [_inertia(rng) for _ in range(n)])


def make(kind, seed, n):
    rng = np.random.default_rng(seed)
    if kind == 'urdf':
        return general_chain(rng, n), rng
    return dh_chain(rng, n, kind), rng


def scaled_error(a, b, scale):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b)))) / scale


KINDS = st.sampled_from(['standard', 'modified', 'urdf'])


@settings(max_examples=25, deadline=None, database=None, derandomize=True)
@given(kind=KINDS, seed=st.integers(0, 2 ** 31 - 1), n=st.integers(1, 12))
def test_aba_inverts_inverse_dynamics_and_equals_cholesky(kind, seed, n):
    model, rng = make(kind, seed, n)
    q, qd, qdd = rng.uniform(-2.0, 2.0, (3, n))
    F = rng.normal(size=6) * 5.0
    D = mass_matrix(model, q)
    norm_d = np.linalg.norm(D, 2)
    cond = mass_matrix_condition(model, q)
    for wrench, frame in ((None, 'base'), (F, 'base'), (F, 'end_effector')):
        for gravity, velocity in ((True, True), (False, True), (True, False)):
            kw = {'gravity': gravity, 'velocity_products': velocity}
            tau = inverse_dynamics(model, q, qd, qdd, wrench, frame, **kw)
            bias = tau - D @ qdd
            aba = forward_dynamics(model, q, qd, tau, wrench, frame, **kw)
            chol = forward_dynamics(model, q, qd, tau, wrench, frame,
                                    method='cholesky', **kw)
            # qdd solves D qdd = tau - bias, whose right side carries the
            # round-off of tau and bias: a backward error of a few n eps
            # in (D, tau, bias) gives a forward error up to cond(D) times
            scale = (np.linalg.norm(tau) + np.linalg.norm(bias)) / norm_d \
                + np.linalg.norm(qdd)
            bound = 50 * n * EPS * cond
            assert scaled_error(aba, qdd, scale) < bound
            assert scaled_error(aba, chol, scale) < bound


@settings(max_examples=25, deadline=None, database=None, derandomize=True)
@given(kind=KINDS, seed=st.integers(0, 2 ** 31 - 1), n=st.integers(1, 12))
def test_composite_coriolis_is_the_christoffel_matrix(kind, seed, n):
    model, rng = make(kind, seed, n)
    q, qd = rng.uniform(-2.0, 2.0, (2, n))
    C = coriolis_matrix(model, q, qd)
    C_ne = coriolis_matrix(model, q, qd, method='newton_euler')
    D = mass_matrix(model, q)
    scale = np.abs(D).max() * np.abs(qd).max()
    assert scaled_error(C, C_ne, scale) < 20 * n * EPS
    # C qd are the velocity-product torques
    vp = inverse_dynamics(model, q, qd) - gravity_torques(model, q)
    assert scaled_error(C @ qd, vp, scale * np.abs(qd).max()) < 50 * n * EPS

    # Ddot = C + C^T; central differences have an h^2 error: take the
    # better of two steps, the truncation error shrinks 16x from h to h/4
    def ddot(h):
        return (mass_matrix(model, q + h * qd)
                - mass_matrix(model, q - h * qd)) / (2 * h)
    errs = [scaled_error(ddot(h), C + C.T, scale) for h in (1e-4, 2.5e-5)]
    assert min(errs) < 1e-7


@pytest.mark.parametrize('name', ['puma560', 'panda', 'stanford', 'scara'])
def test_batches_equal_single_calls_bit_for_bit(name):
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot(name)
    n = model.n
    rng = np.random.default_rng(3)
    Q, QD, TAU = rng.uniform(-2.0, 2.0, (3, 7, n))
    W = rng.normal(size=(7, 6))
    DD = mass_matrix_batch(model, Q)
    CC = coriolis_matrix_batch(model, Q, QD)
    G = gravity_torques_batch(model, Q)
    A = forward_dynamics_batch(model, Q, QD, TAU, W, 'end_effector')
    for k in range(7):
        assert np.array_equal(DD[k], mass_matrix(model, Q[k]))
        assert np.array_equal(CC[k], coriolis_matrix(model, Q[k], QD[k]))
        assert np.array_equal(G[k], gravity_torques(model, Q[k]))
        assert np.array_equal(A[k], forward_dynamics(
            model, Q[k], QD[k], TAU[k], W[k], 'end_effector'))


def _tail():
    """Return a 3-joint arm whose last two links carry nothing."""
    return make_model('tail', 'standard', ['a', 'b', 'c'], ['revolute'] * 3,
                      [0.5, 0.5, 0.5], [0, 0, 0], [0, 0, 0], [0, 0, 0],
                      [1.0, 0.0, 0.0], np.zeros((3, 3)),
                      [np.eye(3) * 0.1, np.zeros((3, 3)), np.zeros((3, 3))])


def test_both_methods_name_the_same_singular_joint():
    tail = _tail()
    for method in ('aba', 'cholesky'):
        with pytest.raises(NotPositiveDefiniteError,
                           match=r'joint 1 \(b\)') as info:
            forward_dynamics(tail, [0.1, 0.2, 0.3], [0, 0, 0], [1, 1, 1],
                             method=method)
        assert info.value.joint == 1
    Q = np.zeros((3, 3))
    with pytest.raises(NotPositiveDefiniteError, match=r'^row 0: .*joint 1'):
        forward_dynamics_batch(tail, Q, Q, Q)


def test_batch_errors_name_row_and_column():
    arm = load_robot('planar_2r')
    Q = np.zeros((4, 2))
    Q[2, 1] = math.nan
    for call in (lambda: mass_matrix_batch(arm, Q),
                 lambda: coriolis_matrix_batch(arm, Q, np.zeros((4, 2))),
                 lambda: gravity_torques_batch(arm, Q),
                 lambda: forward_dynamics_batch(arm, Q, Q * 0, Q * 0)):
        with pytest.raises(DynamicsInputError, match=r'Q\[2, 1\] is nan'):
            call()
    with pytest.raises(DynamicsInputError, match=r'QD must have shape'):
        coriolis_matrix_batch(arm, np.zeros((4, 2)), np.zeros((3, 2)))


def test_bad_arguments_are_named():
    arm = load_robot('planar_2r')
    cases = [
        (lambda: forward_dynamics(arm, [0, 0], [0, 0], [1, math.inf]),
         r'tau\[1\] is inf'),
        (lambda: forward_dynamics(arm, [0, 0], [0, 0], [1]),
         r'tau must have 2 entries'),
        (lambda: forward_dynamics(arm, [0, 0], [0, 0], [1, 1],
                                  method='lu'), r'method must be one of'),
        (lambda: coriolis_matrix(arm, [0, 0], [0, math.nan]),
         r'qd\[1\] is nan'),
        (lambda: coriolis_matrix(arm, [0, 0], [0, 0], method='fast'),
         r'method must be one of'),
        (lambda: inverse_dynamics(arm, np.zeros(3)), r'q must have 2'),
        (lambda: inverse_dynamics(arm, [0, 0], out=np.zeros(2, np.float32)),
         r'out must be'),
        (lambda: gravity_torques(arm, 'ab'), r'q must be'),
    ]
    for call, message in cases:
        with pytest.raises((DynamicsInputError, ValueError), match=message):
            call()


def test_inputs_of_any_numeric_kind_give_the_same_results():
    arm = load_robot('planar_2r')
    q = np.array([0.3, -0.4])
    expected = inverse_dynamics(arm, q, q, q)
    readonly = q.copy()
    readonly.setflags(write=False)
    strided = np.array([0.3, 9.0, -0.4])[::2]
    for x in ([0.3, -0.4], q.astype(np.longdouble), readonly, strided,
              (0.3, -0.4), [np.float64(0.3), -0.4]):
        assert np.array_equal(inverse_dynamics(arm, x, x, x), expected)
        assert np.array_equal(gravity_torques(arm, x),
                              gravity_torques(arm, q))
        assert np.array_equal(forward_dynamics(arm, x, x, x),
                              forward_dynamics(arm, q, q, q))


def test_a_workspace_of_another_model_is_refused():
    arm = load_robot('planar_2r')
    other = Workspace(load_robot('puma560'))
    with pytest.raises(DynamicsInputError, match='ws must be'):
        inverse_dynamics(arm, [0.0, 0.0], ws=other)
    # the kernels check the arrays' sizes too, whatever the Python says
    small = np.zeros((1, K.W_WIDTH))
    status = K.run_inverse_dynamics(arm.packed, np.zeros(2), np.zeros(2),
                                    np.zeros(2), np.zeros(6), 3, small,
                                    np.zeros(2))
    assert status == K.SIZE + 5
    assert arm.default_workspace is arm.default_workspace


WARM_CALLS = """
import numpy as np
from numba.core.runtime import rtsys
from newton_euler_ros.core import load_robot, Workspace
from newton_euler_ros.core import kernels as K
arm = load_robot('planar_rp')
n = arm.n
ws = Workspace(arm)
P = arm.packed
q = np.linspace(-1, 1, n)
w = np.ones(6)
tau = np.empty(n)
D = np.empty((n, n))
J = np.empty((6, n))
Q = np.tile(q, (3, 1))
W = np.zeros((3, 6))
out = np.empty((3, n))
DD = np.empty((3, n, n))
calls = [
    lambda: K.run_inverse_dynamics(P, q, q, q, w, 3 | (1 << K.WRENCH_SHIFT),
                                   ws.ws, tau),
    lambda: K.run_gravity_torques(P, q, ws.ws, tau),
    lambda: K.run_mass_matrix_crba(P, q, ws.ws, D),
    lambda: K.run_mass_matrix(P, q, False, ws.ws, ws.scratch, D),
    lambda: K.run_coriolis_matrix(P, q, q, True, ws.ws, ws.cw, ws.scratch, D),
    lambda: K.run_coriolis_matrix(P, q, q, False, ws.ws, ws.cw, ws.scratch,
                                  D),
    lambda: K.run_forward_dynamics(P, q, q, q, w, 3, ws.ws, ws.aw, tau),
    lambda: K.run_jacobian(P, q, n - 1, arm.frames_array[K.F_TOOL], True,
                           ws.ws, ws.frames, J),
    lambda: K.run_inverse_dynamics_links(P, q, q, q, w, ws.fext,
                                         3 | K.LINK_WRENCHES, ws.ws, tau),
    lambda: K.run_forward_dynamics_links(P, q, q, q, w, ws.fext,
                                         3 | K.LINK_WRENCHES, ws.ws, ws.aw,
                                         tau),
    lambda: K.run_link_poses(P, q, ws.ws, ws.frames),
    lambda: K.run_inverse_dynamics_batch(P, Q, Q, Q, W, 3, ws.ws, out,
                                         ws.status),
    lambda: K.run_forward_dynamics_batch(P, Q, Q, Q, W, 3, ws.ws, ws.aw, out,
                                         ws.status),
    lambda: K.run_mass_matrix_batch(P, Q, ws.ws, DD, ws.status),
    lambda: K.run_gravity_torques_batch(P, Q, ws.ws, out, ws.status),
    lambda: K.run_coriolis_matrix_batch(P, Q, Q, ws.ws, ws.cw, DD, ws.status),
]
for call in calls:
    assert call() == -1                 # compiled (or loaded), and succeeds
before = rtsys.get_allocation_stats()
for _ in range(10):
    for call in calls:
        call()
after = rtsys.get_allocation_stats()
# numba's allocator counts every array the compiled code creates (the
# entry points pass arrays in without wrapping them: _jit.ENTRY)
print(after.alloc - before.alloc)
"""


def test_warm_calls_allocate_nothing():
    """
    The kernels' docstring says so; numba's allocator counts it.

    In a child process: the counters exist only when NUMBA_NRT_STATS is
    set before numba starts.
    """
    import os
    import subprocess
    import sys
    env = dict(os.environ, NUMBA_NRT_STATS='1')
    proc = subprocess.run([sys.executable, '-c', WARM_CALLS], env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.split() == ['0'], proc.stdout
