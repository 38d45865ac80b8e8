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
Motions of the current-sensing arm example (``current_arm_example``).

Each motion is a callable ``f(t) -> (q, qd, qdd)`` of (m,) times in
seconds, with a ``seconds`` attribute (its length), in the order of
``current_arm_example.JOINTS``; they stay within :data:`CENTRE` +-
:data:`HALF_RANGE` and about :data:`SPEED` (rad/s), and every stop is an
exact rest (qd = 0), as a position-controlled arm's.
"""
import math

import numpy as np

# where the motions stay (rad): centre and half range per joint (a UR5)
CENTRE = np.array([0.0, -1.6, 1.4, -1.6, -1.57, 0.0])
HALF_RANGE = np.array([1.5, 0.9, 1.0, 1.2, 1.2, 1.5])
SPEED = np.array([0.9, 0.8, 0.9, 1.2, 1.2, 1.4])    # rad/s, peak


def _smoothstep(x):
    """5th-order 0 -> 1 on [0, 1] and its first two derivatives in x."""
    x = np.clip(x, 0.0, 1.0)
    s = x ** 3 * (10 - 15 * x + 6 * x * x)
    ds = 30 * x * x * (1 - x) ** 2
    dds = 60 * x * (1 - x) * (1 - 2 * x)
    return s, ds, dds


def excitation(seed=0, seconds=60.0, period=20.0, harmonics=6, rest=2.0,
               ramp=3.0, scale=1.0):
    """
    Return a Fourier series per joint, faded in and out, resting at the ends.

    ``rest`` seconds still at each end, ``ramp`` seconds of fade; the
    series stays within :data:`HALF_RANGE` x 0.8 and :data:`SPEED`.
    """
    rng = np.random.default_rng([seed, 1])
    w0 = 2 * math.pi / period
    k = np.arange(1, harmonics + 1)
    a = rng.normal(size=(6, harmonics)) / k
    b = rng.normal(size=(6, harmonics)) / k
    grid = np.linspace(0, period, 3000, endpoint=False)
    arg = w0 * np.outer(grid, k)
    pos = np.sin(arg) @ a.T + np.cos(arg) @ b.T
    vel = w0 * ((np.cos(arg) * k) @ a.T - (np.sin(arg) * k) @ b.T)
    pos0 = b.sum(axis=1)
    amp = scale * np.minimum(0.8 * HALF_RANGE / np.abs(pos - pos0).max(0),
                             0.8 * SPEED / np.abs(vel).max(0))
    a, b = a * amp[:, None], b * amp[:, None]
    pos0 = b.sum(axis=1)

    def f(t):
        t = np.asarray(t, dtype=np.float64)
        arg = w0 * np.outer(t - rest, k)
        s, c = np.sin(arg), np.cos(arg)
        x = s @ a.T + c @ b.T - pos0
        xd = w0 * ((c * k) @ a.T - (s * k) @ b.T)
        xdd = -w0 ** 2 * ((s * k * k) @ a.T + (c * k * k) @ b.T)
        up = _smoothstep((t - rest) / ramp)
        down = _smoothstep((seconds - rest - t) / ramp)
        w = (up[0] * down[0])[:, None]
        wd = (up[1] / ramp * down[0] - up[0] * down[1] / ramp)[:, None]
        wdd = (up[2] / ramp ** 2 * down[0] - 2 * up[1] * down[1] / ramp ** 2
               + up[0] * down[2] / ramp ** 2)[:, None]
        q = CENTRE + w * x
        return q, wd * x + w * xd, wdd * x + 2 * wd * xd + w * xdd
    f.seconds = float(seconds)
    return f


def _moves(start, targets, durations, dwells):
    """Quintic moves between poses, each followed by a dwell at rest."""
    poses = [np.asarray(start, dtype=np.float64)]
    segs = []
    t = 0.0
    for target, d, w in zip(targets, durations, dwells):
        segs.append((t, d, poses[-1], np.asarray(target, dtype=np.float64)))
        t += d + w
        poses.append(segs[-1][3])
    total = t

    def f(tt):
        tt = np.asarray(tt, dtype=np.float64)
        q = np.empty((len(tt), 6))
        qd = np.zeros((len(tt), 6))
        qdd = np.zeros((len(tt), 6))
        q[:] = poses[0]
        for t0, d, p0, p1 in segs:
            after = tt >= t0
            s, ds, dds = _smoothstep((tt[after] - t0) / d)
            moving = (tt[after] < t0 + d)[:, None]
            q[after] = p0 + s[:, None] * (p1 - p0)
            qd[after] = np.where(moving, ds[:, None] / d * (p1 - p0), 0.0)
            qdd[after] = np.where(moving, dds[:, None] / d ** 2 * (p1 - p0),
                                  0.0)
        return q, qd, qdd
    f.seconds = float(total)
    f.end = poses[-1].copy()
    return f


def point_to_point(seed=0, seconds=40.0, dwell=(0.1, 0.4), few=0.0,
                   start=0.5, reverse=1.0, begin=None):
    """
    Point-to-point moves with stops and reversals, about ``seconds`` long.

    After ``start`` seconds at rest, each move goes to a random pose; each
    joint crosses its centre (a reversal) with probability ``reverse``,
    else stays on its side (it may then creep slowly).  A move lasts as
    its largest distance allows at the joints' :data:`SPEED` and ends in
    a stop drawn from ``dwell`` (s); a fraction ``few`` of the moves move
    only one to three joints (the others stay at rest).  ``begin``: the
    pose it starts from (default :data:`CENTRE`).
    """
    rng = np.random.default_rng([seed, 2])
    first = CENTRE.copy() if begin is None else np.array(begin, dtype=float)
    pose = first.copy()
    targets, durations, dwells = [], [], []
    t = start
    side = rng.choice([-1.0, 1.0], 6)
    while True:
        # mostly across the centre (a reversal), sometimes on
        side = np.where(rng.random(6) < reverse, -side, side)
        target = CENTRE + side * rng.uniform(0.25, 0.85, 6) * HALF_RANGE
        if rng.random() < few:
            keep = rng.choice(6, rng.integers(1, 4), replace=False)
            still = np.setdiff1d(np.arange(6), keep)
            target[still] = pose[still]
        # the quintic's peak speed is 1.875 distance / duration
        d = max(0.8, float(np.max(1.875 * np.abs(target - pose) / SPEED)))
        w = rng.uniform(*dwell)
        if targets and t + d + w > seconds:
            break
        targets.append(target)
        durations.append(d)
        dwells.append(w)
        pose = target
        t += d + w
    inner = _moves(first, targets, durations, dwells)

    def g(tt):
        return inner(np.asarray(tt, dtype=np.float64) - start)
    g.seconds = float(t)
    g.end = inner.end
    return g


def holding(seed=0, poses=5, hold=(4.0, 8.0)):
    """Return moves to ``poses`` random poses, each held for ``hold`` s."""
    rng = np.random.default_rng([seed, 3])
    targets, durations, dwells = [], [], []
    pose = CENTRE.copy()
    for k in range(poses):
        target = CENTRE + rng.uniform(-0.7, 0.7, 6) * HALF_RANGE
        d = max(1.0, float(np.max(1.875 * np.abs(target - pose) / SPEED)))
        targets.append(target)
        durations.append(d)
        dwells.append(rng.uniform(*hold))
        pose = target
    f = _moves(CENTRE, targets, durations, dwells)
    return f


def concatenate(*motions):
    """
    One motion after the other; each must start where the last ended.

    ValueError if one does not (the arm would jump between two samples).
    """
    for k in range(1, len(motions)):
        was = motions[k - 1](np.array([motions[k - 1].seconds]))[0][0]
        now = motions[k](np.array([0.0]))[0][0]
        if np.abs(now - was).max() > 1e-9:
            raise ValueError(f'concatenate: motion {k} starts at '
                             f'{now.tolist()}, not where motion {k - 1} '
                             f'ended ({was.tolist()})')
    starts = np.cumsum([0.0] + [m.seconds for m in motions])

    def f(t):
        t = np.asarray(t, dtype=np.float64)
        out = [np.empty((len(t), 6)) for _ in range(3)]
        for k, m in enumerate(motions):
            sel = (t >= starts[k]) & ((t < starts[k + 1])
                                      | (k == len(motions) - 1))
            for o, v in zip(out, m(t[sel] - starts[k])):
                o[sel] = v
        return tuple(out)
    f.seconds = float(starts[-1])
    f.end = getattr(motions[-1], 'end', None)
    return f


def held_then_moving(seed):
    """Three poses held 4-8 s each, then 20 s of point-to-point moves."""
    hold = holding(seed, poses=3)
    return concatenate(hold, point_to_point(seed, 20.0, begin=hold.end))


def random_pushes(seed, seconds, count, newtons=(20.0, 100.0),
                  duration=(0.4, 1.2), margin=2.0):
    """``count`` pushes on the tool, spread over the recording, apart."""
    rng = np.random.default_rng([seed, 4])
    slots = np.linspace(margin, seconds - margin, count + 1)
    out = []
    for k in range(count):
        d = rng.uniform(*duration)
        t0 = rng.uniform(slots[k], max(slots[k], slots[k + 1] - d - 0.5))
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        out.append({'start': float(t0), 'duration': float(d),
                    'force': (rng.uniform(*newtons) * direction).tolist()})
    return out
