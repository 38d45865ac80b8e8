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
The observer's contact test with static friction, and torque constants.

Recordings: the Panda of example-robot-data stops, rests and moves again
(minimum-jerk moves, a reversal); its efforts are Pinocchio's RNEA plus a
friction the observer's model does not know exactly: Coulomb friction
with a true sign while moving (the model has tanh(qd / eps)), and at
rest a static friction holding any torque in [-F_s, F_s], whichever the
joint stopped with.  A push on a resting joint is taken by static
friction first (the joint sticks while the push leaves the friction
within the band), as a stiff position controller shows it: the current
changes only by what exceeds the band.
"""
import math
import warnings

from newton_euler_ros.core import load_robot, RobotFileWarning
from newton_euler_ros.core.observer import (contact_step, drive_options,
                                            initial_contact, initial_state,
                                            MomentumObserver,
                                            observe_recording, observer_step,
                                            suggest_thresholds)
import numpy as np
import pytest

PANDA = 'panda_description/urdf/panda.urdf'
RATE = 500.0
EPS = 0.02                                      # the model's tanh width
COULOMB = np.array([1.0, 1.2, 0.8, 0.8, 0.5, 0.4, 0.3])
VISCOUS = np.array([0.3, 0.3, 0.2, 0.2, 0.1, 0.1, 0.1])
Q0 = np.array([0.1, -0.4, 0.2, -2.0, 0.1, 1.6, 0.5])


@pytest.fixture(scope='module')
def panda():
    """(our model, Pinocchio's reading of the same URDF)."""
    import pinocchio  # noqa: F401 (a test dependency: make setup installs it)
    from newton_euler_tools.peers import example_robot_urdf, PinocchioUrdf
    path = example_robot_urdf(PANDA)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        model = load_robot(path, tip='panda_hand_tcp')
    model = model.replace(info={k: v for k, v in model.info.items()
                                if k != 'drives'})
    return model, PinocchioUrdf(path, model.joint_names,
                                model.info['urdf']['tip'])


def stop_and_go(t, moves):
    """
    q, qd, qdd (m, 7) of minimum-jerk moves ``(t0, T, delta)``; rest between.

    Between moves every joint is exactly at rest (qd = 0).
    """
    q = np.tile(Q0, (t.size, 1))
    qd, qdd = np.zeros_like(q), np.zeros_like(q)
    for t0, T, delta in moves:
        s = np.clip((t - t0) / T, 0.0, 1.0)[:, None]
        inside = ((t >= t0) & (t < t0 + T))[:, None]
        q += delta * (10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5)
        qd += inside * delta * (30 * s ** 2 - 60 * s ** 3 + 30 * s ** 4) / T
        qdd += inside * delta * (60 * s - 180 * s ** 2 + 120 * s ** 3) / T ** 2
    return q, qd, qdd


DELTA = np.array([0.4, -0.3, 0.35, 0.3, -0.5, 0.4, 0.6])
# rest, move, rest (a push goes here), move back, at once a reversal, rest
MOVES = [(0.5, 1.0, DELTA), (3.0, 1.0, -DELTA), (4.0, 0.8, 0.5 * DELTA)]


def model_friction(qd, _qdd=None):
    """Return what the observer's model knows: viscous + Coulomb, tanh."""
    return VISCOUS * qd + COULOMB * np.tanh(qd / EPS)


def efforts(peer, t, Q, QD, QDD, static=COULOMB, held_at_stop=0.9,
            push=None, rng=None):
    """
    Efforts of the arm with true friction; ``push(t) -> (7,)`` on it.

    Moving joints: viscous + Coulomb sign(qd), the push taken by the
    drives.  Resting joints stick: the drives' torque stays, friction
    holds up to ``static``, and the push changes the effort only by what
    exceeds that band.  A joint stops holding ``held_at_stop`` x its
    static friction in the direction it moved (random within the band
    with ``rng``).
    """
    import pinocchio as pin
    tau = np.empty_like(Q)
    held = -0.5 * static
    last = np.zeros(7)
    for k in range(t.size):
        rb = pin.rnea(peer.model, peer.data, peer.config(Q[k]), QD[k],
                      QDD[k])
        ext = np.zeros(7) if push is None else push(t[k])
        stuck = QD[k] == 0.0
        if k:
            stopped = stuck & (QD[k - 1] != 0.0)
            if rng is None:
                new = held_at_stop * static * np.sign(last)
            else:
                new = rng.uniform(-1.0, 1.0, 7) * static
            held = np.where(stopped, new, held)
        held = np.clip(held, -static - ext, static - ext)
        moving = VISCOUS * QD[k] + COULOMB * np.sign(QD[k]) - ext
        tau[k] = rb + np.where(stuck, held, moving)
        last = np.where(stuck, last, QD[k])
    return tau


def observer(model, thresholds=0.3, static=COULOMB, **kw):
    return MomentumObserver(model, 50.0, thresholds=thresholds,
                            drive_torque=model_friction,
                            static_friction=static, friction_width=EPS,
                            **kw)


def test_static_friction_at_rest_is_not_a_contact(panda):
    model, peer = panda
    t = np.arange(0.0, 6.0, 1.0 / RATE)
    Q, QD, QDD = stop_and_go(t, MOVES)
    TAU = efforts(peer, t, Q, QD, QDD)
    out = observe_recording(observer(model), t, Q, QD, TAU)
    assert not out.contact.any()
    # the residual does hold the friction at rest, far above 0.3 N m
    rest = (QD == 0.0).all(axis=1)
    assert np.abs(out.residual[rest]).max(axis=0).min() > 0.5 * \
        COULOMB.min()
    # the same observer without the allowance reports it as contact
    bare = observe_recording(observer(model, static=None), t, Q, QD, TAU)
    assert bare.contact[rest].mean() > 0.5
    # and thresholds large enough for that would hide pushes in motion
    assert suggest_thresholds(bare).min() > COULOMB.min()


def test_a_push_at_rest_is_felt_beyond_the_band(panda):
    """At rest: felt when the push exceeds threshold + 2 F_s, not below."""
    model, peer = panda
    t = np.arange(0.0, 3.0, 1.0 / RATE)
    Q, QD, QDD = stop_and_go(t, MOVES[:1])
    T = 0.3
    j = 1
    for size, felt in ((2 * COULOMB[j] + 3 * T, True),
                       (0.8 * COULOMB[j], False)):
        def push(s, size=size):
            return size * (s >= 2.0) * np.eye(7)[j]
        TAU = efforts(peer, t, Q, QD, QDD, push=push)
        out = observe_recording(observer(model, thresholds=T), t, Q, QD,
                                TAU)
        assert not out.contact[t < 2.0].any()
        if felt:
            first = t[np.argmax(out.contact)]
            assert out.contacts == 1 and 2.0 <= first < 2.1, first
        else:
            assert not out.contact.any()


def test_released_at_the_edge_of_the_band_after_a_push(panda):
    """The hysteresis scales the threshold, not the friction allowance."""
    model, peer = panda
    t = np.arange(0.0, 4.0, 1.0 / RATE)
    Q, QD, QDD = stop_and_go(t, MOVES[:1])
    j, size = 1, 2 * COULOMB[1] + 1.0

    def push(s):
        return size * ((s >= 2.0) & (s < 2.5)) * np.eye(7)[j]
    TAU = efforts(peer, t, Q, QD, QDD, push=push)
    out = observe_recording(observer(model, thresholds=0.3), t, Q, QD, TAU)
    assert out.contacts == 1
    # the push leaves the joint's friction at the band's edge, the
    # residual at about F_s: the contact ends all the same
    assert abs(out.residual[-1, j]) > 0.9 * COULOMB[j]
    assert not out.contact[t > 2.7].any()


def test_the_allowance_bounds_any_friction_within_the_band(panda):
    """
    A torque bounded by B(qd) gives a residual bounded by the allowance.

    The unmodelled friction is drawn at random at every sample, anywhere
    in its bound F_s (1 - |tanh(qd / eps)|): through stops, starts and a
    reversal at speed, |r| stays within the allowance (the same lag).
    """
    import pinocchio as pin
    model, peer = panda
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 5.0, 1e-3)
    Q, QD, QDD = stop_and_go(t, MOVES)
    bound = COULOMB * (1.0 - np.abs(np.tanh(QD / EPS)))
    u = bound * rng.uniform(-1.0, 1.0, Q.shape)
    TAU = np.array([pin.rnea(peer.model, peer.data, peer.config(Q[k]),
                             QD[k], QDD[k]) for k in range(t.size)])
    TAU += model_friction(QD) + u
    out = observe_recording(observer(model), t, Q, QD, TAU)
    excess = np.abs(out.residual) - out.allowance
    assert excess.max() < 2e-3 * COULOMB.max(), excess.max()
    # at rest the allowance is the whole band
    rest = (QD == 0.0).all(axis=1)
    np.testing.assert_allclose(out.allowance[rest][-1], COULOMB, rtol=1e-3)


