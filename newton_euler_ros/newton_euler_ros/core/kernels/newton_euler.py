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
The Newton-Euler recursion: forward pass, backward pass, tip wrench.

:func:`recursion` is the seed text's algorithm: a forward pass, base to
tip, carries velocities and accelerations out along the chain and gives
each link's net force and moment (eqs. (19)-(21)); a backward pass, tip
to base, balances forces and moments link by link and reads each joint's
torque off its axis.  :func:`tip_wrench` is the backward pass's starting
value, the wrench the end effector exerts.  g(q) (:func:`gravity`) and
the column-by-column D and C (:func:`unit_columns`) are this recursion
with some inputs zero: those pass ``None``, which numba compiles away
(a separate specialisation reads no such argument at all).

Notation (all vectors of link j are expressed in kernel frame j, whose z
axis is the axis of joint j through its origin O_j; see
``model.compile_arrays``):

- ``R``, ``p``: rotation and origin of kernel frame j in frame j-1.
- ``w``: angular velocity (from qd); ``r``: the *reference* angular velocity
  (from the second velocity argument ``v``); ``al``: angular acceleration;
  ``ae``: acceleration of the point O_j; ``ac``: acceleration of the centre
  of mass.  With ``v == qd`` these are the physical quantities of the
  seed text and the recursion is its eqs. (19)-(21).

Two velocity streams.  The recursion evaluates
``Y(q, qd, v, qdd) = D(q) qdd + C(q, qd) v (+ g + J^T F_e)`` where C is the
Christoffel-symbol Coriolis matrix.  Expanding the Lagrangian with body
Jacobians J_i gives ``C v = sum_i J_i^T (M_i Jdot_i(qd) v + B_i(V_i) J_i v)``
with ``B(V) = (M ad_V - ad_V^T M - K(M V)) / 2``, which is skew-symmetric
(so Ddot - 2C is skew) and satisfies ``B(V) V = -ad_V^T M V`` (so C qd is
the true velocity-product torque).  Written at the centre of mass in
3-vectors this becomes the classical recursion with
``w x (w x c)`` -> ``w x (r x c)``,
``w_{j-1} x z qd_j`` -> ``r_{j-1} x z qd_j`` (revolute),
``2 w x z qd_j`` -> ``(r x z) qd_j + (w x z) v_j`` (prismatic) and
``w x I w`` -> ``(w x I r + r x I w + I (w x r)) / 2``.
Every replacement reduces to the physical term exactly when ``v == qd``.

