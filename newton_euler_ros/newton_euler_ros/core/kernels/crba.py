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

"""The joint-space mass matrix D(q) by the composite-rigid-body algorithm."""
from ._jit import njit
from .kinematics import (branch_point, branched, has_mimic, joint_trig,
                         parent, placement, put_pair, revolute,
                         stored_placement, zero_matrix)
from .layout import (C_HALF, C_ZERO, F_CONST, L_COM, L_INERTIA, L_MASS,
                     OVERFLOW, W_ACC)
from .spatial import force_to_parent, rot, sym_rotate
from .status import matrix_status


@njit(cache=True, inline='always')
def mass_matrix_crba(links, frames, q, ws, D):
    """
    D(q) by the composite-rigid-body algorithm (CRBA); O(n^2), small constant.

    Column i of D is the torque for qdd = e_i at rest without gravity
    (what ``mass_matrix_columns`` computes with one recursion).  Then links 0..i-1
    stand still and need no force, and links i..n-1 move as one rigid
    *composite body i*; so every joint j <= i transmits just the wrench
    composite i needs, and D[j, i] is joint j's component of it.  The
    entries j > i of the column come from symmetry, D[j, i] = D[i, j],
    filled when column j is done.

    Composite i is kept in kernel frame i as its mass Mc, first moment
    h = sum m_k c_k (c_k: centre of mass of link k seen from O_i) and
    rotational inertia I about O_i, never divided by the mass, so massless
    links and composites need no care.  It is built from the tip: add link
    i (h += m c, I += I_c + m (|c|^2 1 - c c^T), with the symmetric part of
    I_c), use it, then carry it into frame i-1 (R, p of frame i in frame
    i-1): with hr = R h, h' = hr + Mc p and, since the position of each
    mass element becomes r' = R r + p,
    I' = R I R^T - [p][hr] - [hr][p] - Mc [p][p] ([x] the cross-product
    matrix), written with gp = hr + Mc p / 2 as
    I' = R I R^T + 2 (gp . p) 1 - (gp p^T + p gp^T) so it stays symmetric.

    Unit rate of joint i (axis z through O_i): revolute, angular
    acceleration z with O_i at rest; prismatic, no rotation and O_i
    accelerating by z.  Newton-Euler about O_i (not the centre of mass)
    at zero velocity: F = Mc a + al x h, N = I al + h x a, that is
    F = z x h, N = I z (revolute) or F = Mc z, N = h x z (prismatic).
    D[i, i] is joint i's component (N_z, or F_z); for j = i-1..0 the
    wrench is carried to frame j by the recursion's backward step
    F <- R F, N <- R N + p x F and D[j, i] = D[i, j] is joint j's
    component.  D is symmetric exactly.  Cost: about 170 flops per joint
    plus 50 per pair j < i, against the n recursions of ``mass_matrix_columns``;
    the same D as those up to round-off (the tests check 10 n eps in
    float64 and 1e-40 at 50 digits).

    On a tree (Featherstone's CRBA with a parent array): composite i is
    body i and its descendants, carried into its parent's frame and added
    to the parent's composite (in registers on a chain, into the parent's
    ``W_ACC`` sum at a branch point), and the unit-rate wrench goes up the
    support path only, i's ancestors: D[j, i] = 0 for joints on different
    branches, entries the pass never visits (zeroed first).  Mimic joints
    add their entries to their leads' (D = G^T D_b G).

    Returns -1, or OVERFLOW when an entry is not finite (as ``mass_matrix_columns``).

    The steps, per joint from the tip (Pinocchio's CrbaBackwardStep):
    :func:`composite_start` takes the sum a branch point's later children
    carried back, :func:`composite_add_link` adds link i,
    :func:`support_column` fills column i from the unit-rate wrench, and
    :func:`composite_to_parent` carries composite i into its parent's
    frame.  The composite, ``(Mc, h, Io)``, is carried in registers.
    """
    nb = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    mimic = has_mimic(links, frames)
    joint_trig(links, frames, q, ws)
    for j in range(nb):
        R, p = placement(links, frames, j, ws)
        if branch_point(links, frames, j):
            for k in range(10):
                ws[j, W_ACC + k] = zero
    if mimic or branched(frames):
        zero_matrix(frames, D)
    z3 = (zero, zero, zero)
    z6 = (zero, zero, zero, zero, zero, zero)
    composite = (zero, z3, z6)
    # zero times each entry: stays zero unless one is inf or nan (cheaper
    # than a pass over all n^2 entries, most of them zero on a tree)
    check = zero
    for i in range(nb - 1, -1, -1):
        composite = composite_start(links, frames, ws, i, composite)
        composite = composite_add_link(links, frames, i, composite)
        check = support_column(links, frames, ws, D, i, composite, mimic,
                               check)
        composite = composite_to_parent(links, frames, ws, i, composite,
                                        z3, z6)
    if mimic:       # sums of finite entries may still overflow
        return matrix_status(D)
    return -1 if check == zero else OVERFLOW


