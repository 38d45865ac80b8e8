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
The momentum observer against recordings made by an independent source.

Recordings: the Panda of example-robot-data moves along a smooth
prescribed path (q, qd, qdd analytic); the drive efforts that produce that
motion while the environment pushes on the tool with a known wrench
F_ext are Pinocchio's, tau = rnea(q, qd, qdd) - J^T F_ext (its own URDF
reading and Jacobian).  The planar arm (fewer than six joints) uses the
Euler-Lagrange oracle of ``reference_dynamics`` instead.
"""
import math
import warnings

from newton_euler_ros.core import load_robot, RobotFileWarning
from newton_euler_ros.core.errors import DynamicsInputError
from newton_euler_ros.core.observer import (contact_step, drive_terms,
                                            DUPLICATE,
                                            external_wrench,
                                            felt_directions, initial_contact,
                                            initial_state, MomentumObserver,
                                            observe_recording, observer_step,
                                            RESTARTED)
import numpy as np
import pytest
import reference_dynamics as ref

PANDA = 'panda_description/urdf/panda.urdf'
TIP = 'panda_hand_tcp'


def _quiet_load(*args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        return load_robot(*args, **kw)


@pytest.fixture(scope='module')
def panda():
    """(our model, Pinocchio's reading of the same URDF)."""
    import pinocchio  # noqa: F401 (a test dependency: make setup installs it)
    from newton_euler_tools.peers import example_robot_urdf, PinocchioUrdf
    try:
        path = example_robot_urdf(PANDA)
    except ImportError:
        pytest.skip('example-robot-data is not installed')
    model = _quiet_load(path, tip=TIP)
    return model, PinocchioUrdf(path, model.joint_names,
                                model.info['urdf']['tip'])


Q0 = np.array([0.1, -0.4, 0.2, -2.0, 0.1, 1.6, 0.5])
AMP = np.array([0.3, 0.25, 0.3, 0.3, 0.4, 0.3, 0.5])
OMEGA = np.array([1.1, 1.7, 0.9, 1.3, 2.1, 1.5, 2.5])


def path(t, amp=AMP):
    """Prescribed smooth motion: q, qd, qdd at times t (m,) -> (m, 7)."""
    t = np.asarray(t)[:, None]
    ph = OMEGA * t + np.arange(7) * 0.7
    return (Q0 + amp * np.sin(ph), amp * OMEGA * np.cos(ph),
            -amp * OMEGA ** 2 * np.sin(ph))


def record(peer, t, wrench=None, tau_ext=None, amp=AMP, extra=None):
    """
    Efforts (m, 7) that move the arm along ``path`` while pushed.

    ``wrench(t) -> (6,)``: what the environment applies to the tool (base
    axes, about the tool origin); ``tau_ext(t) -> (7,)`` an external joint
    torque; ``extra(qd) -> (7,)`` torque the drives lose (friction).
    """
    Q, QD, QDD = path(t, amp)
    TAU = np.empty_like(Q)
    zero = np.zeros(6)
    for k, tk in enumerate(t):
        F = zero if wrench is None else wrench(tk)
        terms = peer.terms(Q[k], QD[k], QDD[k], -F)   # F_e = -F_ext
        TAU[k] = terms['tau_wrench']
        if tau_ext is not None:
            TAU[k] -= tau_ext(tk)
        if extra is not None:
            TAU[k] += extra(QD[k])
    return Q, QD, TAU


def step_wrench(F, t_on, t_off=math.inf):
    F = np.asarray(F, dtype=float)
    return lambda t: F if t_on <= t < t_off else np.zeros(6)


F_CONTACT = np.array([12.0, -8.0, 15.0, 1.5, -1.0, 0.8])


def within_spec(est, true):
    """Check the bound: 10 % + 1 N on force, 10 % + 0.2 N m on moment."""
    f_ok = np.linalg.norm(est[:3] - true[:3]) <= \
        0.1 * np.linalg.norm(true[:3]) + 1.0
    m_ok = np.linalg.norm(est[3:] - true[3:]) <= \
        0.1 * np.linalg.norm(true[3:]) + 0.2
    return f_ok and m_ok


def test_constant_contact_wrench_is_recovered(panda):
    model, peer = panda
    t = np.arange(0.0, 2.0, 1e-3)
    Q, QD, TAU = record(peer, t, step_wrench(F_CONTACT, 0.5))
    obs = MomentumObserver(model, gain=50.0, thresholds=3.0)
    out = observe_recording(obs, t, Q, QD, TAU)
    settled = t > 0.5 + 6 / 50.0
    for F in out.wrench[settled]:
        assert within_spec(F, F_CONTACT), F
    # far tighter than the spec in fact (the model agrees with
    # Pinocchio's; what is left is the lag behind J^T F of a moving arm)
    err = np.abs(out.wrench[settled] - F_CONTACT).max()
    assert err < 0.3, err
    assert not out.contact[t < 0.5].any()
    assert out.contact[settled].all()
    assert out.contacts == 1


def test_free_motion_with_sensor_noise_reports_no_contact(panda):
    model, peer = panda
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 3.0, 1e-3)
    Q, QD, TAU = record(peer, t)
    Q = Q + rng.normal(0.0, 1e-4, Q.shape)        # encoder noise
    QD = QD + rng.normal(0.0, 2e-3, QD.shape)     # velocity estimate
    TAU = TAU + rng.normal(0.0, 0.05, TAU.shape)  # effort noise
    obs = MomentumObserver(model, gain=50.0, thresholds=2.0)
    out = observe_recording(obs, t, Q, QD, TAU)
    assert not out.contact.any()
    assert np.abs(out.residual).max() < 1.0      # thresholds above this
    assert np.linalg.norm(out.wrench[:, :3], axis=1).max() < 3.0
    # the residual is noise about zero: its mean is far below its spread
    assert np.abs(out.residual[500:].mean(axis=0)).max() < 0.05