def test_the_allowance_fades_after_a_start():
    """At rest F_s; after the joint moves off, F_s exp(-t / 0.1 s)."""
    from newton_euler_ros.core.observer import ALLOWANCE_HOLD
    model = load_robot('planar_2r')
    gain, static = 40.0, np.array([3.0, 1.5])
    obs = MomentumObserver(model, gain, static_friction=static,
                           friction_width=0.02)
    state = initial_state(obs)
    z = np.zeros(2)
    dt = 2e-3
    for k in range(200):                        # at rest
        observer_step(obs, state, k * dt, z, z, z)
    assert np.allclose(state.allowance, static)
    t1 = 200 * dt
    qd = np.array([1.0, -2.0])                  # 50 and 100 widths: moving
    for k in range(200, 300):
        observer_step(obs, state, k * dt, z, qd, z)
        expected = static * math.exp(-(k * dt - t1) / ALLOWANCE_HOLD)
        assert np.allclose(state.allowance, expected, rtol=1e-9,
                           atol=1e-12), (k, state.allowance, expected)
    # the contact test: threshold + allowance
    contact = initial_contact(obs)
    r = state.allowance + obs.thresholds * 0.99
    assert not contact_step(obs, contact, r, state.allowance)
    assert contact_step(obs, contact, r + 0.02 * obs.thresholds,
                        state.allowance)


