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
Peer-library models built from a :class:`~newton_euler_ros.core.RobotModel`.

Used by :mod:`newton_euler_tools.bench` to time the same robot in other
rigid-body dynamics libraries, and usable on its own to cross-check our
results against theirs.  Neither peer is a dependency of the package: every
builder imports its library lazily and raises ``ImportError`` when it is
missing.

Pinocchio (``import pinocchio``)
    One revolute (``JointModelRZ``) or prismatic (``JointModelPZ``) joint per
    DH row, each moving about the z axis of its own joint frame.

    *Standard DH*, ``A_j = Rz(theta_j + q_j) Tz(d_j) Tx(a_j) Rx(alpha_j)``
    (q_j in d_j instead for a prismatic joint):
    joint j moves about z_{j-1}, so the joint frame J_j is link frame j-1
    turned (or slid) by q_j about its own z axis, and link frame j is
    ``J_j X_j`` with the fixed
    ``X_j = Rz(theta_j) Tz(d_j) Tx(a_j) Rx(alpha_j)``
    (Rz and Tz commute, so this holds for both joint types).  Hence the
    placement of J_j in J_{j-1} is ``X_{j-1}`` (``base`` for the first
    joint), and the centre of mass and inertia of link j, given in link
    frame j, are carried into J_j by ``X_j``.

    *Modified DH*, ``A_j = Rx(alpha_j) Tx(a_j) Rz(theta_j + q_j) Tz(d_j)``:
    Rz(q) and Tz(d) commute too, so link frame j is
    ``frame_{j-1} Rx(alpha_j) Tx(a_j) Rz(theta_j) Tz(d_j) Rz(q_j)`` (or
    ``... Tz(d_j) Tz(q_j)`` for a prismatic joint): the joint
    frame *is* link frame j, its placement is that fixed product (preceded
    by ``base`` for the first joint) and the inertias go in unchanged.

    Gravity is ``model.gravity`` in the universe (= our base) frame.

Robotics Toolbox for Python (``import roboticstoolbox``)
    A ``DHRobot`` of ``RevoluteDH``/``PrismaticDH`` (standard) or
    ``RevoluteMDH``/``PrismaticMDH`` (modified) links with the same
    ``m``, ``r`` (centre of mass in link frame j) and ``I`` (about the centre
    of mass, link-frame axes) as ours, and no motor inertia, gearing or
    friction (``Jm = 0``, ``G = 1``, ``B = 0``, ``Tc = 0``).  Our ``theta``
    (revolute) or ``d`` (prismatic) becomes the toolbox's joint ``offset``.
