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
Cost growth with the number of links, on log-log axes.

Random chains of n links (:func:`.chains.random_chain`), one state each,
every operation timed side by side per n.  The exponent p of
``time ~ c n^p`` is the least-squares slope of log time against log n
over the three largest chains (below them, the fixed cost of a call
from Python hides the growth).
"""
import math
import warnings

from newton_euler_ros.core import (coriolis_matrix, forward_dynamics,
                                   gravity_torques, inverse_dynamics,
                                   inverse_dynamics_batch, mass_matrix,
                                   Workspace)
import numpy as np

from .arithmetic import coriolis_by_differences
from .chains import random_chain, random_states

FULL_SIZES = (3, 6, 12, 25, 50, 100, 200)
QUICK_SIZES = (3, 6, 12, 25)
FIT_POINTS = 3
BATCH = 200

OPERATIONS = {
    'tau': 'inverse_dynamics(model, q, qd, qdd, ws=ws, out=tau)',
    'tau, batched (per state)': 'inverse_dynamics_batch(model, Q, QD, QDD, '
                                'ws=ws, out=TAU)',
    'g': 'gravity_torques(model, q, ws=ws, out=g)',
    'D, CRBA': 'mass_matrix(model, q, ws=ws, out=D)',
    'D, n recursions':
        "mass_matrix(model, q, method='newton_euler', ws=ws, out=D)",
    'C, composite': 'coriolis_matrix(model, q, qd, ws=ws, out=C)',
    'C, n recursions':
        "coriolis_matrix(model, q, qd, method='newton_euler', ws=ws, out=C)",
    'C, central differences of D': 'fd(model, q, qd, ws=ws)',
    'FD, ABA': 'forward_dynamics(model, q, qd, qdd, ws=ws, out=tau)',
    'FD, Cholesky': "forward_dynamics(model, q, qd, qdd, method='cholesky', "
                    'ws=ws, out=tau)',
}
PEER_OPERATIONS = {
    'Pinocchio rnea': 'pin.rnea(pm, pd, q, qd, qdd)',
    'Pinocchio crba': 'pin.crba(pm, pd, q)',
    'Pinocchio computeCoriolisMatrix':
        'pin.computeCoriolisMatrix(pm, pd, q, qd)',
    'Pinocchio aba': 'pin.aba(pm, pd, q, qd, qdd)',
}


def _namespace(model):
    n = model.n
    q, qd, qdd = random_states(model, 1)[0]
    states = random_states(model, BATCH, seed=1)
    Q, QD, QDD = (np.ascontiguousarray([s[i] for s in states])
                  for i in range(3))
    return {'model': model, 'ws': Workspace(model), 'q': q, 'qd': qd,
            'qdd': qdd, 'Q': Q, 'QD': QD, 'QDD': QDD,
            'TAU': np.empty((BATCH, n)), 'tau': np.empty(n), 'g': np.empty(n),
            'D': np.empty((n, n)), 'C': np.empty((n, n)),
            'inverse_dynamics': inverse_dynamics,
            'inverse_dynamics_batch': inverse_dynamics_batch,
            'gravity_torques': gravity_torques, 'mass_matrix': mass_matrix,
            'coriolis_matrix': coriolis_matrix,
            'forward_dynamics': forward_dynamics,
            'fd': coriolis_by_differences}


def measure_scaling(timer, sizes, use_peers=True, notes=None):
    """
    Return one record per (n, operation) and the fitted exponents.

    Records: section 'scaling', 'dof', 'method' (the operation), 'us'.
    Exponents: {operation: (p, c)} with time ~ c n^p (microseconds).
    """
    notes = [] if notes is None else notes
    pin = None
    if use_peers:
        try:
            import pinocchio as pin
            from .. import peers
        except Exception as exc:
            notes.append(f'Pinocchio not available ({type(exc).__name__}): '
                         f'no peer in the scaling figure')
    records = []
    for n in sizes:
        model = random_chain(n)
        ns = _namespace(model)
        entries = {op: (stmt, ns, None, BATCH if 'batch' in op else 1)
                   for op, stmt in OPERATIONS.items()}
        if pin is not None:
            pm = peers.pinocchio_model(model)
            pns = dict(ns, pin=pin, pm=pm, pd=pm.createData())
            entries.update({op: (stmt, pns, None, 1)
                            for op, stmt in PEER_OPERATIONS.items()})
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            times = timer.group(entries)
        for op, t in times.items():
            records.append({'section': 'scaling', 'robot': model.name,
                            'dof': n, 'scene': None, 'quantity': op,
                            'method': op, 'us': t['min_us'],
                            'us_median': t['median_us'], 'error': None,
                            'note': ''})
    return records, fit_exponents(records, fit_start(sizes))


def fit_start(sizes):
    """Return the smallest n of the fit: the third largest size."""
    return sorted(sizes)[-FIT_POINTS]


def fit_exponents(records, fit_from):
    """Return {operation: (p, c)}: least squares of log t on log n."""
    out = {}
    for op in dict.fromkeys(r['method'] for r in records):
        pts = [(r['dof'], r['us']) for r in records
               if r['method'] == op and r['dof'] >= fit_from]
        if len(pts) < 2:
            continue
        x = np.log([p[0] for p in pts])
        y = np.log([p[1] for p in pts])
        p, logc = np.polyfit(x, y, 1)
        out[op] = (float(p), float(math.exp(logc)))
    return out
