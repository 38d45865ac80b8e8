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
The contact test's rest reference (core/observer/contact.py), rule by rule.

A two-joint arm at 100 Hz; the residual is written directly, as the
observer would give it: a resting arm holds a friction of any value in
its band (here 6 N m and -5 N m, the allowance 9 N m, far above the
1 N m thresholds), a push adds to it.  Once the whole arm has rested
and settled, a push smaller than the band is a contact within CONFIRM
plus a sample; without the rest reference it is not.  Any motion, a
position creeping beyond REST_TRAVEL, a stamp going backwards or a gap
longer than EXPIRE ends the rest (a shorter one on the settled arm does
not: a push begun in it is reported); a push under way when the rest
value is taken is no contact after its release for longer than EXPIRE;
with rest thresholds of its own, changes on several joints are a
contact together, a joint that joins a contact expiring with it;
and the thresholds suggested from a free recording cover the changes a
settled residual shows.
"""
import warnings

from newton_euler_ros.core import load_robot, RobotFileWarning
from newton_euler_ros.core.observer import (contact_step, initial_contact,
                                            MomentumObserver,
                                            ObserverRecording,
                                            suggest_thresholds)
from newton_euler_ros.core.observer.contact import (CONFIRM, EXPIRE,
                                                    REST_TRAVEL, SETTLE,
                                                    TOGETHER_AFTER)
import numpy as np
import pytest

DT = 0.01
HELD = np.array([6.0, -5.0])       # friction held at rest, N m
THRESHOLDS = [1.0, 1.0]


@pytest.fixture(scope='module')
def model():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        return load_robot('planar_2r')


def run(model, r, q=None, qd=None, t=None, rest_reference=True,
        static=(9.0, 9.0), rest_thresholds=0.0):
    """Contact flags of a residual sequence r (m, 2), as the node steps."""
    obs = MomentumObserver(model, thresholds=THRESHOLDS,
                           static_friction=static,
                           rest_reference=rest_reference,
                           rest_thresholds=rest_thresholds)
    m = len(r)
    t = np.arange(m) * DT if t is None else t
    q = np.zeros((m, 2)) if q is None else q
    qd = np.zeros((m, 2)) if qd is None else qd
    allowance = np.asarray(static, dtype=float)     # at rest: s F_c
    contact = initial_contact(obs)
    out = np.zeros(m, dtype=bool)
    for k in range(m):
        out[k] = contact_step(obs, contact, r[k], allowance, t[k], q[k],
                              qd[k])
    return t, out, contact


def pushed(m, start, size, joint=0, end=None):
    r = np.tile(HELD, (m, 1)) + np.random.default_rng(0).normal(
        0.0, 0.05, (m, 2))
    k1 = m if end is None else int(end / DT)
    r[int(start / DT):k1, joint] += size
    return r


def test_a_push_within_the_band_on_a_settled_arm(model):
    r = pushed(300, 2.0, 2.5)             # 2.5 N m: far within the band
    t, out, c = run(model, r)
    assert not out[t < 2.0].any()
    first = t[np.argmax(out)]
    assert out.any() and 2.0 + CONFIRM <= first <= 2.0 + CONFIRM + 2 * DT
    assert c.count == 1 and c.rest.active[0] and not c.active[0]
    # the threshold and the allowance alone: nothing
    _, out, _ = run(model, r, rest_reference=False)
    assert not out.any()
    # the same push before the arm settled: not felt by the rest test
    r = pushed(300, 0.1, 2.5)
    _, out, _ = run(model, r)
    assert not out[:int((0.1 + SETTLE) / DT)].any()


def test_motion_creep_and_gaps_end_the_rest(model):
    m = 400
    r = pushed(m, 3.0, 2.5)
    # a joint moving at 0.02 rad/s from 2.5 s on: no rest, no contact
    qd = np.zeros((m, 2))
    qd[250:, 1] = 0.02
    _, out, _ = run(model, r, qd=qd)
    assert not out.any()
    # a position creeping beyond REST_TRAVEL, the speed reading zero
    q = np.zeros((m, 2))
    q[:, 0] = np.arange(m) * DT * 5.0 * REST_TRAVEL     # 5 x per second
    _, out, _ = run(model, r, q=q)
    assert not out.any()
    # a gap longer than EXPIRE just before the push: the rest starts
    # again there
    t = np.arange(m) * DT
    t[290:] += EXPIRE + 0.1
    _, out, _ = run(model, r, t=t)
    assert not out[:300 + int(SETTLE / DT)].any()
    # and a stamp going backwards
    t = np.arange(m) * DT
    t[290:] -= 0.5
    _, out, _ = run(model, r, t=t)
    assert not out[:300 + int(SETTLE / DT)].any()


def test_a_shorter_gap_on_the_settled_arm_keeps_its_rest(model):
    # messages lost for 0.5 s (within EXPIRE) while the settled arm stays
    # where it was, a push beginning in the gap: reported CONFIRM after
    # the messages resume, as if none had been lost
    m = 400
    t = np.arange(m) * DT
    t[290:] += 0.5
    r = pushed(m, 0.0, 0.0)
    r[t >= 3.0, 0] += 2.5
    _, out, c = run(model, r, t=t)
    assert not out[t < 3.0].any()
    first = t[np.argmax(out)]
    assert out.any() and first <= t[290] + CONFIRM + 2 * DT
    assert c.count == 1
    # the same gap before the arm settled: the rest starts again after it
    t = np.arange(m) * DT
    t[20:] += 0.5
    r = pushed(m, 0.0, 0.0)
    r[t >= 0.6, 0] += 2.5
    _, out, _ = run(model, r, t=t)
    assert not out.any()


def test_a_push_under_way_when_the_rest_value_is_taken(model):
    # the arm comes to rest with 2 N m of a push on it, held still:
    # its release at 3 s looks like a push the other way; that is
    # reported for at most EXPIRE, then the new value is the rest value
    r = pushed(800, 0.0, 2.0, end=3.0)
    t, out, c = run(model, r)
    assert not out[t < 3.0].any()
    late = out[t > 3.0 + CONFIRM + EXPIRE + 2 * DT]
    assert not late.any() and c.count <= 1


def test_changes_on_several_joints_are_a_contact_together(model):
    # 0.8 of the threshold on both joints: neither alone, but the sum of
    # their squares (1.28) is over 1; tested together only with rest
    # thresholds of the observer's own, once the rest values have held
    # for TOGETHER_AFTER
    m = 400
    r = pushed(m, 2.5, 0.8)
    r[250:, 1] += 0.8
    t, out, c = run(model, r, rest_thresholds=THRESHOLDS)
    assert not out[t < 2.5].any()
    first = t[np.argmax(out)]
    assert out.any() and 2.5 + CONFIRM <= first <= 2.5 + CONFIRM + 2 * DT
    assert c.rest.active.all() and c.count == 1
    _, out, _ = run(model, r)               # each joint on its own: none
    assert not out.any()
    one = pushed(m, 2.5, 0.9)               # one joint: its own test only
    _, out, _ = run(model, one, rest_thresholds=THRESHOLDS)
    assert not out.any()
    # the same changes soon after the arm settled (at SETTLE): not before
    # the rest values have held for TOGETHER_AFTER (by then they have
    # followed part of the change, as slow drift)
    r = pushed(m, 1.0, 0.8)
    r[100:, 1] += 0.8
    t, out, _ = run(model, r, rest_thresholds=THRESHOLDS)
    assert not out[t < SETTLE + TOGETHER_AFTER - 2 * DT].any()


def test_a_joint_that_joins_a_contact_expires_with_it(model):
    # joint 0 pushed by 2 N m from 2.5 s (its own test), joint 1 by 0.8
    # from 2.7 s (the test together): both are the new rest values
    # EXPIRE after joint 0's contact began, and nothing is reported after
    m = 600
    r = pushed(m, 2.5, 2.0)
    r[270:, 1] += 0.8
    t, out, c = run(model, r, rest_thresholds=THRESHOLDS)
    assert out[(t > 2.5 + CONFIRM + 2 * DT) & (t < 2.5 + EXPIRE)].all()
    assert not out[t > 2.5 + CONFIRM + EXPIRE + 2 * DT].any()
    assert c.count == 1 and not c.rest.active.any()


def test_thresholds_cover_what_a_settled_residual_shows(model):
    # a free recording: the arm rests, its residual steps by 0.8 N m
    # (friction settling late), then moves; with the rest reference the
    # suggested threshold covers that step, without it the band rule's
    m = 500
    r = pushed(m, 2.0, 0.8)
    qd = np.zeros((m, 2))
    qd[400:] = 0.3
    obs = MomentumObserver(model, thresholds=THRESHOLDS,
                           static_friction=(9.0, 9.0))
    t = np.arange(m) * DT
    allowance = np.tile([9.0, 9.0], (m, 1))
    allowance[400:] = 0.0
    r[400:] = 0.1 * np.sin(np.arange(100))[:, None]
    rec = ObserverRecording(t, r, np.zeros((m, 6)), np.zeros(m, bool),
                            allowance=allowance, q=np.zeros((m, 2)), qd=qd,
                            rest_reference=True, max_gap=obs.max_gap)
    with_rest = suggest_thresholds(rec)
    rec.rest_reference = False
    without = suggest_thresholds(rec)
    assert without[0] < 0.5 and with_rest[0] >= 2 * 0.8 * 0.9, \
        (without, with_rest)
