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
Fit inertial and drive parameters to a recording, physically consistent.

The parameters theta = [pi (10n, per link), drives (4n, per joint)] enter
the torques linearly, tau = Y theta (``core.regressor`` with
``drives=True``).  The pipeline:

1-2. Read, prepare and reduce the recording (``reduce``): per joint j,
   the R factor of [Y_j | y_j] over the filtered, decimated samples,
   (14n + 1)^2 numbers whatever the recording's length, from which the
   residual ||y_j - Y_j theta||^2 of any theta follows exactly; a
   training part and held-out time blocks.
3. Weights: each joint's rows by 1 / sigma_j, sigma_j the RMS residual of
   an unconstrained least-squares fit on the training part (weighted least
   squares, Gautier & Poignet): small wrist torques count as much as the
   shoulder's.
4. Base parameters (``base.base_parameters``): the rank and condition
   number of the weighted regressor; a recording whose rank is far below
   the structural count does not excite the arm and is refused.
5. A semidefinite program (CVXPY, solved by Clarabel): minimise the mean
   weighted squared residual plus lambda ||D (theta - theta_0)||^2 toward
   the nominal model theta_0, with every link's 4x4 pseudo-inertia
   positive semi-definite (Wensing, Kim & Slotine 2018), viscous and
   Coulomb friction and armature >= 0.  D scales each parameter by its
   column's RMS in the weighted regressor, so lambda is a fraction of what
   a change costs in the data where the data sees it.  Parameters the
   recording does not excite stay at the prior.  lambda is chosen on the
   held-out part over ``LAMBDAS``: the largest lambda whose held-out error
   is within ``LAMBDA_SLACK`` of the best.  The final fit uses all the
   data with that lambda.

Links carrying rigidly attached children (a URDF's fixed joints and locked
off-chain subtrees: a hand, fingers) are constrained as the link's own
body: J(pi_k - pi_fixed_k) >= 0 with pi_fixed_k the nominal parameters
of the attached parts, which stay as published in the written URDF.
"""
from dataclasses import dataclass, field
import time

import numpy as np

from .bag import DEFAULT_TOPIC
from .base import base_parameters, structural_base
from .reduce import IdentificationError, reduce_recording  # noqa: F401
from ..core.drives import DEFAULT_COULOMB_WIDTH, Drives, model_drives
from ..core.regressor import (inertial_parameters, N_DRIVE, N_INERTIAL,
                              regressor_batch, with_parameters)

LAMBDAS = tuple(10.0 ** k for k in range(-8, 1))
LAMBDA_SLACK = 0.02
# a recording whose rank is below this fraction of the structural count
# does not excite the arm
MIN_RANK_FRACTION = 0.5


def accumulate(model, path, topic=DEFAULT_TOPIC, coulomb_width=None,
               cutoff=None, split=True):
    """
    Reduce a recording to the regressor's problem (``reduce``).

    Return (train, held_out or None, info dict): the rows of the torque
    regressor with drive terms (Coulomb width ``coulomb_width``) against
    the effort.
    """
    eps = DEFAULT_COULOMB_WIDTH if coulomb_width is None else coulomb_width

    def rows(q, qd, qdd, effort):
        return regressor_batch(model, q, qd, qdd, drives=True,
                               coulomb_width=eps), effort
    return reduce_recording(path, model.joint_names, rows,
                            model.n * (N_INERTIAL + N_DRIVE), topic, cutoff,
                            split)


# ---------------------------------------------------------------------------
# the semidefinite program

def _pi_of_pseudo(J):
    """Return the 10 parameters (cvxpy expressions) of a pseudo-inertia."""
    return [J[3, 3], J[0, 3], J[1, 3], J[2, 3],
            J[1, 1] + J[2, 2], -J[0, 1], J[0, 0] + J[2, 2], -J[0, 2],
            -J[1, 2], J[0, 0] + J[1, 1]]


class _Program:
    """The SDP, compiled once, solved for any data and lambda."""

    def __init__(self, n, fixed, theta0, D):
        import cvxpy as cp
        self.cp = cp
        p = n * (N_INERTIAL + N_DRIVE)
        self.R = cp.Parameter((p, p))
        self.z = cp.Parameter(p)
        self.sl = cp.Parameter(nonneg=True)
        self.J = [cp.Variable((4, 4), PSD=True) for _ in range(n)]
        self.d = cp.Variable(N_DRIVE * n)
        parts = []
        for k in range(n):
            parts += [fixed[k, i] + e for i, e in
                      enumerate(_pi_of_pseudo(self.J[k]))]
        self.theta = cp.hstack(parts + [self.d])
        j = np.arange(n) * N_DRIVE
        cons = [self.d[j] >= 0, self.d[j + 1] >= 0, self.d[j + 3] >= 0]
        obj = cp.sum_squares(self.R @ self.theta - self.z) + cp.sum_squares(
            self.sl * cp.multiply(D, self.theta - theta0))
        self.problem = cp.Problem(cp.Minimize(obj), cons)

    def solve(self, R, z, lam):
        cp = self.cp
        self.R.value = R
        self.z.value = z
        self.sl.value = float(np.sqrt(lam))
        try:
            self.problem.solve(solver=cp.CLARABEL)
        except cp.error.SolverError:
            return None
        if self.problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
            return None
        return np.asarray(self.theta.value, dtype=np.float64)


def _square(red, weights):
    """Weighted, normalised square problem (R p x p, z p) of a Reduced."""
    A = red.stacked(weights)
    Rf = np.linalg.qr(A, mode='r')
    p = red.p
    Rp = np.zeros((p, p))
    zp = np.zeros(p)
    k = min(Rf.shape[0], p)
    Rp[:k] = Rf[:k, :p]
    zp[:k] = Rf[:k, p]
    scale = 1.0 / np.sqrt(max(int(red.rows.sum()), 1))
    return Rp * scale, zp * scale


def nominal_theta(model, coulomb_width=None):
    """Return theta_0: the model's inertial parameters and drives (or 0)."""
    d = model_drives(model)
    d = np.zeros(N_DRIVE * model.n) if d is None else d.parameters()
    return np.concatenate([inertial_parameters(model), d])


