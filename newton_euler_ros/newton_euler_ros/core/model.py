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
The constant robot model: a tree (or chain) of revolute and prismatic joints.

A :class:`RobotModel` is immutable after construction (its arrays are
read-only).  Per-call scratch memory lives in a separate
:class:`~newton_euler_ros.core.workspace.Workspace`.

The tree.  The model's moving joints are numbered parent first:
``model.parents[j] < j`` is the joint whose link carries joint j (-1: the
base), and a chain is the tree with ``parents[j] = j - 1``
(:mod:`~newton_euler_ros.core.tree`).  Mimic joints (``model.mimic``)
follow a leader and are not coordinates: ``model.joint_names`` lists the
n independent joints, ``model.moving_joints`` all nb moving joints, and
the per-joint arrays (types, placements, masses, limits) run over the
moving joints.  Below, "frame j-1" is the frame of joint j's parent.

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
- *link frame j* (j = 1..nb): the frame of link j, in which its centre of
  mass and inertia are given: for standard DH at the distal end of link
  j, for modified DH and URDF at joint j.
- *end-effector frame*: at pose ``tool`` in the link frame of joint
  ``tool_body`` (for URDF, the tip link's frame; a tree with several tips
  has none, ``tool_body`` None).
- *named frames* (``link_frames``, from URDF): every link of the tree,
  as (the joint whose link it is fixed to, -1 for the base; its pose in
  that link frame, or in frame 0).
"""
from dataclasses import dataclass, field
import functools
import math

import numpy as np

from . import kernels as K
from .inertia import inertia_matrix, merge_bodies  # noqa: F401 (re-export)
from .transforms import (axis_frame, evaluate_ops, Float64Math,  # noqa: F401
                         matrix_op, OPS, ops_matrix, pose_matrix, rpy_matrix)
from .tree import (chain_parents, check_tree, compile_arrays,  # noqa: F401
                   coordinates)
from .workspace import Workspace

REVOLUTE = 'revolute'
PRISMATIC = 'prismatic'
STANDARD = 'standard'
MODIFIED = 'modified'
URDF = 'urdf'
DH_CONVENTIONS = (STANDARD, MODIFIED)


def _readonly(x):
    x = np.array(x, dtype=np.float64)
    x.setflags(write=False)
    return x


# ---------------------------------------------------------------------------
def dh_ops(convention, a, alpha, d, theta):
    """Pre and Post operations of one DH row (see the module docstring)."""
    if convention == STANDARD:
        return (('rz', theta), ('tz', d)), (('tx', a), ('rx', alpha))
    return (('rx', alpha), ('tx', a), ('rz', theta), ('tz', d)), ()


@dataclass(frozen=True, eq=False)
class RobotModel:
    """
    A robot: a tree of joints, inertial parameters, gravity, frames.

    Build one with :func:`make_model` (DH), :func:`make_chain` (general
    joints, as URDF gives them),
    :func:`newton_euler_ros.core.robot_file.load_robot` or
    :func:`newton_euler_ros.core.urdf.load_urdf`.

    Attributes
    ----------
    name : str
    convention : ``'standard'``, ``'modified'`` (DH) or ``'urdf'``
    joint_names : tuple of n str, the independent joints (coordinates)
        in tree order (given to the constructors: all nb moving joints)
    moving_joints : tuple of nb str, every moving joint, mimic ones too
    parents : tuple of nb int, the parent joint of each (-1: the base)
    mimic : tuple of nb, None or (leader joint index, multiplier, offset)
    joint_types : tuple of nb ``'revolute'`` / ``'prismatic'``
    a, alpha, d, theta : (n,) DH parameters (m, rad, m, rad) of a DH
        model; the joint variable adds to ``theta`` (revolute) or ``d``
        (prismatic).  None for other models.
    joint_pre, joint_post : tuple of nb tuples of operations; joint_axis :
        (nb, 3) unit axes (see the module docstring).  Derived from the DH
        table for DH models.
    mass : (nb,) kg
    com : (nb, 3) centre of mass in link frame j, m
    inertia : (nb, 3, 3) about the centre of mass, link-frame axes, kg m^2
    gravity : (3,) gravitational acceleration in the base frame, m/s^2
    base : (4, 4) pose of frame 0 in the base frame
    tool : (4, 4) pose of the end-effector frame in link frame
        ``tool_body`` (frame 0 for -1)
    tool_body : int or None: the joint whose link carries the end
        effector (the last one of a chain); None: no end effector
    link_frames : dict, link name -> (joint index or -1, (4, 4) pose in
        that joint's link frame or in frame 0): the URDF's links
    limits : tuple of nb dicts (keys among lower, upper, velocity, effort)
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
    parents: tuple = None
    mimic: tuple = None
    tool_body: object = 'last'
    link_frames: dict = None
    moving_joints: tuple = field(init=False)
    links_array: np.ndarray = field(init=False, repr=False)
    frames_array: np.ndarray = field(init=False, repr=False)
    packed: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        names = tuple(self.joint_names)
        n = nb = len(names)
        parents, mimic = check_tree(
            names, chain_parents(nb) if self.parents is None
            else self.parents, self.mimic)
        independent, _ = coordinates(mimic)
        tool_body = nb - 1 if self.tool_body == 'last' else self.tool_body
        if tool_body is not None and not -1 <= int(tool_body) < nb:
            raise ValueError(f'tool_body must be -1 (the base), a joint '
                             f'index below {nb} or None, got {tool_body!r}')
        for key, value in (
                ('moving_joints', names), ('parents', parents),
                ('mimic', mimic),
                ('joint_names', tuple(names[j] for j in independent)),
                ('tool_body', None if tool_body is None else int(tool_body)),
                ('link_frames', _frames(self.link_frames, nb))):
            object.__setattr__(self, key, value)
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
                           _readonly(np.reshape(links, (nb, K.L_WIDTH))))
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
        """Return the number of coordinates (independent joints)."""
        return len(self.joint_names)

    @property
    def nb(self):
        """Return the number of moving joints (bodies), mimic ones too."""
        return len(self.moving_joints)

    @property
    def independent(self):
        """Return the index (in ``moving_joints``) of each coordinate."""
        return coordinates(self.mimic)[0]

    @property
    def is_chain(self):
        """Tell whether joint j's parent is j - 1 for all j, no mimic."""
        return (self.parents == chain_parents(self.nb)
                and self.n == self.nb)

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
        keys = ['name', 'convention', 'joint_types', 'a',
                'alpha', 'd', 'theta', 'mass', 'com', 'inertia', 'gravity',
                'base', 'tool', 'limits', 'info', 'tool_body']
        if not self.is_dh:
            keys += ['joint_pre', 'joint_axis', 'joint_post', 'parents',
                     'mimic', 'link_frames']
        fields = {k: getattr(self, k) for k in keys}
        fields['joint_names'] = self.moving_joints
        fields.update(changes)
        if fields['convention'] in DH_CONVENTIONS:
            return make_model(**fields)
        return make_chain(**{k: v for k, v in fields.items()
                             if k not in ('a', 'alpha', 'd', 'theta')})


