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
The constant robot model: a serial chain in Denavit-Hartenberg form.

A :class:`RobotModel` is immutable after construction (its arrays are
read-only).  Per-call scratch memory lives in a separate
:class:`~newton_euler_ros.core.dynamics.Workspace`.

Frames and conventions (SI units throughout):

- *base frame*: the frame the robot is mounted in (``base_link`` in ROS).
  Gravity, wrenches in base axes and the Jacobian are expressed here.
- *frame 0*: the first DH frame, at pose ``base`` in the base frame.
- *link frame j* (j = 1..n): standard DH puts it at the distal end of link
  j, and joint j moves about z_{j-1}; modified (Craig) DH puts it at joint
  j, and joint j moves about z_j.
- *end-effector frame*: at pose ``tool`` in link frame n.
"""
from dataclasses import dataclass, field
import math

import numpy as np

from . import _kernels as K

REVOLUTE = 'revolute'
PRISMATIC = 'prismatic'
STANDARD = 'standard'
MODIFIED = 'modified'


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


@dataclass(frozen=True, eq=False)
class RobotModel:
    """
    A serial manipulator: DH table, inertial parameters, gravity, frames.

    Build one with :func:`make_model` or
    :func:`newton_euler_ros.core.robot_file.load_robot`.

    Attributes
    ----------
    name : str
    convention : ``'standard'`` or ``'modified'``
    joint_names : tuple of n str
    joint_types : tuple of n ``'revolute'`` / ``'prismatic'``
    a, alpha, d, theta : (n,) DH parameters (m, rad, m, rad); the joint
        variable adds to ``theta`` (revolute) or ``d`` (prismatic).
    mass : (n,) kg
    com : (n, 3) centre of mass in link frame j, m
    inertia : (n, 3, 3) about the centre of mass, link-frame axes, kg m^2
    gravity : (3,) gravitational acceleration in the base frame, m/s^2
    base : (4, 4) pose of frame 0 in the base frame
    tool : (4, 4) pose of the end-effector frame in link frame n
    limits : tuple of n dicts (keys among lower, upper, velocity, effort)
    links_array, frames_array : packed, read-only copies for the kernels

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
    links_array: np.ndarray = field(init=False, repr=False)
    frames_array: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        n = len(self.joint_names)
        links = np.zeros((n, K.L_WIDTH))
        for j in range(n):
            links[j, K.L_TYPE] = 0.0 if self.joint_types[j] == REVOLUTE else 1.0
            links[j, K.L_CONV] = 0.0 if self.convention == STANDARD else 1.0
            links[j, K.L_A] = self.a[j]
            links[j, K.L_CA] = math.cos(self.alpha[j])
            links[j, K.L_SA] = math.sin(self.alpha[j])
            links[j, K.L_D] = self.d[j]
            links[j, K.L_THETA] = self.theta[j]
            links[j, K.L_CT0] = math.cos(self.theta[j])
            links[j, K.L_ST0] = math.sin(self.theta[j])
            links[j, K.L_MASS] = self.mass[j]
            links[j, K.L_COM:K.L_COM + 3] = self.com[j]
            links[j, K.L_INERTIA:K.L_INERTIA + 9] = self.inertia[j].ravel()
        frames = np.zeros((K.F_ROWS, 12))
        frames[K.F_CONST, :len(K.CONSTANTS)] = K.CONSTANTS
        for row, T in ((K.F_BASE, self.base), (K.F_TOOL, self.tool)):
            frames[row, :9] = T[:3, :3].ravel()
            frames[row, 9:] = T[:3, 3]
        frames[K.F_GRAV, :3] = self.base[:3, :3].T @ self.gravity
        object.__setattr__(self, 'links_array', _readonly(links))
        object.__setattr__(self, 'frames_array', _readonly(frames))

    @property
    def n(self):
        """Return the number of joints (degrees of freedom)."""
        return len(self.joint_names)

    @property
    def total_mass(self):
        """Sum of the link masses, kg."""
        return float(self.mass.sum())

    def replace(self, **changes):
        """Return a copy with some fields changed (e.g. ``gravity=[0, 0, 0]``)."""
        fields = {k: getattr(self, k) for k in (
            'name', 'convention', 'joint_names', 'joint_types', 'a', 'alpha',
            'd', 'theta', 'mass', 'com', 'inertia', 'gravity', 'base',
            'tool', 'limits')}
        fields.update(changes)
        return make_model(**fields)


def make_model(name, convention, joint_names, joint_types, a, alpha, d,
               theta, mass, com, inertia, gravity=(0.0, 0.0, -9.81),
               base=None, tool=None, limits=None):
    """
    Build a :class:`RobotModel` from plain sequences.

    No validation of physical plausibility: :func:`load_robot` does that for
    files.
    """
    n = len(joint_names)
    if convention not in (STANDARD, MODIFIED):
        raise ValueError(f"convention must be 'standard' or 'modified', "
                         f'got {convention!r}')
    for t in joint_types:
        if t not in (REVOLUTE, PRISMATIC):
            raise ValueError(f"joint type must be 'revolute' or 'prismatic', "
                             f'got {t!r}')
    return RobotModel(
        name=str(name), convention=convention,
        joint_names=tuple(str(x) for x in joint_names),
        joint_types=tuple(str(t) for t in joint_types),
        a=_readonly(np.reshape(a, n)), alpha=_readonly(np.reshape(alpha, n)),
        d=_readonly(np.reshape(d, n)), theta=_readonly(np.reshape(theta, n)),
        mass=_readonly(np.reshape(mass, n)),
        com=_readonly(np.reshape(com, (n, 3))),
        inertia=_readonly(np.reshape(inertia, (n, 3, 3))),
        gravity=_readonly(np.reshape(gravity, 3)),
        base=_readonly(np.eye(4) if base is None else base),
        tool=_readonly(np.eye(4) if tool is None else tool),
        limits=(tuple(limits) if limits is not None
                else tuple({} for _ in range(n))))


def inertia_matrix(ixx, iyy, izz, ixy, iyz, ixz):
    """Symmetric 3x3 inertia from [Ixx, Iyy, Izz, Ixy, Iyz, Ixz]."""
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]],
                    dtype=np.float64)


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
    R_tool = model.tool[:3, :3]
    c_p = R_tool @ np.asarray(com, dtype=float) + model.tool[:3, 3]
    I_p = R_tool @ np.asarray(inertia, dtype=float) @ R_tool.T
    m_l = model.mass[-1]
    c_l = model.com[-1]
    m = m_l + mass
    if m == 0.0:
        return model
    c = (m_l * c_l + mass * c_p) / m

    def shifted(inertia_c, m_b, c_b):
        d = c_b - c
        return inertia_c + m_b * (d @ d * np.eye(3) - np.outer(d, d))

    I_new = shifted(model.inertia[-1], m_l, c_l) + shifted(I_p, mass, c_p)
    masses = np.array(model.mass)
    coms = np.array(model.com)
    inertias = np.array(model.inertia)
    masses[-1], coms[-1], inertias[-1] = m, c, I_new
    return model.replace(mass=masses, com=coms, inertia=inertias)
