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
Whether efforts are what the model says: torques, or currents times K.

``JointState.effort`` is a joint torque for some drivers (Franka, KUKA
FRI) and a motor current for others (UR's ROS 2 driver by default,
Dynamixel-based arms).  Per joint j, the least-squares ratio K_j of the
model's torque to the effort, both less an offset, a viscous and a
Coulomb column (the friction a published URDF lacks), is about 1 for
torques and about the torque constant for currents.  A joint counts when
the two agree in shape (squared correlation at least ``MIN_EXPLAINED``);
the efforts are refused as torques when at least half of the joints that
count lie outside ``TORQUE_BAND``, and as anything proportional to
torque when a joint that counts has a negative ratio.

:func:`sample_ratios` and :func:`describe` are the test (``identify``,
``replay``, ``observe`` and ``payload`` use them through
``ident.effort``); :class:`EffortMonitor` runs it on a live stream (the
node's observer), window after window of motion.
"""
import math

import numpy as np

TORQUE_BAND = (0.4, 2.5)
MIN_EXPLAINED = 0.5


def sample_ratios(tau, effort, qd, width=0.02):
    """
    Per joint: (K, explained) of the ratio, from (m, n) samples.

    The model's torque ``tau`` against the ``effort`` at speeds ``qd``,
    both less their projection on an offset, viscous and Coulomb (tanh of
    ``width``) column per joint; the effort is regressed on the torque,
    e = t / K (noise and stiction in the effort do not bias K), and
    ``explained`` is the squared correlation of the two.
    """
    n = tau.shape[1]
    K = np.zeros(n)
    explained = np.zeros(n)
    for j in range(n):
        v = qd[:, j]
        Q, _ = np.linalg.qr(np.column_stack(
            [np.ones_like(v), v, np.tanh(v / width)]))
        t = tau[:, j] - Q @ (Q.T @ tau[:, j])
        e = effort[:, j] - Q @ (Q.T @ effort[:, j])
        te, tt, ee = float(t @ e), float(t @ t), float(e @ e)
        if tt > 0 and ee > 0 and te != 0:
            K[j] = tt / te
            explained[j] = te * te / (tt * ee)
    return K, explained


def _cells(names, K, sel):
    return ', '.join(f'{names[j]} {K[j]:.3g}' for j in np.flatnonzero(sel))


#: what to do about currents taken for torques (``identify``'s option)
CURRENT_FIX = "if the driver reports motor currents (UR's default), add " \
    '--effort current'

#: the end of the line for a user of the URDF as it is
URDF_FIX = ("if the driver reports motor currents (UR's default), the URDF "
            'needs their torque_constant (identify --effort current writes '
            'it)')


def describe(label, names, K, explained, mode, urdf=None, fix=CURRENT_FIX):
    """
    Return the one line saying the efforts cannot be ``mode``, or None.

    ``mode``: 'torque' (efforts in N m), 'given' (efforts times the
    URDF's torque constants, ``urdf`` names it) or 'current' (efforts
    proportional to torque with unknown constants).  ``fix``: the end of
    the line for efforts that are not torques.
    """
    counts = explained >= MIN_EXPLAINED
    negative = counts & (K < 0)
    if negative.any():
        return (f"{label}: the effort has the opposite sign of the model's "
                f'torque on {_cells(names, K, negative)} (least-squares '
                f"ratio model torque / effort): check the driver's sign "
                f'convention and the joint names')
    if mode == 'current' or counts.sum() == 0:
        return None
    lo, hi = TORQUE_BAND
    off = counts & ((K < lo) | (K > hi))
    if off.sum() * 2 < counts.sum():
        return None
    ratio = _cells(names, K, off)
    if mode == 'given':
        return (f'{label}: the efforts do not match the torque constants '
                f'of {urdf}: model torque / (torque_constant x effort) is '
                f'{ratio} (near 1 expected); fix or remove the '
                f'torque_constant attributes')
    return (f'{label}: the efforts are not joint torques in N m: model '
            f'torque / effort is {ratio} (least-squares ratio per joint, '
            f'near 1 for torques); {fix}')


#: a held arm: every joint slower than this (rad/s)
HELD_SPEED = 0.02
#: at rest a joint counts when its gravity torque is at least this fraction
#: of the largest joint's (static friction holds up to a few N m anywhere)
REST_GRAVITY = 0.25


def rest_ratios(qd, gravity, effort):
    """
    Per joint (K, counts): gravity torque / effort where the arm holds still.

    ``qd`` speeds, ``gravity`` the model's g(q) (N m) and ``effort`` (in
    the unit the model says) at the samples.  A held arm's effort is g(q)
    plus what static friction holds (within +-F_s, any sign): the effort
    regressed on g, e = g / K, gives K about 1 for torques and about the
    torque constant for currents, on the joints that gravity loads
    (``REST_GRAVITY``).  What the test on motion
    (:func:`sample_ratios`) cannot tell from a recording of held poses:
    there the offset column takes it all.  Counts nothing without a
    sample at rest.
    """
    n = gravity.shape[1]
    held = np.all(np.abs(qd) < HELD_SPEED, axis=1)
    g, e = gravity[held], effort[held]
    gg, ge = (g * g).sum(axis=0), (g * e).sum(axis=0)
    size = np.sqrt(gg / max(int(held.sum()), 1))
    counts = (size > 0) & (size >= REST_GRAVITY * size.max(initial=0.0))
    counts &= ge != 0
    K = np.where(counts, gg / np.where(ge != 0, ge, 1.0), 0.0)
    return K, counts if held.any() else np.zeros(n, dtype=bool)


class EffortMonitor:
    """
    The test of :func:`describe` on a live stream, window after window.

    :meth:`add` takes the model's torque and the effort in the unit the
    model says (N m: currents already times their torque constants), at
    most one sample per ``spacing`` seconds and only while some joint
    moves faster than ``moving`` (at rest static friction holds any
    torque, and says nothing of the scale).  Every ``window`` samples it
    decides: :attr:`verdict` is then None (the efforts can be what the
    model says) or the one line; :attr:`windows` counts the decisions.
    Memory is one window, allocated once.
    """

    def __init__(self, names, mode, label, urdf=None, window=1000,
                 spacing=0.01, moving=0.05, fix=URDF_FIX):
        """Make an empty window for joints ``names`` (model order)."""
        self.names = list(names)
        self.mode, self.label, self.urdf, self.fix = mode, label, urdf, fix
        n = len(self.names)
        self._rows = np.zeros((3, int(window), n))
        self.spacing = float(spacing)
        self.moving = float(moving)
        self._k = 0
        self._t = -math.inf
        self.verdict = None
        self.windows = 0

    def due(self, t, qd):
        """Whether a sample at stamp ``t`` (s) and speeds ``qd`` is taken."""
        return (not 0.0 <= t - self._t < self.spacing) and \
            bool(np.max(np.abs(qd)) > self.moving)

    def add(self, t, tau, effort, qd):
        """
        Take one sample (stamp s, model torque, effort, speeds) if due.

        Returns True when it completed a window (:attr:`verdict` is then
        new).
        """
        if not self.due(t, qd):
            return False
        self._t = t
        rows = self._rows
        rows[0, self._k], rows[1, self._k], rows[2, self._k] = \
            tau, effort, qd
        self._k += 1
        if self._k < rows.shape[1]:
            return False
        self._k = 0
        self.windows += 1
        if np.isfinite(rows).all():
            K, explained = sample_ratios(rows[0], rows[1], rows[2])
            self.verdict = describe(self.label, self.names, K, explained,
                                    self.mode, self.urdf, self.fix)
        return True
