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
What a node may publish and accept: torque, velocity and wrench bounds.

ROS-free, shared by inverse_dynamics_node and robot_sim_node.

Torque bounds, per joint, in this order of precedence: the ``effort``
parameter list, the robot's own limits (robot file ``limits.effort`` or
URDF ``<limit effort>``), else a bound derived from the robot, for robots
that state none: twice the largest torque the arm needs to hold itself,
accelerate every joint at a brisk 20 rad/s^2 (or m/s^2) at once, and push
on its environment with its own weight W = m_total |g| (a force of W
along each axis and a moment of W times 10 cm about each), over 64
random configurations,

    bound_j = 2 max_q (|g_j| + 20 sum_k |D_jk| + sum_i |J_ij| w_i).

That is no actuator's rating, but no feedforward for a sane motion or
contact exceeds it, and it stops absurd values (1e200 N m) from reaching
an effort controller.  What happens above a bound is a choice
(:data:`ACTIONS`): ``clamp`` to the bound (the default, as ros2_control's
joint limiters do: a dropped feedforward would leave the controller on a
stale command), ``drop`` the message, or ``publish`` it anyway; every case
is counted.

Implausible inputs are rejected before the dynamics, like a NaN: a joint
speed above ``velocity_factor`` times the robot's velocity limit (or above
``max_velocity`` for joints without one), and a wrench whose force or
moment is beyond what ten times the largest torque bound could resist
through a 10 cm lever (force) or directly (moment).
"""
import numpy as np

from .core import gravity_torques, jacobian, mass_matrix

ACTIONS = ('clamp', 'drop', 'publish')
#: where a bound comes from (:func:`effort_bounds`), in words
BOUND_SOURCES = {'parameter': 'limits.effort',
                 'robot': "the robot's effort limits",
                 'derived': 'derived from the robot (it states none)'}
ACCELERATION = 20.0         # rad/s^2 (or m/s^2) for the derived bound
SAMPLES = 64


def joint_limits(model):
    """Return the limits of the model's coordinates (its independent joints)."""
    return [model.limits[b] for b in model.independent]


def _tips(model):
    """
    Frames that push on the environment: the end effector, or every leaf.

    A tree with several tips has no end effector; each leaf link (a body
    that carries no other) can push, so each one's Jacobian counts.
    """
    if model.tool_body is not None:
        return ['end_effector']
    carried = set(model.parents)
    return [name for name, (body, T) in (model.link_frames or {}).items()
            if body >= 0 and body not in carried
            and np.array_equal(T, np.eye(4))]


def derived_effort_bounds(model, seed=0):
    """Per-joint bounds for a robot without effort limits (see above)."""
    rng = np.random.default_rng(seed)
    limits = joint_limits(model)
    lo = np.array([lim.get('lower', -np.pi) for lim in limits])
    hi = np.array([lim.get('upper', np.pi) for lim in limits])
    weight = model.total_mass * float(np.linalg.norm(model.gravity))
    push = np.array([weight] * 3 + [0.1 * weight] * 3)
    need = np.zeros(model.n)
    tips = _tips(model)
    for _ in range(SAMPLES):
        q = rng.uniform(lo, hi)
        g = np.abs(gravity_torques(model, q))
        D = np.abs(mass_matrix(model, q))
        pushed = sum(np.abs(jacobian(model, q, tip, axes='base')).T @ push
                     for tip in tips)
        need = np.maximum(need, g + ACCELERATION * D.sum(axis=1) + pushed)
    return 2.0 * need


