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
Row steps: each term written once, on one state; the entry points' table.

A term is its *row step*, ``<term>_row(links, frames, <arguments>)``: the
kernel call on one state, returning a status code (``layout``: -1
success, ``OVERFLOW``, ``SINGULAR + j``, or the kernel's own).  One line
of :data:`ENTRIES` at the end of this file names an entry point and its
row step; ``generate.py`` writes from them ``entries.py``, a checked-in
file: the single-state entry point ``run_<term>`` (every size checked
against the model, since numba does not check bounds, and every input
for finiteness: ``SIZE + a``, ``NONFINITE * a + i``) and, for a name
ending in ``_batch``, the batch loop (the row step on each row of (m, n)
arrays; the caller checks shapes and finiteness in numpy, once per
batch; it returns -1, or the first row that failed with its code in
``status[0]``).  The entry points take the model packed into one array
(``layout.pack``) and the switches as one integer (``layout.flags``):
few arguments, because numba's dispatcher costs about 40 ns per
argument.  They are compiled with ``_jit.ENTRY`` (no reference-counting
runtime: see there).

Adding a term: its kernel in the file of its pass; its row step here;
its lines in :data:`ENTRIES`; then ``python -m
newton_euler_ros.core.kernels.generate --write`` (``test_entry_points``
fails until ``entries.py`` is regenerated).  The row step's argument
names say what each is (``generate.SHAPES``: a new kind of array gets a
line there).  Then its strict entry and public function in
``core/dynamics.py``, its batch function in ``core/batch.py``.
"""
from ._jit import njit
from .aba import articulated_body
from .coriolis import coriolis_matrix_composite
from .crba import mass_matrix_crba
from .derivatives import aba_derivatives, rnea_derivatives
from .kinematics import forward_kinematics, jacobian, joint_trig
from .layout import (F_ROWS, F_TREE, GRAVITY, LINK_WRENCHES, OVERFLOW,
                     SINGULAR, T_NQ, VELOCITY, WRENCH_BITS, WRENCH_SHIFT)
from .momentum import momentum_terms
from .newton_euler import (coriolis_matrix_columns, gravity,
                           mass_matrix_columns, recursion)
from .regressor import drive_columns, regressor_columns
from .status import first_nonfinite, matrix_status


@njit(cache=True)
def _split(P):
    nb = P.shape[0] - F_ROWS
    return P[:nb], P[nb:]


@njit(cache=True, inline='always')
def _coordinates(frames):
    """Return the number of coordinates n (the generated checks' ``n``)."""
    return int(frames[F_TREE, T_NQ])


# ---------------------------------------------------------------------------
# the row steps: each term on one state (sizes and finiteness checked)

@njit(cache=True, inline='always')
def inverse_dynamics_row(links, frames, q, qd, qdd, wrench, flags, ws, tau):
    """tau(q, qd, qdd, F_e); ``flags`` selects gravity, velocity, wrench."""
    joint_trig(links, frames, q, ws)
    recursion(links, frames, qd, qd, qdd, wrench, None,
              (flags & GRAVITY) != 0, (flags & VELOCITY) != 0,
              (flags >> WRENCH_SHIFT) & WRENCH_BITS, False, ws, tau)
    if first_nonfinite(tau) >= 0:
        return OVERFLOW
    return -1


@njit(cache=True, inline='always')
def inverse_dynamics_links_row(links, frames, q, qd, qdd, wrench, fext,
                               flags, ws, tau):
    """tau(q, qd, qdd, F_e) with wrenches at links (``fext``, link axes)."""
    joint_trig(links, frames, q, ws)
    recursion(links, frames, qd, qd, qdd, wrench, fext,
              (flags & GRAVITY) != 0, (flags & VELOCITY) != 0,
              (flags >> WRENCH_SHIFT) & WRENCH_BITS,
              (flags & LINK_WRENCHES) != 0, ws, tau)
    if first_nonfinite(tau) >= 0:
        return OVERFLOW
    return -1


@njit(cache=True, inline='always')
def gravity_torques_row(links, frames, q, ws, tau):
    """g(q): the recursion at rest with gravity, fewer arguments."""
    gravity(links, frames, q, ws, tau)
    if first_nonfinite(tau) >= 0:
        return OVERFLOW
    return -1


@njit(cache=True, inline='always')
def mass_matrix_crba_row(links, frames, q, ws, D):
    """D(q) by CRBA."""
    return mass_matrix_crba(links, frames, q, ws, D)


@njit(cache=True, inline='always')
def mass_matrix_row(links, frames, q, crba, ws, scratch, D):
    """D(q) by CRBA (``crba``) or by n recursions."""
    if crba:
        return mass_matrix_crba(links, frames, q, ws, D)
    return mass_matrix_columns(links, frames, q, ws, scratch, D)


@njit(cache=True, inline='always')
def coriolis_matrix_composite_row(links, frames, q, qd, ws, cw, C):
    """C(q, qd) by composite bodies, O(n^2)."""
    return coriolis_matrix_composite(links, frames, q, qd, ws, cw, C)


@njit(cache=True, inline='always')
def coriolis_matrix_row(links, frames, q, qd, composite, ws, cw, scratch, C):
    """C(q, qd) by composite bodies (``composite``) or n recursions."""
    if composite:
        return coriolis_matrix_composite(links, frames, q, qd, ws, cw, C)
    return coriolis_matrix_columns(links, frames, q, qd, ws, scratch, C)


@njit(cache=True, inline='always')
def momentum_terms_row(links, frames, q, qd, ws, cw, terms):
    """D qd, C^T qd and g into the rows of ``terms`` (3, n), one recursion."""
    return momentum_terms(links, frames, q, qd, ws, cw, terms)


# not inlined into its entry point (numba's inline='always'): the
# articulated-body algorithm is itself inlined into this one function,
# and the entry point inlining it all measured 13 % slower than calling it
@njit(cache=True)
def forward_dynamics_row(links, frames, q, qd, tau, wrench, flags, ws, aw,
                         qdd):
    """Compute qdd by the articulated-body algorithm (``articulated_body``)."""
    bad = articulated_body(links, frames, q, qd, tau, wrench, None,
                           (flags & GRAVITY) != 0, (flags & VELOCITY) != 0,
                           (flags >> WRENCH_SHIFT) & WRENCH_BITS, False, ws,
                           aw, qdd)
    if 0 <= bad < links.shape[0]:
        return SINGULAR + bad
    return bad


@njit(cache=True)
def forward_dynamics_links_row(links, frames, q, qd, tau, wrench, fext, flags,
                               ws, aw, qdd):
    """Compute qdd by the articulated-body algorithm, wrenches at links."""
    bad = articulated_body(links, frames, q, qd, tau, wrench, fext,
                           (flags & GRAVITY) != 0, (flags & VELOCITY) != 0,
                           (flags >> WRENCH_SHIFT) & WRENCH_BITS,
                           (flags & LINK_WRENCHES) != 0, ws, aw, qdd)
    if 0 <= bad < links.shape[0]:
        return SINGULAR + bad
    return bad


@njit(cache=True, inline='always')
def jacobian_row(links, frames, q, body, target, local, ws, Ts, J):
    """J(q), 6 x n, of a frame on a body (see ``jacobian``)."""
    jacobian(links, frames, q, body, target, local, ws, Ts, J)
    return matrix_status(J)


@njit(cache=True, inline='always')
def link_poses_row(links, frames, q, ws, Ts):
    """Poses of frame 0, the link frames and the end effector (``Ts``)."""
    forward_kinematics(links, frames, q, ws, Ts)
    return matrix_status(Ts)


@njit(cache=True, inline='always')
def regressor_row(links, frames, q, qd, qdd, drives, eps, ws, line, acc, Y):
    """Y(q, qd, qdd): n x 10nb, and with ``drives`` the 4n drive columns."""
    regressor_columns(links, frames, q, qd, qdd, ws, line, acc, Y)
    if drives:
        drive_columns(links, frames, qd, qdd, eps, Y)
    return -1


@njit(cache=True)
def inverse_dynamics_derivatives_row(links, frames, q, qd, qdd, wrench,
                                     damping, flags, ws, cw, dw, dtau):
    """dtau/dq, dtau/dqd into dtau[0], dtau[1] (``rnea_derivatives``)."""
    return rnea_derivatives(links, frames, q, qd, qdd, wrench, None, None,
                            (flags & GRAVITY) != 0,
                            (flags >> WRENCH_SHIFT) & WRENCH_BITS, False,
                            damping, ws, cw, dw, dtau[0], dtau[1])


@njit(cache=True)
def inverse_dynamics_derivatives_links_row(links, frames, q, qd, qdd, wrench,
                                           fext, wext, damping, flags, ws,
                                           cw, dw, dtau):
    """Compute them with wrenches at links (``fext`` fixed, ``wext`` not)."""
    return rnea_derivatives(links, frames, q, qd, qdd, wrench, fext, wext,
                            (flags & GRAVITY) != 0,
                            (flags >> WRENCH_SHIFT) & WRENCH_BITS,
                            (flags & LINK_WRENCHES) != 0, damping, ws, cw,
                            dw, dtau[0], dtau[1])


@njit(cache=True)
def forward_dynamics_derivatives_row(links, frames, q, qd, tau, wrench,
                                     armature, damping, flags, ws, cw, dw,
                                     chol, scratch, dqdd):
    """dqdd/dq, dqdd/dqd, dqdd/dtau into dqdd[0..2] (``aba_derivatives``)."""
    return aba_derivatives(links, frames, q, qd, tau, wrench, None, None,
                           None,
                           (flags & GRAVITY) != 0,
                           (flags >> WRENCH_SHIFT) & WRENCH_BITS, False,
                           armature, damping, ws, cw, dw, chol, scratch,
                           dqdd[0], dqdd[1], dqdd[2])


@njit(cache=True)
def forward_dynamics_derivatives_links_row(links, frames, q, qd, tau, wrench,
                                           fall, fext, wext, armature,
                                           damping, flags, ws, cw, dw, chol,
                                           scratch, dqdd):
    """
    Compute them with wrenches at links.

    ``fall`` all in link axes (the bias torques), ``fext`` those fixed to
    their link, ``wext`` those of fixed direction (the derivatives).
    """
    return aba_derivatives(links, frames, q, qd, tau, wrench, fall, fext,
                           wext,
                           (flags & GRAVITY) != 0,
                           (flags >> WRENCH_SHIFT) & WRENCH_BITS,
                           (flags & LINK_WRENCHES) != 0, armature, damping,
                           ws, cw, dw, chol, scratch, dqdd[0], dqdd[1],
                           dqdd[2])


# ---------------------------------------------------------------------------
# the entry points: name and row step.  generate.py writes each into
# entries.py (``python -m newton_euler_ros.core.kernels.generate
# --write``): a name ending in _batch gets the batch loop, any other the
# single-state entry point.

ENTRIES = (
    ('run_inverse_dynamics', inverse_dynamics_row),
    ('run_inverse_dynamics_batch', inverse_dynamics_row),
    ('run_inverse_dynamics_links', inverse_dynamics_links_row),
    ('run_gravity_torques', gravity_torques_row),
    ('run_gravity_torques_batch', gravity_torques_row),
    ('run_mass_matrix_crba', mass_matrix_crba_row),
    ('run_mass_matrix_batch', mass_matrix_crba_row),
    ('run_mass_matrix', mass_matrix_row),
    ('run_coriolis_matrix', coriolis_matrix_row),
    ('run_coriolis_matrix_batch', coriolis_matrix_composite_row),
    ('run_momentum_terms', momentum_terms_row),
    ('run_forward_dynamics', forward_dynamics_row),
    ('run_forward_dynamics_batch', forward_dynamics_row),
    ('run_forward_dynamics_links', forward_dynamics_links_row),
    ('run_jacobian', jacobian_row),
    ('run_link_poses', link_poses_row),
    ('run_regressor_batch', regressor_row),
    ('run_inverse_dynamics_derivatives', inverse_dynamics_derivatives_row),
    ('run_inverse_dynamics_derivatives_batch',
     inverse_dynamics_derivatives_row),
    ('run_inverse_dynamics_derivatives_links',
     inverse_dynamics_derivatives_links_row),
    ('run_forward_dynamics_derivatives', forward_dynamics_derivatives_row),
    ('run_forward_dynamics_derivatives_batch',
     forward_dynamics_derivatives_row),
    ('run_forward_dynamics_derivatives_links',
     forward_dynamics_derivatives_links_row),
)