def test_short_impact_is_detected_within_50_ms(panda):
    model, peer = panda
    t = np.arange(0.0, 1.5, 1e-3)
    F = np.array([0.0, 40.0, -20.0, 0.0, 0.0, 0.0])
    Q, QD, TAU = record(peer, t, step_wrench(F, 0.8, 0.86))   # 60 ms
    obs = MomentumObserver(model, gain=50.0, thresholds=2.0)
    out = observe_recording(obs, t, Q, QD, TAU)
    on = t[out.contact]
    assert on.size, 'impact not detected'
    assert 0.8 <= on[0] <= 0.85, on[0]
    assert out.contacts == 1
    assert not out.contact[t > 1.2].any()    # released after it


def test_jitter_lost_messages_and_gaps_do_not_upset_it(panda):
    model, peer = panda
    rng = np.random.default_rng(7)
    t = np.arange(0.0, 3.0, 1e-3) + rng.uniform(-3e-4, 3e-4, 3000)
    keep = rng.uniform(size=t.size) > 0.2          # 20 % lost
    keep &= ~((t > 1.0) & (t < 1.3))               # a 0.3 s outage
    keep &= ~((t > 2.0) & (t < 2.04))              # 40 ms lost: no restart
    t = np.sort(t[keep])
    Q, QD, TAU = record(peer, t, step_wrench(F_CONTACT, 0.5))
    obs = MomentumObserver(model, gain=50.0, thresholds=3.0, max_gap=0.1)
    out = observe_recording(obs, t, Q, QD, TAU)
    assert out.restarts == 1
    assert out.status[int(np.argmax(t > 1.3))] == RESTARTED
    settled = (t > 0.65) | (t > 1.3)
    for F in out.wrench[settled]:
        assert within_spec(F, F_CONTACT), F
    assert out.contacts == 1            # held through the outage
    assert np.isfinite(out.residual).all()


