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
The observer's contact test: thresholds, and the rest reference.

:func:`contact_step` sets a joint in contact when ``|r_j|`` exceeds its
threshold plus its static friction allowance (``momentum.py``), with
hysteresis; and, the observer's ``rest_reference`` on, by the rest
reference's test below.

The rest reference: a push on a resting arm, felt early.

A joint at rest holds a static friction anywhere in its band, so the
static friction allowance (``momentum.py``) lets a push through only
once it exceeds the band.  But a resting arm holds that friction still:
what changes is the push.  Once the whole arm has come to rest (every
joint slower than ``REST_SPEED`` and within ``REST_TRAVEL`` of where it
stopped) and each residual has stayed calm for ``SETTLE`` seconds (its
low-pass, ``SMOOTH``, within ``CALM`` times the joint's threshold, and
the threshold test reporting no contact), the mean residual of that calm
stretch is the joint's rest value ``b``.  A
joint is then in contact when ``|r - b|`` has exceeded its threshold for
``CONFIRM`` seconds, and released below the hysteresis (as the band
test); ``b`` follows slow drift (``TRACK``) while not in contact, and a
change that has held for ``EXPIRE`` seconds becomes the new rest value
(a value taken while a small push was on would otherwise report its
release as a contact for as long as the arm rests).

The changes together (``together``: on when the observer has rest
thresholds of its own, ``rest_thresholds``).  A push on the tool moves
several joints at once; friction drifting at rest moves each on its
own.  So the arm is also in contact when the sum over joints of
``((r - b) / threshold)^2`` has exceeded 1 for ``CONFIRM`` seconds;
the joints whose change exceeds ``TOGETHER_SHARE`` of their threshold
are then in contact, and stay so while the sum exceeds 1 (or their own
change the hysteresis), expiring with the contact they joined.  The
suggested rest thresholds are four times the largest change of the
free recording, so on it each change stays within a quarter of its
threshold and the sum below n / 16.  Not before the
rest values have held for ``TOGETHER_AFTER`` seconds, again after one
expired: a push that went unreported and was still on when the arm
settled leaves its release in them, which the sum would read as a
contact.  With the thresholds themselves (a margin of 2) the sum could
reach n / 4, so it is not tested then.

Why the whole arm: friction settles at a stop and breaks away at a
start, and both look like a push.  The joints of a move start and stop
together, and the one that travels furthest shows it first: a joint
that creeps to its stop below the position's resolution, or breaks away
before its own position moves, is covered by the others.  Any motion,
a stamp going backwards, or a gap in the stamps (longer than the
observer's ``max_gap`` before the rest values are taken, than
``EXPIRE`` after) ends the rest; the band test alone applies until the
arm has settled again.  A shorter gap on the settled arm, its pose
unchanged, keeps the rest values: nothing moved the friction held.
Measured on the current-sensing example in docs/observer.md.
"""
from dataclasses import dataclass
import math

from numba import njit
import numpy as np

from .motion import motion_step, MotionState, state_thresholds
from ..kernels._jit import ENTRY

#: rad/s (m/s): every joint slower than this for the arm to rest
REST_SPEED = 0.01
#: rad (m): and within this of where the arm came to rest
REST_TRAVEL = 1e-4
#: s the residuals must stay calm before their rest values are taken
SETTLE = 0.3
#: calm: the low-passed residual's range within this x the threshold
CALM = 1.0
#: s, the time constant of that low pass
SMOOTH = 0.05
#: s a change beyond the threshold must last to be a contact
CONFIRM = 0.08
#: s a reported change may hold before it becomes the new rest value
EXPIRE = 1.5
#: s, the time constant with which the rest value follows slow drift
TRACK = 2.0
#: the changes tested together: a joint takes part in the contact they
#: report when its change exceeds this x its threshold
TOGETHER_SHARE = 0.5
#: s the rest values must have held before the changes are tested
#: together (a value taken while a push was on has expired by then)
TOGETHER_AFTER = EXPIRE

# rows of RestState.rows (n columns)
_CALM_SINCE, _LOW, _LO, _HI, _SUM, _COUNT, _B, _ABOVE, _SINCE, _DEV = \
    range(10)
_ROWS = 10
# entries of RestState.flags
_RESTING, _ARMED, _T_PREV, _TOGETHER_ABOVE, _ARMED_AT = 0, 1, 2, 3, 4


class RestState:
    """The rest reference's state: constant size, no history."""

    def __init__(self, n):
        """Make the state of ``n`` joints, the arm not (yet) at rest."""
        self.rows = np.zeros((_ROWS, n))
        self.anchor = np.zeros(n)
        self.active = np.zeros(n, dtype=np.bool_)
        self.flags = np.array([0.0, 0.0, math.nan, math.nan, math.nan])

    @property
    def armed(self):
        """Whether the rest values are taken (the test is on)."""
        return bool(self.flags[_ARMED])

    @property
    def deviation(self):
        """Per joint ``|r - b|`` at the last sample (0 unless armed)."""
        return self.rows[_DEV]


