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
Torque constants from recordings whose efforts are motor currents.

With e_j = tau_j / K_j, the residual in torque units, Y_j theta - K_j e_j,
is linear in (theta, K), but least squares on it is biased: the effort's
noise and stiction are multiplied by K_j, so smaller constants and a
smaller theta fit "better" (errors in variables; on a UR-like recording
the constants came out 40 % low that way, a known mass notwithstanding).
In the effort's own unit, e_j - Y_j theta / K_j, the noise is where least
squares expects it, and scaling theta and K together changes nothing:
the scale is set by the nominal model's masses and gravity (the mean of
the constants over the joints the nominal model explains, weighted by
how well, is held at the nominal model's ratio ``effort.ratios``) or, with
a recording of a known mass at the tip, by that mass.

On a tree the scale is one per group of coordinates that share
parameters (:func:`coupled_groups`): the two arms of a dual-arm robot
mounted on a fixed base share none, so each arm's inertials and
constants scaled together fit its own rows equally well, whatever the
other arm does.  Each group's scale is held apart (the nominal model's
mean over that group); a known mass fixes the scale of the group whose
joints carry it (a torso joint carrying both arms joins them in one
group), the others keep the nominal model's.

Variable projection: for given constants, the best theta is a linear
least-squares problem (the reduced, weighted rows of ``problem.stacked``,
joint j's weighted by 1 / (sigma_j K_j) with sigma_j its residual in the
effort's unit, plus a faint prior as rows); what is left is a function
of the n constants, minimised over log K by
``scipy.optimize.least_squares``.  Only the joints whose effort follows
the rigid-body torque (``effort.ratios``) are free; the constant of a
joint whose effort is friction and noise (a UR's base or last wrist
joint) is not told by the data, and gets the mean of the others.  The
final fit (``fit``'s semidefinite program) then runs with the constants
found.
"""
import numpy as np

from . import effort
from .reduce import IdentificationError

PRIOR_WEIGHT = 1e-6


class _Projected:
    """
    The effort-unit residual as a function of the constants.

    Joint j's rows of a recording are R_j (G x + h) with h = -K_j e_pb
    (``layout.coefficients``): T_j x - K_j r_j, with T_j = R_j G and r_j
    R_j's effort column, both independent of K.  Each joint's [T_j, r_j]
    is factored once, on the columns it touches (a joint's torque depends
    on the bodies below it: on a dual-arm tree most columns are zero), to
    F_j = Q_j^T [T_j, r_j]; a fixed rotation of the joint's rows, so
    every evaluation solves the same least-squares problem (and returns
    a residual of the same norm) on a fraction of the rows.
    """

    def __init__(self, recordings, layout, width, sigma_e, lam, D, theta0,
                 mass):
        self.sigma_e = sigma_e
        self.layout = layout
        p = layout.p_theta
        d = layout.size
        sl = np.sqrt(lam)
        self.prior = np.zeros((p, d))
        self.prior[:, :p] = np.diag(sl * D)
        self.prior_z = sl * D * theta0
        self.mcol = layout.pay.start if mass is not None else None
        self.mass = mass
        self.rows = sum(int(r.part('all').rows.sum()) for r in recordings)
        self.blocks = []            # (joint, its columns, F_j)
        for rec in recordings:
            red = rec.part('all')
            pb = layout.bag_columns(rec.loaded)
            for j in range(layout.n):
                G, _ = layout.coefficients(j, width, rec.loaded,
                                           np.ones(layout.n))
                T = red.R[j] @ G
                cols = np.flatnonzero(np.any(T != 0.0, axis=0))
                M = np.column_stack([T[:, cols], red.R[j][:, pb]])
                F = np.linalg.qr(M, mode='r')
                self.blocks.append((j, cols, F))

    def solve(self, K):
        """Return (x, residual vector) at constants K."""
        d = self.layout.size
        w = 1.0 / (self.sigma_e * K)
        scale = 1.0 / np.sqrt(max(self.rows, 1))
        A = np.zeros((sum(F.shape[0] for _, _, F in self.blocks), d + 1))
        at = 0
        for j, cols, F in self.blocks:
            rows = slice(at, at + F.shape[0])
            A[rows, cols] = w[j] * F[:, :-1]
            A[rows, d] = w[j] * K[j] * F[:, -1]
            at += F.shape[0]
        Aug = np.linalg.qr(A, mode='r')[:d + 1] * scale
        M = np.vstack([Aug[:d, :d], self.prior])
        rhs = np.concatenate([Aug[:d, d], self.prior_z])
        x = np.zeros(d)
        free = np.arange(d)
        if self.mcol is not None:
            x[self.mcol] = self.mass
            rhs = rhs - M[:, self.mcol] * self.mass
            free = free[free != self.mcol]
        x[free], *_ = np.linalg.lstsq(M[:, free], rhs, rcond=1e-12)
        # the residual from the fixed factors: a smooth function of K (the
        # stacked QR's rows may change sign from one K to the next)
        parts = [self.prior @ x - self.prior_z]
        for j, cols, F in self.blocks:
            parts.append(w[j] * scale * (F[:, :-1] @ x[cols] - K[j] * F[:, -1]))
        return x, np.concatenate(parts)


def coupled_groups(model):
    """
    Return the groups of coordinates (index arrays) that share parameters.

    Coordinate j's torque depends on the bodies below its joint (and a
    mimic follower's on its leader's row), so two coordinates share
    parameters exactly when they are in the same subtree hanging from
    the base, or in subtrees joined by a follower and its leader.  A
    chain is one group.
    """
    parents, mimic = model.parents, model.mimic
    root = []
    for b in range(model.nb):
        r = b
        while parents[r] >= 0:
            r = parents[r]
        root.append(r)
    top = {r: r for r in root}

    def find(r):
        while top[r] != r:
            r = top[r]
        return r
    for b, m in enumerate(mimic):
        if m is not None:
            top[find(root[b])] = find(root[m[0]])
    groups = {}
    for j, b in enumerate(model.independent):
        groups.setdefault(find(root[b]), []).append(j)
    return [np.array(g) for g in groups.values()]


def mass_excitation(recording, layout, sigma):
    """
    How much a known mass's torque changes, per joint, in residual units.

    The torque of the mass as a point at the tip origin (its column in
    the loaded recording), less what the joint's own drive terms could
    explain (a constant is an offset), RMS over the recording, divided by
    the joint's residual RMS ``sigma`` (N m).  Only a mass whose torque
    changes fixes the scale: measured on UR-like recordings, about 5 on
    the shoulder for excitations of the loaded arm, 0.01 or less on every
    joint when only the base and the last wrist joint move.
    """
    red = recording.part('all')
    out = np.zeros(layout.n)
    for j in range(layout.n):
        R = red.R[j]
        a = R[:, layout.bag_columns(False)] * recording.mass
        Q, _ = np.linalg.qr(R[:, layout.drive_columns(j)])
        a = a - Q @ (Q.T @ a)
        out[j] = np.linalg.norm(a) / np.sqrt(max(red.rows[j], 1)) / sigma[j]
    return out


def fit_constants(recordings, layout, width, sigma_e, k0, lam, D, theta0,
                  free, pins=(), mass=None):
    """
    Return the torque constants (n,).

    ``free`` marks the joints the data determines (the others get the
    mean of theirs); ``pins`` [(group, c)]: for each group of
    coordinates (indices) whose scale the data does not fix (no ``mass``,
    kg at the known-mass link of the loaded recording, carried by it),
    sum c log(K / k0) over its free joints is held at 0 (c >= 0 per
    joint; uniform where it is 0 throughout the group).
    """
    from scipy.optimize import least_squares
    # the prior toward the nominal model must not choose the scale (it would
    # pull the constants toward the nominal masses, 10 % on a UR-like arm
    # against its known mass): a weight just large enough to keep the
    # directions the data does not see regular
    proj = _Projected(recordings, layout, width, sigma_e,
                      min(lam, PRIOR_WEIGHT), D, theta0, mass)
    idx = np.flatnonzero(free)
    shifts = []
    for group, c in pins:
        inside = np.isin(idx, group)
        if not inside.any():
            continue
        cc = np.where(inside, c[idx], 0.0)
        cc = cc if cc.sum() > 0 else inside.astype(np.float64)
        shifts.append((inside, cc / cc.sum()))

    def constants(u):
        for inside, cc in shifts:
            u = u - (cc @ u) * inside
        K = np.array(k0, dtype=np.float64)
        K[idx] = k0[idx] * np.exp(u)
        K[~free] = K[idx].mean()
        return K
    fit = least_squares(lambda u: proj.solve(constants(u))[1],
                        np.zeros(len(idx)), method='trf', x_scale=1.0,
                        diff_step=1e-4, xtol=1e-6, ftol=1e-9)
    return constants(fit.x)


def scale_pins(ratios, model, carried, notes, link):
    """
    [(group, weights c)]: the groups whose scale the nominal model fixes.

    The joints where the nominal model explains the effort (``effort``:
    gravity-loaded joints) count by how well it does: the data fixes the
    constants relative to each other, the nominal model's masses and
    gravity their mean (``constants.fit_constants``), per group of
    coordinates that share parameters (``constants.coupled_groups``)
    except the one whose joints carry the known mass (``carried``).
    """
    c = np.zeros(model.n)
    for k, e in ratios.values():
        c += np.where((e >= effort.MIN_EXPLAINED) & (k > 0), e, 0.0)
    groups = coupled_groups(model)
    pins = [(g, c) for g in groups if not set(g.tolist()) & set(carried)]
    if carried and pins:
        others = [model.joint_names[j] for g, _ in pins for j in g]
        more = ' ...' if len(others) > 4 else ''
        notes.append(f'the known mass at {link} fixes the torque constants '
                     f'of the joints that share parameters with it; those of '
                     f'{", ".join(others[:4])}{more} keep the nominal '
                     f"model's scale")
    return pins


def determined(ratios, n):
    """Joints whose effort follows the nominal model's rigid-body torque."""
    out = np.zeros(n, dtype=bool)
    for k, e in ratios.values():
        out |= (e >= effort.MIN_EXPLAINED) & (k > 0)
    return out


def initial_constants(ratios, n):
    """
    Each determined joint's ratio (weighted over the bags), else their mean.

    Raises IdentificationError when no joint is determined.
    """
    K = np.zeros(n)
    good = np.zeros(n)
    for k, e in ratios.values():
        use = (e >= effort.MIN_EXPLAINED) & (k > 0)
        K += np.where(use, k * e, 0.0)
        good += np.where(use, e, 0.0)
    if not good.any():
        raise IdentificationError(
            f"{next(iter(ratios))}: no joint's effort follows the nominal "
            f"model's torque, so the torque constants cannot be found "
            f'(record the shoulder and elbow moving against gravity, or '
            f'give the constants in the URDF)')
    K = np.where(good > 0, K / np.maximum(good, 1e-300), np.nan)
    return np.where(np.isnan(K), np.nanmean(K), K)
