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
The constant robot model: a serial chain of revolute and prismatic joints.

A :class:`RobotModel` is immutable after construction (its arrays are
read-only).  Per-call scratch memory lives in a separate
:class:`~newton_euler_ros.core.workspace.Workspace`.

One joint model for every source.  Joint j carries link frame j-1 to link
frame j as

    T_j(q) = Pre_j  M(axis_j, q)  Post_j

with ``Pre_j`` and ``Post_j`` constant transforms and ``M`` a rotation
about (revolute) or a translation along (prismatic) the unit ``axis_j``,
given in the frame ``Pre_j`` reaches.  The sources fill it in as:

- standard DH, ``Rz(theta + q) Tz(d) Tx(a) Rx(alpha)``: Pre = Rz(theta)
  Tz(d), axis z, Post = Tx(a) Rx(alpha) (a prismatic joint slides d);
- modified (Craig) DH, ``Rx(alpha) Tx(a) Rz(theta + q) Tz(d)``: Pre =
  Rx(alpha) Tx(a) Rz(theta) Tz(d), axis z, Post = identity;
- URDF: Pre = the joint's ``<origin>`` (after any fixed joints merged
  into it), axis = ``<axis>``, Post = identity.

``Pre`` and ``Post`` are kept as lists of elementary operations
(``('rz', theta)``, ``('xyz', x, y, z)``, ``('rpy', r, p, y)``, ...) so
that :func:`compile_arrays` can evaluate them in any number type: float64
for the kernels, mpmath for the 50-digit reference.  The compiled form the
kernels run on moves everything into *kernel frames* whose z axis is the
joint axis: kernel frame j = link frame j-1 . Pre_j . A_j . Rz(q) (or
Tz(q)), where A_j is a constant rotation taking z to ``axis_j``.  So the
per-call motion is a pure Rz(q) (cos q and sin q, never q + offset, so a
large |q| is not rounded first) or Tz(q); the constant ``A_j^T Post_j`` is
folded into the next joint's placement, the tool, and the link's
inertial parameters.

Frames and conventions (SI units throughout):

- *base frame*: the frame the robot is mounted in (``base_link`` in ROS).
  Gravity, wrenches in base axes and the Jacobian are expressed here.
- *frame 0*: the frame the first joint's placement starts from, at pose
  ``base`` in the base frame (identity for URDF robots).
- *link frame j* (j = 1..n): the frame of link j, in which its centre of
  mass and inertia are given: for standard DH at the distal end of link
  j, for modified DH and URDF at joint j.
- *end-effector frame*: at pose ``tool`` in link frame n (for URDF, the
  tip link's frame).
"""
from dataclasses import dataclass, field
import functools
import math

import numpy as np

from . import kernels as K
from .inertia import inertia_matrix, merge_bodies  # noqa: F401 (re-export)
from .workspace import Workspace

REVOLUTE = 'revolute'
PRISMATIC = 'prismatic'
STANDARD = 'standard'
MODIFIED = 'modified'
URDF = 'urdf'
DH_CONVENTIONS = (STANDARD, MODIFIED)


def rpy_matrix(roll, pitch, yaw):
    """Rotation of ROS roll-pitch-yaw angles: Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr]])


def pose_matrix(xyz=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0)):
    """4x4 homogeneous transform from a translation and ROS rpy angles."""
    T = np.eye(4)
    T[:3, :3] = rpy_matrix(*rpy)
    T[:3, 3] = xyz
    return T


def _readonly(x):
    x = np.array(x, dtype=np.float64)
    x.setflags(write=False)
    return x


# ---------------------------------------------------------------------------
# elementary transforms, in any number type
# ---------------------------------------------------------------------------
class Float64Math:
    """The number type of the kernels: float64 with ``math``."""

    cos = staticmethod(math.cos)
    sin = staticmethod(math.sin)
    sqrt = staticmethod(math.sqrt)
    num = staticmethod(float)


OPS = {'tx': 1, 'ty': 1, 'tz': 1, 'rx': 1, 'ry': 1, 'rz': 1, 'xyz': 3,
       'rpy': 3, 'matrix': 12}


def _identity(m):
    z, o = m.num(0.0), m.num(1.0)
    return [[o, z, z], [z, o, z], [z, z, o]], [z, z, z]


def _mul(A, B):
    return [[A[i][0] * B[0][k] + A[i][1] * B[1][k] + A[i][2] * B[2][k]
             for k in range(3)] for i in range(3)]


def _apply(A, x):
    return [A[i][0] * x[0] + A[i][1] * x[1] + A[i][2] * x[2]
            for i in range(3)]