"""
import math
import os

from newton_euler_ros.core.model import MODIFIED, REVOLUTE, STANDARD
import numpy as np


def _rz(theta):
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s, 0.0, 0.0], [s, c, 0.0, 0.0],
                     [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


def _rx(alpha):
    c, s = math.cos(alpha), math.sin(alpha)
    return np.array([[1.0, 0.0, 0.0, 0.0], [0.0, c, -s, 0.0],
                     [0.0, s, c, 0.0], [0.0, 0.0, 0.0, 1.0]])


def _trans(x, y, z):
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


def fixed_dh_transform(model, j):
    """
    Return the part of joint j's DH transform that does not move, 4x4.

    Standard: ``Rz(theta) Tz(d) Tx(a) Rx(alpha)``; modified:
    ``Rx(alpha) Tx(a) Rz(theta) Tz(d)`` (the joint variable then acts as
    a rotation or translation about/along the z axis of the joint frame,
    see the module docstring for where that frame sits).
    """
    a, alpha = float(model.a[j]), float(model.alpha[j])
    d, theta = float(model.d[j]), float(model.theta[j])
    if model.convention == STANDARD:
        return (_rz(theta) @ _trans(0.0, 0.0, d) @ _trans(a, 0.0, 0.0)
                @ _rx(alpha))
    return _rx(alpha) @ _trans(a, 0.0, 0.0) @ _rz(theta) @ _trans(0.0, 0.0, d)


def pinocchio_model(model):
    """
    Build a ``pinocchio.Model`` with the same dynamics as ``model``.

    Joint j of ours is Pinocchio joint ``j + 1`` (0 is the universe); the
    configuration and velocity vectors are the same as ours.
    """
    import pinocchio as pin

    pm = pin.Model()
    pm.name = model.name
    parent = 0
    for j in range(model.n):
        X = fixed_dh_transform(model, j)
        if model.convention == STANDARD:
            placement = (np.array(model.base) if j == 0
                         else fixed_dh_transform(model, j - 1))
            to_joint = X                    # link frame j in joint frame j
        else:
            placement = (np.array(model.base) @ X if j == 0 else X)
            to_joint = np.eye(4)
        R, p = to_joint[:3, :3], to_joint[:3, 3]
        com = R @ np.asarray(model.com[j]) + p
        inertia = R @ np.asarray(model.inertia[j]) @ R.T
        inertia = 0.5 * (inertia + inertia.T)
        joint = (pin.JointModelRZ() if model.joint_types[j] == REVOLUTE
                 else pin.JointModelPZ())
        jid = pm.addJoint(parent, joint,
                          pin.SE3(placement[:3, :3].copy(),
                                  placement[:3, 3].copy()),
                          model.joint_names[j])
        pm.appendBodyToJoint(jid, pin.Inertia(float(model.mass[j]), com,
                                              inertia), pin.SE3.Identity())
        parent = jid
    pm.gravity = pin.Motion(np.asarray(model.gravity, dtype=float),
                            np.zeros(3))
    return pm


def rtb_robot(model):
    """Build a ``roboticstoolbox.DHRobot`` with the same dynamics as ``model``."""
    import roboticstoolbox as rtb
    from spatialmath import SE3

    links = []
    for j in range(model.n):
        dyn = {'m': float(model.mass[j]), 'r': np.array(model.com[j]),
               'I': np.array(model.inertia[j]), 'Jm': 0.0, 'G': 1.0, 'B': 0.0,
               'Tc': np.zeros(2)}
        a, alpha = float(model.a[j]), float(model.alpha[j])
        d, theta = float(model.d[j]), float(model.theta[j])
        revolute = model.joint_types[j] == REVOLUTE
        if model.convention == MODIFIED:
            link = (rtb.RevoluteMDH(d=d, a=a, alpha=alpha, offset=theta, **dyn)
                    if revolute else
                    rtb.PrismaticMDH(theta=theta, a=a, alpha=alpha, offset=d,
                                     **dyn))
        else:
            link = (rtb.RevoluteDH(d=d, a=a, alpha=alpha, offset=theta, **dyn)
                    if revolute else
                    rtb.PrismaticDH(theta=theta, a=a, alpha=alpha, offset=d,
                                    **dyn))
        link.name = model.joint_names[j]
        links.append(link)
    robot = rtb.DHRobot(links, name=model.name,
                        base=SE3(np.array(model.base), check=False),
                        tool=SE3(np.array(model.tool), check=False),
                        gravity=np.array(model.gravity))
    return robot


def versions():
    """{library: version string, or 'unavailable: <reason>'}."""
    out = {}
    for label, module in (('pinocchio', 'pinocchio'),
                          ('roboticstoolbox', 'roboticstoolbox')):
        try:
            mod = __import__(module)
            out[label] = str(getattr(mod, '__version__', 'unknown'))
        except Exception as exc:  # ImportError, or a broken binary wheel
            out[label] = f'unavailable: {type(exc).__name__}: {exc}'
    return out


def example_robot_urdf(relative):
    """
    Path of a URDF shipped by the ``example-robot-data`` package.

    ``relative`` is below its ``robots`` folder, e.g.
    ``'ur_description/urdf/ur5_robot.urdf'``.  Raises ImportError when the
    package (installed by ``make peers``) is missing.
    """
    from importlib import metadata
    try:
        dist = metadata.distribution('example-robot-data')
    except metadata.PackageNotFoundError:
        raise ImportError('example-robot-data is not installed '
                          '(make peers)') from None
    root = dist.locate_file('cmeel.prefix/share/example-robot-data/robots')
    return os.path.join(str(root), relative)


class PinocchioUrdf:
    """
    Pinocchio's own reading of a URDF, reduced to our chain.

    ``pin.buildModelFromUrdf`` (fixed base), then ``pin.buildReducedModel``
    locks every joint that is not on the chain from ``base`` to ``tip`` at
    its neutral position: the reference for "off-chain subtrees lumped at
    zero".  Continuous joints take (cos q, sin q) in Pinocchio's
    configuration; :meth:`config` converts.  The base must be the URDF's
    root (Pinocchio's universe), so that both use the same axes.
    """

    def __init__(self, path, chain_joints, tip):
        import pinocchio as pin
        self.pin = pin
        full = pin.buildModelFromUrdf(path)
        lock = [i for i in range(1, full.njoints)
                if full.names[i] not in chain_joints]
        self.model = (pin.buildReducedModel(full, lock, pin.neutral(full))
                      if lock else full)
        self.data = self.model.createData()
        names = list(self.model.names)[1:]
        if names != list(chain_joints):
            raise ValueError(f'Pinocchio chain {names} is not {chain_joints}')
        self.frame = self.model.getFrameId(tip, pin.FrameType.BODY)

    def config(self, q):
        """Pinocchio's configuration vector of our joint positions."""
        out = self.pin.neutral(self.model)
        for j in range(1, self.model.njoints):
            joint = self.model.joints[j]
            if joint.nq == 2:       # continuous: cos, sin
                out[joint.idx_q] = math.cos(q[j - 1])
                out[joint.idx_q + 1] = math.sin(q[j - 1])
            else:
                out[joint.idx_q] = q[j - 1]
        return out

    def terms(self, q, qd, qdd, wrench):
        """tau, D, C, g, J (tip, world axes) and tau + J^T F_e."""
        pin = self.pin
        m, d = self.model, self.data
        x = self.config(q)
        tau = pin.rnea(m, d, x, qd, qdd).copy()
        D = pin.crba(m, d, x)
        D = np.triu(D) + np.triu(D, 1).T
        C = pin.computeCoriolisMatrix(m, d, x, qd).copy()
        g = pin.computeGeneralizedGravity(m, d, x).copy()
        pin.computeJointJacobians(m, d, x)
        pin.updateFramePlacements(m, d)
        J = pin.getFrameJacobian(m, d, self.frame,
                                 pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        return {'tau': tau, 'D': D, 'C': C, 'g': g, 'J': J.copy(),
                'tau_wrench': tau + J.T @ wrench}


class PinocchioTree:
    """
    Pinocchio's own reading of a whole URDF tree, as our tree model.

    ``pin.buildModelFromUrdf(path, mimic=True)`` (fixed base at the root
    link): mimic joints follow their leaders as in our model.  Joints are
    matched by name (Pinocchio orders a link's children by joint name, we
    by document order); continuous joints take (cos q, sin q).  ``full``
    is the same URDF without mimic coupling (every joint a coordinate),
    with ``G`` (nv_full x n) and ``offset`` mapping our coordinates to its
    own: Pinocchio 4.1's ``computeCoriolisMatrix`` is not the Christoffel
    matrix on a mimic model (C qd differs from the velocity-product
    torques there), so C is taken as G^T C_full(G q + o, G qd) G.
    """

    def __init__(self, path, model):
        import pinocchio as pin
        self.pin = pin
        self.ours = model
        self.model = pin.buildModelFromUrdf(path, mimic=True)
        self.data = self.model.createData()
        self.full = pin.buildModelFromUrdf(path)
        self.full_data = self.full.createData()
        ids = {self.model.names[i]: i for i in range(1, self.model.njoints)}
        self.joints = [self.model.joints[ids[name]]
                       for name in model.joint_names]
        self.iv = np.array([j.idx_v for j in self.joints])
        fids = {self.full.names[i]: i for i in range(1, self.full.njoints)}
        self.full_joints = [self.full.joints[fids[name]]
                            for name in model.moving_joints]
        self.G = np.zeros((self.full.nv, model.n))
        self.offset = np.zeros(self.full.nv)
        coord = {b: k for k, b in enumerate(model.independent)}
        for b, joint in enumerate(self.full_joints):
            lead, mult, off = ((b, 1.0, 0.0) if model.mimic[b] is None
                               else model.mimic[b])
            self.G[joint.idx_v, coord[lead]] = mult
            self.offset[joint.idx_v] = off

    @staticmethod
    def _put(out, joint, value):
        if joint.nq == 2:       # continuous: cos, sin
            out[joint.idx_q] = math.cos(value)
            out[joint.idx_q + 1] = math.sin(value)
        else:
            out[joint.idx_q] = value

    def config(self, q):
        """Pinocchio's configuration vector of our coordinates."""
        out = self.pin.neutral(self.model)
        for k, joint in enumerate(self.joints):
            self._put(out, joint, q[k])
        return out

    def full_config(self, q):
        """Return the mimic-free model's configuration: every angle."""
        x = self.G @ q + self.offset
        out = self.pin.neutral(self.full)
        for joint in self.full_joints:
            self._put(out, joint, x[joint.idx_v])
        return out

    def vector(self, x):
        """Return our coordinates (rates, torques) in Pinocchio's order."""
        out = np.zeros(self.model.nv)
        out[self.iv] = x
        return out

    def frame(self, link):
        return self.model.getFrameId(link, self.pin.FrameType.BODY)

    def terms(self, q, qd, qdd, links=()):
        """tau, D, C, g, qdd of D^-1 (tau - C qd - g), J of ``links``."""
        pin = self.pin
        m, d, iv = self.model, self.data, self.iv
        x, v, a = self.config(q), self.vector(qd), self.vector(qdd)
        tau = pin.rnea(m, d, x, v, a)[iv].copy()
        Dm = pin.crba(m, d, x).copy()
        Dm = (np.triu(Dm) + np.triu(Dm, 1).T)[np.ix_(iv, iv)]
        g = pin.computeGeneralizedGravity(m, d, x)[iv].copy()
        bias = pin.rnea(m, d, x, v, 0 * v)[iv].copy()
        xf, vf = self.full_config(q), self.G @ qd
        Cf = pin.computeCoriolisMatrix(self.full, self.full_data, xf, vf)
        Df = pin.crba(self.full, self.full_data, xf).copy()
        Df = np.triu(Df) + np.triu(Df, 1).T
        D = self.G.T @ Df @ self.G
        out = {'tau': tau, 'D': D, 'D mimic': Dm, 'g': g,
               'C': self.G.T @ Cf @ self.G,
               'fd': np.linalg.solve(D, tau - bias)}
        pin.computeJointJacobians(m, d, x)
        pin.updateFramePlacements(m, d)
        for link in links:
            for axes, ref in (('base', pin.ReferenceFrame.LOCAL_WORLD_ALIGNED),
                              ('link', pin.ReferenceFrame.LOCAL)):
                J = pin.getFrameJacobian(m, d, self.frame(link), ref)
                J = np.reshape(J, (6, -1))
                out[f'J {link} {axes}'] = J[:, iv].copy()
        return out

    def derivatives(self, q, qd, qdd, tau):
        """
        Pinocchio's analytical derivatives, rows and columns ours.

        ``computeRNEADerivatives`` on the mimic-free model at (G q + o,
        G qd, G qdd), mapped by G^T X G (tau of our coordinates is G^T
        tau_full): dtau/dq, dtau/dqd.  Without mimic joints also
        ``computeABADerivatives`` at (q, qd, tau): dqdd/dq, dqdd/dqd,
        dqdd/dtau (its Minv, the upper triangle mirrored); with them it
        has no counterpart (the constrained accelerations are not the
        free model's).
        """
        pin, G = self.pin, self.G
        dq, dv, _ = pin.computeRNEADerivatives(
            self.full, self.full_data, self.full_config(q), G @ qd, G @ qdd)
        out = {'dtau_dq': G.T @ dq @ G, 'dtau_dqd': G.T @ dv @ G}
        if self.full.nv != self.model.nv:
            return out
        ix = np.ix_(self.iv, self.iv)
        dq, dv, Minv = pin.computeABADerivatives(
            self.model, self.data, self.config(q), self.vector(qd),
            self.vector(tau))
        Minv = np.triu(Minv) + np.triu(Minv, 1).T
        out.update(dqdd_dq=dq[ix].copy(), dqdd_dqd=dv[ix].copy(),
                   dqdd_dtau=Minv[ix].copy())
        return out

    def regressor(self, q, qd, qdd):
        """
        ``pin.computeJointTorqueRegressor``, rows and body columns ours.

        It refuses mimic joints, so it runs on the mimic-free model at the
        same motion (G q + o, G qd, G qdd), its rows mapped by G^T.
        """
        pin = self.pin
        m = self.full
        Y = pin.computeJointTorqueRegressor(
            m, self.full_data, self.full_config(q), self.G @ qd,
            self.G @ qdd)
        ids = {m.names[i]: i for i in range(1, m.njoints)}
        cols = np.concatenate([np.arange(10 * (ids[name] - 1),
                                         10 * ids[name])
                               for name in self.ours.moving_joints])
        return self.G.T @ Y[:, cols]
