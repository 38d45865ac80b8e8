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
Excitation trajectories: a finite Fourier series per joint (Swevers 1997).

Joint j follows, with w = 2 pi / T (T the period) and K harmonics::

    q_j(t) = q0_j + sum_l  a_jl / (w l) sin(w l t) - b_jl / (w l) cos(w l t)

so that qd_j = sum_l a_jl cos(w l t) + b_jl sin(w l t).  Rest at t = 0
(and so at every multiple of T) takes sum_l a_jl = 0 (no velocity) and
sum_l l b_jl = 0 (no acceleration); q0_j is chosen so that q_j(0) is the
start configuration.  The free coefficients are the 2K - 2 coordinates
of (a_j, b_j) in the null space of these two constraints: the optimiser
moves freely and every candidate starts and ends at rest.

Limits by construction: each joint's deviation from the start is scaled,
for every candidate, by the largest factor that keeps its position,
velocity and acceleration inside the limits less the margin (checked on a
dense grid): every joint always uses its whole allowed range, and the
optimiser sees only feasible trajectories.  Margins (``MARGIN``): the
position stays ``MARGIN`` of the range away from each limit; velocity and
acceleration peak at ``1 - MARGIN`` of their limits.  URDF has no
acceleration limit: ``DEFAULT_ACCELERATION`` applies; a joint without a
velocity limit (absent or 0) gets ``DEFAULT_VELOCITY``; one without
position limits (continuous) may swing +-``DEFAULT_HALF_RANGE`` about the
start.

Objective: the condition number of the base-parameter regressor (inertial
and drive columns, the base columns found by pivoted QR at random states,
each column scaled to unit norm) stacked at ``SAMPLES_PER_PERIOD`` states
over a period, minimised (in log) by L-BFGS-B from a random series of the
given seed, within a time budget.  The unoptimised random series is
scaled the same way: its condition number is the baseline printed.

A request whose limits leave a joint less than ``MIN_SWING`` of its
range (a period too short for its velocity or acceleration limit) is
refused with the shortest period that would do.

