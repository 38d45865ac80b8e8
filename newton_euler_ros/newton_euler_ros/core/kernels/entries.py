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
The entry points of the dynamics, the matrices and the kinematics: GENERATED, do not edit.

Written by ``python -m newton_euler_ros.core.kernels.generate --write``
from the row steps and the ``ENTRIES`` table of ``entry.py`` (see
``generate.py`` for what each checks); ``test_entry_points.py`` fails
when this file differs from what the generator writes.
"""
from ._jit import BATCH, ENTRY, njit
from .entry import (_coordinates, _split, coriolis_matrix_composite_row,
                    coriolis_matrix_row, forward_dynamics_links_row,
                    forward_dynamics_row, gravity_torques_row,
                    inverse_dynamics_links_row, inverse_dynamics_row,
                    jacobian_row, link_poses_row, mass_matrix_crba_row,
                    mass_matrix_row, momentum_terms_row, regressor_row)
from .layout import (A_WIDTH, CW_WIDTH, NONFINITE, SIZE, W_WIDTH)
from .status import (first_nonfinite, first_nonfinite_entry)


@njit(**ENTRY)
def run_inverse_dynamics(P, q, qd, qdd, wrench, flags, ws, tau):
    """tau(q, qd, qdd, F_e); ``flags`` selects gravity, velocity, wrench."""
    links, frames = _split(P)
    nb = links.shape[0]
    n = _coordinates(frames)
    if q.shape[0] != n:
        return SIZE + 0
    if qd.shape[0] != n:
        return SIZE + 1
    if qdd.shape[0] != n:
        return SIZE + 2
    if wrench.shape[0] != 6:
        return SIZE + 3
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if tau.shape[0] != n:
        return SIZE + 4
    i = first_nonfinite(q)
    if i >= 0:
        return NONFINITE * 0 + i
    i = first_nonfinite(qd)
    if i >= 0:
        return NONFINITE * 1 + i
    i = first_nonfinite(qdd)
    if i >= 0:
        return NONFINITE * 2 + i
    i = first_nonfinite(wrench)
    if i >= 0:
        return NONFINITE * 3 + i
    return inverse_dynamics_row(links, frames, q, qd, qdd, wrench, flags, ws,
                                tau)


@njit(**BATCH)
def run_inverse_dynamics_batch(P, Q, QD, QDD, WRENCH, flags, ws, TAU, status):
    """inverse_dynamics_row for each row k (see generate.py)."""
    links, frames = _split(P)
    for k in range(Q.shape[0]):
        code = inverse_dynamics_row(links, frames, Q[k], QD[k], QDD[k],
                                    WRENCH[k], flags, ws, TAU[k])
        if code >= 0:
            status[0] = code
            return k
    return -1


@njit(**ENTRY)
def run_inverse_dynamics_links(P, q, qd, qdd, wrench, fext, flags, ws, tau):
    """tau(q, qd, qdd, F_e) with wrenches at links (``fext``, link axes)."""
    links, frames = _split(P)
    nb = links.shape[0]
    n = _coordinates(frames)
    if q.shape[0] != n:
        return SIZE + 0
    if qd.shape[0] != n:
        return SIZE + 1
    if qdd.shape[0] != n:
        return SIZE + 2
    if wrench.shape[0] != 6:
        return SIZE + 3
    if fext.shape[0] != nb:
        return SIZE + 4
    if fext.shape[1] != 6:
        return SIZE + 4
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if tau.shape[0] != n:
        return SIZE + 4
    i = first_nonfinite(q)
    if i >= 0:
        return NONFINITE * 0 + i
    i = first_nonfinite(qd)
    if i >= 0:
        return NONFINITE * 1 + i
    i = first_nonfinite(qdd)
    if i >= 0:
        return NONFINITE * 2 + i
    i = first_nonfinite(wrench)
    if i >= 0:
        return NONFINITE * 3 + i
    i = first_nonfinite_entry(fext)
    if i >= 0:
        return NONFINITE * 4 + i
    return inverse_dynamics_links_row(links, frames, q, qd, qdd, wrench, fext,
                                      flags, ws, tau)


@njit(**ENTRY)
def run_gravity_torques(P, q, ws, tau):
    """g(q): the recursion at rest with gravity, fewer arguments."""
    links, frames = _split(P)
    nb = links.shape[0]
    n = _coordinates(frames)
    if q.shape[0] != n:
        return SIZE + 0
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if tau.shape[0] != n:
        return SIZE + 4
    i = first_nonfinite(q)
    if i >= 0:
        return NONFINITE * 0 + i
    return gravity_torques_row(links, frames, q, ws, tau)


@njit(**BATCH)
def run_gravity_torques_batch(P, Q, ws, TAU, status):
    """gravity_torques_row for each row k (see generate.py)."""
    links, frames = _split(P)
    for k in range(Q.shape[0]):
        code = gravity_torques_row(links, frames, Q[k], ws, TAU[k])
        if code >= 0:
            status[0] = code
            return k
    return -1


@njit(**ENTRY)
def run_mass_matrix_crba(P, q, ws, D):
    """D(q) by CRBA."""
    links, frames = _split(P)
    nb = links.shape[0]
    n = _coordinates(frames)
    if q.shape[0] != n:
        return SIZE + 0
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if D.shape[0] != n:
        return SIZE + 4
    if D.shape[1] != n:
        return SIZE + 4
    i = first_nonfinite(q)
    if i >= 0:
        return NONFINITE * 0 + i
    return mass_matrix_crba_row(links, frames, q, ws, D)


@njit(**BATCH)
def run_mass_matrix_batch(P, Q, ws, D, status):
    """mass_matrix_crba_row for each row k (see generate.py)."""
    links, frames = _split(P)
    for k in range(Q.shape[0]):
        code = mass_matrix_crba_row(links, frames, Q[k], ws, D[k])
        if code >= 0:
            status[0] = code
            return k
    return -1


@njit(**ENTRY)
def run_mass_matrix(P, q, crba, ws, scratch, D):
    """D(q) by CRBA (``crba``) or by n recursions."""
    links, frames = _split(P)
    nb = links.shape[0]
    n = _coordinates(frames)
    if q.shape[0] != n:
        return SIZE + 0
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if scratch.shape[0] != 3:
        return SIZE + 5
    if scratch.shape[1] < n:
        return SIZE + 5
    if D.shape[0] != n:
        return SIZE + 4
    if D.shape[1] != n:
        return SIZE + 4
    i = first_nonfinite(q)
    if i >= 0:
        return NONFINITE * 0 + i
    return mass_matrix_row(links, frames, q, crba, ws, scratch, D)


@njit(**ENTRY)
def run_coriolis_matrix(P, q, qd, composite, ws, cw, scratch, C):
    """C(q, qd) by composite bodies (``composite``) or n recursions."""
    links, frames = _split(P)
    nb = links.shape[0]
    n = _coordinates(frames)
    if q.shape[0] != n:
        return SIZE + 0
    if qd.shape[0] != n:
        return SIZE + 1
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if cw.shape[0] < nb + 1:
        return SIZE + 5
    if cw.shape[1] != CW_WIDTH:
        return SIZE + 5
    if scratch.shape[0] != 3:
        return SIZE + 5
    if scratch.shape[1] < n:
        return SIZE + 5
    if C.shape[0] != n:
        return SIZE + 4
    if C.shape[1] != n:
        return SIZE + 4
    i = first_nonfinite(q)
    if i >= 0:
        return NONFINITE * 0 + i
    i = first_nonfinite(qd)
    if i >= 0:
        return NONFINITE * 1 + i
    return coriolis_matrix_row(links, frames, q, qd, composite, ws, cw,
                               scratch, C)


@njit(**BATCH)
def run_coriolis_matrix_batch(P, Q, QD, ws, cw, C, status):
    """coriolis_matrix_composite_row for each row k (see generate.py)."""
    links, frames = _split(P)
    for k in range(Q.shape[0]):
        code = coriolis_matrix_composite_row(links, frames, Q[k], QD[k], ws,
                                             cw, C[k])
        if code >= 0:
            status[0] = code
            return k
    return -1


@njit(**ENTRY)
def run_momentum_terms(P, q, qd, ws, cw, terms):
    """D qd, C^T qd and g into the rows of ``terms`` (3, n), one recursion."""
    links, frames = _split(P)
    nb = links.shape[0]
    n = _coordinates(frames)
    if q.shape[0] != n:
        return SIZE + 0
    if qd.shape[0] != n:
        return SIZE + 1
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if cw.shape[0] < nb + 1:
        return SIZE + 5
    if cw.shape[1] != CW_WIDTH:
        return SIZE + 5
    if terms.shape[0] != 3:
        return SIZE + 4
    if terms.shape[1] != n:
        return SIZE + 4
    i = first_nonfinite(q)
    if i >= 0:
        return NONFINITE * 0 + i
    i = first_nonfinite(qd)
    if i >= 0:
        return NONFINITE * 1 + i
    return momentum_terms_row(links, frames, q, qd, ws, cw, terms)


@njit(**ENTRY)
def run_forward_dynamics(P, q, qd, tau, wrench, flags, ws, aw, qdd):
    """Compute qdd by the articulated-body algorithm (``articulated_body``)."""
    links, frames = _split(P)
    nb = links.shape[0]
    n = _coordinates(frames)
    if q.shape[0] != n:
        return SIZE + 0
    if qd.shape[0] != n:
        return SIZE + 1
    if tau.shape[0] != n:
        return SIZE + 2
    if wrench.shape[0] != 6:
        return SIZE + 3
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if aw.shape[0] < nb + 1:
        return SIZE + 5
    if aw.shape[1] != A_WIDTH:
        return SIZE + 5
    if qdd.shape[0] != n:
        return SIZE + 4
    i = first_nonfinite(q)
    if i >= 0:
        return NONFINITE * 0 + i
    i = first_nonfinite(qd)
    if i >= 0:
        return NONFINITE * 1 + i
    i = first_nonfinite(tau)
    if i >= 0:
        return NONFINITE * 2 + i
    i = first_nonfinite(wrench)
    if i >= 0:
        return NONFINITE * 3 + i
    return forward_dynamics_row(links, frames, q, qd, tau, wrench, flags, ws,
                                aw, qdd)


@njit(**BATCH)
def run_forward_dynamics_batch(P, Q, QD, TAU, WRENCH, flags, ws, aw, QDD,
                               status):
    """forward_dynamics_row for each row k (see generate.py)."""
    links, frames = _split(P)
    for k in range(Q.shape[0]):
        code = forward_dynamics_row(links, frames, Q[k], QD[k], TAU[k],
                                    WRENCH[k], flags, ws, aw, QDD[k])
        if code >= 0:
            status[0] = code
            return k
    return -1


@njit(**ENTRY)
def run_forward_dynamics_links(P, q, qd, tau, wrench, fext, flags, ws, aw,
                               qdd):
    """Compute qdd by the articulated-body algorithm, wrenches at links."""
    links, frames = _split(P)
    nb = links.shape[0]
    n = _coordinates(frames)
    if q.shape[0] != n:
        return SIZE + 0
    if qd.shape[0] != n:
        return SIZE + 1
    if tau.shape[0] != n:
        return SIZE + 2
    if wrench.shape[0] != 6:
        return SIZE + 3
    if fext.shape[0] != nb:
        return SIZE + 4
    if fext.shape[1] != 6:
        return SIZE + 4
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if aw.shape[0] < nb + 1:
        return SIZE + 5
    if aw.shape[1] != A_WIDTH:
        return SIZE + 5
    if qdd.shape[0] != n:
        return SIZE + 4
    i = first_nonfinite(q)
    if i >= 0:
        return NONFINITE * 0 + i
    i = first_nonfinite(qd)
    if i >= 0:
        return NONFINITE * 1 + i
    i = first_nonfinite(tau)
    if i >= 0:
        return NONFINITE * 2 + i
    i = first_nonfinite(wrench)
    if i >= 0:
        return NONFINITE * 3 + i
    i = first_nonfinite_entry(fext)
    if i >= 0:
        return NONFINITE * 4 + i
    return forward_dynamics_links_row(links, frames, q, qd, tau, wrench, fext,
                                      flags, ws, aw, qdd)


@njit(**ENTRY)
def run_jacobian(P, q, body, target, local, ws, Ts, J):
    """J(q), 6 x n, of a frame on a body (see ``jacobian``)."""
    links, frames = _split(P)
    nb = links.shape[0]
    n = _coordinates(frames)
    if q.shape[0] != n:
        return SIZE + 0
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if Ts.shape[0] != nb + 2:
        return SIZE + 5
    if Ts.shape[1] != 12:
        return SIZE + 5
    if J.shape[0] != 6:
        return SIZE + 4
    if J.shape[1] != n:
        return SIZE + 4
    if body < -1 or body >= nb:
        return SIZE + 5
    i = first_nonfinite(q)
    if i >= 0:
        return NONFINITE * 0 + i
    return jacobian_row(links, frames, q, body, target, local, ws, Ts, J)


@njit(**ENTRY)
def run_link_poses(P, q, ws, Ts):
    """Poses of frame 0, the link frames and the end effector (``Ts``)."""
    links, frames = _split(P)
    nb = links.shape[0]
    n = _coordinates(frames)
    if q.shape[0] != n:
        return SIZE + 0
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if Ts.shape[0] != nb + 2:
        return SIZE + 5
    if Ts.shape[1] != 12:
        return SIZE + 5
    i = first_nonfinite(q)
    if i >= 0:
        return NONFINITE * 0 + i
    return link_poses_row(links, frames, q, ws, Ts)


@njit(**BATCH)
def run_regressor_batch(P, Q, QD, QDD, drives, eps, ws, line, acc, Y, status):
    """regressor_row for each row k (see generate.py)."""
    links, frames = _split(P)
    for k in range(Q.shape[0]):
        code = regressor_row(links, frames, Q[k], QD[k], QDD[k], drives, eps,
                             ws, line, acc, Y[k])
        if code >= 0:
            status[0] = code
            return k
    return -1
