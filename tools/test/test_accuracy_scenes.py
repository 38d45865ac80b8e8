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

"""Scene experiments of the accuracy report, checked by physics."""
import dataclasses
import math

from newton_euler_ros.core import wrench_torques
from newton_euler_ros.sim.run import simulate
from newton_euler_ros.sim.simulate import SceneDynamics, tracking_controller
from newton_euler_tools.accuracy import scenes as S
import numpy as np
import pytest

SECTIONS = {'effects', 'batch', 'feedforward', 'integrators'}
EARTH = ('puma_payload_press', 'panda_slow_earth')


@pytest.fixture(scope='module')
def records():
    return S.run_all(quick=True)


@pytest.fixture(scope='module')
def puma():
    return S.as_scene('puma_payload_press')


def pick(records, **kw):
    rows = [r for r in records if all(r.get(k) == v for k, v in kw.items())]
    assert rows, kw
    return rows


def one(records, **kw):
    rows = pick(records, **kw)
    assert len(rows) == 1, kw
    return rows[0]


def test_run_all_quick_records_are_well_formed(records):
    keys = {'section', 'robot', 'scene', 'quantity', 'method', 'us',
            'error', 'note'}
    assert {(r['scene'], r['section']) for r in records} == {
        (s, sec) for s in S.SCENES for sec in SECTIONS}
    for r in records:
        assert keys <= set(r), r
        for k in ('section', 'robot', 'scene', 'quantity', 'method',
                  'note'):
            assert isinstance(r[k], str), (k, r)
        assert r['robot'] in ('puma560', 'panda'), r
        for k in ('us', 'error'):
            assert r[k] is None or (isinstance(r[k], float)
                                    and math.isfinite(r[k])
                                    and r[k] >= 0.0), (k, r)
        if r['us'] is not None:
            assert 0.0 < r['us'] < 1e5, r
        for k, v in r.items():
            if isinstance(v, float):
                assert math.isfinite(v), (k, r)
    for r in pick(records, section='integrators'):
        for k in ('step', 'cost', 'drift', 'tracking_rms', 'abs_error'):
            assert isinstance(r[k], float) and math.isfinite(r[k]), (k, r)


def test_truth_subset_has_no_error(records):
    for scene in S.SCENES:
        r = one(records, section='effects', scene=scene, method=S.TRUTH)
        assert r['error'] <= 1e-12 and r['abs_error'] <= 1e-12, r
        assert r['truth_rms'] > 0.0


def test_press_is_the_error_of_the_full_model(records, puma):
    """For the Puma, full misses exactly J^T F_e of the 20 N press."""
    full = one(records, section='effects', scene=puma.name, method='full')
    assert full['error'] > 0.01
    T, Q, _, _ = S.reference_states(puma)
    W, frame = S.wrench_series(puma, T)
    assert np.allclose(W, [0.0, 0.0, -20.0, 0.0, 0.0, 0.0])
    press = np.array([wrench_torques(puma.model, q, w, frame)
                      for q, w in zip(Q, W)])
    assert full['abs_error'] == pytest.approx(np.abs(press).max(),
                                              rel=1e-9)
    assert full['error'] == pytest.approx(
        np.sqrt(np.mean(press ** 2)) / full['truth_rms'], rel=1e-9)


def test_subset_errors_are_ordered(records):
    for scene in EARTH:
        g = one(records, section='effects', scene=scene,
                method='gravity only')
        full = one(records, section='effects', scene=scene, method='full')
        assert g['error'] > full['error'], scene
        assert g['error'] > 1e-4, scene
    # no gravity in orbit: the gravity-only model is tau = 0
    orbit = one(records, section='effects', scene='panda_orbit_slow',
                method='gravity only')
    assert orbit['error'] == pytest.approx(1.0, abs=1e-12)
    # the orbit scene keeps velocity products: about 16% of D qdd
    no_vp = one(records, section='effects', scene='panda_orbit_slow',
                method='gravity + inertia')
    assert 0.05 < no_vp['error'] < 0.5
    # and panda_slow_earth leaves them out because they are below 0.1%
    own = one(records, section='effects', scene='panda_slow_earth',
              scene_model=True)
    assert own['method'] == 'gravity + inertia'
    assert 0.0 < own['error'] < 1e-3


def test_batch_equals_loop(records):
    for scene in S.SCENES:
        r = one(records, section='batch', scene=scene,
                method='inverse_dynamics_batch')
        assert r['error'] <= 1e-15, r
        assert r['states'] > 100


def test_precomputed_feedforward_equals_online(records, puma):
    for r in pick(records, section='feedforward',
                  method='desired state, precomputed (one batch)'):
        assert r['ff_mismatch'] <= 1e-15, r
    # every effect of the Puma scene, row by row against SceneDynamics
    dyn = SceneDynamics(puma)
    T, Q, QD, QDD = S.reference_states(puma, duration=0.5)
    QD[3] = 0.0                      # sign(0) of the Coulomb term too
    W, frame = S.wrench_series(puma, T)
    batch = S.scene_torques_batch(puma, Q, QD, QDD, W, frame)
    rows = np.array([dyn.torques(q, qd, qdd, *puma.wrench_at(t))
                     for t, q, qd, qdd in zip(T, Q, QD, QDD)])
    assert np.array_equal(batch, rows)


def test_feedforward_improves_tracking(records):
    for scene in EARTH:
        none = one(records, section='feedforward', scene=scene,
                   method='none (PD only)')
        for method in ('desired state', 'measured state'):
            r = one(records, section='feedforward', scene=scene,
                    method=method)
            assert r['tracking_rms'] < 0.1 * none['tracking_rms'], r
            assert r['us'] > 0.0


