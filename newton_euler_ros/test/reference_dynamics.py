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
An independent Euler-Lagrange reference for serial arms (test oracle).

Nothing here is imported from ``newton_euler_ros``: the only coupling is that
the functions read the public fields of a model object (``a, alpha, d,
theta, joint_types, convention, mass, com, inertia, gravity, base, tool``
for DH arms; ``joint_pre, joint_axis, joint_post`` for general ones, e.g.
from URDF: each joint is Pre . M(axis, q) . Post, with M a rotation about
the axis by Rodrigues' formula or a translation along it, and Pre/Post
products of the elementary operations, all evaluated here).

Trees: ``parents`` (joint j's Pre starts from the link frame of joint
``parents[j]``, the base for -1), ``mimic`` (None, or (leader, multiplier,
offset): the joint's angle is multiplier q_leader + offset, and it has no
coordinate of its own) and ``tool_body`` (the joint whose link carries the
tool) are read when present; without them the model is a chain.  The
kinematics are the products along each link's path to the base; a link's
Jacobian column of coordinate k sums, over the joints on that path moved
by k, multiplier times the joint's own column.
The kinematics are products of elementary 4x4 homogeneous matrices, the
dynamics come from the Lagrangian

    L = T - U,   T = 1/2 qd^T D(q) qd,   U = -sum_j m_j g^T p_cj,

    tau = D qdd + C qd + g + J^T F_e,  g = dU/dq,
    C_kj = sum_i 1/2 (dD_kj/dq_i + dD_ki/dq_j - dD_ij/dq_k) qd_i.

Derivatives and the ``method`` argument
---------------------------------------
Every function here is *complex-safe*: it uses only ``+ - * /``, ``cos``,
``sin`` and transposes (never ``abs``, ``conj`` or comparisons on the
state), so an analytic function f of q can be differentiated by the
complex step  f'(q) e = Im f(q + i h e) / h.  This has no subtractive
cancellation, so with h = 1e-30 the derivative is exact to round-off
(relative error ~1e-16 times the conditioning of f itself).  Supported
methods and the accuracy each supports (relative to the size of the
differentiated quantity, for link lengths ~1 m and q ~ 1):

``'complex'`` (default)
    h = 1e-30, error ~ 1e-15 relative.  Comparisons against the library
    can use ~1e-11 relative tolerances (leaving room for the round-off of
    both codes and for the conditioning of sums of large terms).
``'richardson'``
    central differences at h and h/2 combined as (4 D(h/2) - D(h)) / 3,
    h = 1e-3: truncation O(h^4) ~ 1e-12 * |f^(5)|, round-off
    ~ eps |f| / h ~ 1e-13; supports ~1e-9 relative tolerances.
``'central'``
    (f(q + h e) - f(q - h e)) / (2 h), h = 1e-6: truncation
    h^2 |f'''| / 6 ~ 2e-13 |f'''|, round-off eps |f| / h ~ 2e-10;
    supports ~1e-7 relative tolerances.

