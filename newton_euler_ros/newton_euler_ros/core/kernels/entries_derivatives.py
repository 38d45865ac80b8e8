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
The entry points of the derivatives: GENERATED, do not edit.

Written by ``python -m newton_euler_ros.core.kernels.generate --write``
from the row steps and the ``ENTRIES`` table of ``entry.py`` (see
``generate.py`` for what each checks); ``test_entry_points.py`` fails
when this file differs from what the generator writes.
"""
from ._jit import BATCH, ENTRY, njit
from .entry import (_coordinates, _split,
                    forward_dynamics_derivatives_links_row,
                    forward_dynamics_derivatives_row,
                    inverse_dynamics_derivatives_links_row,
                    inverse_dynamics_derivatives_row)
from .layout import (CW_WIDTH, DW_WIDTH, NONFINITE, SIZE, W_WIDTH)
from .status import (first_nonfinite, first_nonfinite_entry)


@njit(**ENTRY)
def run_inverse_dynamics_derivatives(P, q, qd, qdd, wrench, damping, flags, ws,
                                     cw, dw, dtau):
    """dtau/dq, dtau/dqd into dtau[0], dtau[1] (``rnea_derivatives``)."""
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
    if damping.shape[0] != n:
        return SIZE + 5
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if cw.shape[0] < nb + 1:
        return SIZE + 5
    if cw.shape[1] != CW_WIDTH:
        return SIZE + 5
    if dw.shape[0] < nb + 1:
        return SIZE + 5
    if dw.shape[1] != DW_WIDTH:
        return SIZE + 5
    if dtau.shape[0] != 2:
        return SIZE + 4
    if dtau.shape[1] != n:
        return SIZE + 4
    if dtau.shape[2] != n:
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
    return inverse_dynamics_derivatives_row(links, frames, q, qd, qdd, wrench,
                                            damping, flags, ws, cw, dw, dtau)


@njit(**BATCH)
def run_inverse_dynamics_derivatives_batch(P, Q, QD, QDD, WRENCH, damping,
                                           flags, ws, cw, dw, DTAU, status):
    """inverse_dynamics_derivatives_row for each row k (see generate.py)."""
    links, frames = _split(P)
    for k in range(Q.shape[0]):
        code = inverse_dynamics_derivatives_row(links, frames, Q[k], QD[k],
                                                QDD[k], WRENCH[k], damping,
                                                flags, ws, cw, dw, DTAU[k])
        if code >= 0:
            status[0] = code
            return k
    return -1


@njit(**ENTRY)
def run_inverse_dynamics_derivatives_links(P, q, qd, qdd, wrench, fext, wext,
                                           damping, flags, ws, cw, dw, dtau):
    """Compute them with wrenches at links (``fext`` fixed, ``wext`` not)."""
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
    if wext.shape[0] != nb:
        return SIZE + 4
    if wext.shape[1] != 15:
        return SIZE + 4
    if damping.shape[0] != n:
        return SIZE + 5
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if cw.shape[0] < nb + 1:
        return SIZE + 5
    if cw.shape[1] != CW_WIDTH:
        return SIZE + 5
    if dw.shape[0] < nb + 1:
        return SIZE + 5
    if dw.shape[1] != DW_WIDTH:
        return SIZE + 5
    if dtau.shape[0] != 2:
        return SIZE + 4
    if dtau.shape[1] != n:
        return SIZE + 4
    if dtau.shape[2] != n:
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
    i = first_nonfinite_entry(wext)
    if i >= 0:
        return NONFINITE * 4 + i
    return inverse_dynamics_derivatives_links_row(links, frames, q, qd, qdd,
                                                  wrench, fext, wext, damping,
                                                  flags, ws, cw, dw, dtau)


@njit(**ENTRY)
def run_forward_dynamics_derivatives(P, q, qd, tau, wrench, armature, damping,
                                     flags, ws, cw, dw, chol, scratch, dqdd):
    """dqdd/dq, dqdd/dqd, dqdd/dtau into dqdd[0..2] (``aba_derivatives``)."""
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
    if armature.shape[0] != n:
        return SIZE + 5
    if damping.shape[0] != n:
        return SIZE + 5
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if cw.shape[0] < nb + 1:
        return SIZE + 5
    if cw.shape[1] != CW_WIDTH:
        return SIZE + 5
    if dw.shape[0] < nb + 1:
        return SIZE + 5
    if dw.shape[1] != DW_WIDTH:
        return SIZE + 5
    if chol.shape[0] != n:
        return SIZE + 5
    if chol.shape[1] != n:
        return SIZE + 5
    if scratch.shape[0] != 3:
        return SIZE + 5
    if scratch.shape[1] < n:
        return SIZE + 5
    if dqdd.shape[0] != 3:
        return SIZE + 4
    if dqdd.shape[1] != n:
        return SIZE + 4
    if dqdd.shape[2] != n:
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
    return forward_dynamics_derivatives_row(links, frames, q, qd, tau, wrench,
                                            armature, damping, flags, ws, cw,
                                            dw, chol, scratch, dqdd)


@njit(**BATCH)
def run_forward_dynamics_derivatives_batch(P, Q, QD, TAU, WRENCH, armature,
                                           damping, flags, ws, cw, dw, chol,
                                           scratch, DQDD, status):
    """forward_dynamics_derivatives_row for each row k (see generate.py)."""
    links, frames = _split(P)
    for k in range(Q.shape[0]):
        code = forward_dynamics_derivatives_row(links, frames, Q[k], QD[k],
                                                TAU[k], WRENCH[k], armature,
                                                damping, flags, ws, cw, dw,
                                                chol, scratch, DQDD[k])
        if code >= 0:
            status[0] = code
            return k
    return -1


@njit(**ENTRY)
def run_forward_dynamics_derivatives_links(P, q, qd, tau, wrench, fall, fext,
                                           wext, armature, damping, flags, ws,
                                           cw, dw, chol, scratch, dqdd):
    """Compute them with wrenches at links."""
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
    if fall.shape[0] != nb:
        return SIZE + 4
    if fall.shape[1] != 6:
        return SIZE + 4
    if fext.shape[0] != nb:
        return SIZE + 4
    if fext.shape[1] != 6:
        return SIZE + 4
    if wext.shape[0] != nb:
        return SIZE + 4
    if wext.shape[1] != 15:
        return SIZE + 4
    if armature.shape[0] != n:
        return SIZE + 5
    if damping.shape[0] != n:
        return SIZE + 5
    if ws.shape[0] < nb:
        return SIZE + 5
    if ws.shape[1] != W_WIDTH:
        return SIZE + 5
    if cw.shape[0] < nb + 1:
        return SIZE + 5
    if cw.shape[1] != CW_WIDTH:
        return SIZE + 5
    if dw.shape[0] < nb + 1:
        return SIZE + 5
    if dw.shape[1] != DW_WIDTH:
        return SIZE + 5
    if chol.shape[0] != n:
        return SIZE + 5
    if chol.shape[1] != n:
        return SIZE + 5
    if scratch.shape[0] != 3:
        return SIZE + 5
    if scratch.shape[1] < n:
        return SIZE + 5
    if dqdd.shape[0] != 3:
        return SIZE + 4
    if dqdd.shape[1] != n:
        return SIZE + 4
    if dqdd.shape[2] != n:
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
    i = first_nonfinite_entry(fall)
    if i >= 0:
        return NONFINITE * 4 + i
    i = first_nonfinite_entry(fext)
    if i >= 0:
        return NONFINITE * 4 + i
    i = first_nonfinite_entry(wext)
    if i >= 0:
        return NONFINITE * 4 + i
    return forward_dynamics_derivatives_links_row(links, frames, q, qd, tau,
                                                  wrench, fall, fext, wext,
                                                  armature, damping, flags, ws,
                                                  cw, dw, chol, scratch, dqdd)
