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
    a joint's threshold is raised where the change from the rest value
    that the rest test compares with it (:func:`.observer_contact.
    rest_deviations`, run with the thresholds above) was larger than
    their 1/``factor``.
    """
    peak = beyond_friction(recording).max(axis=0, initial=0.0)
    out = np.array([_round_up(factor * x) for x in peak])
    if not recording.rest_reference or recording.q is None:
        return out
    # the rest reference's test, with these thresholds (its calm test
    # depends on them): what it compares with them, likewise
    held = rest_deviations(recording.t, recording.q, recording.qd,
                           recording.residual, out, recording.max_gap)
    rest = held.max(axis=0, initial=0.0)
    return np.maximum(out, [_round_up(factor * x) if x > 0.0 else 0.0
                            for x in rest])


def _round_up(x):
    if not x > 0.0:
        return 0.1
    scale = 10.0 ** (math.floor(math.log10(x)) - 1)
    return max(0.1, round(math.ceil(x / scale - 1e-9) * scale, 12))