The kinetic energy is computed without the geometric Jacobians: the centre
of mass velocity and the angular velocity are the time derivatives of the
forward kinematics along the motion, v_c = d/dt p_c(q + t qd) and
[w]x = Rdot R^T, taken by the same derivative method.  ``kinetic_energy``
and ``1/2 qd^T mass_matrix qd`` are thus two independent computations.
"""
import numpy as np

REVOLUTE = 'revolute'
STANDARD = 'standard'

COMPLEX_STEP = 1e-30
CENTRAL_STEP = 1e-6
RICHARDSON_STEP = 1e-3

# the relative accuracy each method supports (see the module docstring)
METHOD_RTOL = {'complex': 1e-11, 'richardson': 1e-9, 'central': 1e-7}


# ---------------------------------------------------------------------------
# elementary transforms (complex-safe)
# ---------------------------------------------------------------------------
def _dtype(*xs):
    return np.result_type(float, *[np.asarray(x) for x in xs])


def rot_x(t):
    c, s = np.cos(t), np.sin(t)
    T = np.eye(4, dtype=_dtype(t))
    T[1, 1], T[1, 2], T[2, 1], T[2, 2] = c, -s, s, c
    return T


def rot_z(t):
    c, s = np.cos(t), np.sin(t)
    T = np.eye(4, dtype=_dtype(t))
    T[0, 0], T[0, 1], T[1, 0], T[1, 1] = c, -s, s, c
    return T


def trans_x(a):
    T = np.eye(4, dtype=_dtype(a))
    T[0, 3] = a
    return T


def trans_z(d):
    T = np.eye(4, dtype=_dtype(d))
    T[2, 3] = d
    return T


def rot_y(t):
    c, s = np.cos(t), np.sin(t)
    T = np.eye(4, dtype=_dtype(t))
    T[0, 0], T[0, 2], T[2, 0], T[2, 2] = c, s, -s, c
    return T


def translation(x, y, z):
    T = np.eye(4, dtype=_dtype(x, y, z))
    T[:3, 3] = x, y, z
    return T


def ops_transform(ops):
    """4x4 product of a model's elementary operations, evaluated here."""
    T = np.eye(4)
    for op in ops:
        kind, args = op[0], op[1:]
        if kind in ('tx', 'ty', 'tz'):
            v = [0.0, 0.0, 0.0]
            v['xyz'.index(kind[1])] = args[0]
            E = translation(*v)
        elif kind in ('rx', 'ry', 'rz'):
            E = {'rx': rot_x, 'ry': rot_y, 'rz': rot_z}[kind](args[0])
        elif kind == 'xyz':
            E = translation(*args)
        elif kind == 'rpy':
            E = rot_z(args[2]) @ rot_y(args[1]) @ rot_x(args[0])
        elif kind == 'matrix':
            E = np.eye(4)
            E[:3, :3] = np.reshape(args[:9], (3, 3))
            E[:3, 3] = args[9:]
        else:
            raise ValueError(kind)
        T = T @ E
    return T


def axis_motion(joint_type, axis, q):
    """Rotation about (Rodrigues) or translation along a unit axis by q."""
    k = np.asarray(axis, dtype=float)
    k = k / np.sqrt(k @ k)
    T = np.eye(4, dtype=_dtype(q))
    if joint_type == REVOLUTE:
        K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]],
                      [-k[1], k[0], 0.0]])
        T[:3, :3] = (np.eye(3) + np.sin(q) * K
                     + (1.0 - np.cos(q)) * (K @ K))
    else:
        T[:3, 3] = k * q
    return T


def dh_transform(convention, a, alpha, d, theta):
    """
    Return the 4x4 DH transform of one joint in the given convention.

    Standard: Rz(theta) Tz(d) Tx(a) Rx(alpha); modified (Craig):
    Rx(alpha) Tx(a) Rz(theta) Tz(d).
    """
    if convention == STANDARD:
        return rot_z(theta) @ trans_z(d) @ trans_x(a) @ rot_x(alpha)
    return rot_x(alpha) @ trans_x(a) @ rot_z(theta) @ trans_z(d)


# ---------------------------------------------------------------------------
# the tree: parents, and the coordinate moving each joint
# ---------------------------------------------------------------------------
def tree(model):
    """
    Return (parents, coordinate, multiplier, offset) per joint, and n.

    Read from the model's public ``parents`` and ``mimic`` (a chain and no
    mimic joint when it has none).
    """
    nb = len(model.joint_types)
    parents = list(getattr(model, 'parents', None) or range(-1, nb - 1))
    mimic = list(getattr(model, 'mimic', None) or [None] * nb)
    independent = [j for j in range(nb) if mimic[j] is None]
    index = {j: k for k, j in enumerate(independent)}
    coord, mult, offset = [], [], []
    for j in range(nb):
        lead, m, o = (j, 1.0, 0.0) if mimic[j] is None else mimic[j]
        coord.append(index[lead])
        mult.append(m)
        offset.append(o)
    return parents, coord, mult, offset, len(independent)


