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
The terms of the dynamics a robot's situation has, and their torques.

:class:`Effects` says which terms exist (gravity, velocity products, a
payload, an end-effector wrench, joint friction, rotor inertia);
:class:`EffectDynamics` evaluates exactly those, paying for nothing else:
without gravity the recursion skips it, without velocity products it
skips every velocity term, without a wrench no Jacobian is formed, and
friction and rotor inertia are added only when present.  The wrench is
always an argument: where it comes from (a scene's schedule, a live
topic) is the caller's business.  The nodes' live torques and the
simulator (:mod:`newton_euler_ros.sim`) both use it.
"""
from dataclasses import dataclass

import numpy as np

from .dynamics import inverse_dynamics, mass_matrix, solve_mass_matrix
from .workspace import Workspace


@dataclass(frozen=True)
class Effects:
    """Which terms of the dynamics are present."""

    gravity: bool = True
    velocity_products: bool = True
    payload: bool = False
    wrench: bool = False
    friction: bool = False
    armature: bool = False

    def names(self):
        """Return the enabled effects, in a fixed order."""
        return [k for k in ('gravity', 'velocity_products', 'payload',
                            'wrench', 'friction', 'armature')
                if getattr(self, k)]


#: every rigid-body term and the wrench: what the node computes without
#: a scene
RIGID_BODY = Effects(wrench=True)


def friction_torque(joints, qd):
    """
    Return the friction torque the joints lose: viscous qd + Coulomb sign(qd).

    ``joints`` has per-joint ``viscous`` and ``coulomb`` arrays (a scene or
    an :class:`EffectDynamics`); ``qd`` is one state (n,) or many (m, n).
    """
    return joints.viscous * qd + joints.coulomb * np.sign(qd)


class EffectDynamics:
    """
    Inverse and forward dynamics with exactly the given effects.

    ``viscous``, ``coulomb`` (friction) and ``armature`` (rotor inertia
    reflected to the joint) are per-joint arrays, zeros by default; they
    act only when ``effects`` has friction or armature.  Every method that
    can involve a wrench takes it as an argument (None: none), in
    ``frame`` 'base' or 'end_effector'; it is ignored, and no Jacobian is
    formed, unless ``effects.wrench``.  Owns a reusable workspace ``ws``.
    """

    def __init__(self, model, effects=RIGID_BODY, viscous=None,
                 coulomb=None, armature=None):
        n = model.n
        self.model = model
        self.effects = effects
        self.viscous = np.zeros(n) if viscous is None else viscous
        self.coulomb = np.zeros(n) if coulomb is None else coulomb
        self.armature = np.zeros(n) if armature is None else armature
        self.ws = Workspace(model)
        self._D = np.zeros((n, n))

    def friction(self, qd):
        """Friction torque the joints lose (:func:`friction_torque`)."""
        return friction_torque(self, qd)

    def torques(self, q, qd, qdd, wrench=None, frame='base', out=None):
        """Return the inverse dynamics with the effects; qdd may be None."""
        eff = self.effects
        if not eff.wrench:
            wrench = None
        tau = inverse_dynamics(self.model, q, qd, qdd, wrench, frame,
                               gravity=eff.gravity,
                               velocity_products=eff.velocity_products,
                               ws=self.ws, out=out)
        if eff.armature and qdd is not None:
            tau += self.armature * qdd
        if eff.friction:
            tau += self.friction(qd)
        return tau

    def mass_matrix(self, q, out=None):
        """D(q), plus the rotor inertia on its diagonal with armature."""
        D = mass_matrix(self.model, q, ws=self.ws, out=out)
        if self.effects.armature:
            D.flat[::D.shape[0] + 1] += self.armature
        return D

    def accelerations(self, q, qd, tau, wrench=None, frame='base'):
        """Forward dynamics: qdd for applied torques ``tau``."""
        bias = self.torques(q, qd, None, wrench, frame)
        D = self.mass_matrix(q, out=self._D)
        return solve_mass_matrix(self.model, q, D, tau - bias, ws=self.ws)