The user narrows the limits (:func:`narrowed`: a joint range inside the
URDF's, lower velocity limits, acceleration limits) and may keep the arm
clear of planes (``ident.clearance``: the mounting surface, walls, a
workcell box).  Clearance is not linear in the coefficients: after the
per-joint scaling, the whole motion about the start is shrunk by the
largest factor in [0, 1] that keeps every body clear on the grid
(bisection; the start itself is clear), so the optimiser still sees
only feasible trajectories and is steered away from motions that must
shrink.  The result is checked again on the fine grid; a motion that the
clearance shrinks below ``MIN_SWING`` of a joint's range is refused as
not useful.
"""
from dataclasses import dataclass, field
import math
import time

from numba import njit
import numpy as np

from ..core.errors import DynamicsInputError
# the package's cache locators stand first before njit(cache=True) below
from ..core.kernels import package_locators  # noqa: F401

MARGIN = 0.05
DEFAULT_VELOCITY = 1.0       # rad/s (m/s for prismatic: DEFAULT_VELOCITY_P)
DEFAULT_VELOCITY_P = 0.2
DEFAULT_ACCELERATION = 4.0   # rad/s^2 (m/s^2 for prismatic: ..._P)
DEFAULT_ACCELERATION_P = 1.0
DEFAULT_HALF_RANGE = math.pi / 2
MIN_SWING = 0.1              # of the usable position range
SAMPLES_PER_PERIOD = 150     # states for the condition number
GRID_PER_HARMONIC = 40       # limit checks per period of the top harmonic
TIME_BUDGET = 40.0           # s of optimisation at most
RATE = 50.0                  # trajectory points per second in the JSON


class ExcitationError(DynamicsInputError):
    """The request cannot be met (one line)."""


@dataclass
class Limits:
    """Usable limits per joint (margins applied) and where they came from."""

    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    notes: list = field(default_factory=list)


@dataclass
class Excitation:
    """An optimised series and what it reached."""

    joint_names: list
    period: float
    harmonics: int
    start: np.ndarray
    a: np.ndarray            # (n, K), scaled
    b: np.ndarray
    condition: float
    condition_random: float
    base_count: int
    seconds: float
    evaluations: int
    limits: Limits
    margins: dict = field(default_factory=dict)
    clearance: object = None     # ident.clearance.Clearance, or None
    shrink: float = 1.0          # of the motion, kept by the clearance

    def sample(self, t):
        """Return (q, qd, qdd) at times t, each (len(t), n)."""
        return _series(self.a, self.b, self.start, self.period,
                       np.asarray(t, dtype=np.float64))


def _series(a, b, start, period, t):
    K = a.shape[1]
    w = 2.0 * math.pi / period
    ll = np.arange(1, K + 1)
    arg = w * np.outer(t, ll)
    s, c = np.sin(arg), np.cos(arg)
    q = start + (s / (w * ll)) @ a.T - ((c - 1.0) / (w * ll)) @ b.T
    qd = c @ a.T + s @ b.T
    qdd = (-w * ll * s) @ a.T + (w * ll * c) @ b.T
    return q, qd, qdd


def model_limits(model):
    """Return :class:`Limits` of a model with the margins applied."""
    n = model.n
    lo = np.full(n, -np.inf)
    hi = np.full(n, np.inf)
    vel = np.zeros(n)
    acc = np.zeros(n)
    notes = []
    lims = list(model.limits or ()) + [{}] * n
    for j in range(n):
        lim = lims[j] or {}
        prism = model.joint_types[j] == 'prismatic'
        if ('lower' in lim and 'upper' in lim
                and lim['upper'] > lim['lower']):
            lo[j], hi[j] = lim['lower'], lim['upper']
        v = float(lim.get('velocity') or 0.0)
        if not v > 0:
            v = DEFAULT_VELOCITY_P if prism else DEFAULT_VELOCITY
            notes.append(f'{model.joint_names[j]}: no velocity limit, '
                         f'using {v:g}')
        vel[j] = v
        acc[j] = DEFAULT_ACCELERATION_P if prism else DEFAULT_ACCELERATION
    return Limits(lo, hi, vel, acc, notes)


def narrowed(model, limits, ranges=(), max_velocity=None,
             max_acceleration=None):
    """
    Return ``limits`` narrowed by the user (ExcitationError if not inside).

    ``ranges``: (joint name, lower, upper) inside the joint's URDF limits;
    ``max_velocity``: one value for every joint or one per joint, the
    lower of it and the URDF's is used; ``max_acceleration``: the same,
    replacing the default (URDF has no acceleration limit).
    """
    lo, hi = limits.lower.copy(), limits.upper.copy()
    vel, acc = limits.velocity.copy(), limits.acceleration.copy()
    names = list(model.joint_names)
    for name, a, b in ranges:
        if name not in names:
            raise ExcitationError(f'--range: no joint {name!r} in the chain '
                                  f'(joints: {", ".join(names)})')
        j = names.index(name)
        if not (math.isfinite(a) and math.isfinite(b) and a < b):
            raise ExcitationError(f'--range {name}: needs LOWER < UPPER, '
                                  f'got {a:g} {b:g}')
        if a < lo[j] or b > hi[j]:
            raise ExcitationError(
                f'--range {name} {a:g} {b:g}: not inside its URDF limits '
                f'[{lo[j]:g}, {hi[j]:g}]')
        lo[j], hi[j] = a, b
    for option, values, out in (('--max-velocity', max_velocity, vel),
                                ('--max-acceleration', max_acceleration,
                                 acc)):
        if values is None:
            continue
        values = np.atleast_1d(np.asarray(values, dtype=np.float64))
        if values.size not in (1, len(names)):
            raise ExcitationError(f'{option}: one value or one per joint '
                                  f'({len(names)}), got {values.size}')
        if not (np.isfinite(values).all() and (values > 0).all()):
            raise ExcitationError(f'{option}: must be positive numbers')
        values = np.broadcast_to(values, out.shape)
        if option == '--max-velocity':
            out[:] = np.minimum(out, values)
        else:
            out[:] = values
    return Limits(lo, hi, vel, acc, list(limits.notes))


def _usable(limits, start):
    """Per joint: allowed deviation below/above start, vel and acc caps."""
    rng = limits.upper - limits.lower
    finite = np.isfinite(rng)
    pad = np.where(finite, MARGIN * np.where(finite, rng, 0.0), 0.0)
    down = np.where(finite, start - (limits.lower + pad), DEFAULT_HALF_RANGE)
    up = np.where(finite, (limits.upper - pad) - start, DEFAULT_HALF_RANGE)
    return (down, up, (1.0 - MARGIN) * limits.velocity,
            (1.0 - MARGIN) * limits.acceleration)


def precompile():
    """Compile (or load) this module's kernel (``precompile.py``)."""
    _gram_eigenvalues(np.eye(2), np.ones(2))


@njit(cache=True)
def _gram_eigenvalues(A, scale):
    # single-threaded on purpose: a multi-threaded BLAS call on a small
    # matrix costs ten times more on a loaded machine
    m, p = A.shape
    G = np.zeros((p, p))
    for r in range(m):
        for i in range(p):
            ai = A[r, i] * scale[i]
            if ai != 0.0:
                for k in range(i, p):
                    G[i, k] += ai * A[r, k] * scale[k]
    for i in range(p):
        for k in range(i):
            G[i, k] = G[k, i]
    return np.linalg.eigvalsh(G)


class _OneBlasThread:
    """
    Run OpenBLAS single-threaded inside the block (Linux; else no-op).

    The optimiser makes thousands of small LAPACK calls; OpenBLAS's
    threads cost about ten times the work on a loaded 2-core machine.
    """

    def __init__(self):
        self.saved = []

    def __enter__(self):
        import ctypes
        try:
            with open('/proc/self/maps', encoding='utf-8') as f:
                paths = {line.split()[-1] for line in f
                         if 'openblas' in line.lower()}
        except OSError:
            return self
        for path in sorted(paths):
            try:
                lib = ctypes.CDLL(path)
            except OSError:
                continue
            for stem in ('openblas', 'scipy_openblas'):
                for tail in ('64_', ''):
                    get = getattr(lib, f'{stem}_get_num_threads{tail}', None)
                    put = getattr(lib, f'{stem}_set_num_threads{tail}', None)
                    if get is not None and put is not None:
                        self.saved.append((put, int(get())))
                        put(1)
        return self

    def __exit__(self, *exc):
        for put, count in self.saved:
            put(count)
        return False


def _null_basis(K, period):
    """(2K, 2K-2) orthonormal basis of {sum a = 0, sum l b = 0}."""
    C = np.zeros((2, 2 * K))
    C[0, :K] = 1.0
    C[1, K:] = np.arange(1, K + 1)
    _, _, Vt = np.linalg.svd(C)
    return Vt[2:].T


class _Problem:
    def __init__(self, model, start, period, harmonics, limits, base_cols,
                 eps, clearance=None):
        from ..core.regressor import regressor_batch
        self.regressor_batch = regressor_batch
        self.model = model
        self.n = model.n
        self.K = harmonics
        self.period = period
        self.start = start
        self.limits = limits
        self.down, self.up, self.vmax, self.amax = _usable(limits, start)
        self.N = _null_basis(harmonics, period)
        self.cols = base_cols
        self.eps = eps
        grid = max(200, GRID_PER_HARMONIC * harmonics)
        self.t_grid = np.linspace(0.0, period, grid, endpoint=False)
        self.t_cond = np.linspace(0.0, period, SAMPLES_PER_PERIOD,
                                  endpoint=False)
        self.evaluations = 0
        self.clearance = clearance
        self.shrink = 1.0

    def coefficients(self, x, fine=False):
        """Scaled (a, b), each (n, K), from the free variables x."""
        ab = (self.N @ x.reshape(self.n, -1).T).T      # (n, 2K)
        a, b = ab[:, :self.K].copy(), ab[:, self.K:].copy()
        grid = (np.linspace(0.0, self.period, 50 * len(self.t_grid),
                            endpoint=False) if fine else self.t_grid)
        q, qd, qdd = _series(a, b, np.zeros(self.n), self.period, grid)
        with np.errstate(divide='ignore', invalid='ignore'):
            s = np.min(np.stack([
                self.up / np.maximum(q.max(axis=0), 1e-300),
                self.down / np.maximum(-q.min(axis=0), 1e-300),
                self.vmax / np.maximum(np.abs(qd).max(axis=0), 1e-300),
                self.amax / np.maximum(np.abs(qdd).max(axis=0), 1e-300)]),
                axis=0)
        s = np.where(np.isfinite(s), s, 0.0)
        self.shrink = 1.0
        if self.clearance is not None:
            self.shrink = self.clearance.shrink(self.start, q * s)
        s = s * self.shrink
        return a * s[:, None], b * s[:, None]

    def log_condition(self, x):
        self.evaluations += 1
        a, b = self.coefficients(x)
        q, qd, qdd = _series(a, b, self.start, self.period, self.t_cond)
        Y = self.regressor_batch(self.model, q, qd, qdd, drives=True,
                                 coulomb_width=self.eps)
        A = np.ascontiguousarray(Y.reshape(-1, Y.shape[2])[:, self.cols])
        norms = np.sqrt(np.einsum('ij,ij->j', A, A))
        if norms.min() <= 1e-12 * max(norms.max(), 1e-300):
            return 50.0
        # eigenvalues of the scaled Gram matrix: the squared singular
        # values, at a fraction of an SVD's cost (condition numbers of
        # interest are far below 1e8, where squaring loses nothing)
        lam = _gram_eigenvalues(A, 1.0 / norms)
        if not lam[0] > 0:
            return 50.0
        return float(0.5 * np.log(lam[-1] / lam[0]))


def _swing_range(limits):
    """Usable range per joint (a turn at most) that MIN_SWING is of."""
    rng = np.where(np.isfinite(limits.upper - limits.lower),
                   (1 - 2 * MARGIN) * (limits.upper - limits.lower),
                   2 * DEFAULT_HALF_RANGE)
    return np.minimum(rng, 2 * math.pi)


def check_feasible(model, limits, start, period, harmonics):
    """Raise :class:`ExcitationError` when the limits leave no swing."""
    down, up, vmax, amax = _usable(limits, start)
    names = model.joint_names
    for j in range(model.n):
        if not (limits.lower[j] <= start[j] <= limits.upper[j]):
            raise ExcitationError(
                f'start position of {names[j]} ({start[j]:g}) is outside '
                f'its limits [{limits.lower[j]:g}, {limits.upper[j]:g}]')
    rng = _swing_range(limits)
    # the fundamental alone, amplitude A: peak speed A w, acceleration A w^2
    w = 2 * math.pi / period
    swing = np.minimum(np.minimum(down, up), np.minimum(vmax / w,
                                                        amax / w ** 2))
    need = 0.5 * MIN_SWING * rng
    for j in range(model.n):
        if min(down[j], up[j]) < need[j]:
            raise ExcitationError(
                f'start position of {names[j]} ({start[j]:g}) is within '
                f'{min(down[j], up[j]):.3g} of its limit (margin included): '
                f'choose a start nearer the middle')
    short = np.flatnonzero(swing < need)
    if short.size:
        # the shortest period every joint can live with
        t_min = max(2 * math.pi * max(need[k] / vmax[k],
                                      math.sqrt(need[k] / amax[k]))
                    for k in range(model.n))
        j = int(short[np.argmin(swing[short] / need[short])])
        raise ExcitationError(
            f'period {period:g} s is too short for the velocity and '
            f'acceleration limits of {names[j]} ({vmax[j]:.3g} rad/s, '
            f'{amax[j]:.3g} rad/s^2 with the margin): it could swing '
            f'only +-{swing[j]:.3g}; use --period '
            f'{math.ceil(t_min * 10) / 10:g} or more (the least that '
            f'excites at all: a few times that swings wider and '
            f'identifies better; the default is 10)')


def excite(model, period=10.0, harmonics=5, seed=0, start=None,
           budget=TIME_BUDGET, coulomb_width=0.02, limits=None,
           clearance=None, evaluations=None):
    """
    Return the optimised :class:`Excitation` of ``model``.

    The optimisation stops at ``budget`` seconds, or after
    ``evaluations`` evaluations of the condition number if that comes
    first: with a count, the same seed gives the same motion on any
    machine, however loaded.

    ``limits``: :class:`Limits` (default the model's, see
    :func:`narrowed`); ``clearance``: an ``ident.clearance.Clearance`` to
    keep (default none).
    """
    from scipy.optimize import minimize
    from .base import structural_base
    t0 = time.perf_counter()
    period = float(period)
    harmonics = int(harmonics)
    if not (period > 0 and math.isfinite(period)):
        raise ExcitationError(f'--period must be a positive number of '
                              f'seconds, got {period:g}')
    if harmonics < 2:
        raise ExcitationError(f'--harmonics must be at least 2 (rest at '
                              f'both ends takes two coefficients per '
                              f'joint), got {harmonics}')
    limits = model_limits(model) if limits is None else limits
    if start is None:
        mid = 0.5 * (limits.lower + limits.upper)
        start = np.where(np.isfinite(mid), mid, 0.0)
    start = np.asarray(start, dtype=np.float64)
    if start.shape != (model.n,):
        raise ExcitationError(f'the start configuration needs {model.n} '
                              f'values (one per joint), got {start.size}')
    check_feasible(model, limits, start, period, harmonics)
    if clearance is not None:
        clearance.set_start(start)
    base = structural_base(model, drives=True)
    prob = _Problem(model, start, period, harmonics, limits, base.columns,
                    coulomb_width, clearance)
    rng = np.random.default_rng(seed)
    x0 = rng.normal(size=model.n * (2 * harmonics - 2))
    f0 = prob.log_condition(x0)
    best = {'x': x0, 'f': f0}
    deadline = t0 + budget

    class _Stop(Exception):
        pass

    def fun(x):
        if time.perf_counter() > deadline or (
                evaluations is not None and prob.evaluations >= evaluations):
            raise _Stop
        f = prob.log_condition(x)
        if f < best['f']:
            best['x'], best['f'] = x.copy(), f
        return f

    with _OneBlasThread():
        try:
            minimize(fun, x0, method='L-BFGS-B',
                     options={'maxiter': 300, 'eps': 1e-5})
        except _Stop:
            pass
    # the optimiser's grid may miss a peak by a little: the final
    # scaling is checked on a grid 50 times finer
    a, b = prob.coefficients(best['x'], fine=True)
    exc = Excitation(
        joint_names=list(model.joint_names), period=period,
        harmonics=harmonics, start=start, a=a, b=b,
        condition=float(math.exp(best['f'])),
        condition_random=float(math.exp(f0)), base_count=base.rank,
        seconds=time.perf_counter() - t0, evaluations=prob.evaluations,
        limits=limits, clearance=clearance, shrink=prob.shrink)
    exc.margins = margins(exc)
    if clearance is not None:
        _check_useful(exc, model)
    return exc


def _check_useful(exc, model):
    """Raise ExcitationError if the clearance leaves a joint hardly moving."""
    swing = np.maximum(exc.margins['q_max'] - exc.start,
                       exc.start - exc.margins['q_min'])
    need = 0.5 * MIN_SWING * _swing_range(exc.limits)
    short = np.flatnonzero(swing < need)
    if not short.size:
        return
    j = int(short[np.argmin(swing[short] / need[short])])
    cl = exc.clearance
    slack = cl.slack(exc.sample(np.linspace(0.0, exc.period, 2000))[0])
    b, p = np.unravel_index(np.argmin(slack), slack.shape)
    unit = 'm' if model.joint_types[j] == 'prismatic' else 'rad'
    raise ExcitationError(
        f'nothing useful fits in the constraints: keeping '
        f'{cl.bodies[b].name} {cl.required[b, p]:.3g} m from the '
        f'{cl.planes[p].label} leaves {model.joint_names[j]} a swing '
        f'of +-{swing[j]:.3g} {unit} (at least +-{need[j]:.3g} is needed; '
        f'{100 * exc.shrink:.0f} % of the motion the limits allow): start '
        f'farther from the plane, or narrow the motion with --range')


def margins(exc):
    """Per joint: the closest approach to each limit, as fractions."""
    t = np.linspace(0.0, exc.period, 4000, endpoint=False)
    q, qd, qdd = exc.sample(t)
    lim = exc.limits
    rng = lim.upper - lim.lower
    finite = np.isfinite(rng)
    with np.errstate(invalid='ignore'):
        pos = np.where(finite, np.minimum(q.min(axis=0) - lim.lower,
                                          lim.upper - q.max(axis=0))
                       / np.where(finite, rng, 1.0), np.nan)
    return {'q_min': q.min(axis=0), 'q_max': q.max(axis=0),
            'position': pos,
            'velocity': np.abs(qd).max(axis=0) / lim.velocity,
            'acceleration': np.abs(qdd).max(axis=0) / lim.acceleration}


def trajectory_json(exc, seconds=None, rate=RATE):
    """Return the JointTrajectory JSON (``newton-euler feedforward`` reads)."""
    periods = 1 if seconds is None else max(
        1, int(math.ceil(float(seconds) / exc.period - 1e-9)))
    total = periods * exc.period
    count = int(round(total * rate))
    t = np.arange(count + 1) / rate
    t[-1] = total
    q, qd, qdd = exc.sample(t)
    # the series is at rest at every multiple of the period: make it exact
    qd[[0, -1]] = 0.0
    qdd[[0, -1]] = 0.0
    q[[0, -1]] = exc.start
    points = [{'time_from_start': float(round(t[i], 9)),
               'positions': [round(float(v), 9) for v in q[i]],
               'velocities': [round(float(v), 9) for v in qd[i]],
               'accelerations': [round(float(v), 9) for v in qdd[i]]}
              for i in range(len(t))]
    return {'joint_names': list(exc.joint_names), 'points': points}