def _compose(X, Y):
    """(R1, p1) . (R2, p2) = (R1 R2, p1 + R1 p2)."""
    (R1, p1), (R2, p2) = X, Y
    t = _apply(R1, p2)
    return _mul(R1, R2), [p1[i] + t[i] for i in range(3)]


def _transpose(A):
    return [[A[k][i] for k in range(3)] for i in range(3)]


def _elementary(op, args, m):
    """(R, p) of one operation, in the number type of ``m``."""
    R, p = _identity(m)
    if op in ('tx', 'ty', 'tz'):
        p['xyz'.index(op[1])] = m.num(args[0])
    elif op in ('rx', 'ry', 'rz'):
        c, s = m.cos(m.num(args[0])), m.sin(m.num(args[0]))
        i = 'xyz'.index(op[1])
        a, b = (i + 1) % 3, (i + 2) % 3
        R[a][a], R[a][b], R[b][a], R[b][b] = c, -s, s, c
    elif op == 'xyz':
        p = [m.num(x) for x in args]
    elif op == 'rpy':
        for angle, axis in zip(args[::-1], 'zyx'):
            R = _mul(R, _elementary('r' + axis, (angle,), m)[0])
    elif op == 'matrix':
        R = [[m.num(args[3 * i + k]) for k in range(3)] for i in range(3)]
        p = [m.num(x) for x in args[9:]]
    else:
        raise ValueError(f'unknown transform operation {op!r}')
    return R, p


def evaluate_ops(ops, m=Float64Math):
    """Compose a list of elementary operations into (R, p)."""
    X = _identity(m)
    for op in ops:
        X = _compose(X, _elementary(op[0], op[1:], m))
    return X


def matrix_op(T):
    """Return the operation ``('matrix', ...)`` of a 4x4 transform."""
    T = np.asarray(T, dtype=np.float64)
    return ('matrix',) + tuple(float(x) for x in T[:3, :3].ravel()) + tuple(
        float(x) for x in T[:3, 3])


def ops_matrix(ops):
    """4x4 float64 transform of a list of operations."""
    R, p = evaluate_ops(ops)
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


def axis_frame(axis, m=Float64Math):
    """
    Return a rotation A with A z = axis (a unit vector).

    Exact for +-x, +-y and +-z.

    For axis_z >= 0 it is the rotation about z x axis (Rodrigues, written
    with k = 1 / (1 + z)); for axis_z < 0, A(-axis) Rx(pi), which keeps
    1 + z away from zero.
    """
    x, y, z = (m.num(v) for v in axis)
    o = m.num(1.0)
    if z >= 0:
        k = o / (o + z)
        return [[o - x * x * k, -(x * y * k), x],
                [-(x * y * k), o - y * y * k, y],
                [-x, -y, z]]
    k = o / (o - z)
    return [[o - x * x * k, x * y * k, x],
            [-(x * y * k), -(o - y * y * k), y],
            [x, -y, z]]


def compile_arrays(model, m=Float64Math):
    """
    Compile a model into its kernel arrays, in the number type of ``m``.

    Returns ``(links, frames)`` as nested lists (``links``: n rows of
    ``K.L_WIDTH``; ``frames``: ``K.F_ROWS`` rows of 12).  See the module
    docstring for the kernel frames: row j holds joint j's placement
    P_j = B_{j-1} Pre_j A_j (B_{j-1} = A_{j-1}^T Post_{j-1}, the pose of
    link frame j-1 in kernel frame j-1), the link's mass, centre of mass
    and inertia re-expressed in kernel frame j, and B_j itself (for
    poses of the link frames).
    """
    n = model.n
    z = m.num(0.0)
    B_prev = _identity(m)
    links = []
    for j in range(n):
        A = axis_frame(model.joint_axis[j], m)
        pre = evaluate_ops(model.joint_pre[j], m)
        P = _compose(_compose(B_prev, pre), (A, [z, z, z]))
        B = _compose((_transpose(A), [z, z, z]),
                     evaluate_ops(model.joint_post[j], m))
        RB, pB = B
        c = [m.num(v) for v in model.com[j]]
        t = _apply(RB, c)
        com = [t[i] + pB[i] for i in range(3)]
        inertia = [[m.num(v) for v in row] for row in model.inertia[j]]
        inertia = _mul(_mul(RB, inertia), _transpose(RB))
        row = [z] * K.L_WIDTH
        row[K.L_TYPE] = m.num(0.0 if model.joint_types[j] == REVOLUTE
                              else 1.0)
        row[K.L_R:K.L_R + 9] = [x for r in P[0] for x in r]
        row[K.L_P:K.L_P + 3] = P[1]
        row[K.L_MASS] = m.num(model.mass[j])
        row[K.L_COM:K.L_COM + 3] = com
        row[K.L_INERTIA:K.L_INERTIA + 9] = [x for r in inertia for x in r]
        row[K.L_BODY:K.L_BODY + 9] = [x for r in RB for x in r]
        row[K.L_BODY + 9:K.L_BODY + 12] = pB
        links.append(row)
        B_prev = B
    tool = _compose(B_prev, evaluate_ops([matrix_op(model.tool)], m))
    base = evaluate_ops([matrix_op(model.base)], m)
    frames = [[z] * 12 for _ in range(K.F_ROWS)]
    frames[K.F_CONST][:len(K.CONSTANTS)] = [m.num(c) for c in K.CONSTANTS]
    for row, (R, p) in ((K.F_BASE, base), (K.F_TOOL, tool)):
        frames[row][:9] = [x for r in R for x in r]
        frames[row][9:] = p
    g = [m.num(v) for v in model.gravity]
    frames[K.F_GRAV][:3] = _apply(_transpose(base[0]), g)
    return links, frames


