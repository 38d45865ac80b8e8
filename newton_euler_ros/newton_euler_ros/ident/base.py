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
Base (identifiable) parameters, numerically.

Some columns of the regressor are zero (a link that never moves about an
axis) or combinations of others (a mass that only ever appears with the
next link's): only r combinations of the parameters, the base
parameters, act on the torques.  QR with column pivoting of the stacked
regressor (Gautier 1990) finds them: the first r pivots are independent
columns, r is the numerical rank.  Columns are scaled to unit norm first,
so that the rank does not depend on the units (kg against kg m^2).

The structural count (what the robot's geometry allows) comes from the
regressor at random states; the recording's rank from its own stacked
(reduced) regressor: a recording that barely moves has a rank far below.
"""
from dataclasses import dataclass

import numpy as np

RANK_TOL = 1e-7


@dataclass
class BaseInfo:
    """Rank, the independent columns (sorted) and the condition number."""

    rank: int
    columns: np.ndarray
    condition: float
    n_columns: int


def base_parameters(A, tol=RANK_TOL):
    """
    Rank and base columns of a stacked regressor ``A`` (rows x p).

    ``A`` may be the R factor of the stacked regressor (same column
    space and singular values).  The condition number is that of the base
    columns after scaling each to unit norm.
    """
    from scipy.linalg import qr
    A = np.asarray(A, dtype=np.float64)
    p = A.shape[1]
    norms = np.linalg.norm(A, axis=0)
    big = norms.max() if p else 0.0
    usable = norms > 1e-12 * max(big, 1e-300)
    scale = np.where(usable, norms, 1.0)
    As = A / scale
    As[:, ~usable] = 0.0
    if not usable.any():
        return BaseInfo(0, np.zeros(0, dtype=int), float('inf'), p)
    _, R, piv = qr(As, mode='economic', pivoting=True)
    d = np.abs(np.diag(R))
    rank = int(np.sum(d > tol * d[0]))
    cols = np.sort(piv[:rank])
    s = np.linalg.svd(As[:, cols], compute_uv=False)
    cond = float(s[0] / s[-1]) if s[-1] > 0 else float('inf')
    return BaseInfo(rank, cols, cond, p)


def random_states(model, count, seed=0):
    """``count`` random (q, qd, qdd) within the joint limits."""
    rng = np.random.default_rng(seed)
    n = model.n
    lo = np.full(n, -np.pi)
    hi = np.full(n, np.pi)
    limits = list(model.limits or ())
    # coordinate j is moving joint model.independent[j] (a tree's mimic
    # followers have no coordinate)
    for j, b in enumerate(model.independent):
        lim = limits[b] if b < len(limits) else {}
        if 'lower' in lim and 'upper' in lim and lim['upper'] > lim['lower']:
            lo[j], hi[j] = lim['lower'], lim['upper']
        elif model.joint_types[b] == 'prismatic':
            lo[j], hi[j] = -0.5, 0.5
    Q = rng.uniform(lo, hi, (count, n))
    return Q, rng.normal(size=(count, n)), rng.normal(size=(count, n))


def structural_base(model, drives=True, count=200, seed=0):
    """Return the :class:`BaseInfo` of the regressor at random states."""
    from ..core.regressor import regressor_batch
    Q, QD, QDD = random_states(model, count, seed)
    Y = regressor_batch(model, Q, QD, QDD, drives=drives)
    # the R factor has the stacked regressor's column norms and singular
    # values: the pivoted QR runs on a p x p matrix
    return base_parameters(np.linalg.qr(Y.reshape(-1, Y.shape[2]),
                                        mode='r'))