def _frames(link_frames, nb):
    """Return the named frames, checked: name -> (joint, read-only 4x4)."""
    out = {}
    for name, (body, pose) in (link_frames or {}).items():
        body = int(body)
        if not -1 <= body < nb:
            raise ValueError(f'link frame {name!r}: joint index {body} is '
                             f'not -1 (the base) or below {nb}')
        pose = _readonly(pose)
        if pose.shape != (4, 4):
            raise ValueError(f'link frame {name!r}: the pose must be 4x4')
        out[str(name)] = (body, pose)
    return out


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
               base=None, tool=None, limits=None, info=None,
               tool_body='last'):
    """
    Build a DH :class:`RobotModel` (a chain) from plain sequences.

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
        tool_body=tool_body,
        **_common(n, name, joint_names, joint_types, mass, com, inertia,
                  gravity, base, tool, limits, info))


def make_chain(name, joint_names, joint_types, joint_pre, joint_axis,
               mass, com, inertia, joint_post=None, gravity=(0.0, 0.0, -9.81),
               base=None, tool=None, limits=None, info=None,
               convention=URDF, parents=None, mimic=None, tool_body='last',
               link_frames=None):
    """
    Build a :class:`RobotModel` from general joints (URDF-style), a tree.

    ``joint_names`` lists every moving joint, parent first;
    ``joint_pre[j]`` is a sequence of operations (see :data:`OPS`), or a
    4x4 matrix, placing joint j in its parent's link frame;
    ``joint_axis[j]`` a nonzero 3-vector (normalized here);
    ``joint_post`` defaults to identities.  ``parents`` (default: a
    chain), ``mimic``, ``tool_body`` and ``link_frames`` as the
    attributes of :class:`RobotModel`.
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
        joint_post=tuple(ops(x) for x in post), parents=parents,
        mimic=mimic, tool_body=tool_body, link_frames=link_frames,
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


def with_payload(model, mass, com, inertia, link=None):
    """
    Return the model with a rigid payload fixed to the end effector or a link.

    The payload (``mass`` kg, centre of mass ``com`` in the frame's axes
    and origin, ``inertia`` 3x3 about its centre of mass in the frame's
    axes) is merged into the body carrying the frame (the last link of a
    chain for the end effector) by the parallel-axis theorem, so the
    dynamics cost nothing extra.  The frame is the end effector, or
    ``link``, a name of ``model.link_frames`` (any link of a URDF tree: a
    gripper of a dual-arm robot).  A model without an end effector (a
    tree with several tips) and no ``link`` raises ValueError, as does an
    unknown link.
    """
    if not mass >= 0.0:
        raise ValueError(f'payload mass must be >= 0, got {mass}')
    if link:
        frames = model.link_frames or {}
        if link not in frames:
            raise ValueError(f'{model.name}: no link {link!r} to carry the '
                             f'payload')
        b, T = frames[link]
    else:
        b, T = model.tool_body, model.tool
    if b is None:
        raise ValueError(f'{model.name}: the model has no end effector (a '
                         f'tree with several tips): name the link that '
                         f'carries the payload, or load it with a tip link')
    if b < 0:       # a frame fixed to the base carries nothing
        return model
    T = np.asarray(T, dtype=np.float64)
    m, c, I_new = merge_bodies([
        (model.mass[b], model.com[b], model.inertia[b], np.eye(3),
         np.zeros(3)),
        (mass, com, inertia, T[:3, :3], T[:3, 3])])
    if m == 0.0:
        return model
    masses = np.array(model.mass)
    coms = np.array(model.com)
    inertias = np.array(model.inertia)
    masses[b], coms[b], inertias[b] = m, c, I_new
    return model.replace(mass=masses, com=coms, inertia=inertias)