def test_stamp_going_backwards_restarts_cleanly(panda):
    model, peer = panda
    t = np.arange(0.0, 1.0, 1e-3)
    Q, QD, TAU = record(peer, t)
    # replay the recording twice (a looping bag): the stamps jump back
    T2 = np.concatenate([t, t])
    out = observe_recording(MomentumObserver(model), T2, np.vstack([Q, Q]),
                            np.vstack([QD, QD]), np.vstack([TAU, TAU]))
    assert out.restarts == 1 and out.status[t.size] == RESTARTED
    assert np.abs(out.residual).max() < 1e-3
    # a repeated stamp is ignored, not a zero-length step
    obs = MomentumObserver(model)
    state = initial_state(obs)
    observer_step(obs, state, 0.0, Q[0], QD[0], TAU[0])
    _, what = observer_step(obs, state, 0.0, Q[1], QD[1], TAU[1])
    assert what == DUPLICATE and state.duplicates == 1


@pytest.mark.parametrize('gain', [20.0, 80.0])
def test_residual_is_a_first_order_lag_with_the_gain(panda, gain):
    model, peer = panda
    dt = 1e-3
    t = np.arange(0.0, 1.0, dt)
    t_on = 0.3
    tau_step = np.array([5.0, -3.0, 4.0, 2.0, -1.0, 1.0, 0.5])
    Q, QD, TAU = record(peer, t, tau_ext=lambda s: tau_step * (s >= t_on))
    out = observe_recording(MomentumObserver(model, gain=gain), t, Q, QD,
                            TAU)
    # the efforts jump at a sample: the trapezoid sees half the step over
    # that interval, so the lag starts half a sample late
    after = t >= t_on
    s = t[after] - t_on + dt / 2
    expected = tau_step * (1.0 - np.exp(-gain * s))[:, None]
    err = np.abs(out.residual[after] - expected).max()
    assert err < 0.01 * np.abs(tau_step).max(), err
    assert np.abs(out.residual[~after]).max() < 1e-3


def test_sinusoidal_push_is_filtered_by_the_lag(panda):
    model, peer = panda
    gain, w = 30.0, 2 * math.pi * 5.0           # 5 Hz, above the corner
    t = np.arange(0.0, 2.0, 1e-3)
    amp = np.array([3.0, 2.0, 2.0, 1.0, 1.0, 0.5, 0.5])
    Q, QD, TAU = record(peer, t, tau_ext=lambda s: amp * math.sin(w * s))
    out = observe_recording(MomentumObserver(model, gain=gain), t, Q, QD,
                            TAU)
    G = gain / (gain + 1j * w)                 # K / (s + K) at s = j w
    late = t > 1.0
    expected = (amp[None, :] * np.abs(G) *
                np.sin(w * t[late] + np.angle(G))[:, None])
    assert np.abs(out.residual[late] - expected).max() < 0.02 * amp.max()


def test_no_drift_over_a_long_recording_with_a_wrong_model(panda):
    model, peer = panda
    dt = 2e-3
    t = np.arange(0.0, 200.0, dt)
    Q, QD, TAU = record(peer, t)
    # our model with link 4 5 % heavier than Pinocchio's: the mismatch
    # feeds the integral for 200 s; the residual must stay at the
    # mismatch torque, never grow
    mass = model.mass.copy()
    mass[3] *= 1.05
    wrong = model.replace(mass=mass)
    out = observe_recording(MomentumObserver(wrong, gain=50.0), t, Q, QD,
                            TAU)
    from newton_euler_ros.core.dynamics import inverse_dynamics_batch
    # what the wrong model takes for an external torque
    mismatch = inverse_dynamics_batch(wrong, Q, QD, path(t)[2]) - TAU
    first = (t > 1.0) & (t < 11.0)
    last = t > t[-1] - 10.0
    bound = np.abs(mismatch).max()
    assert np.abs(out.residual).max() < 1.5 * bound + 1e-3
    assert np.abs(out.residual[last]).max() <= \
        1.05 * np.abs(out.residual[first]).max() + 1e-3
    # and it tracks the mismatch (a slow signal) closely
    assert np.abs(out.residual[t > 1.0] - mismatch[t > 1.0]).max() < \
        0.1 * bound + 1e-3
    assert np.isfinite(out.residual).all()


