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
Contact thresholds of the momentum observer from a free-motion recording.

The contact test (:func:`.contact.contact_step`) compares ``|r_j|`` with
the joint's threshold plus its static friction allowance; over a
recording with nothing touching the arm, what lies beyond the allowance
is noise and model error, and thresholds a margin above its peak keep a
like recording free of contacts, stops included (docs/observer.md).
"""
import math

import numpy as np

from .contact import rest_deviations

#: suggested threshold = this x the free-motion peak beyond the allowance:
#: the peaks of other recordings of like motion reached up to 1.6 x that
#: of the one suggesting (model error depends on the motion)
FACTOR = 2.0
#: the rest reference's own tolerance = this x FACTOR x the largest
#: change of a settled residual on the free recording (held poses rest
#: longer than its stops): measured over 18 arms of the current-sensing
#: example (docs/observer.md)
REST_MARGIN = 2.0
#: the intercept a of a + b s + c u is at least this x the joint's largest
#: static friction allowance on the free recording
BAND_SHARE = 0.05


def beyond_friction(recording):
    """Return (m, n): how far each |residual| lies beyond the allowance."""
    return np.maximum(np.abs(recording.residual) - recording.allowance, 0.0)


def suggest_thresholds(recording, factor=FACTOR):
    """
    Return per-joint thresholds (n,) from a free-motion recording.

    ``factor`` times the largest ``|r|`` beyond the static friction
    allowance (:func:`beyond_friction`), rounded up to two digits (0.1 at
    least): what the contact test compares with the threshold, so a like
    recording stays below them by that factor.  Stops are allowed for,
    whatever their length; a contact during the recording would be taken
    for noise.  When the recording's observer had the rest reference on,
    likewise with the largest change from the rest value
    (:func:`rest_changes`) where it is larger.
    """
    out = _band_thresholds(recording, factor)
    rest = rest_changes(recording, factor)
    return np.maximum(out, [_round_up(factor * x) if x > 0.0 else 0.0
                            for x in rest])


def suggest_state_thresholds(recording, factor=FACTOR):
    """
    Return per-joint ``(a, b, c)`` (3 arrays (n,)) from a free recording.

    The threshold ``a + b s + c u`` of ``motion.py`` (``s``,
    ``u``: the lagged speed and acceleration the recording carries)
    that is smallest on average over the recording's samples while
    lying above ``|r|`` beyond the static friction allowance at every
    one of them (a linear program per joint, ``a, b, c >= 0``), times
    ``factor``, each rounded up to two digits.  ``a`` is at least
    ``BAND_SHARE`` x the joint's largest static friction allowance (the
    envelope needs no intercept where the allowance covers the free
    recording's stops, but a held pose can hold friction nearer the
    band's edge, which is itself an estimate: 1.5 x an identified
    Coulomb friction), and at least the rest reference's
    :func:`rest_changes` times ``factor`` (0.1 at least), as
    :func:`suggest_thresholds`, run with these thresholds.
    With the recording at rest
    throughout, ``b = c = 0``.
    """
    beyond = beyond_friction(recording)
    n = beyond.shape[1]
    a, b, c = np.zeros(n), np.zeros(n), np.zeros(n)
    for j in range(n):
        a[j], b[j], c[j] = _envelope(beyond[:, j], recording.speed[:, j],
                                     recording.acceleration[:, j])
    a = np.array([_round_up(factor * x) for x in a])
    # the edge of the static friction band is an estimate: a resting
    # joint may hold more than the free recording's stops did
    band = np.max(recording.allowance, axis=0)
    a = np.maximum(a, [_round_up(BAND_SHARE * x) if x > 0.0 else 0.0
                       for x in band])
    b = np.array([_round_up(factor * x, 0.0) for x in b])
    c = np.array([_round_up(factor * x, 0.0) for x in c])
    # the rest reference's test and its calm test, with the thresholds
    # it will have at each sample (a larger a arms it sooner: again)
    for _ in range(2):
        thr = a + b * recording.speed + c * recording.acceleration
        rest = rest_changes(recording, factor, thr)
        a = np.maximum(a, [_round_up(factor * x) if x > 0.0 else 0.0
                           for x in rest])
    return a, b, c


def suggest_rest_thresholds(recording, a, b, c, factor=FACTOR,
                            margin=REST_MARGIN):
    """
    Return per joint the rest reference's own tolerance (n,).

    With thresholds ``a + b s + c u`` (:func:`suggest_state_thresholds`)
    a joint's ``a`` can be near 0, the static friction allowance
    covering it at rest; the rest reference's calm test (the settled
    residual within the threshold) then never passes and it never arms,
    on the free recording or after.  Its own tolerance: ``margin`` x
    ``factor`` x the largest change from the rest value on the free
    recording, the rest reference run first with one threshold per
    joint (which arms it), then twice with these tolerances; never below
    ``a``.  The margin: a held pose rests longer than the recording's
    stops, and the friction it holds drifts further.
    """
    thr = a + b * recording.speed + c * recording.acceleration
    rest = _rounded(factor, rest_changes(recording, factor))
    for _ in range(2):
        changes = rest_changes(recording, factor, np.maximum(thr, rest))
        rest = np.maximum(a, _rounded(margin * factor, changes))
    return rest


def _rounded(factor, changes):
    return np.array([_round_up(factor * x) if x > 0.0 else 0.0
                     for x in changes])


def _envelope(y, s, u):
    """Smallest mean a + b s + c u (a, b, c >= 0) above y at every sample."""
    from scipy.optimize import linprog     # on demand: scipy loads slowly
    keep = y > 0.0
    if not keep.any():
        return 0.0, 0.0, 0.0
    # scaled to comparable columns; only samples with y > 0 constrain
    scale = np.array([1.0, max(s.max(), 1e-9), max(u.max(), 1e-9)])
    X = np.column_stack([np.ones(y.size), s, u]) / scale
    res = linprog(X.mean(axis=0), A_ub=-X[keep], b_ub=-y[keep],
                  bounds=[(0.0, None)] * 3, method='highs')
    if res.status != 0:          # cannot happen: a = max(y) is feasible
        return float(y.max()), 0.0, 0.0
    x = res.x / scale
    # the solver's tolerance: lift a to cover every sample exactly
    lack = float(np.max(y - np.column_stack([np.ones(y.size), s, u]) @ x))
    return float(x[0] + max(lack, 0.0)), float(x[1]), float(x[2])


def rest_changes(recording, factor=FACTOR, thresholds=None):
    """
    Return per joint the largest change from the rest value (n,).

    What the rest reference's test compares with the thresholds
    (:func:`.contact.rest_deviations`, a change held for its
    confirmation time), run with the thresholds the allowance test
    alone suggests (its calm test depends on them), or with
    ``thresholds`` ((n,) or one row per sample); zeros when the recording's observer had the rest
    reference off.
    """
    n = recording.residual.shape[1]
    if not recording.rest_reference or recording.q is None:
        return np.zeros(n)
    held = rest_deviations(recording.t, recording.q, recording.qd,
                           recording.residual,
                           _band_thresholds(recording, factor)
                           if thresholds is None else
                           np.asarray(thresholds, dtype=np.float64),
                           recording.max_gap)
    return held.max(axis=0, initial=0.0)


def _band_thresholds(recording, factor):
    peak = beyond_friction(recording).max(axis=0, initial=0.0)
    return np.array([_round_up(factor * x) for x in peak])


def _round_up(x, least=0.1):
    if not x > 0.0:
        return least
    scale = 10.0 ** (math.floor(math.log10(x)) - 1)
    return max(least, round(math.ceil(x / scale - 1e-9) * scale, 12))