def path(parents, j):
    """Joint j and its ancestors (the joints that move its link)."""
    out = []
    while j >= 0:
        out.append(j)
        j = parents[j]
    return out


def tool_body(model):
    nb = len(model.joint_types)
    b = getattr(model, 'tool_body', nb - 1)
    return -1 if b is None else b


# ---------------------------------------------------------------------------
# forward kinematics
# ---------------------------------------------------------------------------
def forward_kinematics(model, q):
    """
    Poses in the base frame, and the joint axes.

    Returns ``(T, axes)``: ``T`` is a list of nb + 2 (4, 4) arrays, frame
    0, link frames 1..nb and the end effector; ``axes[j] = (z, o)`` is the
    unit direction of joint j+1 and a point on it, in base coordinates.
    """
    q = np.asarray(q)
    nb = len(model.joint_types)
    parents, coord, mult, offset, _ = tree(model)
    dt = _dtype(q)
    T = [np.asarray(model.base, dtype=dt)]
    axes = []
    dh = model.convention in (STANDARD, 'modified')
    for j in range(nb):
        qj = mult[j] * q[coord[j]] + offset[j]
        if not dh:
            # general joint: Pre . M(axis, q) . Post; the axis passes
            # through the origin of Pre's frame, on its parent's link
            P = T[parents[j] + 1] @ ops_transform(model.joint_pre[j])
            axes.append((P[:3, :3] @ np.asarray(model.joint_axis[j]),
                         P[:3, 3]))
            T.append(P @ axis_motion(model.joint_types[j],
                                     model.joint_axis[j], qj)
                     @ ops_transform(model.joint_post[j]))
            continue
        theta = model.theta[j]
        d = model.d[j]
        if model.joint_types[j] == REVOLUTE:
            theta = theta + qj
        else:
            d = d + qj
        A = dh_transform(model.convention, model.a[j], model.alpha[j], d,
                         theta)
        Tj = T[-1] @ A
        if model.convention == STANDARD:
            # joint j+1 moves about z of the previous frame, through its origin
            axes.append((T[-1][:3, 2], T[-1][:3, 3]))
        else:
            # modified: about z of the link's own frame, through its origin
            axes.append((Tj[:3, 2], Tj[:3, 3]))
        T.append(Tj)
    T.append(T[tool_body(model) + 1] @ np.asarray(model.tool, dtype=dt))
    return T, axes


def ee_pose(model, q):
    """4x4 pose of the end-effector frame in the base frame."""
    return forward_kinematics(model, q)[0][-1]


def com_positions(model, q):
    """(nb, 3) centres of mass in the base frame."""
    T, _ = forward_kinematics(model, q)
    nb = len(model.joint_types)
    return np.array([T[j + 1][:3, :3] @ np.asarray(model.com[j])
                     + T[j + 1][:3, 3] for j in range(nb)])


def _cross(a, b):
    # written out (np.cross is fine on complex too; this keeps it obvious)
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


def _column(model, k, z, o, p):
    """Linear and angular Jacobian column of joint k for the point p."""
    if model.joint_types[k] == REVOLUTE:
        return _cross(z, p - o), z
    return z, np.zeros(3, dtype=z.dtype)


def com_jacobians(model, q):
    """
    Centre-of-mass Jacobians and rotation of every link.

    For each link j: (Jv (3, n), Jw (3, n)) of its centre of mass, base
    axes, and its rotation R_j (3, 3) in the base frame.
    """
    T, axes = forward_kinematics(model, q)
    nb = len(model.joint_types)
    out = []
    for j in range(nb):
        R = T[j + 1][:3, :3]
        pc = R @ np.asarray(model.com[j]) + T[j + 1][:3, 3]
        Jv, Jw = point_jacobian(model, q, axes, j, pc)
        out.append((Jv, Jw, R))
    return out