def fixed_parts(model, urdf_text=None):
    """
    (n, 10): nominal parameters of the parts rigidly attached to each link.

    For a URDF model, each chain link's body is its own ``<inertial>``
    plus the links joined to it by fixed joints (and locked off-chain
    subtrees); this returns the latter (the total minus the link's own).
    Zeros for other models.
    """
    n = model.n
    out = np.zeros((n, N_INERTIAL))
    report = (model.info or {}).get('urdf')
    if urdf_text is None or not report:
        return out
    from ..core.regressor import link_parameters
    from ..core.urdf import parse_urdf
    _, _, links, _ = parse_urdf(urdf_text)
    total = inertial_parameters(model).reshape(n, N_INERTIAL)
    for k, lname in enumerate(report['links']):
        lk = links[lname]
        own = link_parameters(lk.mass, lk.com, lk.inertia)
        out[k] = total[k] - own
    return out


@dataclass
class Result:
    """What :func:`identify` found; thetas are [pi (10n), drives (4n)]."""

    model: object
    theta: np.ndarray
    theta0: np.ndarray
    drives: Drives
    coulomb_width: float
    rank: int
    structural_rank: int
    condition: float
    lam: float
    sigma: np.ndarray
    fit_stats: dict = field(default_factory=dict)
    validate_stats: dict = field(default_factory=dict)
    info: dict = field(default_factory=dict)
    seconds: float = 0.0
    validate_seconds: float = 0.0
    lambda_errors: list = field(default_factory=list)


def _weights(red):
    """1 / sigma_j from an unconstrained least-squares fit."""
    A = red.stacked(np.ones(red.n))
    theta, *_ = np.linalg.lstsq(A[:, :-1], A[:, -1], rcond=1e-10)
    rows = np.maximum(red.rows, 1)
    sigma = np.sqrt(red.sq_residuals(theta) / rows)
    ref = np.sqrt(red.sq_effort() / rows)
    sigma = np.maximum(sigma, np.maximum(1e-3 * ref, 1e-6))
    return sigma