The prismatic Coriolis term is ``2 w x z qd``: the seed's eqs. (15)-(18)
keep only the ``zdot qd`` half and miss the half that comes from
differentiating ``w x r`` while r grows at the rate ``z qd``.
"""
from ._jit import njit
from .kinematics import (branch_point, frame_rotation, has_mimic, joint_trig,
                         link_inertia, parent, placement, put, rate_or_zero,
                         revolute, stored_placement, tool_body)
from .layout import (C_HALF, C_ONE, C_ZERO, F_CONST, F_GRAV, F_TOOL,
                     L_BODY, L_COM, L_MASS, W_ACC, W_F, W_N, W_X,
                     WRENCH_BASE, WRENCH_NONE)
from .spatial import (cross, force_to_parent, frame_rot, load3, load9,
                      matmul, rot, rot_t)
from .status import matrix_status


@njit(cache=True, inline='always')
def recursion(links, frames, qd, v, qdd, wrench, fext, gravity_on,
              velocity_on, wrench_mode, link_wrenches, ws, tau):
    """
    Newton-Euler recursion: tau = D qdd + C(q, qd) v [+ g] [+ J^T F_e].

    ``joint_trig(links, frames, q, ws)`` must have been called for the same q.
    A forward step per body, base to tip, then a backward step per body,
    tip to base, as in the seed text (Pinocchio's RneaForwardStep and
    RneaBackwardStep), on the tree: body j starts from its parent's
    velocities and accelerations, and its parent takes the wrench it
    transmits.  On a chain the running values stay in registers; a
    branch point stores its state for its later children (``W_X``) and
    sums what they carry back (``W_ACC``).  The two passes are
    :func:`forward_pass` and :func:`backward_pass`; the workspace carries
    each body's net force and moment from one to the other.  Each pass is
    its per-body step in a loop (:func:`forward_step` after
    :func:`forward_start`, :func:`backward_step` before
    :func:`backward_carry`), the steps inlined into the loop by numba
    (``inline='always'``).  Cost: about 250 flops per body, O(nb).
    Every vector of link j is in kernel frame j, whose z axis is joint
    j's axis through its origin.

    Parameters
    ----------
    links : (nb, L_WIDTH) array
        Per-body placement, parent, mass, centre-of-mass and inertia
        parameters (the ``L_*`` columns).
    frames : (F_ROWS, 12) array
        Base frame, tool frame, gravity, constants and the tree's shape
        (the ``F_*`` rows).
    qd, v, qdd : (n,) arrays or None
        Joint velocity, reference velocity, acceleration (coordinates: a
        mimic joint moves with its lead); None is zero.  qd and v are
        read only with ``velocity_on``.
    wrench : (6,) array or None
        [f; n] exerted by the end effector on its environment, moment about
        the end-effector origin; base-frame axes when
        ``wrench_mode == WRENCH_BASE``, end-effector axes when
        ``WRENCH_EE``; ignored when ``WRENCH_NONE``.  None: no wrench.
    fext : (nb, 6) array or None
        With ``link_wrenches``: row j is [f; n] exerted by link j on its
        environment, in link j's axes, the moment about its origin
        (several links at once); ignored otherwise.  None: none.
    gravity_on, velocity_on : bool
        Skip the gravity or velocity-product terms altogether when False.
    wrench_mode : int
        ``WRENCH_NONE``, ``WRENCH_BASE`` or ``WRENCH_EE``.
    link_wrenches : bool
        Apply ``fext``.
    ws : (nb, W_WIDTH) array
        Workspace: reads the trig columns ``joint_trig`` filled, overwrites
        the other ``W_*`` columns.
    tau : (n,) array
        Output.

    """
    forward_pass(links, frames, qd, v, qdd, gravity_on, velocity_on, ws)
    backward_pass(links, frames, wrench, wrench_mode, fext, link_wrenches,
                  ws, tau)


@njit(cache=True, inline='always')
def forward_pass(links, frames, qd, v, qdd, gravity_on, velocity_on, ws):
    """
    Run the forward steps, base to tip: velocities and accelerations out.

    The state carried from body to body is ``(w, r, al, ae)``: angular
    velocity, reference velocity, angular acceleration and the
    acceleration of the origin, each a 3-tuple in the body's axes; the
    base's is at rest, accelerating up at g.  Per body,
    :func:`forward_start` picks the state it starts from and
    :func:`forward_step` takes it on.  Arguments as :func:`recursion`'s.
    """
    nb = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    mimic = has_mimic(links, frames)
    # Gravity enters as an upward acceleration of the base: a_0 = -g.
    if gravity_on:
        a0 = (-frames[F_GRAV, 0], -frames[F_GRAV, 1], -frames[F_GRAV, 2])
    else:
        a0 = (zero, zero, zero)
    z3 = (zero, zero, zero)
    state = (z3, z3, z3, a0)
    for j in range(nb):
        state = forward_start(links, ws, j, state, a0, z3)
        state = forward_step(links, frames, qd, v, qdd, velocity_on, ws, j,
                             mimic, state)


@njit(cache=True, inline='always')
def forward_start(links, ws, j, state, a0, z3):
    """
    Return body j's starting state: its parent's (a branch: as stored).

    A root starts from the base's (``a0``; ``z3`` is the zero 3-tuple).
    """
    par = parent(links, j)
    if par == j - 1:
        return state
    if par < 0:
        return (z3, z3, z3, a0)
    return (load3(ws, par, W_X), load3(ws, par, W_X + 3),
            load3(ws, par, W_X + 6), load3(ws, par, W_X + 9))


@njit(cache=True, inline='always')
def forward_step(links, frames, qd, v, qdd, velocity_on, ws, j, mimic,
                 state):
    """
    Take the state from body j's parent to body j; return body j's state.

    The seed's eqs. (19)-(21): from the parent's ``(w, r, al, ae)`` (its
    axes) to body j's (frame j axes), then body j's net force m a_c
    (``W_F``) and net moment about its centre of mass (``W_N``) into the
    workspace, which is all the backward pass reads of it.  A branch
    point keeps its state for its later children (``W_X``) and zeroes the
    sum they will carry back (``W_ACC``).
    """
    w, r, al, ae = state
    zero = frames[F_CONST, C_ZERO]
    half = frames[F_CONST, C_HALF]
    R, p = placement(links, frames, j, ws)
    qddj = rate_or_zero(links, frames, qdd, j, mimic)
    t = cross(al[0], al[1], al[2], p[0], p[1], p[2])
    ae = (ae[0] + t[0], ae[1] + t[1], ae[2] + t[2])
    if velocity_on:
        t = cross(r[0], r[1], r[2], p[0], p[1], p[2])
        t = cross(w[0], w[1], w[2], t[0], t[1], t[2])
        ae = (ae[0] + t[0], ae[1] + t[1], ae[2] + t[2])
    ae = rot_t(R, ae[0], ae[1], ae[2])
    al = rot_t(R, al[0], al[1], al[2])
    is_revolute = revolute(links, frames, j)
    if velocity_on:
        qdj = rate_or_zero(links, frames, qd, j, mimic)
        vj = rate_or_zero(links, frames, v, j, mimic)
        w = rot_t(R, w[0], w[1], w[2])
        r = rot_t(R, r[0], r[1], r[2])
        if is_revolute:
            al = (al[0] + r[1] * qdj, al[1] - r[0] * qdj,
                  al[2] + qddj)
            w = (w[0], w[1], w[2] + qdj)
            r = (r[0], r[1], r[2] + vj)
        else:
            ae = (ae[0] + r[1] * qdj + w[1] * vj,
                  ae[1] - r[0] * qdj - w[0] * vj,
                  ae[2] + qddj)
    elif is_revolute:
        al = (al[0], al[1], al[2] + qddj)
    else:
        ae = (ae[0], ae[1], ae[2] + qddj)
    if branch_point(links, frames, j):
        for k in range(3):
            ws[j, W_X + k] = w[k]
            ws[j, W_X + 3 + k] = r[k]
            ws[j, W_X + 6 + k] = al[k]
            ws[j, W_X + 9 + k] = ae[k]
        for k in range(6):
            ws[j, W_ACC + k] = zero
    c0 = links[j, L_COM]
    c1 = links[j, L_COM + 1]
    c2 = links[j, L_COM + 2]
    t = cross(al[0], al[1], al[2], c0, c1, c2)
    ac = (ae[0] + t[0], ae[1] + t[1], ae[2] + t[2])
    if velocity_on:
        t = cross(r[0], r[1], r[2], c0, c1, c2)
        t = cross(w[0], w[1], w[2], t[0], t[1], t[2])
        ac = (ac[0] + t[0], ac[1] + t[1], ac[2] + t[2])
    m = links[j, L_MASS]
    ws[j, W_F] = m * ac[0]
    ws[j, W_F + 1] = m * ac[1]
    ws[j, W_F + 2] = m * ac[2]
    Ic = link_inertia(links, j)
    Ia = rot(Ic, al[0], al[1], al[2])
    Nn = Ia
    if velocity_on:
        Ir = rot(Ic, r[0], r[1], r[2])
        Iw = rot(Ic, w[0], w[1], w[2])
        t = cross(w[0], w[1], w[2], Ir[0], Ir[1], Ir[2])
        t2 = cross(r[0], r[1], r[2], Iw[0], Iw[1], Iw[2])
        wr = cross(w[0], w[1], w[2], r[0], r[1], r[2])
        t3 = rot(Ic, wr[0], wr[1], wr[2])
        Nn = (Ia[0] + half * ((t[0] + t2[0]) + t3[0]),
              Ia[1] + half * ((t[1] + t2[1]) + t3[1]),
              Ia[2] + half * ((t[2] + t2[2]) + t3[2]))
    ws[j, W_N] = Nn[0]
    ws[j, W_N + 1] = Nn[1]
    ws[j, W_N + 2] = Nn[2]
    return (w, r, al, ae)


@njit(cache=True, inline='always')
def backward_pass(links, frames, wrench, wrench_mode, fext, link_wrenches,
                  ws, tau):
    """
    Run the backward steps, tip to base: forces and moments in, torques.

    Per body, :func:`backward_step` gives the force and moment body j
    exerts and its joint's torque, and :func:`backward_carry` hands them
    to its parent.  Arguments as :func:`recursion`'s.
    """
    nb = links.shape[0]
    zero = frames[F_CONST, C_ZERO]
    mimic = has_mimic(links, frames)
    # f, nm hold the force and the moment (about O_j) that link j exerts on
    # its children and its environment, in frame j axes; the wrench the
    # end effector exerts (the seed's "f_{n+1}, tau_{n+1}") enters at the
    # tool's body
    if mimic:
        for i in range(tau.shape[0]):
            tau[i] = zero
    tool = tool_body(frames) if wrench_mode != WRENCH_NONE else -2
    z3 = (zero, zero, zero)
    f = z3
    nm = z3
    for j in range(nb - 1, -1, -1):
        f, nm = backward_step(links, frames, wrench, wrench_mode, fext,
                              link_wrenches, ws, tau, j, tool, mimic, f, nm)
        f, nm = backward_carry(links, ws, j, f, nm, z3)


@njit(cache=True, inline='always')
def backward_step(links, frames, wrench, wrench_mode, fext, link_wrenches,
                  ws, tau, j, tool, mimic, f, nm):
    """
    Return what body j exerts, ``(f, nm)``; put its joint's torque in tau.

    ``f`` and ``nm`` come in as what its children carry back (a branch
    point adds their sum, ``W_ACC``); then the end effector's wrench at
    the tool's body (``wrench_mode``, :func:`tip_wrench`; ``tool`` is
    that body), the links' own wrenches (``link_wrenches``,
    :func:`link_wrench`) and its net force and moment from
    :func:`forward_step`.  The force and the moment (about O_j, frame j
    axes) are what body j exerts on its children and its environment;
    joint j takes the moment about (revolute) or the force along
    (prismatic) its axis.
    """
    if branch_point(links, frames, j):
        f = (f[0] + ws[j, W_ACC], f[1] + ws[j, W_ACC + 1],
             f[2] + ws[j, W_ACC + 2])
        nm = (nm[0] + ws[j, W_ACC + 3], nm[1] + ws[j, W_ACC + 4],
              nm[2] + ws[j, W_ACC + 5])
    if wrench is not None:      # (compiled away when None)
        if j == tool:
            e = tip_wrench(frames, wrench, wrench_mode,
                           frame_rotation(links, frames, ws, j))
            nm = (nm[0] + e[0], nm[1] + e[1], nm[2] + e[2])
            f = (f[0] + e[3], f[1] + e[4], f[2] + e[5])
    if fext is not None:
        if link_wrenches:
            fe, ne = link_wrench(links, fext, j)
            f = (f[0] + fe[0], f[1] + fe[1], f[2] + fe[2])
            nm = (nm[0] + ne[0], nm[1] + ne[1], nm[2] + ne[2])
    F0 = ws[j, W_F]
    F1 = ws[j, W_F + 1]
    F2 = ws[j, W_F + 2]
    t = cross(links[j, L_COM], links[j, L_COM + 1], links[j, L_COM + 2],
              F0, F1, F2)
    nm = (nm[0] + t[0] + ws[j, W_N], nm[1] + t[1] + ws[j, W_N + 1],
          nm[2] + t[2] + ws[j, W_N + 2])
    f = (f[0] + F0, f[1] + F1, f[2] + F2)
    if revolute(links, frames, j):
        put(links, tau, j, nm[2], mimic)
    else:
        put(links, tau, j, f[2], mimic)
    return f, nm


@njit(cache=True, inline='always')
def backward_carry(links, ws, j, f, nm, z3):
    """
    Return what body j hands its parent, in the parent's frame.

    A root hands on nothing, a branch adds into its parent's ``W_ACC``.
    """
    par = parent(links, j)
    if par < 0:
        return z3, z3
    R, p = stored_placement(ws, j)
    f, nm = force_to_parent(R, p, f, nm)
    if par != j - 1:    # a branch: into the parent's sum
        for k in range(3):
            ws[par, W_ACC + k] += f[k]
            ws[par, W_ACC + 3 + k] += nm[k]
        return z3, z3
    return f, nm


@njit(cache=True, inline='always')
def link_wrench(links, fext, j):
    """
    Return fext[j] (link j's axes, about its origin) in kernel frame j.

    As (f, n), the moment about O_j: with (R_B, p_B) the link frame in
    kernel frame j, f' = R_B f and n' = R_B n + p_B x f'.
    """
    RB = load9(links, j, L_BODY)
    f = rot(RB, fext[j, 0], fext[j, 1], fext[j, 2])
    n = rot(RB, fext[j, 3], fext[j, 4], fext[j, 5])
    t = cross(links[j, L_BODY + 9], links[j, L_BODY + 10],
              links[j, L_BODY + 11], f[0], f[1], f[2])
    return f, (n[0] + t[0], n[1] + t[1], n[2] + t[2])


@njit(cache=True)
def tip_wrench(frames, wrench, wrench_mode, Racc):
    """
    Return the wrench the tip exerts, at its body's kernel frame: [n; f].

    About the origin of the kernel frame of the tool's body, in its axes.

    ``Racc`` is the rotation of that frame in the base frame (used for
    ``WRENCH_BASE``).  As the recursion's "f_{n+1}, tau_{n+1}".
    """
    Rt = frame_rot(frames, F_TOOL)
    fe = (wrench[0], wrench[1], wrench[2])
    ne = (wrench[3], wrench[4], wrench[5])
    if wrench_mode == WRENCH_BASE:
        Ree = matmul(Racc, Rt)
        fe = rot_t(Ree, fe[0], fe[1], fe[2])
        ne = rot_t(Ree, ne[0], ne[1], ne[2])
    f = rot(Rt, fe[0], fe[1], fe[2])
    nm = rot(Rt, ne[0], ne[1], ne[2])
    t = cross(frames[F_TOOL, 9], frames[F_TOOL, 10], frames[F_TOOL, 11],
              f[0], f[1], f[2])
    return (nm[0] + t[0], nm[1] + t[1], nm[2] + t[2], f[0], f[1], f[2])


@njit(cache=True, inline='always')
def gravity(links, frames, q, ws, tau):
    """g(q) into tau: the recursion at rest with gravity only."""
    joint_trig(links, frames, q, ws)
    # no velocities, no acceleration but gravity's, no wrenches
    forward_pass(links, frames, None, None, None, True, False, ws)
    backward_pass(links, frames, None, WRENCH_NONE, None, False, ws, tau)


@njit(cache=True)
def unit_columns(links, frames, qd, coriolis, ws, scratch, M):
    """
    Columns of D (``coriolis`` False) or C(q, qd) from unit inputs.

    D e_k = Y(q, 0, 0, e_k) and C e_k = Y(q, qd, e_k, 0), where Y is the
    two-stream recursion (the zeros pass as None); ``joint_trig`` must
    have been called for q.  ``scratch`` is a (3, n) array (rows 1 and 2
    used).  Cost: n recursions, O(n nb).
    """
    n = M.shape[0]
    unit = scratch[1]
    col = scratch[2]
    for i in range(n):
        unit[i] = frames[F_CONST, C_ZERO]
    for k in range(n):
        unit[k] = frames[F_CONST, C_ONE]
        if coriolis:
            recursion(links, frames, qd, unit, None, None, None, False, True,
                      WRENCH_NONE, False, ws, col)
        else:
            recursion(links, frames, None, None, unit, None, None, False,
                      False, WRENCH_NONE, False, ws, col)
        unit[k] = frames[F_CONST, C_ZERO]
        for i in range(n):
            M[i, k] = col[i]


@njit(cache=True)
def mass_matrix_columns(links, frames, q, ws, scratch, D):
    """D(q) column by column: D e_k = recursion(qd = 0, qdd = e_k)."""
    n = D.shape[0]
    half = frames[F_CONST, C_HALF]
    joint_trig(links, frames, q, ws)
    unit_columns(links, frames, q, False, ws, scratch, D)
    # D is symmetric in exact arithmetic; make it so to the last bit.
    for i in range(n):
        for k in range(i + 1, n):
            avg = half * (D[i, k] + D[k, i])
            D[i, k] = avg
            D[k, i] = avg
    return matrix_status(D)


@njit(cache=True)
def coriolis_matrix_columns(links, frames, q, qd, ws, scratch, C):
    """Christoffel C(q, qd) column by column: C e_k = Y(q, qd, e_k, 0)."""
    joint_trig(links, frames, q, ws)
    unit_columns(links, frames, qd, True, ws, scratch, C)
    return matrix_status(C)