@njit(**ENTRY)
def _rest_step(t, q, qd, r, thr, hysteresis, max_gap, measure, together,
               band, rows, anchor, active, flags):
    """
    One sample of the rest reference; True when a joint is in contact.

    ``band``: the threshold test's flags (no rest value is taken while
    one is set); ``measure``: take no contact (the rest values follow
    the residual throughout), to measure the deviations of a free
    recording; ``together``: test the changes together as well.
    """
    n = r.shape[0]
    dt = t - flags[_T_PREV]
    flags[_T_PREV] = t
    # a stamp backwards, or a gap the armed rest does not span
    moving = not (0.0 < dt <= max_gap
                  or (flags[_ARMED] != 0.0 and 0.0 < dt <= EXPIRE))
    for i in range(n):
        if abs(qd[i]) > REST_SPEED or abs(q[i] - anchor[i]) > REST_TRAVEL:
            moving = True
    if moving:
        for i in range(n):
            anchor[i] = q[i]
            active[i] = False
            rows[_DEV, i] = 0.0
        flags[_RESTING] = 0.0
        flags[_ARMED] = 0.0
        return False
    if flags[_RESTING] == 0.0:
        flags[_RESTING] = 1.0
        for i in range(n):
            rows[_CALM_SINCE, i] = t
            rows[_LOW, i] = rows[_LO, i] = rows[_HI, i] = r[i]
            rows[_SUM, i] = r[i]
            rows[_COUNT, i] = 1.0
        return False
    if flags[_ARMED] == 0.0:
        a = 1.0 - math.exp(-dt / SMOOTH)
        settled = True
        for i in range(n):
            low = rows[_LOW, i] + a * (r[i] - rows[_LOW, i])
            rows[_LOW, i] = low
            rows[_LO, i] = min(rows[_LO, i], low)
            rows[_HI, i] = max(rows[_HI, i], low)
            rows[_SUM, i] += r[i]
            rows[_COUNT, i] += 1.0
            if rows[_HI, i] - rows[_LO, i] > CALM * thr[i] or band[i]:
                rows[_CALM_SINCE, i] = t
                rows[_LO, i] = rows[_HI, i] = low
                rows[_SUM, i] = r[i]
                rows[_COUNT, i] = 1.0
            settled &= t - rows[_CALM_SINCE, i] >= SETTLE
        if settled:
            flags[_ARMED] = 1.0
            flags[_TOGETHER_ABOVE] = math.nan
            flags[_ARMED_AT] = t
            for i in range(n):
                rows[_B, i] = rows[_SUM, i] / rows[_COUNT, i]
                rows[_ABOVE, i] = math.nan
        return False
    track = 1.0 - math.exp(-dt / TRACK)
    any_active = False
    # the changes together: the sum of their squares, each over its
    # threshold (joints with a threshold of 0 left out)
    total = 0.0
    for i in range(n):
        if thr[i] > 0.0:
            x = abs(r[i] - rows[_B, i]) / thr[i]
            total += x * x
    if total > 1.0:
        if math.isnan(flags[_TOGETHER_ABOVE]):
            flags[_TOGETHER_ABOVE] = t
    else:
        flags[_TOGETHER_ABOVE] = math.nan
    together_on = (together and not measure
                   and t - flags[_TOGETHER_ABOVE] >= CONFIRM
                   and t - flags[_ARMED_AT] >= TOGETHER_AFTER)
    together_hold = together and total > 1.0
    episode = t     # when the contact under way began: joints join it
    for i in range(n):
        if active[i]:
            episode = min(episode, rows[_SINCE, i])
    for i in range(n):
        d = abs(r[i] - rows[_B, i])
        rows[_DEV, i] = d
        if d > thr[i]:
            if math.isnan(rows[_ABOVE, i]):
                rows[_ABOVE, i] = t
        else:
            rows[_ABOVE, i] = math.nan
        if measure:
            pass
        elif active[i]:
            active[i] = d > hysteresis * thr[i] or (
                together_hold and d > TOGETHER_SHARE * thr[i])
            if active[i] and t - rows[_SINCE, i] > EXPIRE:
                active[i] = False           # the new rest value
                rows[_B, i] = r[i]
                rows[_ABOVE, i] = math.nan
                flags[_ARMED_AT] = t        # the test together waits
                flags[_TOGETHER_ABOVE] = math.nan
        elif t - rows[_ABOVE, i] >= CONFIRM or (        # False when NaN
                together_on and d > TOGETHER_SHARE * thr[i]):
            active[i] = True
            # by its own change: its own contact; by the test together
            # only: it joins the contact under way, and expires with it
            rows[_SINCE, i] = (t if t - rows[_ABOVE, i] >= CONFIRM
                               else episode)
        if not active[i]:
            rows[_B, i] += track * (r[i] - rows[_B, i])
        any_active |= active[i]
    return any_active


