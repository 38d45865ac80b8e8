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
The dynamics of many states at once: one compiled loop per term.

``inverse_dynamics_batch``, ``mass_matrix_batch``, ``coriolis_matrix_batch``,
``gravity_torques_batch`` and ``forward_dynamics_batch`` take (m, n) arrays
of states, check them once in numpy (shapes, finiteness) and run the
batch entry point of their kernel (``kernels/entry.py``, beside the
single-state one): no Python work per state.  All are importable from
:mod:`newton_euler_ros.core` and :mod:`newton_euler_ros.core.dynamics`.

:func:`run_split` shares a batch among threads, each with its own
workspace, for the loops that release the GIL (the derivatives'): the
rows are independent, so the result is the same bit for bit whatever
the number of threads.
"""
from concurrent.futures import ThreadPoolExecutor
import os
import threading

import numpy as np

from . import kernels as K
from .calling import matrix, out_array, status_error, workspace, wrench_mode
from .errors import DynamicsInputError
from .workspace import Workspace

ROWS_PER_THREAD = 32        # fewer rows a thread: starting it costs more
_POOL = [None, 0, 0]        # the shared pool, its workers, its process
_POOL_LOCK = threading.Lock()
_CORES = [None]


def usable_cores():
    """Return the number of cores this process may run on (asked once)."""
    if _CORES[0] is None:
        try:
            _CORES[0] = len(os.sched_getaffinity(0))
        except AttributeError:          # not on Linux
            _CORES[0] = os.cpu_count() or 1
    return _CORES[0]


def row_ranges(m, threads=None):
    """
    Return the (lo, hi) row ranges of m rows shared among ``threads``.

    None: one thread per usable core, but no fewer than
    ``ROWS_PER_THREAD`` rows a thread; 1: the whole batch here.
    """
    if threads is None:
        threads = min(usable_cores(), max(1, m // ROWS_PER_THREAD))
    elif type(threads) is not int or threads < 1:
        raise DynamicsInputError(
            f'threads must be None or a whole number >= 1, got {threads!r}')
    threads = max(1, min(threads, m))
    edges = [m * k // threads for k in range(threads + 1)]
    return list(zip(edges[:-1], edges[1:]))


def _pool(workers):
    """Return the shared pool, with at least ``workers`` threads."""
    with _POOL_LOCK:
        if _POOL[1] < workers or _POOL[2] != os.getpid():
            if _POOL[0] is not None and _POOL[2] == os.getpid():
                _POOL[0].shutdown(wait=False)
            # (a forked child has the pool but not its threads: a new one)
            _POOL[:] = [ThreadPoolExecutor(
                workers, thread_name_prefix='newton_euler_batch'), workers,
                os.getpid()]
        return _POOL[0]


def run_split(model, ws, m, threads, kernel, arguments, Q=None):
    """
    Run ``kernel(*arguments(lo, hi, w))`` over the row ranges of m rows.

    The first range runs in this thread with ``ws``, the others on the
    shared pool, each with a workspace of its own (kept on ``ws``); the
    kernel must release the GIL (``kernels.BATCH``).  It returns the
    failed row of its range or -1 (its code in ``w.status``); the first
    failed row of the batch is raised.
    """
    ranges = row_ranges(m, threads)
    if len(ranges) == 1:
        _check(kernel(*arguments(0, m, ws)), ws, model, Q)
        return
    spaces = [ws] + helper_workspaces(model, ws, len(ranges) - 1)
    pool = _pool(len(ranges) - 1)
    futures = [pool.submit(kernel, *arguments(lo, hi, w))
               for (lo, hi), w in zip(ranges[1:], spaces[1:])]
    rows = [kernel(*arguments(*ranges[0], ws))]
    rows += [f.result() for f in futures]
    for (lo, _), w, row in zip(ranges, spaces, rows):
        _check(row if row < 0 else lo + row, w, model, Q)


def helper_workspaces(model, ws, count):
    """Return ``count`` more workspaces for ``ws``'s model, made once."""
    helpers = ws.helpers
    while len(helpers) < count:
        helpers.append(Workspace(model, ws.dtype))
    return helpers[:count]


def _states(model, ws, Q, QD, name_qd='QD'):
    ws = workspace(model, ws)
    Q = matrix('Q', Q, ws.n)
    QD = None if QD is None else matrix(name_qd, QD, ws.n, Q.shape[0])
    return ws, Q, QD


def _wrenches(W, wrench_frame, m):
    if W is None:
        return np.zeros((m, 6)), K.WRENCH_NONE
    return matrix('W', W, 6, m), wrench_mode(W, wrench_frame)


def _check(row, ws, model=None, Q=None):
    """Raise for the first failed row of a batch (its code in ws.status)."""
    if row >= 0:
        raise status_error(int(ws.status[0]), model=model,
                           q=None if Q is None else Q[row], ws=ws, row=row)


def inverse_dynamics_batch(model, Q, QD=None, QDD=None, W=None,
                           wrench_frame='base', *, gravity=True,
                           velocity_products=True, ws=None, out=None):
    """
    :func:`~newton_euler_ros.core.dynamics.inverse_dynamics` for each row.

    Of (m, n) arrays of states; ``W`` is an (m, 6) array of wrenches or
    None.  Returns (m, n).  One compiled loop: no Python work per state.
    """
    ws, Q, QD = _states(model, ws, Q, QD)
    m = Q.shape[0]
    QD = np.zeros_like(Q) if QD is None else QD
    QDD = np.zeros_like(Q) if QDD is None else matrix('QDD', QDD, ws.n, m)
    W, mode = _wrenches(W, wrench_frame, m)
    TAU = out_array(out, Q.shape)
    _check(K.run_inverse_dynamics_batch(
        model.packed, Q, QD, QDD, W, K.flags(gravity, velocity_products, mode),
        ws.ws, TAU, ws.status), ws)
    return TAU


def gravity_torques_batch(model, Q, *, ws=None, out=None):
    """:func:`gravity_torques` for each row of an (m, n) array; (m, n)."""
    ws, Q, _ = _states(model, ws, Q, None)
    G = out_array(out, Q.shape)
    _check(K.run_gravity_torques_batch(model.packed, Q, ws.ws, G, ws.status),
           ws)
    return G


def mass_matrix_batch(model, Q, *, ws=None, out=None):
    """:func:`mass_matrix` (CRBA) for each row of Q; returns (m, n, n)."""
    ws, Q, _ = _states(model, ws, Q, None)
    DD = out_array(out, (Q.shape[0], ws.n, ws.n))
    _check(K.run_mass_matrix_batch(model.packed, Q, ws.ws, DD, ws.status), ws)
    return DD


def coriolis_matrix_batch(model, Q, QD, *, ws=None, out=None):
    """:func:`coriolis_matrix` (composite) for each row; (m, n, n)."""
    ws, Q, QD = _states(model, ws, Q, QD)
    QD = np.zeros_like(Q) if QD is None else QD
    CC = out_array(out, (Q.shape[0], ws.n, ws.n))
    _check(K.run_coriolis_matrix_batch(model.packed, Q, QD, ws.ws, ws.cw, CC,
                                       ws.status), ws)
    return CC


def forward_dynamics_batch(model, Q, QD, TAU, W=None, wrench_frame='base', *,
                           gravity=True, velocity_products=True, ws=None,
                           out=None):
    """
    :func:`forward_dynamics` (articulated-body) for each row; (m, n).

    Raises :class:`NotPositiveDefiniteError` for the first row where D is
    singular, naming the row and the joint.  A model with mimic joints
    takes the Cholesky path of
    :func:`~newton_euler_ros.core.dynamics.forward_dynamics`, row by row.
    """
    ws, Q, QD = _states(model, ws, Q, QD)
    m = Q.shape[0]
    QD = np.zeros_like(Q) if QD is None else QD
    TAU = matrix('TAU', TAU, ws.n, m)
    W, mode = _wrenches(W, wrench_frame, m)
    QDD = out_array(out, Q.shape)
    row = K.run_forward_dynamics_batch(
        model.packed, Q, QD, TAU, W, K.flags(gravity, velocity_products, mode),
        ws.ws, ws.aw, QDD, ws.status)
    if row >= 0 and ws.status[0] == K.MIMIC:    # coupled joints: Cholesky
        _solve_rows(model, ws, Q, QD, TAU, W,
                    K.flags(gravity, velocity_products, mode), QDD)
        return QDD
    _check(row, ws, model, Q)
    return QDD


def _solve_rows(model, ws, Q, QD, TAU, W, flags, QDD):
    """Solve D qdd = tau - bias per row: D by CRBA, bias by Newton-Euler."""
    n = ws.n
    D = np.empty((n, n))
    bias = np.empty(n)
    for k in range(Q.shape[0]):
        code = K.run_inverse_dynamics(model.packed, Q[k], QD[k], ws.zeros,
                                      W[k], flags, ws.ws, bias)
        if code < 0:
            code = K.run_mass_matrix_crba(model.packed, Q[k], ws.ws, D)
        if code >= 0:
            raise status_error(code, row=k)
        rhs = TAU[k] - bias
        bad = K.cholesky_solve(D, rhs, ws.chol, QDD[k])
        if bad >= 0:
            raise status_error(K.SINGULAR + bad, model=model, q=Q[k], ws=ws,
                               row=k)