def dh_ops(convention, a, alpha, d, theta):
    """Pre and Post operations of one DH row (see the module docstring)."""
    if convention == STANDARD:
        return (('rz', theta), ('tz', d)), (('tx', a), ('rx', alpha))
    return (('rx', alpha), ('tx', a), ('rz', theta), ('tz', d)), ()


@dataclass(frozen=True, eq=False)
class RobotModel:
    """
    A serial manipulator: joints, inertial parameters, gravity, frames.

    Build one with :func:`make_model` (DH), :func:`make_chain` (general
    joints, as URDF gives them),
    :func:`newton_euler_ros.core.robot_file.load_robot` or
    :func:`newton_euler_ros.core.urdf.load_urdf`.

    Attributes
    ----------
    name : str
    convention : ``'standard'``, ``'modified'`` (DH) or ``'urdf'``
    joint_names : tuple of n str
    joint_types : tuple of n ``'revolute'`` / ``'prismatic'``
    a, alpha, d, theta : (n,) DH parameters (m, rad, m, rad) of a DH
        model; the joint variable adds to ``theta`` (revolute) or ``d``
        (prismatic).  None for other models.
    joint_pre, joint_post : tuple of n tuples of operations; joint_axis :
        (n, 3) unit axes (see the module docstring).  Derived from the DH
        table for DH models.
    mass : (n,) kg
    com : (n, 3) centre of mass in link frame j, m
    inertia : (n, 3, 3) about the centre of mass, link-frame axes, kg m^2
    gravity : (3,) gravitational acceleration in the base frame, m/s^2
    base : (4, 4) pose of frame 0 in the base frame
    tool : (4, 4) pose of the end-effector frame in link frame n
    limits : tuple of n dicts (keys among lower, upper, velocity, effort)
    info : dict of source details (e.g. URDF link names); not dynamics
    links_array, frames_array : read-only copies for the kernels
    packed : both in one read-only array, as the kernels' entry points
        take them (``kernels.pack``)

    """

    name: str
    convention: str
    joint_names: tuple
    joint_types: tuple
    a: np.ndarray
    alpha: np.ndarray
    d: np.ndarray
    theta: np.ndarray
    mass: np.ndarray
    com: np.ndarray
    inertia: np.ndarray
    gravity: np.ndarray
    base: np.ndarray
    tool: np.ndarray
    limits: tuple = ()
    joint_pre: tuple = None
    joint_axis: np.ndarray = None
    joint_post: tuple = None
    info: dict = None
    links_array: np.ndarray = field(init=False, repr=False)
    frames_array: np.ndarray = field(init=False, repr=False)
    packed: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        n = len(self.joint_names)
        if self.convention in DH_CONVENTIONS:
            pre, post = zip(*(dh_ops(self.convention, self.a[j],
                                     self.alpha[j], self.d[j], self.theta[j])
                              for j in range(n))) if n else ((), ())
            object.__setattr__(self, 'joint_pre', tuple(pre))
            object.__setattr__(self, 'joint_post', tuple(post))
            object.__setattr__(self, 'joint_axis',
                               _readonly(np.tile([0.0, 0.0, 1.0], (n, 1))))
        if self.info is None:
            object.__setattr__(self, 'info', {})
        links, frames = compile_arrays(self)
        object.__setattr__(self, 'links_array',
                           _readonly(np.reshape(links, (n, K.L_WIDTH))))
        object.__setattr__(self, 'frames_array', _readonly(frames))
        object.__setattr__(self, 'packed', _readonly(
            K.pack(self.links_array, self.frames_array)))

    @functools.cached_property
    def default_workspace(self):
        """
        Return the workspace every dynamics call without ``ws=`` uses.

        Created on first use and shared by all such calls on this model:
        not thread-safe (give each thread its own ``Workspace(model)``).
        """
        return Workspace(self)

    @property
    def n(self):
        """Return the number of joints (degrees of freedom)."""
        return len(self.joint_names)

    @property
    def total_mass(self):
        """Sum of the link masses, kg."""
        return float(self.mass.sum())

    @property
    def is_dh(self):
        """Return True for a model given by a DH table."""
        return self.convention in DH_CONVENTIONS

    def joint_pre_matrix(self, j):
        """4x4 float64 Pre transform of joint j."""
        return ops_matrix(self.joint_pre[j])

    def joint_post_matrix(self, j):
        """4x4 float64 Post transform of joint j."""
        return ops_matrix(self.joint_post[j])

    def replace(self, **changes):
        """Return a copy with some fields changed (e.g. ``gravity=[0, 0, 0]``)."""
        keys = ['name', 'convention', 'joint_names', 'joint_types', 'a',
                'alpha', 'd', 'theta', 'mass', 'com', 'inertia', 'gravity',
                'base', 'tool', 'limits', 'info']
        if not self.is_dh:
            keys += ['joint_pre', 'joint_axis', 'joint_post']
        fields = {k: getattr(self, k) for k in keys}
        fields.update(changes)
        if fields['convention'] in DH_CONVENTIONS:
            return make_model(**fields)
        return make_chain(**{k: v for k, v in fields.items()
                             if k not in ('a', 'alpha', 'd', 'theta')})


