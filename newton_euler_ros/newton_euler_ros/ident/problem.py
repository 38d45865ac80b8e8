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
The identification's least-squares problem, from reduced recordings.

**Columns of a recording.**  Each recording is reduced once
(``reduce.reduce_recording``) with the columns

    [ Y (10nb inertial + 4n drive, Coulomb at widths[0])
      | tanh(qd_j / w) for w in widths[1:]  (joint j's rows)
      | Y_b T (10, only for a recording with a known mass at a link) ]

against the raw effort e, on a chain (nb = n) or a tree (nb bodies, a
mimic follower's too; n coordinates, each with its drive terms).  Every
Coulomb width candidate is there, so that the width can be chosen on
held-out blocks without reading the bag again; the known mass's
parameters are the payload's, in the frame of the link it is fixed to
(``payload.payload_frame``: the tip by default), Y_b being the columns
of the body carrying that link and T the map from that frame
(``payload.tip_to_link``).

**Unknowns** x = [theta (10nb + 4n) | pi_p (10), when there is a
known-mass recording].  For a width choice i, each joint's rows of a recording are
R_j (G x + h): G puts the Coulomb coefficient on the chosen width's
column and the payload's parameters on the payload's; h the effort's
coefficient, -K_j (the torque constant, 1 for torques; ``constants``
finds them when they are unknown).  The weighted rows
of every recording and joint, stacked and reduced again by a QR, give
the square problem (d + 1) x (d + 1) the fit solves: the residual of any
x, on the training part, the held-out blocks or everything, in N m.
"""
from dataclasses import dataclass

import numpy as np

from ..core.regressor import N_DRIVE, N_INERTIAL, regressor_batch

N_PAYLOAD = 10
REST_SPEED = 0.02     # rad/s (m/s): a joint's slower rows are not fitted
# ... or, for a joint whose velocity limit is below 10 x REST_SPEED (a
# torso lift of 0.013 m/s), this fraction of its velocity limit
REST_FRACTION = 0.1


def rest_speeds(model):
    """
    Each coordinate's speed below which its rows are not fitted.

    ``REST_SPEED``, or ``REST_FRACTION`` of the joint's URDF velocity
    limit when that is lower: a slow joint (PR2's torso lifts at
    0.013 m/s) would otherwise never count as moving.
    """
    limits = list(model.limits or ())
    out = np.full(model.n, REST_SPEED)
    for j, b in enumerate(model.independent):
        v = (limits[b] if b < len(limits) else {}).get('velocity', 0.0)
        if v > 0:
            out[j] = min(REST_SPEED, REST_FRACTION * v)
    return out


class Layout:
    """
    Positions of theta, K and the payload in x; columns of a bag.

    ``n`` coordinates (rows, drive terms), ``nb`` bodies (default n; a
    tree with mimic joints has more bodies than coordinates).
    """

    def __init__(self, n, widths, payload=False, nb=None):
        self.n = n
        self.nb = n if nb is None else nb
        self.widths = tuple(float(w) for w in widths)
        self.p_theta = N_INERTIAL * self.nb + N_DRIVE * n
        size = self.p_theta
        self.pay = slice(size, size + N_PAYLOAD) if payload else None
        size += N_PAYLOAD if payload else 0
        self.size = size

    def bag_columns(self, loaded):
        """Return the number of columns a recording is reduced with."""
        return (self.p_theta + len(self.widths) - 1
                + (N_PAYLOAD if loaded else 0))

    def coulomb(self, j):
        """Return joint j's Coulomb column in theta."""
        return N_INERTIAL * self.nb + N_DRIVE * j + 1

    def drive_columns(self, j):
        """Return joint j's four drive columns."""
        a = N_INERTIAL * self.nb + N_DRIVE * j
        return np.arange(a, a + N_DRIVE)

    def coefficients(self, j, width, loaded, k_const):
        """(G, h): joint j's column coefficients are G x + h."""
        pb = self.bag_columns(loaded)
        G = np.zeros((pb + 1, self.size))
        h = np.zeros(pb + 1)
        G[:self.p_theta, :self.p_theta] = np.eye(self.p_theta)
        if width > 0:
            c = self.coulomb(j)
            G[c, c] = 0.0
            G[self.p_theta + width - 1, c] = 1.0
        if loaded:
            a = self.p_theta + len(self.widths) - 1
            G[a:a + N_PAYLOAD, self.pay] = np.eye(N_PAYLOAD)
        h[pb] = -float(k_const[j])
        return G, h


def recording_rows(model, layout, loaded, frame=None):
    """
    Return the ``rows`` function of ``reduce.reduce_recording``.

    ``loaded``: add the known mass's ten columns, at ``frame`` = (body,
    pose of the mass's link in that body's frame), from
    ``payload.payload_frame`` (default: the end effector).

    Each joint's fit keeps its rows where it moves at ``REST_SPEED`` or
    faster (``rest_speeds``: slower for a slow joint): at rest, static
    friction holds any torque within +-F_s,
    which no model of (q, qd, qdd) predicts (on UR-like recordings with
    stops, fitting them tripled the error where joints move).
    """
    n = model.n
    extra = layout.widths[1:]
    rest = rest_speeds(model)
    T = None
    if loaded:
        from .payload import payload_frame, tip_to_link
        body, pose, _ = payload_frame(model) if frame is None else frame
        T = tip_to_link(pose)
        cols = slice(N_INERTIAL * body, N_INERTIAL * (body + 1))

    def rows(q, qd, qdd, effort):
        Y = regressor_batch(model, q, qd, qdd, drives=True,
                            coulomb_width=layout.widths[0])
        parts = [Y]
        if extra:
            C = np.zeros((len(q), n, len(extra)))
            for i, w in enumerate(extra):
                C[:, np.arange(n), i] = np.tanh(qd / w)
            parts.append(C)
        if T is not None:
            parts.append(Y[:, :, cols] @ T)
        return (np.concatenate(parts, axis=2), effort,
                np.abs(qd) >= rest)
    return rows


@dataclass
class Recording:
    """One reduced bag: its parts, what was read, the known mass."""

    path: str
    train: object
    held: object
    info: dict
    mass: float = None          # kg at the known-mass link, or None

    @property
    def loaded(self):
        """Return True for a recording with a known mass."""
        return self.mass is not None

    def part(self, name):
        """
        Return a reduction: 'train', 'held' or 'all' of the fitted rows.

        'samples' and 'held_samples' add the rows at rest (every sample,
        every held-out sample), for reports.
        """
        if name in ('samples', 'held_samples'):
            rest = self.info.get('rest')
            base = self.part('all' if name == 'samples' else 'held')
            if rest is None:
                return base
            spare = [r for r in (rest if name == 'samples' else rest[1:])
                     if r is not None]
            key = '_' + name
            if not hasattr(self, key):
                out = base
                for r in spare:
                    out = out.merged(r)
                setattr(self, key, out)
            return getattr(self, key)
        if name == 'all':
            if self.held is None or self.held.rows.min() == 0:
                return self.train
            if not hasattr(self, '_all'):
                self._all = self.train.merged(self.held)
            return self._all
        if name == 'held' and (self.held is None
                               or self.held.rows.min() == 0):
            return self.train
        return getattr(self, name)


def stacked(recordings, part, layout, width, weights, k_const):
    """
    Return (Aug, rows): the weighted problem of ``part``, normalised.

    ``Aug`` is (d + 1) x (d + 1) upper triangular: the mean weighted
    squared residual of x is ||Aug [x; -1]||^2 (rows of every recording
    and joint, joint j weighted by ``weights[j]``).
    """
    blocks = []
    rows = 0
    for rec in recordings:
        red = rec.part(part)
        rows += int(red.rows.sum())
        for j in range(layout.n):
            G, h = layout.coefficients(j, width, rec.loaded, k_const)
            Rj = red.R[j]
            blocks.append(weights[j] * np.column_stack([Rj @ G, -(Rj @ h)]))
    A = np.vstack(blocks)
    Aug = np.linalg.qr(A, mode='r')
    d = layout.size + 1
    out = np.zeros((d, d))
    out[:min(d, Aug.shape[0])] = Aug[:d]
    return out / np.sqrt(max(rows, 1)), rows


def joint_stats(recordings, part, layout, width, x, k_const, k_effort):
    """
    Per joint (rms N m, relative rms) of x over the recordings' ``part``.

    ``k_effort`` converts the effort to N m for the relative error's
    reference (the torque constants, or ones).  The relative error of a
    joint whose effort is zero throughout (a finger the driver reports
    at 0) is NaN.
    """
    n = layout.n
    res = np.zeros(n)
    ref = np.zeros(n)
    rows = np.zeros(n)
    for rec in recordings:
        red = rec.part(part)
        for j in range(n):
            G, h = layout.coefficients(j, width, rec.loaded, k_const)
            r = red.R[j] @ (G @ x + h)
            res[j] += float(r @ r)
            e = red.R[j][:, -1] * k_effort[j]
            ref[j] += float(e @ e)
            rows[j] += red.rows[j]
    rows = np.maximum(rows, 1)
    rms = np.sqrt(res / rows)
    ref = np.sqrt(ref / rows)
    return rms, np.where(ref > 0, rms / np.maximum(ref, 1e-300), np.nan)