def test_drive_friction_is_not_external(panda):
    model, peer = panda
    t = np.arange(0.0, 1.5, 1e-3)
    viscous = np.linspace(0.5, 0.1, 7)
    coulomb = np.linspace(0.8, 0.2, 7)

    def friction(qd, _qdd=None):
        return viscous * qd + coulomb * np.tanh(qd / 0.02)

    Q, QD, TAU = record(peer, t, extra=friction)
    bare = observe_recording(MomentumObserver(model, thresholds=0.5), t, Q,
                             QD, TAU)
    assert bare.contact.any()          # friction alone looks like contact
    obs = MomentumObserver(model, thresholds=0.5, drive_torque=friction)
    out = observe_recording(obs, t, Q, QD, TAU)
    assert not out.contact.any()
    assert np.abs(out.residual[200:]).max() < 0.05


def test_drives_carried_by_the_model_are_used(panda):
    """An identified model's drives (model.info['drives']) plug in."""
    from types import SimpleNamespace
    model, peer = panda
    # the published URDF's own <dynamics> (if any) are left out here
    model = model.replace(info={k: v for k, v in model.info.items()
                                if k != 'drives'})
    t = np.arange(0.0, 1.5, 1e-3)
    viscous, offset, armature = np.full(7, 0.3), np.full(7, 0.2), \
        np.full(7, 0.05)

    def torques(qd, qdd):
        return viscous * qd + offset + armature * qdd

    drives = SimpleNamespace(torques=torques, armature=armature)
    info = dict(model.info, drives=drives)
    identified = model.replace(info=info)
    lost, arm = drive_terms(identified)
    assert drive_terms(model) == (None, None)
    Q, QD, QDD = path(t)
    _, _, TAU = record(peer, t)
    TAU = TAU + torques(QD, QDD)
    out = observe_recording(MomentumObserver(model, drive_torque=lost,
                                             armature=arm), t, Q, QD, TAU)
    assert np.abs(out.residual[200:]).max() < 0.02


def test_armature_enters_the_momentum(panda):
    model, peer = panda
    t = np.arange(0.0, 1.5, 1e-3)
    armature = np.full(7, 0.1)
    Q, QD, QDD = path(t)
    _, _, TAU = record(peer, t)
    TAU = TAU + armature * QDD          # the motors' rotors, accelerated
    out = observe_recording(MomentumObserver(model, armature=armature), t,
                            Q, QD, TAU)
    assert np.abs(out.residual[200:]).max() < 0.02


def test_never_nan_or_inf(panda):
    model, peer = panda
    t = np.arange(0.0, 0.5, 1e-3)
    Q, QD, TAU = record(peer, t)
    Q[100, 2] = np.nan
    QD[150, 0] = np.inf
    TAU[200, 6] = -np.inf
    TAU[250] = 1e300                   # finite but absurd
    out = observe_recording(MomentumObserver(model), t, Q, QD, TAU)
    assert out.skipped == 3
    assert np.isfinite(out.residual).all() and np.isfinite(out.wrench).all()
    # a singular pose (Panda stretched out) with no damping: still finite
    obs = MomentumObserver(model, damping=0.0)
    z = np.zeros(7)
    F = external_wrench(obs, z, np.ones(7))
    assert np.isfinite(F).all()
    # and the step refuses bad input with the library's error, state kept
    state = initial_state(obs)
    observer_step(obs, state, 0.0, Q[0], QD[0], TAU[0])
    before = state.S.copy()
    with pytest.raises(DynamicsInputError):
        observer_step(obs, state, 1e-3, Q[1], QD[1], [np.nan] * 7)
    with pytest.raises(DynamicsInputError):
        observer_step(obs, state, math.nan, Q[1], QD[1], TAU[1])
    assert (state.S == before).all() and state.samples == 1


def test_contact_hysteresis():
    model = _quiet_load('planar_2r')
    obs = MomentumObserver(model, thresholds=[2.0, 1.0], hysteresis=0.5)
    c = initial_contact(obs)
    seq = [([0.0, 0.0], False), ([1.9, 0.0], False), ([2.1, 0.0], True),
           ([1.5, 0.0], True), ([0.9, 0.0], False), ([0.0, -1.2], True),
           ([0.0, -0.6], True), ([0.0, 0.4], False)]
    for r, want in seq:
        assert contact_step(obs, c, np.array(r)) is want, r
    assert c.count == 2


