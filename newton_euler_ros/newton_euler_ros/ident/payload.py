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
Estimate a payload fixed to a link (the tip by default) from a recording.

The arm's model (identified inertials and drive terms) predicts what the
drives need without the payload; the rest of the measured effort is the
payload's:

    K effort - tau_arm(q, qd, qdd) - tau_drives(qd, qdd) = Y_tip T pi_p

with K the URDF's torque constants when the efforts are motor currents
(``core.drives``: ``torque_constant``; 1 for torques).

``Y_tip`` is the ten columns of the torque regressor of the body the
payload's link is fixed to (``core.regressor``: parameters about that
body's link frame origin, in its axes; the last link of a chain) and
``T`` the linear map of a body's ten parameters from the payload's link
frame to the body's link frame (the pseudo-inertia J transforms as
X J X^T with X the 4x4 pose of the link in the body's frame: the model's
``tool`` for the tip).  ``pi_p`` = (m, m c, I about the link origin) in
the link's frame.  On a tree (``payload_frame``) the link is the single
tip when there is one, else it must be named; only the joints that carry
it (its body's ancestors, a mimic follower's through its leader) see the
payload, and only they enter the fit.

The samples come from the identification pipeline (``reduce``:
resampled, zero-phase filtered, same filter on the effort), reduced to an
11 x 11 R factor per joint.  Each joint is weighted by 1 / its residual RMS
(unconstrained fit first), and the fit is a small semidefinite program:
the payload's pseudo-inertia positive semi-definite (so m >= 0 and the
inertia physical), with a tiny pull toward zero so that directions the
motion does not excite come out at zero instead of at noise.

