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
Whole robots (kinematic trees) against Pinocchio on the same URDF.

For each tree (default: Centauro's whole body, 39 joints on five
branches, from example-robot-data) the model is loaded without a tip
(``load_urdf(path)``), Pinocchio's from the same file
(``buildModelFromUrdf``), the two are checked to agree at random states
(tau, D, forward dynamics; a peer that disagrees is INVALID), and one
call from Python of each operation is timed, ours and Pinocchio's
interleaved (:class:`~newton_euler_tools.bench.measure.Timer`).
Targets: tau, D and forward dynamics each <= 0.8x Pinocchio's Python
call (``rnea``, ``crba``, ``aba``); C and g are printed beside them.
"""
import warnings

from newton_euler_ros.core import (coriolis_matrix, forward_dynamics,
                                   gravity_torques, inverse_dynamics,
                                   load_urdf, mass_matrix, Workspace)
import numpy as np

from .report import log_head, ratio_text
from .. import peers

TREES = {'centauro': 'centauro_description/urdf/centauro.urdf'}
DEFAULT_TREES = ('centauro',)
TREE_OPS = ('tau', 'D', 'FD', 'C', 'g')
TREE_TARGETS = {'tau': 0.8, 'D': 0.8, 'FD': 0.8}
TREE_LABELS = {'tau': 'tau  ID(q,qd,qdd)', 'D': 'D(q)  CRBA',
               'FD': 'FD  qdd(q,qd,tau)', 'C': 'C(q,qd)', 'g': 'g(q)'}
OURS = {
    'tau': 'inverse_dynamics(model, q, qd, qdd, ws=ws, out=out)',
    'D': 'mass_matrix(model, q, ws=ws, out=D)',
    'FD': 'forward_dynamics(model, q, qd, tau, ws=ws, out=out)',
    'C': 'coriolis_matrix(model, q, qd, ws=ws, out=C)',
    'g': 'gravity_torques(model, q, ws=ws, out=out)',
}
PIN = {'tau': 'rnea(pm, pd, x, v, a)', 'D': 'crba(pm, pd, x)',
       'FD': 'aba(pm, pd, x, v, t)',
       'C': 'computeCoriolisMatrix(pm, pd, x, v)',
       'g': 'computeGeneralizedGravity(pm, pd, x)'}


def _setup(name, rng, log):
    path = peers.example_robot_urdf(TREES[name])
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_urdf(path)
    n = model.n
    log(f'\n=== {name} (whole tree): {n} joints, {model.nb} bodies, '
        f'{model.parents.count(-1)} branches on the base ===')
    q, qd, qdd = rng.uniform(-1.0, 1.0, (3, n))
    ws = Workspace(model)
    tau = inverse_dynamics(model, q, qd, qdd, ws=ws)
    ns = {'model': model, 'q': q, 'qd': qd, 'qdd': qdd, 'tau': tau,
          'ws': ws, 'out': np.empty(n), 'D': np.empty((n, n)),
          'C': np.empty((n, n)), 'inverse_dynamics': inverse_dynamics,
          'mass_matrix': mass_matrix, 'forward_dynamics': forward_dynamics,
          'coriolis_matrix': coriolis_matrix,
          'gravity_torques': gravity_torques}
    return path, model, ns


def _pinocchio(path, model, ns, rng, log):
    """Return (Pinocchio's namespace or None, valid)."""
    try:
        peer = peers.PinocchioTree(path, model)
    except ImportError as exc:
        log(f'  Pinocchio: unavailable ({exc})')
        return None, False
    pin = peer.pin
    worst = 0.0
    for _ in range(3):
        q, qd, qdd = rng.uniform(-1.0, 1.0, (3, model.n))
        theirs = peer.terms(q, qd, qdd)
        tau = inverse_dynamics(model, q, qd, qdd)
        for key, ours in (('tau', tau), ('D', mass_matrix(model, q)),
                          ('fd', forward_dynamics(model, q, qd,
                                                  theirs['tau']))):
            scale = max(np.abs(theirs[key]).max(), 1e-300)
            worst = max(worst, np.abs(ours - theirs[key]).max() / scale)
    valid = worst < 1e-9
    log(f'  Pinocchio (same URDF): largest relative difference in tau, D, '
        f'qdd {worst:.1e} -> {"OK" if valid else "INVALID"}')
    pns = {'pm': peer.model, 'pd': peer.data, 'x': peer.config(ns['q']),
           'v': peer.vector(ns['qd']), 'a': peer.vector(ns['qdd']),
           't': peer.vector(ns['tau']), 'rnea': pin.rnea, 'crba': pin.crba,
           'aba': pin.aba,
           'computeCoriolisMatrix': pin.computeCoriolisMatrix,
           'computeGeneralizedGravity': pin.computeGeneralizedGravity}
    return pns, valid


def bench_tree(name, timer, rng, log):
    """Set up, check and time one tree; its result (timings, verdicts)."""
    path, model, ns = _setup(name, rng, log)
    pns, valid = _pinocchio(path, model, ns, rng, log)
    timings = {}
    for op in TREE_OPS:
        entries = {('ours', op): (OURS[op], ns, None, 1)}
        if pns is not None:
            entries[('pin', op)] = (PIN[op], pns, None, 1)
        timings.update(timer.group(entries))
    verdicts = {}
    for op in TREE_OPS:
        ours, pin = timings[('ours', op)], timings.get(('pin', op))
        if pin is None:
            verdicts[op] = {'verdict': 'n/a (no Pinocchio)'}
            continue
        ratio = ours['min_us'] / pin['min_us']
        limit = TREE_TARGETS.get(op)
        verdict = ('-' if limit is None else 'INVALID peer' if not valid
                   else 'PASS' if ratio <= limit else 'MISS')
        verdicts[op] = {'ratio_min': ratio, 'verdict': verdict,
                        'target': f'<= {limit:g}x Pinocchio' if limit
                        else '-'}
    return {'robot': name, 'dof': model.n, 'bodies': model.nb,
            'timings': timings, 'verdicts': verdicts, 'valid': valid}


def print_tree_table(result, timer, log):
    """Print one tree's rows: ours, Pinocchio, ratio, target, verdict."""
    T, V = result['timings'], result['verdicts']
    log(f'\n{result["robot"]} whole tree ({result["dof"]} joints): '
        f'microseconds per call, min (median) of {timer.reps} repeats')
    log_head(log)
    for op in TREE_OPS:
        ours, pin, v = T[('ours', op)], T.get(('pin', op)), V[op]
        cell = (lambda t: '-' if t is None else
                f'{t["min_us"]:.2f} ({t["median_us"]:.2f})')
        ratio = ratio_text(v)
        log(f'{TREE_LABELS[op]:<22}{cell(ours):>16}{cell(pin):>16}'
            f'{ratio:>10}  {v.get("target", "-"):<22}{v["verdict"]:<13}')
    log('  D: Pinocchio crba fills only the upper triangle; ours returns '
        'the full matrix (zero across branches).')
