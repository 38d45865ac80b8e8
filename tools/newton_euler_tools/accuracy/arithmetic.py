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
Arithmetic and algorithms, per robot: microseconds and error vs truth.

For tau, D, C and g of one model this measures, side by side in one run
(the repeats of one quantity's methods interleaved by
:class:`newton_euler_tools.bench.Timer`):

- our float64 path and the float32 path (the same kernels compiled for
  float32; inputs rounded to float32 count towards its error);
- D from n Newton-Euler recursions and from the composite-rigid-body
  algorithm;
- C exact (the Christoffel-form recursion) and C from finite differences
  of D through the Christoffel symbols, central and forward;
- Pinocchio and Robotics Toolbox for Python, where installed, on models
  built from ours by :mod:`newton_euler_tools.peers`.

The error of a method is the largest normwise relative error over the
states (see :func:`.truth.relative_error`).
"""
import warnings

from newton_euler_ros.core import (coriolis_matrix, forward_dynamics,
                                   gravity_torques, inverse_dynamics,
                                   mass_matrix, Workspace)
from newton_euler_ros.core.float32 import Float32Dynamics
from newton_euler_ros.core.highprec import relative_error
import numpy as np

from .truth import QUANTITIES
from .. import peers

EPS = float(np.finfo(np.float64).eps)
# Central differences balance truncation (h^2) against rounding (eps / h):
# h = eps^(1/3); forward differences (h against eps / h): h = sqrt(eps).
CENTRAL_STEP = EPS ** (1.0 / 3.0)
FORWARD_STEP = EPS ** 0.5


def coriolis_by_differences(model, q, qd, h=CENTRAL_STEP, central=True,
                            method='crba', ws=None):
    """
    Return C(q, qd) from finite differences of D(q).

    The Christoffel symbols give
    ``C[k, j] = 1/2 sum_i (dD[k,j]/dq_i + dD[k,i]/dq_j - dD[i,j]/dq_k) qd_i``,
    i.e. ``C = (Ddot + T - T^T) / 2`` with ``Ddot = sum_i qd_i dD/dq_i``
    and ``T[:, j] = (dD/dq_j) qd``.  Each dD/dq_i costs two evaluations of
    D (central) or one (forward, plus D(q) once): 2n or n + 1 D calls.
    """
    n = model.n
    q = np.asarray(q, dtype=np.float64)
    qd = np.asarray(qd, dtype=np.float64)
    ws = ws or Workspace(model)
    dD = np.empty((n, n, n))
    qh = q.copy()
    D0 = None if central else mass_matrix(model, q, method=method, ws=ws)
    for i in range(n):
        qh[i] = q[i] + h
        Dp = mass_matrix(model, qh, method=method, ws=ws)
        if central:
            qh[i] = q[i] - h
            dD[i] = (Dp - mass_matrix(model, qh, method=method, ws=ws)) / (
                2.0 * h)
        else:
            dD[i] = (Dp - D0) / h
        qh[i] = q[i]
    Ddot = np.tensordot(qd, dD, axes=1)
    T = (dD @ qd).T
    return 0.5 * (Ddot + T - T.T)


class Method:
    """One way of computing one quantity: a timed statement and its value."""

    def __init__(self, quantity, label, family, stmt, namespace, post=None,
                 note=''):
        self.quantity = quantity
        self.label = label
        self.family = family          # 'ours', 'float32', 'fd', 'peer'
        self.stmt = stmt
        self.namespace = namespace
        self.post = post
        self.note = note

    def value(self, state):
        """Evaluate the statement at ``state`` = (q, qd, qdd)."""
        ns = dict(self.namespace)
        ns['q'], ns['qd'], ns['qdd'] = (np.array(x) for x in state)
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            out = np.array(eval(self.stmt, ns))  # noqa: S307 - our own text
        return self.post(out) if self.post is not None else out


def our_methods(model):
    """Yield the methods of this package (float64, float32, CRBA, FD)."""
    n = model.n
    f32 = Float32Dynamics(model)
    ns = {'model': model, 'ws': Workspace(model), 'f32': f32,
          'inverse_dynamics': inverse_dynamics, 'mass_matrix': mass_matrix,
          'coriolis_matrix': coriolis_matrix,
          'gravity_torques': gravity_torques,
          'forward_dynamics': forward_dynamics,
          'fd': coriolis_by_differences, 'a': np.empty(n),
          'a32': np.empty(n, np.float32),
          'tau': np.empty(n), 'D': np.empty((n, n)), 'C': np.empty((n, n)),
          'g': np.empty(n), 'tau32': np.empty(n, np.float32),
          'D32': np.empty((n, n), np.float32),
          'C32': np.empty((n, n), np.float32), 'g32': np.empty(n, np.float32),
          'h_c': CENTRAL_STEP, 'h_f': FORWARD_STEP}
    yield Method('tau', 'float64', 'ours',
                 'inverse_dynamics(model, q, qd, qdd, ws=ws, out=tau)', ns)
    yield Method('tau', 'float32', 'float32',
                 'f32.inverse_dynamics(q, qd, qdd, out=tau32)', ns)
    # D and C alike: the default algorithm and n recursions, float64 and
    # float32
    for out, function, args, default in (
            ('D', 'mass_matrix', 'q', 'CRBA'),
            ('C', 'coriolis_matrix', 'q, qd', 'composite, O(n^2)')):
        yield Method(out, f'float64, {default}', 'ours',
                     f'{function}(model, {args}, ws=ws, out={out})', ns,
                     note=f'the default of {function}')
        yield Method(out, 'float64, n recursions', 'ours',
                     f"{function}(model, {args}, method='newton_euler', "
                     f'ws=ws, out={out})', ns)
        yield Method(out, f'float32, {default}', 'float32',
                     f'f32.{function}({args}, out={out}32)', ns)
        yield Method(out, 'float32, n recursions', 'float32',
                     f"f32.{function}({args}, method='newton_euler', "
                     f'out={out}32)', ns)
    yield Method('C', 'central differences of D', 'fd',
                 'fd(model, q, qd, h_c, True, ws=ws)', ns,
                 note=f'2n CRBA calls, h = eps^(1/3) = {CENTRAL_STEP:.1e}')
    yield Method('C', 'forward differences of D', 'fd',
                 'fd(model, q, qd, h_f, False, ws=ws)', ns,
                 note=f'n+1 CRBA calls, h = sqrt(eps) = {FORWARD_STEP:.1e}')
    yield Method('g', 'float64', 'ours',
                 'gravity_torques(model, q, ws=ws, out=g)', ns)
    yield Method('g', 'float32', 'float32', 'f32.gravity_torques(q, out=g32)',
                 ns)
    # forward dynamics with the state's qdd as the torques
    yield Method('FD', 'float64, ABA, O(n)', 'ours',
                 'forward_dynamics(model, q, qd, qdd, ws=ws, out=a)', ns,
                 note='the default of forward_dynamics')
    yield Method('FD', 'float64, Cholesky of D', 'ours',
                 "forward_dynamics(model, q, qd, qdd, method='cholesky', "
                 'ws=ws, out=a)', ns)
    yield Method('FD', 'float32, ABA', 'float32',
                 'f32.forward_dynamics(q, qd, qdd, out=a32)', ns)


def _symmetric_from_upper(M):
    return np.triu(M) + np.triu(M, 1).T


def peer_methods(model, notes):
    """Yield Pinocchio's and RTB's methods; append to ``notes`` if missing."""
    try:
        import pinocchio as pin
    except Exception as exc:   # ImportError, or a broken binary wheel
        notes.append(f'Pinocchio not available ({type(exc).__name__}: '
                     f'{exc}): skipped; `make peers` installs it')
    else:
        pm = peers.pinocchio_model(model)
        ns = {'pin': pin, 'pm': pm, 'pd': pm.createData()}
        yield Method('tau', 'Pinocchio rnea', 'peer',
                     'pin.rnea(pm, pd, q, qd, qdd)', ns)
        yield Method('D', 'Pinocchio crba', 'peer', 'pin.crba(pm, pd, q)', ns,
                     post=_symmetric_from_upper,
                     note='fills the upper triangle; symmetrised after timing')
        yield Method('C', 'Pinocchio computeCoriolisMatrix', 'peer',
                     'pin.computeCoriolisMatrix(pm, pd, q, qd)', ns)
        yield Method('g', 'Pinocchio computeGeneralizedGravity', 'peer',
                     'pin.computeGeneralizedGravity(pm, pd, q)', ns)
        yield Method('FD', 'Pinocchio aba', 'peer',
                     'pin.aba(pm, pd, q, qd, qdd)', ns)
    try:
        import roboticstoolbox  # noqa: F401
    except Exception as exc:
        notes.append(f'Robotics Toolbox not available ({type(exc).__name__}: '
                     f'{exc}): skipped; `make peers` installs it')
    else:
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            robot = peers.rtb_robot(model)
        ns = {'robot': robot}
        yield Method('tau', 'RTB rne', 'peer', 'robot.rne(q, qd, qdd)', ns)
        yield Method('D', 'RTB inertia', 'peer', 'robot.inertia(q)', ns)
        yield Method('C', 'RTB coriolis', 'peer', 'robot.coriolis(q, qd)', ns)
        yield Method('g', 'RTB gravload', 'peer', 'robot.gravload(q)', ns)
        yield Method('FD', 'RTB accel', 'peer', 'robot.accel(q, qd, qdd)',
                     ns)


def measure_robot(model, truth, timer, use_peers=True, notes=None,
                  section='arithmetic'):
    """
    Return one record per (quantity, method) for ``model``.

    ``truth`` is a :class:`.truth.GroundTruth` over the states to check;
    the timing uses its first state.  Records carry 'us' (minimum over the
    timer's repeats, per call), 'us_median', 'ratio' (time over our
    float64 method for the quantity) and 'error'.
    """
    notes = [] if notes is None else notes
    methods = list(our_methods(model))
    if use_peers:
        methods += list(peer_methods(model, notes))
    state = truth.states[0]
    records = []
    for quantity in QUANTITIES:
        group = [m for m in methods if m.quantity == quantity]
        entries = {}
        for m in group:
            ns = dict(m.namespace)
            # float32 is timed on float32 input: what a float32 user has
            # (rounding float64 input costs about 0.4 us per vector more)
            dtype = np.float32 if m.family == 'float32' else np.float64
            ns['q'], ns['qd'], ns['qdd'] = (np.array(x, dtype=dtype)
                                            for x in state)
            entries[m.label] = (m.stmt, ns, None, 1)
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            times = timer.group(entries)
        base = times[group[0].label]['min_us']
        for m in group:
            err = max(relative_error(m.value(s), truth.value(quantity, k))
                      for k, s in enumerate(truth.states))
            t = times[m.label]
            records.append({
                'section': section, 'robot': model.name, 'dof': model.n,
                'scene': None, 'quantity': quantity, 'method': m.label,
                'family': m.family, 'us': t['min_us'],
                'us_median': t['median_us'], 'ratio': t['min_us'] / base,
                'error': err, 'error_eps': err / EPS,
                'states': len(truth.states), 'note': m.note})
    return records