def rest_step(state, t, q, qd, r, thresholds, hysteresis, max_gap, band,
              measure=False, together=False):
    """
    Advance ``state`` by one sample; return whether a joint is in contact.

    ``band``: per joint, whether the threshold test reports contact;
    ``together``: test the changes together as well (see above).
    """
    return bool(_rest_step(float(t), q, qd, r, thresholds, float(hysteresis),
                           float(max_gap), measure, together, band, state.rows,
                           state.anchor, state.active, state.flags))


def rest_deviations(T, Q, QD, R, thresholds, max_gap):
    """
    Return (m, n): the change from the rest value held for ``CONFIRM`` s.

    Per sample, its smallest value over the last ``CONFIRM`` seconds (0
    where the test is off), over a recording taken as free of contact:
    what the test compares with the thresholds, for suggesting them.
    ``thresholds``: (n,), or (m, n) one row per sample.
    """
    m, n = R.shape
    thr = np.broadcast_to(np.asarray(thresholds, dtype=np.float64), (m, n))
    state = RestState(n)
    band = np.zeros(n, dtype=np.bool_)
    dev = np.zeros((m, n))
    armed = np.zeros(m, dtype=np.bool_)
    for k in range(m):
        rest_step(state, T[k], Q[k], QD[k], R[k], thr[k], 1.0, max_gap,
                  band, measure=True)
        armed[k] = state.armed
        dev[k] = state.deviation
    held = np.zeros((m, n))
    start = np.searchsorted(T, T - CONFIRM, side='left')
    for k in range(m):
        s = start[k]
        if s < k and armed[s:k + 1].all() and T[k] - T[s] >= 0.9 * CONFIRM:
            held[k] = dev[s:k + 1].min(axis=0)
    return held


@njit(**ENTRY)
def _contact(r, on, hysteresis, allowance, active):
    """
    Per-joint hysteresis; True when any joint is in contact.

    On above ``on + allowance``, off below ``hysteresis * on +
    allowance``: the static friction allowance is not scaled (a joint
    left at the edge of its friction band after a push is released).
    """
    any_active = False
    for i in range(r.shape[0]):
        x = abs(r[i]) - allowance[i]
        if active[i]:
            active[i] = x > hysteresis * on[i]
        else:
            active[i] = x > on[i]
        any_active |= active[i]
    return any_active


@dataclass
class ContactState:
    """Per-joint contact flags, the overall flag and the contact count."""

    active: np.ndarray      # per joint, the threshold test (band)
    in_contact: bool = False
    count: int = 0          # contacts begun (false -> true)
    rest: RestState = None  # the rest reference (its own flags)
    # the lagged speeds and accelerations (``motion.py``)
    motion: MotionState = None
    threshold: np.ndarray = None    # per joint, the last sample's
    # per joint, the rest reference's: the larger of that and
    # the observer's rest_thresholds
    rest_threshold: np.ndarray = None


def initial_contact(obs):
    """Return a contact state with no joint in contact."""
    return ContactState(np.zeros(obs.n, dtype=np.bool_),
                        rest=RestState(obs.n), motion=MotionState(obs.n),
                        threshold=obs.thresholds.copy(),
                        rest_threshold=obs.thresholds.copy())


def contact_step(obs, contact, r, allowance=None, t=None, q=None, qd=None):
    """
    Update ``contact`` from the residual; return whether in contact.

    ``allowance``: the state's static friction allowance
    (``state.allowance``), added to every threshold; None: none.  With
    the sample's stamp ``t`` (s), ``q`` and ``qd`` (model order), and the
    observer's ``rest_reference`` on, a joint is also in contact by the
    rest reference's test (``contact.py``), with the larger of each
    threshold and the observer's ``rest_thresholds``.  With ``t`` and
    ``qd``, each threshold grows with the joint's speed and acceleration
    by the observer's ``speed_thresholds`` and
    ``acceleration_thresholds`` (``motion.py``; the thresholds
    alone without them, or without ``t``).
    """
    if allowance is None:
        allowance = obs._no_allowance
    thr = obs.thresholds
    if contact.motion is not None and t is not None and qd is not None:
        motion_step(obs, contact.motion, t, qd)
        if obs.moving_thresholds:
            thr = state_thresholds(obs, contact.motion, contact.threshold)
    now = _contact(r, thr, obs.hysteresis, allowance, contact.active)
    if t is not None and obs.rest_reference and contact.rest is not None:
        own = contact.rest_threshold is not None and \
            obs.rest_thresholds.any()
        rest_thr = np.maximum(thr, obs.rest_thresholds,
                              out=contact.rest_threshold) if own else thr
        now |= rest_step(contact.rest, t, q, qd, r, rest_thr, obs.hysteresis,
                         obs.max_gap, contact.active, together=own)
    if now and not contact.in_contact:
        contact.count += 1
    contact.in_contact = bool(now)
    return contact.in_contact
