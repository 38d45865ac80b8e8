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
The semidefinite programs of the fit and of the payload, well scaled.

A body is physically realisable iff its 4 x 4 pseudo-inertia
J = [[Sigma, h], [h^T, m]] is positive semi-definite (Wensing, Kim &
Slotine 2018); the ten parameters are linear in J (:func:`pi_of_pseudo`).
CVXPY states the constraint as it is and Clarabel solves it.

**Scaling.**  An arm's parameters span five orders of magnitude (a
shoulder's mass of 8 kg, a wrist's inertia of 1e-3 kg m^2, a torque
constant of 10 N m/A, a viscous friction of 0.1 N m s/rad), and an
interior-point solver's tolerances are absolute: on such a problem
Clarabel stops at its reduced accuracy ("Solution may be inaccurate") or
fails.  So every variable is solved for in units where it is of order
one: a link's pseudo-inertia as J = S Jt S with S = sqrt(mu) diag(l, l,
l, 1) (mu its nominal mass, l its nominal radius of gyration about the
link origin; a congruence, so Jt is PSD iff J is), every other
parameter divided by its typical size, and the objective scaled up
(:func:`objective_scale`; a solve that still stops early is repeated
once with it 30 times larger).  :class:`Solve` records what the solver
reported; an answer at reduced accuracy is kept (it is a feasible,
nearly optimal point) and said in one line by the command.
"""
import warnings

import numpy as np

MIN_LENGTH = 0.02      # m, least length scale of a link
MIN_MASS = 0.05        # kg, least mass scale of a link


def objective_scale(Aug):
    """
    Return f: the objective times f^2 is about 1e4 times the unknowns.

    ``Aug`` is the augmented square problem [R z; 0 rho] of a weighted
    least-squares fit ||R x - z||^2 + rho^2, rho^2 the unconstrained
    least residual (about 1: the rows are weighted by the residual of
    such a fit).  The program minimises the excess ||R x - z||^2, which
    the constraints and the prior make a few percent of rho^2 at most.
    Clarabel's tolerances are absolute, and measured on UR-like
    recordings the larger objective is the safer: unscaled, 14 of 24
    solves stopped at reduced accuracy (an objective of 0.04); with
    f^2 = 100 d / rho^2, 3 of 63 over five recordings; with
    f^2 = 1e4 d / rho^2, 2 solves at prior weights of 1e-7 and 1e-6 with
    a known mass, which the repeat with 30 times that brought to full
    accuracy.
    """
    d = Aug.shape[0] - 1
    floor = float(Aug[d, d]) ** 2
    total = floor + float(Aug[:d, d] @ Aug[:d, d])
    return float(np.sqrt(1e4 * d / max(floor, 1e-6 * total, 1e-300)))


def pi_of_pseudo(J):
    """Return the 10 parameters (cvxpy expressions) of a pseudo-inertia."""
    return [J[3, 3], J[0, 3], J[1, 3], J[2, 3],
            J[1, 1] + J[2, 2], -J[0, 1], J[0, 0] + J[2, 2], -J[0, 2],
            -J[1, 2], J[0, 0] + J[1, 1]]


def body_scale(pi):
    """Return (mass, length) scales of a body's 10 parameters."""
    from ..core.regressor import pseudo_inertia
    pi = np.asarray(pi, dtype=np.float64)
    m = float(pi[0])
    if not np.all(np.isfinite(pi)) or m <= MIN_MASS:
        return MIN_MASS if not m > MIN_MASS else m, 0.1
    Sigma = pseudo_inertia(pi)[:3, :3]
    length = np.sqrt(max(float(np.trace(Sigma)), 0.0) / m)
    return m, max(length, MIN_LENGTH)


class ScaledBody:
    """A body's 10 parameters from a scaled PSD variable, J = S Jt S."""

    def __init__(self, cp, mass, length):
        self.J = cp.Variable((4, 4), PSD=True)
        s = np.sqrt(mass) * np.array([length, length, length, 1.0])
        self.S = np.outer(s, s)
        self.params = pi_of_pseudo(cp.multiply(self.S, self.J))


class Solve:
    """What the solver said: 'optimal', 'inaccurate' or 'failed'."""

    def __init__(self, status, label=''):
        self.status = status
        self.label = label

    @property
    def ok(self):
        """Return True when there is an answer (maybe inaccurate)."""
        return self.status in ('optimal', 'inaccurate')


def solve(problem, label=''):
    """
    Solve a cvxpy problem with Clarabel; return a :class:`Solve`.

    CVXPY's "Solution may be inaccurate" warning is not passed on: the
    status says it, and the command reports it in one line.
    """
    import cvxpy as cp
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        try:
            problem.solve(solver=cp.CLARABEL)
        except cp.error.SolverError:
            return Solve('failed', label)
    if problem.status == cp.OPTIMAL:
        return Solve('optimal', label)
    if problem.status == cp.OPTIMAL_INACCURATE:
        return Solve('inaccurate', label)
    return Solve('failed', label)


INACCURATE = ('the solver stopped at its reduced accuracy (an answer a '
              'little off the optimum, still physically consistent)')