def point_jacobian(model, q, axes, j, p):
    """(Jv, Jw), (3, n) each, of point p moving with link j, base axes."""
    parents, coord, mult, _, n = tree(model)
    dt = _dtype(q)
    Jv = np.zeros((3, n), dtype=dt)
    Jw = np.zeros((3, n), dtype=dt)
    for k in path(parents, j):
        z, o = axes[k]
        v, w = _column(model, k, z, o, p)
        Jv[:, coord[k]] = Jv[:, coord[k]] + mult[k] * v
        Jw[:, coord[k]] = Jw[:, coord[k]] + mult[k] * w
    return Jv, Jw


def frame_jacobian(model, q, j, T_local, frame='base'):
    """
    Geometric Jacobian (6, n) of a frame fixed to link j at ``T_local``.

    Rows [v; w] of the frame's origin, base axes (or the frame's own with
    ``frame='link'``); j = -1 for a frame on the base (zero).
    """
    T, axes = forward_kinematics(model, q)
    Tf = T[j + 1] @ np.asarray(T_local)
    Jv, Jw = point_jacobian(model, q, axes, j, Tf[:3, 3])
    if frame == 'link':
        Rf = Tf[:3, :3]
        return np.vstack([Rf.T @ Jv, Rf.T @ Jw])
    return np.vstack([Jv, Jw])


def ee_jacobian(model, q, frame='base'):
    """
    Geometric Jacobian (6, n) of the end-effector origin, rows [v; w].

    Base axes (or end-effector axes with ``frame='end_effector'``).
    """
    T, axes = forward_kinematics(model, q)
    Jv, Jw = point_jacobian(model, q, axes, tool_body(model), T[-1][:3, 3])
    J = np.vstack([Jv, Jw])
    if frame == 'end_effector':
        Re = T[-1][:3, :3]
        J = np.vstack([Re.T @ J[:3], Re.T @ J[3:]])
    return J


# ---------------------------------------------------------------------------
# energies and the mass matrix
# ---------------------------------------------------------------------------
def mass_matrix(model, q):
    """D(q) = sum_j m_j Jv^T Jv + Jw^T R I R^T Jw."""
    n = tree(model)[-1]
    D = np.zeros((n, n), dtype=_dtype(q))
    for j, (Jv, Jw, R) in enumerate(com_jacobians(model, q)):
        inertia = R @ np.asarray(model.inertia[j]) @ R.T
        D = D + model.mass[j] * (Jv.T @ Jv) + Jw.T @ inertia @ Jw
    return D


def potential_energy(model, q):
    """U(q) = -sum_j m_j g^T p_cj (gravity and positions in the base frame)."""
    pc = com_positions(model, q)
    g = np.asarray(model.gravity, dtype=float)
    return -sum(model.mass[j] * (g @ pc[j]) for j in range(len(pc)))


def _directional(fun, x, e, method):
    """d/dt fun(x + t e) at t = 0 by the chosen derivative method."""
    x = np.asarray(x, dtype=float)
    e = np.asarray(e, dtype=float)
    if method == 'complex':
        h = COMPLEX_STEP
        return np.imag(fun(x + 1j * h * e)) / h
    if method == 'central':
        h = CENTRAL_STEP
        return (np.asarray(fun(x + h * e)) - np.asarray(fun(x - h * e))) / (
            2 * h)
    if method == 'richardson':
        def cd(h):
            return (np.asarray(fun(x + h * e))
                    - np.asarray(fun(x - h * e))) / (2 * h)
        h = RICHARDSON_STEP
        return (4 * cd(h / 2) - cd(h)) / 3
    raise ValueError(f'unknown derivative method {method!r}')


def partials(fun, q, method='complex'):
    """[d fun / d q_i for i in range(n)]."""
    n = len(q)
    return [_directional(fun, q, np.eye(n)[i], method) for i in range(n)]


def mass_matrix_rate(model, q, qd, method='complex'):
    """Ddot = d/dt D(q + t qd)."""
    return _directional(lambda x: mass_matrix(model, x), q, qd, method)