def test_measured_feedforward_uses_the_measured_state(puma):
    dyn = SceneDynamics(puma)
    measured = tracking_controller(dyn, True, 'measured')
    desired = tracking_controller(dyn, True, 'desired')
    t = 0.7
    q_d, qd_d, qdd_d = puma.reference.at(t)
    # on the reference the two agree
    assert np.array_equal(measured(t, q_d, qd_d)[1],
                          desired(t, q_d, qd_d)[1])
    # off it, the measured one follows the arm: shoulder 0.1 rad off
    q = q_d + np.array([0.0, 0.1, 0.0, 0.0, 0.0, 0.0])
    qd = qd_d + 0.05
    tau_m, ff_m = measured(t, q, qd)
    tau_d, ff_d = desired(t, q, qd)
    w = puma.wrench_at(t)
    assert np.array_equal(ff_m, dyn.torques(q, qd, qdd_d, *w))
    assert np.array_equal(ff_d, dyn.torques(q_d, qd_d, qdd_d, *w))
    # gravity on the shoulder changes by about dg/dq * 0.1 (> 1 N m)
    assert abs(ff_m[1] - ff_d[1]) > 1.0
    # the PD part is the same
    assert np.allclose(tau_m - ff_m, tau_d - ff_d, rtol=0, atol=1e-12)


def test_simulate_feedforward_at_measured(puma):
    r = simulate(puma, duration=0.3, feedforward_at='measured')
    d = simulate(puma, duration=0.3, feedforward_at='desired')
    dyn = SceneDynamics(puma)
    steps = r.summary['steps']
    diff = 0.0
    for k in range(0, steps, 7):
        t = r.t[k]
        q_d, qd_d, qdd_d = puma.reference.at(t)
        w = puma.wrench_at(t)
        assert np.array_equal(r.tau_ff[k],
                              dyn.torques(r.q[k], r.qd[k], qdd_d, *w))
        assert np.array_equal(d.tau_ff[k],
                              dyn.torques(q_d, qd_d, qdd_d, *w))
        diff = max(diff, float(np.abs(
            r.tau_ff[k] - dyn.torques(q_d, qd_d, qdd_d, *w)).max()))
    assert diff > 1e-3         # the arm is off the reference: they differ


@pytest.mark.parametrize('value', ['actual', 'Desired', '', None, 1,
                                   ['desired']])
def test_bad_feedforward_at_is_rejected(puma, value):
    with pytest.raises(ValueError, match='feedforward_at'):
        simulate(puma, duration=0.01, feedforward_at=value)
    with pytest.raises(ValueError, match='feedforward_at'):
        tracking_controller(SceneDynamics(puma), True, value)


def test_held_controller_holds_for_a_period(puma):
    period = 4e-3
    runs = [simulate(puma, 0.1, integrator='rk4', step=h,
                     controller=S.held_controller(SceneDynamics(puma),
                                                  period))
            for h in (1e-3, 4e-3)]
    fine, coarse = runs
    per = fine.tau[:-1].reshape(-1, 4, puma.model.n)
    assert np.array_equal(per, np.repeat(per[:, :1], 4, axis=1))
    assert not np.array_equal(per[0, 0], per[1, 0])
    # the first sample is the same state at either step: same torque
    assert np.array_equal(fine.tau[0], coarse.tau[0])


def _orders(rows):
    return {r['method']: r['order'] for r in rows}


def test_rk4_is_fourth_and_euler_first_order(records, puma):
    # without Coulomb friction the Puma's dynamics are smooth; 1 s keeps
    # rk4's error at 2 ms (~1e-13 rad) above round-off
    smooth = dataclasses.replace(puma, coulomb=np.zeros(puma.model.n))
    cases = {'panda_slow_earth': pick(records, section='integrators',
                                      scene='panda_slow_earth'),
             'puma without Coulomb': S.integrator_sweep(smooth, quick=True,
                                                        duration=1.0)}
    for name, rows in cases.items():
        order = _orders(rows)
        assert 3.3 < order['rk4'] < 4.7, (name, order)
        assert 0.7 < order['semi_implicit_euler'] < 1.3, (name, order)
        for method in ('rk4', 'semi_implicit_euler'):
            errs = [r['error'] for r in sorted(
                (r for r in rows if r['method'] == method),
                key=lambda r: r['step'])]
            assert all(a < b for a, b in zip(errs, errs[1:])), (name, errs)
    # semi-implicit Euler's energy drift is first order too (orbit)
    drift = {r['step']: r['drift'] for r in pick(
        records, section='integrators', scene='panda_orbit_slow',
        method='semi_implicit_euler')}
    small, large = min(drift), max(drift)
    assert 0.7 < (math.log(drift[large] / drift[small])
                  / math.log(large / small)) < 1.3


def test_coulomb_friction_caps_the_order_of_rk4(records):
    """sign(qd) is discontinuous: rk4 is no longer fourth order."""
    order = _orders(pick(records, section='integrators',
                         scene='puma_payload_press'))
    assert order['rk4'] is not None and order['rk4'] < 2.5
    assert 0.7 < order['semi_implicit_euler'] < 1.3


def test_sweep_rejects_steps_that_do_not_divide_the_period(puma):
    with pytest.raises(ValueError, match='divide'):
        S.integrator_sweep(puma, quick=True, steps=(3e-3,))
