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
Entry points: what Python calls, one per term, each with its batch loop.

Each takes the model packed into one array (``layout.pack``), the switches
as one integer (``layout.flags``), checks every size against the model
(numba does not check bounds) and every input for finiteness, and
returns a status code (``layout``: -1 success, ``NONFINITE * a + i``,
``SIZE + a``, ``OVERFLOW``, ``SINGULAR + j``).  Few arguments, because
numba's dispatcher costs about 40 ns per argument.  They are compiled
with ``_jit.ENTRY`` (no reference-counting runtime: see there).

Batches: one compiled loop over the rows of (m, n) arrays of states,
beside the single-state entry point of the same term.  The caller checks
shapes and finiteness (numpy, once per batch); each returns -1, or the
first row that failed (its code in ``status[0]``).

Adding a term: its kernel in the file of its pass, ``run_<term>`` and
``run_<term>_batch`` here, and one line in ``dynamics._ENTRIES``.
"""
from ._jit import ENTRY, njit
from .aba import articulated_body
from .coriolis import coriolis_matrix_composite
from .crba import mass_matrix_crba
from .kinematics import forward_kinematics, jacobian, joint_trig
from .layout import (A_WIDTH, CW_WIDTH, F_ROWS, GRAVITY, OVERFLOW, SINGULAR,
                     SIZE, VELOCITY, W_WIDTH, WRENCH_SHIFT)
from .newton_euler import (coriolis_matrix_columns, gravity,
                           mass_matrix_columns, momentum_terms, recursion)
from .regressor import drive_columns, regressor_columns
from .status import check_finite, first_bad_row, first_nonfinite, matrix_status


@njit(cache=True)
def _split(P):
    n = P.shape[0] - F_ROWS
    return P[:n], P[n:]


@njit(cache=True)
def _sizes(n, q, qd, qdd, wrench, ws, ws_width):
    """SIZE + a for the first argument of the wrong size, else -1."""
    if q.shape[0] != n:
        return SIZE
    if qd.shape[0] != n:
        return SIZE + 1
    if qdd.shape[0] != n:
        return SIZE + 2
    if wrench.shape[0] != 6:
        return SIZE + 3
    if ws.shape[0] < n or ws.shape[1] != ws_width:
        return SIZE + 5
    return -1


@njit(cache=True, inline='always')
def _split_checked(P, q, ws):
    """
    Return (links, frames, status) for an entry point taking q only.

    status is -1, or the code of q's size, the workspace's size or q's
    first non-finite entry.  (frames[0, :6] stands for a wrench: a
    6-vector, always finite.)
    """
    links, frames = _split(P)
    bad = _sizes(links.shape[0], q, q, q, frames[0, :6], ws, W_WIDTH)
    if bad < 0:
        bad = first_nonfinite(q)
    return links, frames, bad


@njit(cache=True)
def _square(M, n):
    return M.shape[0] == n and M.shape[1] == n


@njit(**ENTRY)
def run_inverse_dynamics(P, q, qd, qdd, wrench, flags, ws, tau):
    """tau(q, qd, qdd, F_e); ``flags`` selects gravity, velocity, wrench."""
    links, frames = _split(P)
    n = links.shape[0]
    bad = _sizes(n, q, qd, qdd, wrench, ws, W_WIDTH)
    if bad >= 0:
        return bad
    if tau.shape[0] != n:
        return SIZE + 4
    bad = check_finite(q, qd, qdd, wrench)
    if bad >= 0:
        return bad
    joint_trig(links, frames, q, ws)
    recursion(links, frames, qd, qd, qdd, wrench, (flags & GRAVITY) != 0,
              (flags & VELOCITY) != 0, flags >> WRENCH_SHIFT, ws, tau)
    if first_nonfinite(tau) >= 0:
        return OVERFLOW
    return -1


@njit(**ENTRY)
def run_inverse_dynamics_batch(P, Q, QD, QDD, W, flags, ws, TAU, status):
    """Compute tau for each row (the inputs are finite: checked in numpy)."""
    links, frames = _split(P)
    gravity_on = (flags & GRAVITY) != 0
    velocity_on = (flags & VELOCITY) != 0
    mode = flags >> WRENCH_SHIFT
    for k in range(Q.shape[0]):
        joint_trig(links, frames, Q[k], ws)
        recursion(links, frames, QD[k], QD[k], QDD[k], W[k], gravity_on,
                  velocity_on, mode, ws, TAU[k])
    return first_bad_row(TAU, status)


@njit(**ENTRY)
def run_gravity_torques(P, q, ws, tau):
    """g(q): ``run_inverse_dynamics`` at rest with gravity, fewer arguments."""
    links, frames, bad = _split_checked(P, q, ws)
    if bad >= 0:
        return bad
    n = links.shape[0]
    if tau.shape[0] != n:
        return SIZE + 4
    gravity(links, frames, q, ws, tau)
    if first_nonfinite(tau) >= 0:
        return OVERFLOW
    return -1


@njit(**ENTRY)
def run_gravity_torques_batch(P, Q, ws, G, status):
    """Compute g for each row (see ``run_gravity_torques``)."""
    links, frames = _split(P)
    for k in range(Q.shape[0]):
        gravity(links, frames, Q[k], ws, G[k])
    return first_bad_row(G, status)


@njit(**ENTRY)
def run_mass_matrix_crba(P, q, ws, D):
    """D(q) by CRBA: ``run_mass_matrix`` with fewer arguments."""
    links, frames, bad = _split_checked(P, q, ws)
    if bad >= 0:
        return bad
    n = links.shape[0]
    if not _square(D, n):
        return SIZE + 4
    return mass_matrix_crba(links, frames, q, ws, D)


@njit(**ENTRY)
def run_mass_matrix(P, q, crba, ws, scratch, D):
    """D(q) by CRBA (``crba``) or by n recursions."""
    links, frames, bad = _split_checked(P, q, ws)
    if bad >= 0:
        return bad
    n = links.shape[0]
    if not _square(D, n):
        return SIZE + 4
    if scratch.shape[0] != 3 or scratch.shape[1] < n:
        return SIZE + 5
    if crba:
        return mass_matrix_crba(links, frames, q, ws, D)
    return mass_matrix_columns(links, frames, q, ws, scratch, D)


@njit(**ENTRY)
def run_mass_matrix_batch(P, Q, ws, DD, status):
    """D for each row, by CRBA."""
    links, frames = _split(P)
    for k in range(Q.shape[0]):
        code = mass_matrix_crba(links, frames, Q[k], ws, DD[k])
        if code >= 0:
            status[0] = code
            return k
    return -1


@njit(**ENTRY)
def run_coriolis_matrix(P, q, qd, composite, ws, cw, scratch, C):
    """C(q, qd) by composite bodies (``composite``) or n recursions."""
    links, frames = _split(P)
    n = links.shape[0]
    bad = _sizes(n, q, qd, q, frames[0, :6], ws, W_WIDTH)
    if bad >= 0:
        return bad
    if not _square(C, n):
        return SIZE + 4
    if (cw.shape[0] < n + 1 or cw.shape[1] != CW_WIDTH
            or scratch.shape[0] != 3 or scratch.shape[1] < n):
        return SIZE + 5
    bad = check_finite(q, qd, q, frames[0, :6])
    if bad >= 0:
        return bad
    if composite:
        return coriolis_matrix_composite(links, frames, q, qd, ws, cw, C)
    return coriolis_matrix_columns(links, frames, q, qd, ws, scratch, C)


@njit(**ENTRY)
def run_coriolis_matrix_batch(P, Q, QD, ws, cw, CC, status):
    """C for each row, by composite bodies (O(n^2) each)."""
    links, frames = _split(P)
    for k in range(Q.shape[0]):
        code = coriolis_matrix_composite(links, frames, Q[k], QD[k], ws, cw,
                                         CC[k])
        if code >= 0:
            status[0] = code
            return k
    return -1


@njit(**ENTRY)
def run_momentum_terms(P, q, qd, ws, cw, out):
    """D qd, C^T qd and g into the rows of ``out`` (3, n), one recursion."""
    links, frames = _split(P)
    n = links.shape[0]
    bad = _sizes(n, q, qd, q, frames[0, :6], ws, W_WIDTH)
    if bad >= 0:
        return bad
    if out.shape[0] != 3 or out.shape[1] != n:
        return SIZE + 4
    if cw.shape[0] < n + 1 or cw.shape[1] != CW_WIDTH:
        return SIZE + 5
    bad = check_finite(q, qd, q, frames[0, :6])
    if bad >= 0:
        return bad
    return momentum_terms(links, frames, q, qd, ws, cw, out)


@njit(**ENTRY)
def run_forward_dynamics(P, q, qd, tau, wrench, flags, ws, aw, qdd):
    """Compute qdd by the articulated-body algorithm (``articulated_body``)."""
    links, frames = _split(P)
    n = links.shape[0]
    bad = _sizes(n, q, qd, tau, wrench, ws, W_WIDTH)
    if bad >= 0:
        return bad
    if qdd.shape[0] != n:
        return SIZE + 4
    if aw.shape[0] < n + 1 or aw.shape[1] != A_WIDTH:
        return SIZE + 5
    bad = check_finite(q, qd, tau, wrench)
    if bad >= 0:
        return bad
    bad = articulated_body(links, frames, q, qd, tau, wrench,
                           (flags & GRAVITY) != 0, (flags & VELOCITY) != 0,
                           flags >> WRENCH_SHIFT, ws, aw, qdd)
    if 0 <= bad < n:
        return SINGULAR + bad
    return bad


@njit(**ENTRY)
def run_forward_dynamics_batch(P, Q, QD, TAU, W, flags, ws, aw, QDD,
                               status):
    """Compute qdd for each row by the articulated-body algorithm."""
    links, frames = _split(P)
    n = links.shape[0]
    for k in range(Q.shape[0]):
        code = articulated_body(links, frames, Q[k], QD[k], TAU[k], W[k],
                                (flags & GRAVITY) != 0,
                                (flags & VELOCITY) != 0,
                                flags >> WRENCH_SHIFT, ws, aw, QDD[k])
        if code >= 0:
            status[0] = SINGULAR + code if code < n else code
            return k
    return -1


@njit(**ENTRY)
def run_jacobian(P, q, in_ee_axes, ws, Ts, J):
    """J(q), 6 x n (see ``jacobian``)."""
    links, frames, bad = _split_checked(P, q, ws)
    if bad >= 0:
        return bad
    n = links.shape[0]
    if J.shape[0] != 6 or J.shape[1] != n:
        return SIZE + 4
    if Ts.shape[0] != n + 2 or Ts.shape[1] != 12:
        return SIZE + 5
    jacobian(links, frames, q, in_ee_axes, ws, Ts, J)
    return matrix_status(J)


@njit(**ENTRY)
def run_link_poses(P, q, ws, Ts):
    """Poses of frame 0, the link frames and the end effector (``Ts``)."""
    links, frames, bad = _split_checked(P, q, ws)
    if bad >= 0:
        return bad
    n = links.shape[0]
    if Ts.shape[0] != n + 2 or Ts.shape[1] != 12:
        return SIZE + 5
    forward_kinematics(links, frames, q, ws, Ts)
    return matrix_status(Ts)


@njit(**ENTRY)
def run_regressor_batch(P, Q, QD, QDD, drives, eps, ws, line, acc, Y):
    """
    Fill the torque regressor Y at each row (``regressor_columns``).

    The caller checks the states (numpy, once per batch); this checks the
    scratch and ``Y`` sizes only: -1, or ``SIZE + 5`` (scratch) or
    ``SIZE + 4`` (Y).  With ``drives`` the 4n drive columns follow.
    """
    links, frames = _split(P)
    n = links.shape[0]
    m = Q.shape[0]
    if (QD.shape[0] != m or QDD.shape[0] != m or Q.shape[1] != n
            or QD.shape[1] != n or QDD.shape[1] != n):
        return SIZE
    if (ws.shape[0] < n or ws.shape[1] != W_WIDTH or line.shape[0] < n
            or line.shape[1] != 6 or acc.shape[0] < 10 * n
            or acc.shape[1] != 6):
        return SIZE + 5
    if (Y.shape[0] != m or Y.shape[1] != n
            or Y.shape[2] != (14 * n if drives else 10 * n)):
        return SIZE + 4
    for i in range(m):
        regressor_columns(links, frames, Q[i], QD[i], QDD[i], ws, line, acc,
                          Y[i])
        if drives:
            drive_columns(frames, QD[i], QDD[i], eps, Y[i])
    return -1