def identify(model, path, topic=DEFAULT_TOPIC, validate=None,
             coulomb_width=None, cutoff=None, urdf_text=None):
    """
    Identify ``model``'s parameters from the bag at ``path``.

    Returns a :class:`Result` whose ``model`` carries the identified
    inertials and ``drives`` the identified drive terms.  Raises
    :class:`BagError` (or :class:`IdentificationError`) with one line.
    """
    start = time.perf_counter()
    nominal = model_drives(model)
    if coulomb_width is None:
        coulomb_width = (float(nominal.coulomb_width[0])
                         if nominal is not None else DEFAULT_COULOMB_WIDTH)
    eps = float(coulomb_width)
    n = model.n
    theta0 = nominal_theta(model)
    fixed = fixed_parts(model, urdf_text)
    train, held, info = accumulate(model, path, topic, eps, cutoff)
    if held.rows.min() == 0:
        # too short to hold a block out: fit and choose on the same data
        held = train
    sigma = _weights(train)
    w = 1.0 / sigma
    everything = train.merged(held) if held is not train else train
    Rall, zall = _square(everything, w)
    base = base_parameters(Rall)
    struct = structural_base(model, drives=True)
    if base.rank < MIN_RANK_FRACTION * struct.rank:
        raise IdentificationError(
            f'{path}: the recording does not excite the arm: rank '
            f'{base.rank} of the regressor against {struct.rank} base '
            f'parameters (move every joint, with varied speeds and '
            f'accelerations)')
    Rt, zt = _square(train, w)
    D = np.linalg.norm(Rall, axis=0)
    D = np.maximum(D, 1e-3 * max(float(np.median(D)), 1e-12))
    program = _Program(n, fixed, theta0, D)
    errors = []
    for lam in LAMBDAS:
        theta = program.solve(Rt, zt, lam)
        if theta is None:
            continue
        err = float(np.sum(held.sq_residuals(theta) * w ** 2)
                    / max(int(held.rows.sum()), 1))
        errors.append((lam, err))
    if not errors:
        raise IdentificationError(f'{path}: the fit failed (the solver '
                                  f'found no solution)')
    best = min(e for _, e in errors)
    lam = max(lam for lam, e in errors if e <= best * (1 + LAMBDA_SLACK))
    theta = program.solve(Rall, zall, lam)
    if theta is None:
        raise IdentificationError(f'{path}: the fit failed (the solver '
                                  f'found no solution)')
    # the SDP's answer is PSD to the solver's tolerance: clip round-off
    theta = _clean(theta, fixed, n)
    ident = with_parameters(model, theta[:N_INERTIAL * n])
    drives = Drives.from_parameters(theta[N_INERTIAL * n:], eps)
    info_ = dict(model.info or {})
    info_['drives'] = drives
    ident = ident.replace(info=info_)
    result = Result(
        model=ident, theta=theta, theta0=theta0, drives=drives,
        coulomb_width=eps, rank=base.rank, structural_rank=struct.rank,
        condition=base.condition, lam=lam, sigma=sigma, info=info,
        lambda_errors=errors)
    result.fit_stats = {'nominal': everything.stats(theta0),
                        'identified': everything.stats(theta)}
    if held is not train:
        result.fit_stats['held_out_nominal'] = held.stats(theta0)
        result.fit_stats['held_out_identified'] = held.stats(theta)
    result.seconds = time.perf_counter() - start
    if validate is not None:
        val, _, vinfo = accumulate(model, validate, topic, eps, cutoff,
                                   split=False)
        result.validate_stats = {'nominal': val.stats(theta0),
                                 'identified': val.stats(theta)}
        result.validate_seconds = (time.perf_counter() - start
                                   - result.seconds)
    return result


def _clean(theta, fixed, n):
    """Project each link's own pseudo-inertia onto the PSD cone."""
    from ..core.regressor import pseudo_inertia
    theta = theta.copy()
    for k in range(n):
        sl = slice(N_INERTIAL * k, N_INERTIAL * (k + 1))
        own = theta[sl] - fixed[k]
        J = pseudo_inertia(own)
        lam, V = np.linalg.eigh(J)
        if lam.min() < 0:
            J = (V * np.maximum(lam, 0.0)) @ V.T
            I = np.trace(J[:3, :3]) * np.eye(3) - J[:3, :3]  # noqa: E741
            own = np.array([J[3, 3], J[0, 3], J[1, 3], J[2, 3], I[0, 0],
                            I[0, 1], I[1, 1], I[0, 2], I[1, 2], I[2, 2]])
            theta[sl] = own + fixed[k]
    d = theta[N_INERTIAL * n:].reshape(n, N_DRIVE)
    for col in (0, 1, 3):
        d[:, col] = np.maximum(d[:, col], 0.0)
    theta[N_INERTIAL * n:] = d.ravel()
    return theta


def predict(model, drives, Q, QD, QDD):
    """Model torques (rigid body + drives) at (m, n) states."""
    from ..core import inverse_dynamics_batch
    tau = inverse_dynamics_batch(model, Q, QD, QDD)
    if drives is not None:
        tau += drives.torques(QD, QDD)
    return tau
