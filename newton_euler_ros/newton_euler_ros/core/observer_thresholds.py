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

The contact test (:func:`.observer.contact_step`) compares ``|r_j|`` with
the joint's threshold plus its static friction allowance; over a
recording with nothing touching the arm, what lies beyond the allowance
is noise and model error, and thresholds a margin above its peak keep a
like recording free of contacts, stops included (docs/observer.md).
"""
import math

import numpy as np

from .observer_contact import rest_deviations

#: suggested threshold = this x the free-motion peak beyond the allowance:
#: the peaks of other recordings of like motion reached up to 1.6 x that
#: of the one suggesting (model error depends on the motion)
FACTOR = 2.0


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


def rest_changes(recording, factor=FACTOR):
    """
    Return per joint the largest change from the rest value (n,).

    What the rest reference's test compares with the thresholds
    (:func:`.observer_contact.rest_deviations`, a change held for its
    confirmation time), run with the thresholds the allowance test
    alone suggests (its calm test depends on them); zeros when the
    recording's observer had the rest reference off.
    """
    n = recording.residual.shape[1]
    if not recording.rest_reference or recording.q is None:
        return np.zeros(n)
    held = rest_deviations(recording.t, recording.q, recording.qd,
                           recording.residual,
                           _band_thresholds(recording, factor),
                           recording.max_gap)
    return held.max(axis=0, initial=0.0)


def _band_thresholds(recording, factor):
    peak = beyond_friction(recording).max(axis=0, initial=0.0)
    return np.array([_round_up(factor * x) for x in peak])


def _round_up(x):
    if not x > 0.0:
        return 0.1
    scale = 10.0 ** (math.floor(math.log10(x)) - 1)
    return max(0.1, round(math.ceil(x / scale - 1e-9) * scale, 12))