How well the recording determines each quantity: one standard uncertainty
u of the mass, each centre-of-mass coordinate and each inertia term about
the com, propagated from the covariance of the ten parameters (delta
method). That covariance is the largest of the estimates
(:func:`_covariance`): the weighted residual's variance through (A^T W
A)^-1, times the rows per independent sample of the filtered signals, and
sandwiches over blocks of 5, 20 and 80 cutoff periods (0.5, 2 and 8 s at
10 Hz) that hold when the residual is correlated for longer (the arm
model's error follows the motion). All shrink as the recording grows. A
quantity is *undetermined* when ``K_EXPAND`` u (about 95 % coverage)
exceeds ``MASS_TOL`` of the mass (at least ``MASS_TOL_ABS``), ``COM_TOL``
for a com coordinate, or ``INERTIA_TOL`` of the largest inertia term (at
least ``INERTIA_ABS``); a direction the motion does not excite has no
bound. A motion that never rotates the wrist cannot tell the inertia, and
a payload whose mass does not stand ``PRESENT_SIGMAS`` u out of zero has
no centre of mass.
"""
from dataclasses import dataclass, field

import numpy as np

from .reduce import (FIT_RATE_FACTOR, IdentificationError,
                     reduce_recording)
from ..core.drives import model_drives
from ..core.errors import NewtonEulerError
from ..core.regressor import (link_inertials, N_INERTIAL, pseudo_inertia,
                              regressor_batch)
from ..core.text import clip

# A value is determined when its expanded uncertainty (K_EXPAND standard
# uncertainties, about 95 % coverage) is within these:
K_EXPAND = 2.0
MASS_TOL = 0.05           # relative
MASS_TOL_ABS = 0.05       # kg: a mass known this well is determined
MASS_ABS = 0.02           # kg: below this the payload is "no payload"
PRESENT_SIGMAS = 3.0      # a payload's mass stands out of its uncertainty
COM_TOL = 0.015           # m, the 15 mm a payload's centre of mass is asked
INERTIA_TOL = 0.3         # relative to the largest inertia term
INERTIA_ABS = 2e-3        # kg m^2
UNBOUNDED = 1e6           # an uncertainty this large is no bound
PRIOR_WEIGHT = 1e-6       # pull toward zero, of the data's scale
BLOCK_ROWS = int(5 * FIT_RATE_FACTOR)   # rows: five cutoff periods
INERTIA_KEYS = ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2))
INERTIA_NAMES = ('Ixx', 'Iyy', 'Izz', 'Ixy', 'Iyz', 'Ixz')


def _pi_from_pseudo(J):
    Sigma = J[:3, :3]
    I = np.trace(Sigma) * np.eye(3) - Sigma  # noqa: E741
    return np.array([J[3, 3], J[0, 3], J[1, 3], J[2, 3], I[0, 0], I[0, 1],
                     I[1, 1], I[0, 2], I[1, 2], I[2, 2]])


class LinkError(NewtonEulerError, ValueError):
    """No such link for a payload, or none named on a tree with several."""


def _leaves(model):
    """Links at the ends of the tree's branches that move (for messages)."""
    report = (model.info or {}).get('urdf') or {}
    parents = set((report.get('parent_links') or {}).values())
    frames = model.link_frames or {}
    return [lk for lk in report.get('chain_links', ())
            if lk not in parents and frames.get(lk, (-1,))[0] >= 0]


def _named_frame(model, link):
    """(body, pose) of ``link`` in ``model``, or None."""
    report = (model.info or {}).get('urdf') or {}
    if link in (model.link_frames or {}):
        return model.link_frames[link]
    tool = np.asarray(model.tool)
    if link == report.get('tip') and model.tool_body is not None:
        return model.tool_body, tool
    if link in report.get('tip_frames', {}):
        return model.tool_body, tool @ report['tip_frames'][link]
    if link in report.get('links', ()):     # a chain link's own frame
        return list(report['links']).index(link), np.eye(4)
    if link in report.get('base_frames', {}):
        return -1, report['base_frames'][link]
    return None


def payload_frame(model, link=None, option='the link'):
    """
    Return (body, 4x4 pose in the body's link frame, link name).

    The frame a payload (or a known mass) is fixed to: ``link``, or the
    end effector (the tip) when None.  Raises :class:`LinkError` (one
    line naming the candidates; ``option`` says how to name one) on a
    tree with several tips and no link named, a link the model does not
    have, or one fixed to the base.
    """
    report = (model.info or {}).get('urdf') or {}
    if link is None:
        if model.tool_body is None:
            raise LinkError(
                f'the tree below {report.get("base", "the base")!r} has '
                f'several tips ({clip(", ".join(_leaves(model)), 600)}): '
                f'name the link the mass is fixed to with {option}')
        return model.tool_body, np.asarray(model.tool), report.get(
            'tip') or 'the end effector'
    found = _named_frame(model, link)
    if found is None:
        names = (list(model.link_frames or ()) or list(
            report.get('links', ())) + [report.get('tip')])
        raise LinkError(f'no link {clip(repr(link), 100)} in the model ('
                        + clip(', '.join(str(x) for x in names), 300) + ')')
    body, pose = found
    if body < 0:
        raise LinkError(f'link {link!r} is fixed to the base: a mass there '
                        f"changes no joint's torque")
    return int(body), np.asarray(pose, dtype=np.float64), link


def carrying(model, body):
    """Coordinates (indices) whose torque a mass on ``body`` changes."""
    coord = {b: k for k, b in enumerate(model.independent)}
    out = set()
    b = body
    while b >= 0:
        lead = b if model.mimic[b] is None else model.mimic[b][0]
        out.add(coord[lead])
        b = model.parents[b]
    return sorted(out)


def tip_to_link(tool):
    """10 x 10 map of a body's parameters from the tip to the link frame."""
    X = np.asarray(tool, dtype=np.float64)
    T = np.zeros((N_INERTIAL, N_INERTIAL))
    for k in range(N_INERTIAL):
        e = np.zeros(N_INERTIAL)
        e[k] = 1.0
        T[:, k] = _pi_from_pseudo(X @ pseudo_inertia(e) @ X.T)
    return T


@dataclass
class PayloadEstimate:
    """The estimate, its standard errors and what is determined."""

    mass: float
    com: np.ndarray           # tip frame, m
    inertia: np.ndarray       # 3x3 about the com, tip frame
    pi: np.ndarray            # 10 parameters about the tip origin
    mass_std: float
    com_std: np.ndarray
    inertia_std: np.ndarray   # 6, in INERTIA_NAMES order
    determined: dict = field(default_factory=dict)
    samples: int = 0
    duration: float = 0.0
    residual_before: np.ndarray = None   # per joint RMS, arm model alone
    residual_after: np.ndarray = None    # with the payload
    joint_names: list = field(default_factory=list)

    def _uncertain(self):
        """(quantity, its index, value, standard uncertainty, unit) rows."""
        I = self.inertia  # noqa: E741
        out = [('payload.mass', None, self.mass, self.mass_std)]
        out += [('payload.com', a, self.com[a], self.com_std[a])
                for a in range(3)]
        out += [('payload.inertia', k, I[a, b], self.inertia_std[k])
                for k, (a, b) in enumerate(INERTIA_KEYS)]
        return out

    def uncertainty(self):
        """
        One standard uncertainty of each value, as in :meth:`parameters`.

        ``None`` where the motion leaves it unbounded (a direction it does
        not excite at all).
        """
        out = {'payload.mass': None, 'payload.com': [None] * 3,
               'payload.inertia': [None] * 6}
        for key, k, _, u in self._uncertain():
            u = float(u) if np.isfinite(u) and u < UNBOUNDED else None
            if k is None:
                out[key] = u
            else:
                out[key][k] = u
        return out

    def parameters(self):
        """
        Return the node's payload.* parameters as a JSON-ready dict.

        What the motion does not determine is ``None`` (JSON ``null``):
        the mass, a centre-of-mass coordinate or an inertia term, and
        ``'undetermined'`` maps each parameter holding one to the reason,
        with the estimate and its uncertainty.  A parameter without
        ``None`` can be set on the node as it is.  ``'uncertainty'``:
        one standard uncertainty of every value (kg, m, kg m^2), null
        where unbounded; a value is determined when ``K_EXPAND`` times it
        is within its tolerance (``MASS_TOL``, ``COM_TOL``, ``INERTIA_TOL``).
        """
        d = self.determined
        I = self.inertia  # noqa: E741
        com = [float(x) if ok else None for x, ok in zip(self.com, d['com'])]
        inertia = [float(I[a, b]) if ok else None
                   for (a, b), ok in zip(INERTIA_KEYS, d['inertia'])]
        out = {'payload.mass': float(self.mass) if d['mass'] else None,
               'payload.com': com, 'payload.inertia': inertia}
        why = {}
        if not d['mass']:
            why['payload.mass'] = (f'estimate {self.mass:.4g} kg, standard '
                                   f'uncertainty {_u(self.mass_std)} kg')
        if not d['present']:
            reason = f'no payload: {self._absent()}'
            why['payload.com'] = why['payload.inertia'] = reason
        else:
            bad = [f'{a} ({1000 * x:.1f} mm +- {_u(1000 * u)})'
                   for a, x, u, ok in zip('xyz', self.com, self.com_std,
                                          d['com']) if not ok]
            if bad:
                why['payload.com'] = (f'{", ".join(bad)} not determined by '
                                      f'this motion')
            bad = [f'{n} ({I[a, b]:.2g} +- {_u(u)})' for n, (a, b), u, ok
                   in zip(INERTIA_NAMES, INERTIA_KEYS, self.inertia_std,
                          d['inertia']) if not ok]
            if bad:
                why['payload.inertia'] = (
                    f'{", ".join(bad)} not determined by this motion (rotate '
                    f'the wrist about more axes)')
        out['undetermined'] = why
        out['uncertainty'] = self.uncertainty()
        return out

    def _absent(self):
        return (f'the mass ({self.mass:.3g} kg +- {_u(self.mass_std)}) is '
                f'below {MASS_ABS:g} kg or {PRESENT_SIGMAS:g} standard '
                f'uncertainties')

    def settable(self):
        """Return the parameters the node can take as they are (no None)."""
        return {k: v for k, v in self.parameters().items()
                if k.startswith('payload.') and v is not None
                and not (isinstance(v, list) and None in v)}

    def undetermined_lines(self):
        """One line per quantity the recording does not determine."""
        out = []
        if not self.determined['mass']:
            out.append(f'the mass is undetermined (estimate {self.mass:.3g} '
                       f'kg, standard uncertainty {_u(self.mass_std)} kg)')
        if not self.determined['present']:
            out.append(f'no payload: {self._absent()}; centre of mass and '
                       f'inertia are meaningless')
            return out
        bad = [a for a, ok in zip('xyz', self.determined['com']) if not ok]
        if bad:
            out.append(f'centre of mass {", ".join(bad)} undetermined by '
                       f'this motion (null in the JSON)')
        bad = [n for n, ok in zip(INERTIA_NAMES, self.determined['inertia'])
               if not ok]
        if bad:
            out.append(f'inertia {", ".join(bad)} undetermined by this '
                       f'motion (rotate the wrist about more axes; null in '
                       f'the JSON)')
        return out

    def summary_lines(self, tip):
        """Return a readable summary (``payload`` without --json)."""
        d = self.determined
        lines = [f'payload fixed to {tip}, from {self.samples} samples over '
                 f'{self.duration:.1f} s (+- one standard uncertainty)']
        if d['mass']:
            lines.append(f'  mass         {self.mass:.3f} kg  '
                         f'(+-{_u(self.mass_std)})')
        else:
            lines.append(f'  mass         undetermined (estimate '
                         f'{self.mass:.3g} kg, +-{_u(self.mass_std)})')
        if not d['present']:
            lines.append(f'  no payload: {self._absent()} (centre of mass '
                         f'and inertia not reported)')
        else:
            cells = []
            for a in range(3):
                text = (f'{1000 * self.com[a]:.1f} mm (+-'
                        f'{_u(1000 * self.com_std[a])})')
                cells.append(text if d['com'][a]
                             else f'undetermined (estimate {text})')
            lines.append(f'  com ({tip} frame)  x {cells[0]}, y {cells[1]}, '
                         f'z {cells[2]}')
            cells = []
            for k, (a, b) in enumerate(INERTIA_KEYS):
                text = (f'{self.inertia[a, b]:.2g} (+-'
                        f'{_u(self.inertia_std[k])})')
                cells.append(f'{INERTIA_NAMES[k]} ' + (
                    text if d['inertia'][k] else 'undetermined'))
            lines.append('  inertia about the com (kg m^2): '
                         + ', '.join(cells))
        lines.append('torque residual per joint, RMS N m (arm model alone -> '
                     'with the payload):')
        for j, name in enumerate(self.joint_names):
            lines.append(f'  {name:<16}{self.residual_before[j]:>10.4g} -> '
                         f'{self.residual_after[j]:.4g}')
        for line in self.undetermined_lines():
            lines.append(f'note: {line}')
        return lines


def _u(u):
    """Format an uncertainty in two digits, or 'unbounded'."""
    return f'{u:.2g}' if np.isfinite(u) and u < UNBOUNDED else 'unbounded'


def _solve_sdp(Rw, zw, prior):
    import cvxpy as cp
    J = cp.Variable((4, 4), PSD=True)
    pi = cp.hstack([J[3, 3], J[0, 3], J[1, 3], J[2, 3],
                    J[1, 1] + J[2, 2], -J[0, 1], J[0, 0] + J[2, 2],
                    -J[0, 2], -J[1, 2], J[0, 0] + J[1, 1]])
    obj = cp.sum_squares(Rw @ pi - zw) + cp.sum_squares(
        cp.multiply(prior, pi))
    prob = cp.Problem(cp.Minimize(obj))
    try:
        prob.solve(solver=cp.CLARABEL)
    except cp.error.SolverError:
        return None
    if prob.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
        return None
    return np.asarray(pi.value, dtype=np.float64)


def _clip_psd(pi):
    lam, V = np.linalg.eigh(pseudo_inertia(pi))
    if lam.min() >= 0:
        return pi
    return _pi_from_pseudo((V * np.maximum(lam, 0.0)) @ V.T)


def estimate_payload(model, path, topic='/joint_states', cutoff=None,
                     link=None):
    """
    Return a :class:`PayloadEstimate` from the bag at ``path``.

    The payload is fixed to ``link`` (default: the tip, see
    :func:`payload_frame`); its centre of mass and inertia are given in
    that link's frame.
    """
    from ..core import inverse_dynamics_batch
    n = model.n
    drives = model_drives(model)
    body, pose, _ = payload_frame(model, link)
    T = tip_to_link(pose)
    cols = slice(N_INERTIAL * body, N_INERTIAL * (body + 1))
    sees = carrying(model, body)

    def rows(q, qd, qdd, effort):
        tau = inverse_dynamics_batch(model, q, qd, qdd)
        if drives is not None:
            tau = tau + drives.torques(qd, qdd)
            # a motor current's torque: the torque constants of the URDF
            effort = drives.effort_to_torque(effort)
        Y = regressor_batch(model, q, qd, qdd)[:, sees, cols] @ T
        y = (effort - tau)[:, sees]
        blocks.append(_block_grams(Y, y))
        return Y, y
    blocks = []
    red, _, info = reduce_recording(path, model.joint_names, rows,
                                    N_INERTIAL, topic, cutoff, split=False,
                                    outputs=len(sees))
    n = len(sees)
    rows = np.maximum(red.rows, 1)
    A = red.stacked(np.ones(n))
    theta, *_ = np.linalg.lstsq(A[:, :-1], A[:, -1], rcond=1e-12)
    sigma = np.sqrt(red.sq_residuals(theta) / rows)
    ref = np.sqrt(red.sq_effort() / rows)
    sigma = np.maximum(sigma, np.maximum(1e-3 * ref, 1e-6))
    w = 1.0 / sigma
    Aw = red.stacked(w)
    Rf = np.linalg.qr(Aw, mode='r')
    k = min(Rf.shape[0], N_INERTIAL)
    Rw = np.zeros((N_INERTIAL, N_INERTIAL))
    zw = np.zeros(N_INERTIAL)
    Rw[:k], zw[:k] = Rf[:k, :N_INERTIAL], Rf[:k, N_INERTIAL]
    # scale: a pull of PRIOR_WEIGHT of each column's weight in the data
    D = np.linalg.norm(Rw, axis=0)
    D = np.maximum(D, 1e-6 * max(float(D.max()), 1e-12))
    pi = _solve_sdp(Rw, zw, np.sqrt(PRIOR_WEIGHT) * D)
    if pi is None:
        raise IdentificationError(f'{path}: the payload fit failed (the '
                                  f'solver found no solution)')
    pi = _clip_psd(pi)
    pi[0] = max(pi[0], 0.0)
    m, c, Ic = link_inertials(pi)
    if m <= 0:
        c = np.zeros(3)
        Ic = np.zeros((3, 3))
    Ic = 0.5 * (Ic + Ic.T)
    theta_w = np.linalg.lstsq(Rw, zw, rcond=1e-12)[0]
    covs = _covariance(Rw, D, red, w, theta_w, np.vstack(blocks))
    est = _uncertainty(m, c, Ic, pi, covs)
    est.samples = info['samples']
    est.duration = info['duration']
    est.residual_before = np.sqrt(red.sq_effort() / rows)
    est.residual_after = np.sqrt(red.sq_residuals(pi) / rows)
    est.joint_names = [model.joint_names[j] for j in sees]
    return est


def _block_grams(Y, y):
    """
    (blocks, n, 11, 11) Gram matrices of [Y_j | y_j] per block of rows.

    A block is ``BLOCK_ROWS`` consecutive rows (the last of a chunk may
    be shorter): the residual is correlated over a few cutoff periods
    and the arm model's error over longer, and a block's summed score
    carries both.
    """
    M = np.concatenate([Y, y[:, :, None]], axis=2)
    return np.stack([np.einsum('bni,bnj->nij', M[a:a + BLOCK_ROWS],
                               M[a:a + BLOCK_ROWS])
                     for a in range(0, max(len(M), 1), BLOCK_ROWS)])


def _covariance(Rw, D, red, w, theta, grams):
    """
    Estimates of the covariance of the ten parameters (weighted fit).

    White noise through the filter: s^2 (A^T W A)^-1 times the rows per
    independent sample (the filtered effort carries nothing above the
    cutoff and rows are FIT_RATE_FACTOR per cutoff period: Nyquist gives
    two independent samples per period), s^2 the weighted residual
    variance.  Blocks: the sandwich H^-1 (sum_b s_b s_b^T) H^-1 of the
    blocks' scores s_b = A_b^T W r_b, which holds when the residual is
    correlated over longer (the arm model's error follows the motion).
    Blocks of 2 s and 8 s too where the recording has twice as many as
    there are parameters.  A direction the motion does not excite gets
    an inverse of 1e30.
    """
    Ds = np.maximum(D, 1e-300)
    U, s, Vt = np.linalg.svd(Rw / Ds)
    keep = s > 1e-12 * s[0]
    inv_s2 = np.where(keep, 1.0 / np.where(keep, s, 1.0) ** 2, 1e30)
    Hinv = (Vt.T * inv_s2) @ Vt / np.outer(Ds, Ds)
    total = float(red.rows.sum())
    dof = max(total - float(keep.sum()), 1.0)
    s2 = float(np.sum(red.sq_residuals(theta) * w ** 2)) / dof
    white = Hinv * s2 * (FIT_RATE_FACTOR / 2.0)
    w2 = w ** 2
    p = N_INERTIAL
    scores = (np.einsum('j,bji->bi', w2, grams[:, :, :p, p])
              - np.einsum('j,bjik,k->bi', w2, grams[:, :, :p, :p], theta))
    out = [white]
    # blocks of 0.5 s and, where there are enough of them, 2 s and 8 s:
    # the arm model's error is correlated over more than half a second
    for group in (1, 4, 16):
        nb = len(scores) // group
        if group > 1 and nb < 2 * p:
            break
        s_b = np.add.reduceat(scores, np.arange(0, len(scores), group))
        meat = s_b.T @ s_b * (len(s_b) / max(len(s_b) - 1.0, 1.0))
        out.append(Hinv @ meat @ Hinv)
    return out


def _uncertainty(m, c, Ic, pi, covs):
    """Propagate the covariance of pi to m, c and I_c (delta method)."""
    def quantities(p):
        mm = p[0]
        cc = p[1:4] / mm if mm > 0 else np.zeros(3)
        I = np.array([[p[4], p[5], p[7]], [p[5], p[6], p[8]],  # noqa: E741
                      [p[7], p[8], p[9]]])
        Icc = I - mm * (cc @ cc * np.eye(3) - np.outer(cc, cc))
        return np.concatenate([[mm], cc, [Icc[a, b] for a, b in
                                          INERTIA_KEYS]])
    base = quantities(pi)
    G = np.zeros((10, 10))
    for k in range(10):
        h = 1e-6 * max(abs(pi[k]), 1e-3)
        dp = pi.copy()
        dp[k] += h
        G[:, k] = (quantities(dp) - base) / h
    # each quantity's variance: the largest of the estimates
    var = np.max([np.einsum('ik,kl,il->i', G, cov, G) for cov in covs],
                 axis=0)
    std = np.sqrt(np.maximum(var, 0.0))
    mass_std = float(std[0])
    com_std = std[1:4]
    in_std = std[4:]
    # a payload is there when its mass stands out of its uncertainty
    present = m >= max(MASS_ABS, PRESENT_SIGMAS * mass_std)
    mass_ok = K_EXPAND * mass_std <= max(MASS_TOL * m, MASS_TOL_ABS)
    com_ok = [bool(present and K_EXPAND * com_std[a] <= COM_TOL)
              for a in range(3)]
    ref = max([abs(Ic[a, b]) for a, b in INERTIA_KEYS] + [0.0])
    in_tol = max(INERTIA_TOL * ref, INERTIA_ABS)
    in_ok = [bool(present and K_EXPAND * in_std[k] <= in_tol)
             for k in range(6)]
    if not present:
        c = np.zeros(3)
        Ic = np.zeros((3, 3))
    return PayloadEstimate(
        mass=float(m), com=c, inertia=Ic, pi=pi, mass_std=mass_std,
        com_std=com_std, inertia_std=in_std,
        determined={'mass': bool(mass_ok), 'present': bool(present),
                    'com': com_ok, 'inertia': in_ok})