def christoffel_coriolis(model, q, qd, method='complex'):
    """C(q, qd) from the Christoffel symbols of the reference D."""
    q = np.asarray(q, dtype=float)
    qd = np.asarray(qd, dtype=float)
    n = len(q)
    dD = partials(lambda x: mass_matrix(model, x), q, method)
    C = np.zeros((n, n))
    for k in range(n):
        for j in range(n):
            C[k, j] = sum(0.5 * (dD[i][k, j] + dD[j][k, i] - dD[k][i, j])
                          * qd[i] for i in range(n))
    return C


def gravity_vector(model, q, method='complex'):
    """g(q) = dU/dq."""
    return np.array(partials(lambda x: potential_energy(model, x), q,
                             method))


def _vee(S):
    return np.array([S[2, 1] - S[1, 2], S[0, 2] - S[2, 0],
                     S[1, 0] - S[0, 1]]) / 2


def kinetic_energy(model, q, qd, method='complex'):
    """
    Kinetic energy from time derivatives of the forward kinematics.

    sum_j 1/2 m |v_c|^2 + 1/2 w^T R I R^T w, with v_c and w the time
    derivatives of the forward kinematics along qd (no Jacobians).
    """
    q = np.asarray(q, dtype=float)
    qd = np.asarray(qd, dtype=float)
    nb = len(model.joint_types)

    def poses(x):
        T, _ = forward_kinematics(model, x)
        return np.array([T[j + 1] for j in range(nb)])

    Ts = poses(q)
    Tdot = _directional(poses, q, qd, method)
    total = 0.0
    for j in range(nb):
        R = Ts[j, :3, :3]
        c = np.asarray(model.com[j])
        vc = Tdot[j, :3, :3] @ c + Tdot[j, :3, 3]
        w = _vee(Tdot[j, :3, :3] @ R.T)
        inertia = R @ np.asarray(model.inertia[j]) @ R.T
        total += 0.5 * model.mass[j] * (vc @ vc) + 0.5 * (w @ inertia @ w)
    return float(total)


def total_energy(model, q, qd, method='complex'):
    """T + U with T from ``kinetic_energy`` (FK time derivatives)."""
    return kinetic_energy(model, q, qd, method) + float(
        potential_energy(model, q))


def energy_rate(model, q, qd, qdd):
    """
    Return d/dt (T + U) along a motion through (q, qd) with acceleration qdd.

    Computed by one complex step of E = 1/2 qd^T D(q) qd + U(q) along
    (q + t qd, qd + t qdd): exact to round-off.
    """
    q = np.asarray(q, dtype=float)
    n = len(q)

    def energy(x):
        return 0.5 * x[n:] @ mass_matrix(model, x[:n]) @ x[n:] \
            + potential_energy(model, x[:n])

    return float(_directional(energy, np.concatenate([q, qd]),
                              np.concatenate([qd, qdd]), 'complex'))


# ---------------------------------------------------------------------------
# inverse dynamics
# ---------------------------------------------------------------------------
def wrench_in_base(model, q, wrench, wrench_frame='base'):
    """[f; n] re-expressed in base axes (moment still about the EE origin)."""
    F = np.asarray(wrench, dtype=float)
    if wrench_frame == 'base':
        return F
    R = ee_pose(model, q)[:3, :3]
    return np.concatenate([R @ F[:3], R @ F[3:]])


def inverse_dynamics(model, q, qd=None, qdd=None, wrench=None,
                     wrench_frame='base', method='complex'):
    """Lagrangian tau = D qdd + C qd + g + J^T F_e."""
    q = np.asarray(q, dtype=float)
    n = len(q)
    qd = np.zeros(n) if qd is None else np.asarray(qd, dtype=float)
    qdd = np.zeros(n) if qdd is None else np.asarray(qdd, dtype=float)
    tau = (mass_matrix(model, q) @ qdd
           + christoffel_coriolis(model, q, qd, method) @ qd
           + gravity_vector(model, q, method))
    if wrench is not None:
        F = wrench_in_base(model, q, wrench, wrench_frame)
        tau = tau + ee_jacobian(model, q).T @ F
    return tau