def effort_bounds(model, override=()):
    """
    Return (bounds, sources) in the model's joint order.

    ``override``: n positive values, or empty.  ``sources[j]`` says where
    bound j comes from: ``'parameter'``, ``'robot'`` or ``'derived'``.
    """
    n = model.n
    if len(override):
        values = np.asarray(override, dtype=np.float64)
        if values.shape != (n,) or not (np.isfinite(values).all()
                                        and (values > 0).all()):
            raise ValueError(f'limits.effort: must be {n} finite values > 0 '
                             f'(one per joint, output order), got '
                             f'{list(override)[:n + 1]}')
        return values, ['parameter'] * n
    bounds = np.array([lim.get('effort', np.nan)
                       for lim in joint_limits(model)],
                      dtype=np.float64).reshape(n)
    sources = ['robot' if np.isfinite(b) else 'derived' for b in bounds]
    if 'derived' in sources:
        derived = derived_effort_bounds(model)
        bounds = np.where(np.isfinite(bounds), bounds, derived)
    return bounds, sources


def velocity_bounds(model, factor=2.0, fallback=20.0):
    """Speeds above these are implausible (model order)."""
    vel = np.array([lim.get('velocity', np.nan)
                    for lim in joint_limits(model)],
                   dtype=np.float64).reshape(model.n)
    return np.where(np.isfinite(vel), factor * vel, fallback)


def wrench_bounds(bounds):
    """(force N, moment N m) beyond which a wrench is implausible."""
    top = float(np.max(bounds))
    return 10.0 * top / 0.1, 10.0 * top


class TorqueGuard:
    """
    Apply the torque bounds to outgoing torques (output order).

    :meth:`check` returns the torques to publish (clamped if so chosen)
    or None to drop the message, and whether a bound was exceeded;
    :meth:`over` names the joints above their bound.  ``names`` and
    ``units`` ('N m' or 'N') are the joints' (default: their indices).
    """

    def __init__(self, bounds, action='clamp', names=None, units=None):
        if action not in ACTIONS:
            raise ValueError(f'limits.action: must be one of '
                             f'{", ".join(ACTIONS)}, got {action!r}')
        self.bounds = np.asarray(bounds, dtype=np.float64)
        self.action = action
        n = self.bounds.size
        self.names = (list(names) if names is not None
                      else [f'joint {j}' for j in range(n)])
        self.units = list(units) if units is not None else ['N m/N'] * n

    def check(self, tau):
        """Return (torques or None, exceeded)."""
        over = np.abs(tau) > self.bounds
        if not over.any():
            return tau, False
        if self.action == 'drop':
            return None, True
        if self.action == 'clamp':
            return np.clip(tau, -self.bounds, self.bounds), True
        return tau, True

    def over(self, tau):
        """
        Return {joint: (torque asked, bound, unit)} above their bound.

        Only the joints over, in output order; empty within the bounds.
        """
        tau = np.asarray(tau, dtype=np.float64)
        return {self.names[j]: (float(tau[j]), float(self.bounds[j]),
                                self.units[j])
                for j in np.flatnonzero(np.abs(tau) > self.bounds)}

    def sub(self, names):
        """Return the guard of some joints (by name), in that order."""
        at = [self.names.index(name) for name in names]
        return TorqueGuard(self.bounds[at], self.action, names,
                           [self.units[k] for k in at])


def joint_units(model):
    """Return 'N m' or 'N' per coordinate (revolute or prismatic)."""
    return ['N' if model.joint_types[b] == 'prismatic' else 'N m'
            for b in model.independent]


def over_text(over):
    """Say the joints over their bound: 'j2 asked 31.2 N m, bound 12'."""
    return '; '.join(f'{name} asked {asked:.4g} {unit}, bound {bound:.4g}'
                     for name, (asked, bound, unit) in over.items())


class OverLimitLog:
    """
    Say the joints over their torque bound once per change of their set.

    :meth:`news` is True when ``over`` names another set of joints than
    the last one said (not when back within the bounds: a torque
    hovering at its bound is not said at every crossing).
    """

    def __init__(self):
        self.said = None

    def news(self, over):
        """Return whether ``over``'s joints should be said now."""
        joints = frozenset(over)
        if not joints or joints == self.said:
            return False
        self.said = joints
        return True
