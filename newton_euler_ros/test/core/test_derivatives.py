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
Analytical derivatives of tau and qdd (``core.derivatives``).

- Against Pinocchio's ``computeRNEADerivatives`` and
  ``computeABADerivatives`` (within 1e-9 relative) on published chains
  and trees and on random trees, without mimic joints.
- Against central differences of the library's own torques and
  accelerations where Pinocchio has none: mimic joints, end-effector
  wrenches in either axes, several wrenches at links in base and link
  axes, the drive terms (viscous, smooth Coulomb, rotor inertia).
- Identities: dtau/dqd = 0 at rest without viscous friction, dtau/dqd =
  2 C, dqdd/dtau D = I, the forward derivatives equal -D^-1 times the
  inverse ones at qdd = FD(q, qd, tau), dg/dq symmetric.
- Batches equal single calls; bad input gets a one-line error.
"""
import multiprocessing
import warnings

from newton_euler_ros.core import (coriolis_matrix, Drives,
                                   forward_dynamics,
                                   forward_dynamics_derivatives,
                                   forward_dynamics_derivatives_batch,
                                   gravity_torques, inverse_dynamics,
                                   inverse_dynamics_derivatives,
                                   inverse_dynamics_derivatives_batch,
                                   load_robot, load_urdf, mass_matrix,
                                   Workspace)
from newton_euler_ros.core.errors import (DynamicsInputError,
                                          NotPositiveDefiniteError)
from newton_euler_ros.core.model import make_chain
from newton_euler_ros.core.robot_file import RobotFileWarning
import numpy as np
import pytest
from test_trees import BRANCHED, torso, urdf_path

H = 1e-4


def quiet(source):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        return load_urdf(source)


def rel(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1.0))


def central(f, x):
    """
    Central differences of f at x, column k the partial along x_k.

    The five-point stencil (error O(H^4), round-off about eps / H): the
    accelerations' partials go through D^-1, whose conditioning the plain
    two-point one (round-off eps / H at H = 1e-6) amplifies past 1e-6.
    """
    cols = []
    for k in range(len(x)):
        e = np.zeros(len(x))
        e[k] = H
        cols.append((8 * (f(x + e) - f(x - e)) - (f(x + 2 * e)
                                                  - f(x - 2 * e))) / (12 * H))
    return np.array(cols).T


def state(model, seed, scale=1.0):
    rng = np.random.default_rng(seed)
    return scale * rng.uniform(-1.2, 1.2, (4, model.n))


# Pinocchio on the same URDFs: the published chains and trees, and random
# trees (revolute, continuous, prismatic and fixed joints, some mimic)
@pytest.mark.parametrize('source', [source for source, _ in BRANCHED]
                         + [3, 11, 23])
def test_derivatives_match_pinocchio(source, tmp_path):
    from newton_euler_tools.peers import PinocchioTree
    path = urdf_path(source, tmp_path)
    model = quiet(path)
    peer = PinocchioTree(path, model)
    for seed in (1, 2):
        q, qd, qdd, tau = state(model, seed)
        want = peer.derivatives(q, qd, qdd, tau)
        dq, dqd = inverse_dynamics_derivatives(model, q, qd, qdd)
        assert rel(dq, want['dtau_dq']) < 1e-9
        assert rel(dqd, want['dtau_dqd']) < 1e-9
        if model.n != model.nb:     # mimic joints: central differences
            continue
        aq, aqd, at = forward_dynamics_derivatives(model, q, qd, tau)
        assert rel(aq, want['dqdd_dq']) < 1e-9
        assert rel(aqd, want['dqdd_dqd']) < 1e-9
        assert rel(at, want['dqdd_dtau']) < 1e-9


def check_central(model, q, qd, qdd, tau, wrench=None, frame='base',
                  drives=None, tol=1e-8):
    """Both derivative calls against central differences of the library."""
    def tau_of(x, xd):
        t = inverse_dynamics(model, x, xd, qdd, wrench, frame)
        return t if drives is None else t + drives.torques(xd, qdd)

    def qdd_of(x, xd, t):
        if drives is not None:
            t = t - drives.torques(xd, np.zeros(model.n))
            D = mass_matrix(model, x) + np.diag(drives.armature)
            bias = inverse_dynamics(model, x, xd, None, wrench, frame)
            return np.linalg.solve(D, t - bias)
        return forward_dynamics(model, x, xd, t, wrench, frame)

    dq, dqd = inverse_dynamics_derivatives(model, q, qd, qdd, wrench, frame,
                                           drives=drives)
    assert rel(dq, central(lambda x: tau_of(x, qd), q)) < tol
    assert rel(dqd, central(lambda x: tau_of(q, x), qd)) < tol
    aq, aqd, at = forward_dynamics_derivatives(model, q, qd, tau, wrench,
                                               frame, drives=drives)
    # through D^-1: the differences lose what D's conditioning costs (the
    # exact identity dqdd/dx = -D^-1 dtau/dx is test_identities')
    assert rel(aq, central(lambda x: qdd_of(x, qd, tau), q)) < 100 * tol
    assert rel(aqd, central(lambda x: qdd_of(q, x, tau), qd)) < 100 * tol
    assert rel(at, central(lambda x: qdd_of(q, qd, x), tau)) < 100 * tol


@pytest.mark.parametrize('robot', ['puma560', 'stanford', 'scara',
                                   'planar_rp'])
@pytest.mark.parametrize('frame', ['base', 'end_effector'])
def test_end_effector_wrench_in_either_axes(robot, frame):
    model = load_robot(robot)
    q, qd, qdd, tau = state(model, 3)
    wrench = np.random.default_rng(4).normal(size=6) * 5
    check_central(model, q, qd, qdd, tau, wrench, frame)


def test_mimic_joints_and_wrenches_at_links_on_a_tree():
    model = quiet(torso())
    assert model.n < model.nb       # a mimic joint
    q, qd, qdd, tau = state(model, 5)
    check_central(model, q, qd, qdd, tau)
    rng = np.random.default_rng(6)
    wrenches = {'la2': rng.normal(size=6), 'fb': rng.normal(size=6),
                'ra1': rng.normal(size=6), 'cam': rng.normal(size=6)}
    for frame in ('base', 'link', {'la2': 'link', 'fb': 'base',
                                   'ra1': 'link', 'cam': 'base'}):
        check_central(model, q, qd, qdd, tau, wrenches, frame)


@pytest.mark.parametrize('source', [BRANCHED[1][0], BRANCHED[4][0], 5, 8])
def test_published_and_random_trees_with_mimic_joints(source, tmp_path):
    model = quiet(urdf_path(source, tmp_path, mimic=3))
    q, qd, qdd, tau = state(model, 7, 0.5)
    check_central(model, q, qd, qdd, tau)
    tip = list(model.link_frames)[-1]
    check_central(model, q, qd, qdd, tau, {tip: np.ones(6)}, 'base')


def test_drive_terms():
    model = load_robot('panda')
    n = model.n
    drives = Drives(np.full(n, 0.4), np.linspace(0.5, 2.0, n),
                    np.full(n, 0.1), np.linspace(0.1, 0.3, n),
                    np.full(n, 0.3))
    q, qd, qdd, tau = state(model, 8, 0.3)   # |qd| near the Coulomb width
    check_central(model, q, qd, qdd, tau, drives=drives)
    _, dqd = inverse_dynamics_derivatives(model, q, np.zeros(n), qdd,
                                          drives=drives)
    slopes = drives.viscous + drives.coulomb / drives.coulomb_width
    assert rel(dqd, np.diag(slopes)) < 1e-14


@pytest.mark.parametrize('robot', ['panda', 'puma560', 'stanford'])
def test_identities(robot):
    model = load_robot(robot)
    n = model.n
    q, qd, qdd, tau = state(model, 9)
    _, dqd = inverse_dynamics_derivatives(model, q, np.zeros(n), qdd)
    assert np.abs(dqd).max() == 0.0
    _, dqd = inverse_dynamics_derivatives(model, q, qd, qdd)
    C = coriolis_matrix(model, q, qd)
    assert rel(dqd, 2 * C) < 1e-13
    D = mass_matrix(model, q)
    aq, aqd, at = forward_dynamics_derivatives(model, q, qd, tau)
    assert rel(at @ D, np.eye(n)) < 1e-12
    a = forward_dynamics(model, q, qd, tau)
    dq, dqd = inverse_dynamics_derivatives(model, q, qd, a)
    assert rel(aq, -np.linalg.solve(D, dq)) < 1e-10
    assert rel(aqd, -np.linalg.solve(D, dqd)) < 1e-10
    dg, _ = inverse_dynamics_derivatives(model, q, np.zeros(n), np.zeros(n))
    assert rel(dg, dg.T) < 1e-13
    assert rel(dg, central(lambda x: gravity_torques(model, x), q)) < 1e-7


def _two_arms(order):
    """Two 3-joint arms on the base, numbered ``order`` (bodies a0..b2)."""
    rng = np.random.default_rng(12)
    names = ['a0', 'a1', 'a2', 'b0', 'b1', 'b2']
    types = ['revolute', 'revolute', 'prismatic', 'revolute', 'prismatic',
             'revolute']
    posts = [[('xyz', *rng.uniform(-0.3, 0.3, 3)),
              ('rpy', *rng.uniform(-1, 1, 3))] for _ in names]
    axes = rng.normal(size=(6, 3))
    masses = rng.uniform(0.5, 2.0, 6)
    coms = rng.uniform(-0.1, 0.1, (6, 3))
    inertias = [np.diag(rng.uniform(0.01, 0.02, 3)) for _ in names]
    parent = {'a0': None, 'a1': 'a0', 'a2': 'a1', 'b0': None, 'b1': 'b0',
              'b2': 'b1'}
    k = [names.index(x) for x in order]
    return make_chain(
        'two_arms', order, [types[i] for i in k], [posts[i] for i in k],
        axes[k], masses[k], coms[k], [inertias[i] for i in k],
        parents=[-1 if parent[x] is None else order.index(parent[x])
                 for x in order])


def test_separate_roots_numbered_depth_first_or_not():
    # depth first, the legs-and-torso case (D^-1 block diagonal, worked
    # block by block), against the same robot numbered across its arms
    # (the general loops)
    first = _two_arms(['a0', 'a1', 'a2', 'b0', 'b1', 'b2'])
    mixed = _two_arms(['a0', 'b0', 'a1', 'b1', 'a2', 'b2'])
    k = [0, 3, 1, 4, 2, 5]     # mixed's coordinates in first's order
    q, qd, qdd, tau = state(first, 13)
    for model, x in ((first, slice(None)), (mixed, k)):
        check_central(model, q[x], qd[x], qdd[x], tau[x])
    want = forward_dynamics_derivatives(first, q, qd, tau)
    got = forward_dynamics_derivatives(mixed, q[k], qd[k], tau[k])
    back = np.argsort(k)
    for a, b in zip(want, got):
        assert rel(b[np.ix_(back, back)], a) < 1e-13
        assert np.all(a[:3, 3:] == 0.0) and np.all(a[3:, :3] == 0.0)


def test_batches_equal_single_calls():
    model = quiet(torso())
    rng = np.random.default_rng(10)
    Q, QD, QDD, TAU = rng.uniform(-1, 1, (4, 5, model.n))
    W = rng.normal(size=(5, 6))
    DQ, DQD = inverse_dynamics_derivatives_batch(model, Q, QD, QDD)
    FQ, FQD, FT = forward_dynamics_derivatives_batch(model, Q, QD, TAU)
    for k in range(5):
        dq, dqd = inverse_dynamics_derivatives(model, Q[k], QD[k], QDD[k])
        assert np.array_equal(DQ[k], dq) and np.array_equal(DQD[k], dqd)
        fq, fqd, ft = forward_dynamics_derivatives(model, Q[k], QD[k], TAU[k])
        assert np.array_equal(FQ[k], fq) and np.array_equal(FT[k], ft)
        assert np.array_equal(FQD[k], fqd)
    arm = load_robot('puma560')
    Q, QD, QDD = rng.uniform(-1, 1, (3, 4, arm.n))
    drives = Drives.zeros(arm.n)
    drives.viscous[:] = 0.5
    DQ, DQD = inverse_dynamics_derivatives_batch(
        arm, Q, QD, QDD, W[:4], 'end_effector', drives=drives)
    for k in range(4):
        dq, dqd = inverse_dynamics_derivatives(
            arm, Q[k], QD[k], QDD[k], W[k], 'end_effector', drives=drives)
        assert np.array_equal(DQ[k], dq) and np.array_equal(DQD[k], dqd)


def test_threads_share_a_batch_bit_for_bit():
    model = quiet(torso())
    rng = np.random.default_rng(12)
    m = 70
    Q, QD, QDD, TAU = rng.uniform(-1, 1, (4, m, model.n))
    want_i = inverse_dynamics_derivatives_batch(model, Q, QD, QDD, threads=1)
    want_f = forward_dynamics_derivatives_batch(model, Q, QD, TAU, threads=1)
    for threads in (2, 3, None):
        ws = Workspace(model)
        got_i = inverse_dynamics_derivatives_batch(model, Q, QD, QDD,
                                                   threads=threads, ws=ws)
        got_f = forward_dynamics_derivatives_batch(model, Q, QD, TAU,
                                                   threads=threads, ws=ws)
        for a, b in zip(want_i + want_f, got_i + got_f):
            assert np.array_equal(a, b)
        if threads == 3:
            assert len(ws.helpers) == 2     # the rows were shared
    QD[60] = 1e200                  # overflows, in the third share
    for call, third in ((inverse_dynamics_derivatives_batch, QDD),
                        (forward_dynamics_derivatives_batch, TAU)):
        with pytest.raises(DynamicsInputError, match='for row 60 '):
            call(model, Q, QD, third, threads=3)
        for bad in (0, -1, 1.5, True, '2'):
            with pytest.raises(DynamicsInputError, match='threads must be'):
                call(model, Q, QD, third, threads=bad)


def _child_batch(model, Q, QD, QDD, want, queue):
    got = inverse_dynamics_derivatives_batch(model, Q, QD, QDD, threads=2)
    queue.put(all(np.array_equal(a, b) for a, b in zip(want, got)))


def test_a_forked_child_shares_a_batch_among_threads():
    # the child inherits the pool but not its threads: it must make its own
    model = load_robot('puma560')
    Q, QD, QDD = np.random.default_rng(13).uniform(-1, 1, (3, 80, model.n))
    want = inverse_dynamics_derivatives_batch(model, Q, QD, QDD, threads=2)
    context = multiprocessing.get_context('fork')
    queue = context.Queue()
    child = context.Process(target=_child_batch,
                            args=(model, Q, QD, QDD, want, queue))
    child.start()
    child.join(60)
    if child.is_alive():
        child.kill()
        pytest.fail('the forked child hung on a shared batch')
    assert child.exitcode == 0 and queue.get(timeout=5)


def test_lists_workspaces_and_out():
    arm = load_robot('puma560')
    q, qd, qdd, tau = state(arm, 11)
    want = inverse_dynamics_derivatives(arm, q, qd, qdd)
    got = inverse_dynamics_derivatives(arm, list(q), list(qd), list(qdd),
                                       ws=Workspace(arm))
    assert all(np.array_equal(a, b) for a, b in zip(want, got))
    out = np.empty((3, arm.n, arm.n))
    res = forward_dynamics_derivatives(arm, tuple(q), qd, tau, out=out)
    assert res[0].base is out or np.shares_memory(res[0], out)


@pytest.mark.parametrize('call, args, match', [
    (inverse_dynamics_derivatives, ([0.0] * 5,), r'q must have 6 entries'),
    (inverse_dynamics_derivatives, ([0.0] * 5 + [float('nan')],),
     r'q\[5\] is nan'),
    (forward_dynamics_derivatives, ([0.0] * 6, [0.0] * 6, None),
     r'tau must be a vector of 6 numbers'),
    (forward_dynamics_derivatives, ([0.0] * 6, [0.0] * 6,
                                    [0.0] * 5 + [float('inf')]),
     r'tau\[5\] is inf'),
])
def test_bad_input_gets_one_line(call, args, match):
    arm = load_robot('puma560')
    with pytest.raises(DynamicsInputError, match=match) as err:
        call(arm, *args)
    assert '\n' not in str(err.value)


def test_a_singular_mass_matrix_is_named():
    text = torso().replace('<mass value="1.0"/><inertia ixx="0.01" ixy="0" '
                           'ixz="0" iyy="0.02" iyz="0" izz="0.03"/>',
                           '<mass value="0.0"/><inertia ixx="0" ixy="0" '
                           'ixz="0" iyy="0" iyz="0" izz="0"/>')
    model = quiet(text)
    with pytest.raises(NotPositiveDefiniteError, match='joint'):
        forward_dynamics_derivatives(model, np.zeros(model.n),
                                     np.zeros(model.n), np.zeros(model.n))