def _check_types(joint_types):
    for t in joint_types:
        if t not in (REVOLUTE, PRISMATIC):
            raise ValueError(f"joint type must be 'revolute' or 'prismatic', "
                             f'got {t!r}')


def _common(n, name, joint_names, joint_types, mass, com, inertia, gravity,
            base, tool, limits, info):
    return {
        'name': str(name),
        'joint_names': tuple(str(x) for x in joint_names),
        'joint_types': tuple(str(t) for t in joint_types),
        'mass': _readonly(np.reshape(mass, n)),
        'com': _readonly(np.reshape(com, (n, 3))),
        'inertia': _readonly(np.reshape(inertia, (n, 3, 3))),
        'gravity': _readonly(np.reshape(gravity, 3)),
        'base': _readonly(np.eye(4) if base is None else base),
        'tool': _readonly(np.eye(4) if tool is None else tool),
        'limits': (tuple(limits) if limits is not None
                   else tuple({} for _ in range(n))),
        'info': dict(info or {})}


def make_model(name, convention, joint_names, joint_types, a, alpha, d,
               theta, mass, com, inertia, gravity=(0.0, 0.0, -9.81),
               base=None, tool=None, limits=None, info=None):
    """
    Build a DH :class:`RobotModel` from plain sequences.

    No validation of physical plausibility: :func:`load_robot` does that for
    files.
    """
    n = len(joint_names)
    if convention not in DH_CONVENTIONS:
        raise ValueError(f"convention must be 'standard' or 'modified', "
                         f'got {convention!r}')
    _check_types(joint_types)
    return RobotModel(
        convention=convention,
        a=_readonly(np.reshape(a, n)), alpha=_readonly(np.reshape(alpha, n)),
        d=_readonly(np.reshape(d, n)), theta=_readonly(np.reshape(theta, n)),
        **_common(n, name, joint_names, joint_types, mass, com, inertia,
                  gravity, base, tool, limits, info))


def make_chain(name, joint_names, joint_types, joint_pre, joint_axis,
               mass, com, inertia, joint_post=None, gravity=(0.0, 0.0, -9.81),
               base=None, tool=None, limits=None, info=None,
               convention=URDF):
    """
    Build a :class:`RobotModel` from general joints (URDF-style).

    ``joint_pre[j]`` is a sequence of operations (see :data:`OPS`), or a
    4x4 matrix; ``joint_axis[j]`` a nonzero 3-vector (normalized here);
    ``joint_post`` defaults to identities.
    """
    n = len(joint_names)
    _check_types(joint_types)

    def ops(x):
        if isinstance(x, np.ndarray) and x.shape == (4, 4):
            return (matrix_op(x),)
        out = []
        for op in x:
            op = tuple(op)
            if op[0] not in OPS or len(op) != OPS[op[0]] + 1:
                raise ValueError(f'bad transform operation {op!r}')
            out.append((op[0],) + tuple(float(v) for v in op[1:]))
        return tuple(out)

    axes = np.array(joint_axis, dtype=np.float64).reshape(n, 3)
    for j in range(n):
        norm = math.sqrt(float(axes[j] @ axes[j]))
        if not norm > 0.0 or not math.isfinite(norm):
            raise ValueError(f'joint {joint_names[j]!r}: axis must be a '
                             f'nonzero finite vector, got {axes[j].tolist()}')
        if norm != 1.0:
            axes[j] = axes[j] / norm
    post = joint_post if joint_post is not None else [()] * n
    return RobotModel(
        convention=convention, a=None, alpha=None, d=None, theta=None,
        joint_pre=tuple(ops(x) for x in joint_pre),
        joint_axis=_readonly(axes),
        joint_post=tuple(ops(x) for x in post),
        **_common(n, name, joint_names, joint_types, mass, com, inertia,
                  gravity, base, tool, limits, info))