@njit(cache=True, inline='always')
def composite_start(links, frames, ws, i, composite):
    """
    Return composite i before link i: what its children carried back.

    On a chain that is the child's composite, in registers; a branch
    point adds the sum its later children put into its ``W_ACC``.
    """
    if not branch_point(links, frames, i):
        return composite
    Mc, h, Io = composite
    a = W_ACC
    Mc = Mc + ws[i, a]
    h = (h[0] + ws[i, a + 1], h[1] + ws[i, a + 2], h[2] + ws[i, a + 3])
    Io = (Io[0] + ws[i, a + 4], Io[1] + ws[i, a + 5],
          Io[2] + ws[i, a + 6], Io[3] + ws[i, a + 7],
          Io[4] + ws[i, a + 8], Io[5] + ws[i, a + 9])
    return (Mc, h, Io)


@njit(cache=True, inline='always')
def composite_add_link(links, frames, i, composite):
    """
    Return composite i with link i added, in frame i about O_i.

    h += m c, I += I_c + m (|c|^2 1 - c c^T), with the symmetric part of
    I_c (stored as xx, yy, zz, xy, yz, xz).
    """
    Mc, h, Io = composite
    half = frames[F_CONST, C_HALF]
    m = links[i, L_MASS]
    c0 = links[i, L_COM]
    c1 = links[i, L_COM + 1]
    c2 = links[i, L_COM + 2]
    mc0 = m * c0
    mc1 = m * c1
    mc2 = m * c2
    k = L_INERTIA
    Mc = Mc + m
    h = (h[0] + mc0, h[1] + mc1, h[2] + mc2)
    Io = (Io[0] + links[i, k] + (mc1 * c1 + mc2 * c2),
          Io[1] + links[i, k + 4] + (mc0 * c0 + mc2 * c2),
          Io[2] + links[i, k + 8] + (mc0 * c0 + mc1 * c1),
          Io[3] + half * (links[i, k + 1] + links[i, k + 3]) - mc0 * c1,
          Io[4] + half * (links[i, k + 5] + links[i, k + 7]) - mc1 * c2,
          Io[5] + half * (links[i, k + 2] + links[i, k + 6]) - mc0 * c2)
    return (Mc, h, Io)


@njit(cache=True, inline='always')
def support_column(links, frames, ws, D, i, composite, mimic, check):
    """
    Fill column i of D (and row i) on joint i's support; return ``check``.

    The wrench composite i needs for a unit rate of joint i (F = z x h,
    N = I z revolute; F = Mc z, N = h x z prismatic) gives D[i, i], then
    goes up the ancestors j of i by the recursion's backward step
    (``force_to_parent``), each giving D[j, i] = D[i, j].  ``check``
    comes back plus zero times each entry (nan or inf if one is not
    finite).
    """
    zero = frames[F_CONST, C_ZERO]
    Mc, h, Io = composite
    if revolute(links, frames, i):
        F = (-h[1], h[0], zero)
        N = (Io[5], Io[4], Io[2])
        put_pair(links, D, i, i, N[2], mimic)
        check = check + zero * N[2]
    else:
        F = (zero, zero, Mc)
        N = (h[1], -h[0], zero)
        put_pair(links, D, i, i, F[2], mimic)
        check = check + zero * F[2]
    k = i
    j = parent(links, i)
    while j >= 0:
        R, p = stored_placement(ws, k)
        F, N = force_to_parent(R, p, F, N)
        if revolute(links, frames, j):
            x = N[2]
        else:
            x = F[2]
        put_pair(links, D, j, i, x, mimic)
        put_pair(links, D, i, j, x, mimic)
        check = check + zero * x
        k = j
        j = parent(links, j)
    return check


@njit(cache=True, inline='always')
def composite_to_parent(links, frames, ws, i, composite, z3, z6):
    """
    Return what composite i hands on: itself in its parent's frame.

    About the parent's origin: h' = R h + Mc p and
    I' = R I R^T + 2 (gp . p) 1 - (gp p^T + p gp^T), gp = R h + Mc p / 2.
    At a branch (the parent is not body i - 1) it goes into the parent's
    ``W_ACC`` sum instead, and a root hands on nothing: both return the
    empty composite (``z3``, ``z6``: zero tuples).
    """
    Mc, h, Io = composite
    zero = frames[F_CONST, C_ZERO]
    par = parent(links, i)
    if par < 0:
        return (zero, z3, z6)
    half = frames[F_CONST, C_HALF]
    R, p = stored_placement(ws, i)
    hr = rot(R, h[0], h[1], h[2])
    Ir = sym_rotate(R, Io)
    hMc = half * Mc
    gp = (hr[0] + hMc * p[0], hr[1] + hMc * p[1], hr[2] + hMc * p[2])
    gp0 = gp[0] * p[0]
    gp1 = gp[1] * p[1]
    gp2 = gp[2] * p[2]
    Io = (Ir[0] + ((gp1 + gp2) + (gp1 + gp2)),
          Ir[1] + ((gp0 + gp2) + (gp0 + gp2)),
          Ir[2] + ((gp0 + gp1) + (gp0 + gp1)),
          Ir[3] - (gp[0] * p[1] + gp[1] * p[0]),
          Ir[4] - (gp[1] * p[2] + gp[2] * p[1]),
          Ir[5] - (gp[0] * p[2] + gp[2] * p[0]))
    h = (hr[0] + Mc * p[0], hr[1] + Mc * p[1], hr[2] + Mc * p[2])
    if par == i - 1:
        return (Mc, h, Io)
    a = W_ACC               # a branch: into the parent's sum
    ws[par, a] += Mc
    for k in range(3):
        ws[par, a + 1 + k] += h[k]
    for k in range(6):
        ws[par, a + 4 + k] += Io[k]
    return (zero, z3, z6)
