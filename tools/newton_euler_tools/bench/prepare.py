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
Set-up of the benchmark: the rows, their targets, the states.

Every timed row is one statement in the tables below, run in the
namespace :func:`setup_robot` builds (``PUBLIC`` our call, ``RAW`` our
kernel, ``PIN``/``RTB``/``NAIVE`` the peers, ``BATCH_STMTS`` the batch
rows, ``INPUT_ROWS`` tau from other input types, ``PROBES`` where the
time goes): a new row is a line in one table (and, for a row with a
target, a line in ``TARGETS`` and ``OP_LABELS``).
"""
import warnings

from newton_euler_ros.core import calling as _calling
from newton_euler_ros.core import (coriolis_matrix, coriolis_matrix_batch,
                                   forward_dynamics, forward_dynamics_batch,
                                   gravity_torques, gravity_torques_batch,
                                   inverse_dynamics, inverse_dynamics_batch,
                                   load_robot, mass_matrix, mass_matrix_batch,
                                   Workspace)
from newton_euler_ros.core import kernels as K
from newton_euler_ros.core.model import REVOLUTE
import numpy as np

from .references import naive_mass_matrix, naive_rnea

DEFAULT_ROBOTS = ('puma560', 'panda')
BATCH_STATES = 10_000
PIN_LOOP_STATES = 1_000      # states in the Python loops over Pinocchio
SINGLE = ('tau', 'D', 'C', 'g', 'FD')
BATCHES = ('batch', 'batch_D', 'batch_C', 'batch_g', 'batch_FD')
OPS = SINGLE + BATCHES
# targets, ours / Pinocchio's Python call (batches: per state, against a
# Python loop of the matching Pinocchio function)
TARGETS = {'tau': 1.25, 'D': 1.25, 'C': 1.25, 'g': 1.25, 'FD': 1.5,
           'batch': 0.4, 'batch_D': 0.5, 'batch_C': 0.5, 'batch_g': 0.5,
           'batch_FD': 0.5}
OP_LABELS = {
    'tau': 'tau = ID(q,qd,qdd)',
    'D': 'D(q) mass matrix',
    'C': 'C(q,qd) Coriolis',
    'g': 'g(q) gravity',
    'FD': 'FD qdd (ABA)',
    'batch': 'batch ID, per state',
    'batch_D': 'batch D, per state',
    'batch_C': 'batch C, per state',
    'batch_g': 'batch g, per state',
    'batch_FD': 'batch FD, per state',
}


# --------------------------------------------------------------------------
# numba dispatch floor: do-nothing functions with our kernels' arguments


def _dispatch_probes():
    """
    Do-nothing njit functions with the entry points' argument lists.

    Compiled with the entry points' options (``K.ENTRY``, not cached), so
    that they pay the same dispatch as the kernels do.
    """
    from numba import njit
    options = dict(K.ENTRY, cache=False)

    @njit(**options)
    def noop0():
        return -1

    @njit(**options)
    def noop1(x):
        return -1

    @njit(**options)
    def noop4(P, q, ws, out):
        return -1

    @njit(**options)
    def noop_tau(P, q, qd, qdd, wrench, flags, ws, tau):
        return -1

    @njit(**options)
    def noop_c(P, q, qd, composite, ws, cw, scratch, C):
        return -1

    @njit(**options)
    def noop_fd(P, q, qd, tau, wrench, flags, ws, aw, qdd):
        return -1

    return {'noop0': noop0, 'noop1': noop1, 'noop4': noop4,
            'noop_tau': noop_tau, 'noop_c': noop_c, 'noop_fd': noop_fd}


# --------------------------------------------------------------------------
# states, checks


def random_state(model, rng):
    n = model.n
    lo = np.empty(n)
    hi = np.empty(n)
    for j in range(n):
        lim = model.limits[j] if j < len(model.limits) else {}
        default = np.pi if model.joint_types[j] == REVOLUTE else 0.5
        lo[j] = lim.get('lower', -default)
        hi[j] = lim.get('upper', default)
    q = rng.uniform(lo, hi)
    return q, rng.normal(size=n), rng.normal(size=n)


def random_states(model, rng, m):
    rows = [random_state(model, rng) for _ in range(m)]
    return tuple(np.ascontiguousarray(np.array([r[i] for r in rows]))
                 for i in range(3))


# --------------------------------------------------------------------------
# one robot


# statements timed for every robot: one line each.  ``ns`` names (see
# ``setup_robot``): model, q, qd, qdd, ws, outputs tau D C g, batches Q QD
# QDD TAU DD W, raw kernel arguments P wsa cw aw scratch zero_w status.
PUBLIC = {
    'tau': 'inverse_dynamics(model, q, qd, qdd, ws=ws, out=tau)',
    'D': 'mass_matrix(model, q, ws=ws, out=D)',
    'C': 'coriolis_matrix(model, q, qd, ws=ws, out=C)',
    'g': 'gravity_torques(model, q, ws=ws, out=g)',
    'FD': 'forward_dynamics(model, q, qd, qdd, ws=ws, out=g)',
}
RAW = {
    'tau': 'K.run_inverse_dynamics(P, q, qd, qdd, zero_w, 3, wsa, tau)',
    'D': 'K.run_mass_matrix_crba(P, q, wsa, D)',
    'C': 'K.run_coriolis_matrix(P, q, qd, True, wsa, cw, scratch, C)',
    'g': 'K.run_gravity_torques(P, q, wsa, g)',
    'FD': 'K.run_forward_dynamics(P, q, qd, qdd, zero_w, 3, wsa, aw, g)',
}
NAIVE = {'tau': 'naive_rnea(model, q, qd, qdd)',
         'D': 'naive_mass_matrix(model, q)',
         'g': 'naive_rnea(model, q, zeros, zeros)'}
PIN = {'tau': 'rnea(pm, pd, q, qd, qdd)', 'D': 'crba(pm, pd, q)',
       'C': 'computeCoriolisMatrix(pm, pd, q, qd)',
       'g': 'computeGeneralizedGravity(pm, pd, q)',
       'FD': 'aba(pm, pd, q, qd, qdd)'}
RTB = {'tau': 'robot.rne(q, qd, qdd)', 'D': 'robot.inertia(q)',
       'C': 'robot.coriolis(q, qd)', 'g': 'robot.gravload(q)',
       'FD': 'robot.accel(q, qd, qdd)'}
# (ours, our raw kernel, one Pinocchio call in its Python loop)
BATCH_STMTS = {
    'batch': ('inverse_dynamics_batch(model, Q, QD, QDD, ws=ws, out=TAU)',
              'K.run_inverse_dynamics_batch(P, Q, QD, QDD, W, 3, wsa, TAU, '
              'status)', 'rnea(pm, pd, Q[i], QD[i], QDD[i])'),
    'batch_D': ('mass_matrix_batch(model, Q, ws=ws, out=DD)',
                'K.run_mass_matrix_batch(P, Q, wsa, DD, status)',
                'crba(pm, pd, Q[i])'),
    'batch_C': ('coriolis_matrix_batch(model, Q, QD, ws=ws, out=DD)',
                'K.run_coriolis_matrix_batch(P, Q, QD, wsa, cw, DD, status)',
                'computeCoriolisMatrix(pm, pd, Q[i], QD[i])'),
    'batch_g': ('gravity_torques_batch(model, Q, ws=ws, out=TAU)',
                'K.run_gravity_torques_batch(P, Q, wsa, TAU, status)',
                'computeGeneralizedGravity(pm, pd, Q[i])'),
    'batch_FD': ('forward_dynamics_batch(model, Q, QD, QDD, ws=ws, out=TAU)',
                 'K.run_forward_dynamics_batch(P, Q, QD, QDD, W, 3, wsa, aw, '
                 'TAU, status)', 'aba(pm, pd, Q[i], QD[i], QDD[i])'),
}
# tau with its inputs given otherwise than as float64 arrays, beside the
# float64 row: a list or an int array costs one conversion more
INPUT_ROWS = {
    'q list': 'inverse_dynamics(model, q_list, qd, qdd, ws=ws, out=tau)',
    'q int array': 'inverse_dynamics(model, q_int, qd, qdd, ws=ws, out=tau)',
    'all lists': 'inverse_dynamics(model, q_list, qd_list, qdd_list, '
                 'wrench_list, ws=ws, out=tau)',
    'wrench array': 'inverse_dynamics(model, q, qd, qdd, wrench, ws=ws, '
                    'out=tau)',
    'wrench list': 'inverse_dynamics(model, q, qd, qdd, wrench_list, ws=ws, '
                   'out=tau)',
}
PROBES = {
    'empty_loop': 'pass',
    'njit_0_args': 'noop0()',
    'njit_1_array': 'noop1(q)',
    'njit_tau_args': 'noop_tau(P, q, qd, qdd, zero_w, 3, wsa, tau)',
    'njit_D_args': 'noop4(P, q, wsa, D)',
    'njit_C_args': 'noop_c(P, q, qd, True, wsa, cw, scratch, C)',
    'njit_g_args': 'noop4(P, q, wsa, g)',
    'njit_FD_args': 'noop_fd(P, q, qd, qdd, zero_w, 3, wsa, aw, g)',
    '_vector_one_arg': "_vector('q', q, n)",
    'np_empty_n': 'np.empty(n)',
}


def setup_robot(name, rng, log):
    """Load a robot; return (result skeleton, our namespace, states)."""
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')     # e.g. the Puma's published
        model = load_robot(name)            # triangle-inequality oddities
    n = model.n
    result = {'robot': name, 'convention': model.convention, 'dof': n,
              'timings': {}, 'correctness': {}, 'valid': {}}
    log(f'\n=== {name}: {model.convention} DH, {n} DoF '
        f'({", ".join(sorted(set(model.joint_types)))}) ===')
    ws = Workspace(model)
    q, qd, qdd = random_state(model, rng)
    Q, QD, QDD = random_states(model, rng, BATCH_STATES)
    m = BATCH_STATES
    wrench = np.array([0.0, 0.0, 10.0, 0.0, 0.0, 0.0])
    ns = {'model': model, 'q': q, 'qd': qd, 'qdd': qdd, 'ws': ws,
          'tau': np.empty(n), 'D': np.empty((n, n)), 'C': np.empty((n, n)),
          'g': np.empty(n), 'Q': Q, 'QD': QD, 'QDD': QDD,
          'TAU': np.empty((m, n)), 'W': np.zeros((m, 6)), 'K': K,
          'P': model.packed, 'DD': np.empty((m, n, n)),
          'inverse_dynamics': inverse_dynamics, 'mass_matrix': mass_matrix,
          'coriolis_matrix': coriolis_matrix,
          'gravity_torques': gravity_torques,
          'forward_dynamics': forward_dynamics,
          'inverse_dynamics_batch': inverse_dynamics_batch,
          'mass_matrix_batch': mass_matrix_batch,
          'coriolis_matrix_batch': coriolis_matrix_batch,
          'gravity_torques_batch': gravity_torques_batch,
          'forward_dynamics_batch': forward_dynamics_batch,
          'naive_rnea': naive_rnea, 'naive_mass_matrix': naive_mass_matrix,
          'zeros': np.zeros(n), 'zero_w': np.zeros(6), 'wsa': ws.ws,
          'scratch': ws.scratch, 'cw': ws.cw, 'aw': ws.aw,
          'status': ws.status, '_vector': _calling.vector, 'n': n,
          'np': np, 'wrench': wrench, 'wrench_list': wrench.tolist(),
          'q_list': q.tolist(), 'qd_list': qd.tolist(),
          'qdd_list': qdd.tolist(),
          'q_int': np.round(q).astype(np.int64)}
    ns.update(_dispatch_probes())
    check_states = [random_state(model, rng) for _ in range(3)]
    return result, ns, check_states