def _tx_rx(a, alpha):
    """Homogeneous Tx(a) Rx(alpha)."""
    ca, sa = math.cos(alpha), math.sin(alpha)
    return np.array([[1.0, 0.0, 0.0, a], [0.0, ca, -sa, 0.0],
                     [0.0, sa, ca, 0.0], [0.0, 0.0, 0.0, 1.0]])


def convert_convention(model, convention):
    """
    Return the same robot written in the given DH convention.

    The chain ``Rz Tz Tx Rx | Rz Tz Tx Rx | ...`` (standard) regroups as
    ``Rz Tz | Tx Rx Rz Tz | ... | Tx Rx`` (modified): modified link frame j
    is standard frame j without its trailing ``Tx(a_j) Rx(alpha_j)``, which
    moves into the next row (the last one into the tool).  Centres of mass
    and inertias are re-expressed in the new link frames, so the dynamics
    are identical.
    """
    if convention == model.convention:
        return model
    n = model.n
    com = np.array(model.com)
    inertia = np.array(model.inertia)
    a = np.zeros(n)
    alpha = np.zeros(n)
    base = np.array(model.base)
    tool = np.array(model.tool)
    if convention == MODIFIED:
        # X_j = Tx(a_j) Rx(alpha_j) maps standard frame j into modified j.
        for j in range(n):
            X = _tx_rx(model.a[j], model.alpha[j])
            com[j] = X[:3, :3] @ model.com[j] + X[:3, 3]
            inertia[j] = X[:3, :3] @ model.inertia[j] @ X[:3, :3].T
            if j + 1 < n:
                a[j + 1], alpha[j + 1] = model.a[j], model.alpha[j]
            else:
                tool = X @ model.tool
    elif convention == STANDARD:
        # the first row's Rx(alpha_0) Tx(a_0) moves into the base pose
        # (Rx(alpha) Tx(a) = Tx(a) Rx(alpha): both act along x)
        base = base @ _tx_rx(model.a[0], model.alpha[0])
        for j in range(n):
            if j + 1 < n:
                a[j], alpha[j] = model.a[j + 1], model.alpha[j + 1]
            X = _tx_rx(a[j], alpha[j])
            Xinv = np.linalg.inv(X)
            com[j] = Xinv[:3, :3] @ model.com[j] + Xinv[:3, 3]
            inertia[j] = Xinv[:3, :3] @ model.inertia[j] @ Xinv[:3, :3].T
        tool = np.linalg.inv(_tx_rx(a[n - 1], alpha[n - 1])) @ model.tool
    else:
        raise ValueError(f"convention must be 'standard' or 'modified', "
                         f'got {convention!r}')
    return model.replace(convention=convention, a=a, alpha=alpha, com=com,
                         inertia=inertia, base=base, tool=tool)


def with_payload(model, mass, com, inertia):
    """
    Return the model with a rigid payload fixed to the end effector.

    The payload (``mass`` kg, centre of mass ``com`` in end-effector axes
    and origin, ``inertia`` 3x3 about its centre of mass in end-effector
    axes) is merged into the last link by the parallel-axis theorem, so the
    dynamics cost nothing extra.
    """
    if not mass >= 0.0:
        raise ValueError(f'payload mass must be >= 0, got {mass}')
    m, c, I_new = merge_bodies([
        (model.mass[-1], model.com[-1], model.inertia[-1], np.eye(3),
         np.zeros(3)),
        (mass, com, inertia, model.tool[:3, :3], model.tool[:3, 3])])
    if m == 0.0:
        return model
    masses = np.array(model.mass)
    coms = np.array(model.com)
    inertias = np.array(model.inertia)
    masses[-1], coms[-1], inertias[-1] = m, c, I_new
    return model.replace(mass=masses, com=coms, inertia=inertias)
