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
Effort feedforward along a planned joint trajectory.

joint_trajectory_controller (ros2_controllers >= 4.22, Jazzy) adds the
``effort`` of each trajectory point as feedforward when the robot has an
effort command interface; planners publish positions, velocities and
accelerations but no efforts.  :func:`trajectory_efforts` fills them:
tau = D qdd + C qd + g (+ J^T F_e) at every point, by one batched call.

Points use the field names of ``trajectory_msgs/JointTrajectoryPoint``
(``positions``, ``velocities``, ``accelerations``, ``effort``,
``time_from_start`` in seconds).

Missing derivatives.  ``velocities`` (or ``accelerations``) must be given
in every point or in none.  When none has them they are the derivatives
of the positions (of the velocities) at the given times, by second-order
finite differences on the non-uniform grid (one-sided at the ends); a
single point gets zeros.  Zeros would be wrong for a moving arm (the
velocity-product and inertial torques would vanish), and the times are
in the message, so differentiating is what the planner's curve implies.
"""
import math

import numpy as np

from .dynamics import inverse_dynamics_batch, wrench_torques
from .errors import DynamicsInputError

MAX_POINTS = 100000
FIELDS = ('positions', 'velocities', 'accelerations')


class TrajectoryError(DynamicsInputError):
    """A trajectory is unusable; the message says which point and field."""


def differentiate(times, values):
    """
    Return d values / d t at each time, second order on a non-uniform grid.

    ``times`` (m,) strictly increasing, ``values`` (m, n).  Interior points
    use the three-point formula (exact for quadratics), the ends the
    one-sided three-point formulas; two points give the slope, one zero.
    """
    t = np.asarray(times, dtype=np.float64)
    x = np.asarray(values, dtype=np.float64)
    m = t.shape[0]
    out = np.zeros_like(x)
    if m == 1:
        return out
    if m == 2:
        out[:] = (x[1] - x[0]) / (t[1] - t[0])
        return out
    h0 = t[1:-1] - t[:-2]
    h1 = t[2:] - t[1:-1]
    out[1:-1] = ((-h1 / (h0 * (h0 + h1)))[:, None] * x[:-2]
                 + ((h1 - h0) / (h0 * h1))[:, None] * x[1:-1]
                 + (h0 / (h1 * (h0 + h1)))[:, None] * x[2:])
    a, b = t[1] - t[0], t[2] - t[1]
    out[0] = (-(2 * a + b) / (a * (a + b)) * x[0] + (a + b) / (a * b) * x[1]
              - a / (b * (a + b)) * x[2])
    a, b = t[-1] - t[-2], t[-2] - t[-3]
    out[-1] = ((2 * a + b) / (a * (a + b)) * x[-1]
               - (a + b) / (a * b) * x[-2] + a / (b * (a + b)) * x[-3])
    return out


def _column_map(model, joint_names, where, partial=False):
    """
    Return (cols, named): the trajectory's columns of the model's joints.

    ``named`` are the model indices of the joints the trajectory names, in
    model order, and ``cols`` their columns in the trajectory.  Every
    joint must be named unless ``partial``.
    """
    names = list(joint_names)
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise TrajectoryError(f'{where}joint_names: {dup!r} appears twice')
    unknown = [n for n in names if n not in model.joint_names]
    if unknown:
        followers = {model.moving_joints[b]: model.moving_joints[m[0]]
                     for b, m in enumerate(model.mimic or ()) if m}
        if unknown[0] in followers:
            raise TrajectoryError(
                f'{where}joint_names: {unknown[0]!r} is a mimic joint (it '
                f'follows {followers[unknown[0]]!r}): name its leader')
        raise TrajectoryError(f'{where}joint_names: unknown joints '
                              f'{unknown[:5]} (the robot has '
                              f'{list(model.joint_names)})')
    missing = [n for n in model.joint_names if n not in names]
    if missing and not partial:
        raise TrajectoryError(f'{where}joint_names: missing joints '
                              f'{missing[:5]}; every joint of the robot is '
                              f'needed')
    named = np.array([k for k, n in enumerate(model.joint_names)
                      if n in names], dtype=np.intp)
    cols = np.array([names.index(model.joint_names[k]) for k in named],
                    dtype=np.intp)
    return cols, named


def _get(point, key):
    if isinstance(point, dict):
        return point.get(key)
    return getattr(point, key, None)


def _vectorized(points, n, cols):
    """
    Return the arrays of well-formed points in a few numpy calls, or None.

    A trajectory from a planner is almost always well formed; checking it
    with whole-array operations keeps the per-point cost near the
    dynamics' own.  Anything unusual returns None, and the point-by-point
    check then names the problem.
    """
    try:
        times = np.array([_get(p, 'time_from_start') for p in points],
                         dtype=np.float64)
        if not np.isfinite(times).all() or times[0] < 0.0 or (
                times.shape[0] > 1 and not (np.diff(times) > 0.0).all()):
            return None
        arrays, given = {}, {}
        for field in FIELDS:
            rows = [_get(p, field) for p in points]
            sizes = {0 if r is None else len(r) for r in rows}
            if sizes == {0}:
                arrays[field], given[field] = None, 0
                continue
            if sizes != {n}:
                return None
            X = np.array(rows, dtype=np.float64)
            if X.shape != (len(points), n) or not np.isfinite(X).all():
                return None
            arrays[field], given[field] = X[:, cols], len(points)
        return times, arrays, given
    except (TypeError, ValueError):
        return None


def _point_by_point(points, n, cols, where):
    """Return the same arrays, checked point by point (errors name it)."""
    m = len(points)
    times = np.empty(m)
    arrays = {f: np.empty((m, n)) for f in FIELDS}
    given = dict.fromkeys(FIELDS, 0)
    for k, point in enumerate(points):
        t = _get(point, 'time_from_start')
        try:
            t = float(t)
        except (TypeError, ValueError):
            raise TrajectoryError(f'{where}points[{k}].time_from_start: must '
                                  f'be a number of seconds, got {t!r}') \
                from None
        if not math.isfinite(t) or t < 0.0:
            raise TrajectoryError(f'{where}points[{k}].time_from_start: must '
                                  f'be finite and >= 0, got {t}')
        if k and not t > times[k - 1]:
            raise TrajectoryError(
                f'{where}points[{k}].time_from_start: {t} s is not after '
                f'the previous point ({times[k - 1]} s); times must increase')
        times[k] = t
        for field in FIELDS:
            values = _get(point, field)
            if values is None or len(values) == 0:
                continue
            if len(values) != n:
                raise TrajectoryError(
                    f'{where}points[{k}].{field}: {len(values)} values for '
                    f'{n} joints')
            try:
                row = np.asarray(values, dtype=np.float64)
            except (TypeError, ValueError):
                raise TrajectoryError(f'{where}points[{k}].{field}: must be '
                                      f'numbers') from None
            bad = np.flatnonzero(~np.isfinite(row))
            if bad.size:
                raise TrajectoryError(
                    f'{where}points[{k}].{field}[{bad[0]}]: must be finite, '
                    f'got {row[bad[0]]}')
            arrays[field][k] = row[cols]
            given[field] += 1
    for field in FIELDS:
        if given[field] == 0:
            arrays[field] = None
    return times, arrays, given


def trajectory_arrays(model, joint_names, points, where='', hold=None):
    """
    Validate points; return (times, Q, QD, QDD) in the model's joint order.

    ``points`` is a sequence of mappings (or objects with the same
    attributes) with ``time_from_start`` and the three fields; ``where``
    prefixes every error message (a file name, or the topic).  With
    ``hold`` (n positions, model order) the trajectory may name some of
    the joints only: the others stay at ``hold``, at rest (one arm of a
    dual-arm robot moves, the other is held where it was measured).
    """
    cols, named = _column_map(model, joint_names, where, hold is not None)
    m = len(points)
    if m == 0:
        raise TrajectoryError(f'{where}points: the trajectory has no points')
    if m > MAX_POINTS:
        raise TrajectoryError(f'{where}points: {m} points, more than the '
                              f'{MAX_POINTS} accepted')
    n = len(cols)
    fast = _vectorized(points, n, cols)
    if fast is not None:
        times, arrays, given = fast
    else:       # something is off: find it point by point, for the message
        times, arrays, given = _point_by_point(points, n, cols, where)
    for field in FIELDS:
        if given[field] not in (0, m):
            raise TrajectoryError(
                f'{where}points: {field} given in {given[field]} of {m} '
                f'points; give them in every point or in none')
    if not given['positions']:
        raise TrajectoryError(f'{where}points: every point needs positions')
    Q = arrays['positions']
    QD = arrays['velocities'] if given['velocities'] else differentiate(
        times, Q)
    QDD = (arrays['accelerations'] if given['accelerations']
           else differentiate(times, QD))
    if n == model.n:
        return times, Q, QD, QDD
    full = [np.zeros((m, model.n)) for _ in range(3)]
    full[0][:] = np.asarray(hold, dtype=np.float64)
    for X, part in zip(full, (Q, QD, QDD)):
        X[:, named] = part
    return (times, *full)


def trajectory_efforts(model, joint_names, points, wrench=None,
                       wrench_frame='base', where='', ws=None, drives=None,
                       gravity=True, hold=None):
    """
    Efforts (m, k) at every point, for the k joints of the trajectory.

    In the trajectory's joint order: tau = D qdd + C qd + g (+ J^T F_e for
    a ``wrench`` held along the whole trajectory, an end-effector [f; n]
    or wrenches at links ``{link: [f; n]}`` as
    :func:`~newton_euler_ros.core.dynamics.inverse_dynamics` takes them;
    + the drive terms of ``drives``, a ``core.drives.Drives``; without g
    when not ``gravity``: a robot that adds it itself), one batched call;
    with ``hold``, the joints the trajectory does not name stay there at
    rest (:func:`trajectory_arrays`).  Raises :class:`TrajectoryError`
    for a bad trajectory (one line naming the point and the field).
    """
    _, Q, QD, QDD = trajectory_arrays(model, joint_names, points, where,
                                      hold)
    W = None
    if wrench is not None and not isinstance(wrench, dict):
        W = np.tile(np.asarray(wrench, dtype=np.float64), (Q.shape[0], 1))
    tau = inverse_dynamics_batch(model, Q, QD, QDD, W,
                                 'base' if W is None else wrench_frame,
                                 gravity=gravity, ws=ws)
    if isinstance(wrench, dict):
        for k in range(Q.shape[0]):
            tau[k] += wrench_torques(model, Q[k], wrench, wrench_frame,
                                     ws=ws)
    if drives is not None:
        tau = tau + drives.torques(QD, QDD)
    cols, named = _column_map(model, joint_names, where, hold is not None)
    out = np.empty((tau.shape[0], len(cols)))
    out[:, cols] = tau[:, named]
    return out


def fill_efforts(model, trajectory, wrench=None, wrench_frame='base',
                 where='', hold=None, drives=None):
    """
    Return a JSON-style trajectory dict with ``effort`` in every point.

    ``wrench``, ``wrench_frame``, ``hold`` and ``drives`` as
    :func:`trajectory_efforts` takes them.
    """
    names = trajectory.get('joint_names')
    if not isinstance(names, list) or not all(isinstance(x, str)
                                              for x in names):
        raise TrajectoryError(f'{where}joint_names: must be a list of '
                              f'strings')
    points = trajectory.get('points')
    if not isinstance(points, list) or not all(isinstance(p, dict)
                                               for p in points):
        raise TrajectoryError(f'{where}points: must be a list of objects')
    for k, point in enumerate(points):
        unknown = set(point) - {'time_from_start', 'effort', *FIELDS}
        if unknown:
            raise TrajectoryError(f'{where}points[{k}]: unknown key '
                                  f'{sorted(unknown)[0]!r}')
    efforts = trajectory_efforts(model, names, points, wrench, wrench_frame,
                                 where, hold=hold, drives=drives)
    out = dict(trajectory)
    out['points'] = [dict(p, effort=e.tolist())
                     for p, e in zip(points, efforts)]
    return out


class TrajectoryFollower:
    """
    What joint_trajectory_controller does with a trajectory, as a sampler.

    Holds the trajectories received (each anchored at its absolute start
    time); :meth:`sample` returns the desired positions, velocities and
    efforts at time t from the newest trajectory that has started, linear
    in time between its points (JTC interpolates with splines; at the
    10 ms spacing of a planner's points the difference is negligible
    here), holding the last point after its end.  Efforts default to
    zero when the points have none.  The simulator uses it to stand in
    for JTC with an effort command interface: tau = kp (q_d - q) +
    kd (qd_d - qd) + effort_d.
    """

    def __init__(self, model, keep=8):
        self.model = model
        self.keep = keep
        self.trajectories = []      # (start, times, Q, QD, EFF)

    def set(self, joint_names, start, points):  # noqa: A003 (JTC's verb)
        """Add a trajectory starting at ``start`` (s); raises on bad input."""
        times, Q, QD, _ = trajectory_arrays(self.model, joint_names, points)
        cols, _ = _column_map(self.model, joint_names, '')
        eff = np.zeros_like(Q)
        efforts = [p.get('effort') if isinstance(p, dict)
                   else getattr(p, 'effort', None) for p in points]
        if all(e is not None and len(e) == len(cols) for e in efforts):
            eff = np.asarray(efforts, dtype=np.float64)[:, cols]
            if not np.isfinite(eff).all():
                raise TrajectoryError('effort: must be finite')
        self.trajectories.append((float(start), times, Q, QD, eff))
        self.trajectories.sort(key=lambda tr: tr[0])
        del self.trajectories[:-self.keep]

    def sample(self, t):
        """Desired (q, qd, effort) at time t, or None before any start."""
        active = None
        for tr in self.trajectories:
            if tr[0] <= t:
                active = tr
        if active is None:
            return None
        start, times, Q, QD, eff = active
        s = t - start
        if s <= times[0]:
            return Q[0], QD[0], eff[0]
        if s >= times[-1]:
            return Q[-1], np.zeros_like(QD[-1]), eff[-1]
        k = int(np.searchsorted(times, s, side='right'))
        w = (s - times[k - 1]) / (times[k] - times[k - 1])
        return tuple((1.0 - w) * X[k - 1] + w * X[k] for X in (Q, QD, eff))