def test_planar_arm_feels_only_its_plane():
    """Fewer than six joints: the felt components, from the oracle."""
    model = _quiet_load('planar_2r')
    obs = MomentumObserver(model, gain=50.0, damping=1e-6)
    q = np.array([0.4, 0.9])
    B = felt_directions(obs, q)
    assert B.shape == (6, 2)
    # the oracle's Jacobian: its range is what B spans
    Jr = ref.ee_jacobian(model, q)
    np.testing.assert_allclose(B @ (B.T @ Jr), Jr, atol=1e-9)
    planar = np.abs(Jr).max(axis=1) > 1e-9         # fx, fy, mz rows
    assert np.abs(B[~planar]).max() < 1e-12
    # any push, in the plane or not: the estimate is its felt part
    rng = np.random.default_rng(1)
    for _ in range(5):
        F = rng.normal(size=6) * 10.0
        est = external_wrench(obs, q, Jr.T @ F)
        np.testing.assert_allclose(est, B @ (B.T @ F), atol=1e-6)
        np.testing.assert_allclose(Jr.T @ est, Jr.T @ F, atol=1e-6)


def test_bad_configuration_is_refused():
    model = _quiet_load('planar_2r')
    for kw, msg in [({'gain': 0.0}, 'gain'), ({'gain': [1, 2, 3]}, 'gain'),
                    ({'thresholds': -1.0}, 'thresholds'),
                    ({'hysteresis': 1.5}, 'hysteresis'),
                    ({'max_gap': 0.0}, 'max_gap'),
                    ({'damping': math.nan}, 'damping'),
                    ({'armature': [-1.0, 0.0]}, 'armature'),
                    ({'drive_torque': 3.0}, 'drive_torque')]:
        with pytest.raises(ValueError, match=msg):
            MomentumObserver(model, **kw)


def test_single_steps_match_the_recording_function(panda):
    model, peer = panda
    t = np.arange(0.0, 0.3, 1e-3)
    Q, QD, TAU = record(peer, t, step_wrench(F_CONTACT, 0.1))
    obs = MomentumObserver(model)
    out = observe_recording(obs, t, Q, QD, TAU)
    obs2 = MomentumObserver(model)
    state, contact = initial_state(obs2), initial_contact(obs2)
    for k in range(t.size):
        r, _ = observer_step(obs2, state, t[k], Q[k], QD[k], TAU[k])
        F = external_wrench(obs2, Q[k], r)
        contact_step(obs2, contact, r)
    assert (r == out.residual[-1]).all() and (F == out.wrench[-1]).all()


def test_wrench_at_each_end_effector_of_a_tree():
    """Baxter: a push on one gripper is read there, not at the other."""
    from newton_euler_tools.peers import example_robot_urdf, PinocchioTree
    path = example_robot_urdf('baxter_description/urdf/baxter.urdf')
    model = _quiet_load(path)
    peer = PinocchioTree(path, model)
    obs = MomentumObserver(model, damping=0.0)
    q = np.random.default_rng(5).uniform(-1, 1, model.n)
    F = np.array([3.0, -5.0, 12.0, 0.3, -0.6, 0.2])
    links = ('left_gripper', 'right_gripper')
    for axes in ('base', 'link'):
        J = peer.terms(q, q, q, links)      # Pinocchio's Jacobians
        r = J[f'J left_gripper {axes}'].T @ F
        np.testing.assert_allclose(external_wrench(
            obs, q, r, frame='left_gripper', axes=axes), F, atol=1e-9)
        assert not external_wrench(obs, q, r, frame='right_gripper',
                                   axes=axes).any()
    with pytest.raises(DynamicsInputError, match='left_grip'):
        external_wrench(obs, q, r, frame='left_grip')
    # a chain: the end effector named is the default one
    puma = _quiet_load('puma560')
    chain = MomentumObserver(puma)
    r = np.random.default_rng(6).uniform(-5, 5, 6)
    np.testing.assert_array_equal(
        external_wrench(chain, q[:6], r),
        external_wrench(chain, q[:6], r, frame='end_effector'))