def test_torque_constants_turn_currents_into_torques(panda):
    model, peer = panda
    t = np.arange(0.0, 3.0, 1.0 / RATE)
    Q, QD, QDD = stop_and_go(t, MOVES[:2])
    TAU = efforts(peer, t, Q, QD, QDD)
    K = np.array([9.0, 11.0, 8.5, 7.0, 4.0, 3.5, 3.0])     # N m / A
    amps = TAU / K
    torque = observe_recording(observer(model), t, Q, QD, TAU)
    current = observe_recording(observer(model, torque_constant=K), t, Q,
                                QD, amps)
    np.testing.assert_allclose(current.residual, torque.residual,
                               atol=1e-9 * np.abs(TAU).max())
    assert not current.contact.any()
    # read as torques, amperes are a large external torque: gravity
    raw = observe_recording(observer(model), t, Q, QD, amps)
    assert raw.contact[t > 0.1].all()


UR5_DRIVE = ('<dynamics damping="{d}" friction="{f}"/>'
             '<ne:drive armature="0.3" offset="0.1" coulomb_width="0.03"{k}/>')


@pytest.mark.parametrize('constants', [True, False])
def test_drive_options_from_an_identified_urdf(tmp_path, constants):
    """Friction, width and torque constants as identify writes them."""
    import re
    from newton_euler_tools.peers import example_robot_urdf
    with open(example_robot_urdf('ur_description/urdf/ur5_robot.urdf'),
              encoding='utf-8') as fh:
        text = fh.read()
    text = text.replace('<robot ', '<robot xmlns:ne="https://newton-euler-'
                        'ros.github.io/ns/drives/1" ', 1)
    count = [0]

    def drive(_match):
        count[0] += 1
        j = count[0]
        k = f' torque_constant="{9.0 + j}"' if constants else ''
        return UR5_DRIVE.format(d=0.5 * j, f=float(j), k=k)
    text = re.sub(r'<dynamics damping="0.0" friction="0.0"/>', drive, text)
    assert count[0] == 6
    path = tmp_path / 'ur5.urdf'
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot(str(path), base='base_link', tip='tool0')
    opts = drive_options(model)         # 1.5 x the Coulomb friction
    np.testing.assert_allclose(opts['static_friction'],
                               1.5 * np.arange(1, 7))
    np.testing.assert_allclose(opts['friction_width'], 0.03)
    np.testing.assert_allclose(opts['armature'], 0.3)
    if constants:
        np.testing.assert_allclose(opts['torque_constant'],
                                   9.0 + np.arange(1, 7))
    else:
        assert 'torque_constant' not in opts
    np.testing.assert_allclose(drive_options(model, 1.0)['static_friction'],
                               np.arange(1, 7))
    assert 'static_friction' not in drive_options(model, 0.0)
    with pytest.raises(ValueError, match='static_friction'):
        drive_options(model, -1.0)
    obs = MomentumObserver(model, **opts)
    assert obs.torque_constant is None if not constants else \
        np.allclose(obs.torque_constant, 9.0 + np.arange(1, 7))
    # a URDF without drive terms: nothing to allow for, efforts in N m
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        plain = load_robot(example_robot_urdf(
            'ur_description/urdf/ur5_robot.urdf'), base='base_link',
            tip='tool0')
    assert drive_options(plain) == {'drive_torque': None, 'armature': None}
