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

"""Scenes and simulation: only the effects a scene calls for, by physics."""
import copy

from newton_euler_ros.core import dynamics, kernels as K
from newton_euler_ros.core import (gravity_torques, inverse_dynamics,
                                   load_robot, RobotFileError)
from newton_euler_ros.core.model import with_payload
from newton_euler_ros.core.robot_file import read_yaml
from newton_euler_ros.sim.run import simulate
from newton_euler_ros.sim.scene import load_scene, scene_dirs, \
    scene_from_dict
from newton_euler_ros.sim.simulate import SceneDynamics
import numpy as np
import pytest


def bundled(name):
    import os
    for folder in scene_dirs():
        path = os.path.join(folder, name + '.yaml')
        if os.path.isfile(path):
            return read_yaml(path), folder
    raise FileNotFoundError(name)


def scene_with(name, **effects):
    data, folder = bundled(name)
    data = copy.deepcopy(data)
    data['effects'] = effects
    return scene_from_dict(data, f'{name}.yaml', folder)


@pytest.fixture(scope='module')
def default_scene():
    return load_scene('puma_payload_press')


def test_zero_gravity_never_evaluates_gravity(monkeypatch):
    scene = scene_with('puma_payload_press', gravity=False)
    dyn = SceneDynamics(scene)
    q = np.array([0.1, 0.7, -0.3, 0.2, 0.4, 0.1])
    seen = []
    real = dynamics._tau              # the Newton-Euler entry point

    def spy(*args):
        seen.append(bool(args[5] & K.GRAVITY))    # the gravity flag
        return real(*args)
    monkeypatch.setattr(dynamics, '_tau', spy)
    tau = dyn.torques(q, np.zeros(6), np.zeros(6), *scene.wrench_at(0.0))
    assert seen == [False]
    assert np.all(tau == 0.0)         # exactly zero, not round-off
    # and the gravity vector really is irrelevant: change it, same torques
    heavier = scene.model.replace(gravity=[0.0, 0.0, -1e3])
    assert np.all(inverse_dynamics(heavier, q, gravity=False) == 0.0)


def test_effects_select_terms(default_scene):
    full = default_scene.effects.names()
    assert full == ['gravity', 'velocity_products', 'payload', 'wrench',
                    'friction', 'armature']
    orbit = load_scene('panda_orbit_slow')
    assert orbit.effects.names() == ['velocity_products']
    dyn = SceneDynamics(orbit)
    # at rest in orbit: exactly zero
    assert np.all(dyn.torques(orbit.q0, np.zeros(7), np.zeros(7)) == 0.0)
    slow = load_scene('panda_slow_earth')
    assert slow.effects.names() == ['gravity']
    dyn = SceneDynamics(slow)
    q, qd = slow.q0, np.full(7, 0.3)
    # with no velocity products, torques at rest and in motion agree
    assert np.array_equal(dyn.torques(q, qd, np.zeros(7)),
                          dyn.torques(q, np.zeros(7), np.zeros(7)))


def test_left_out_velocity_products_are_negligible():
    """
    Check the slow scene's reason for leaving velocity products out.

    Along its reference, C qd (with the full model) stays below 0.1% of
    the full torque: the omission changes the feedforward by less than
    that.  Measured: 0.06%.
    """
    from newton_euler_ros.core import velocity_products
    scene = load_scene('panda_slow_earth')
    worst_c, worst_tau = 0.0, 0.0
    for t in np.linspace(0.0, scene.duration, 201):
        q, qd, qdd = scene.reference.at(t)
        worst_c = max(worst_c, np.abs(velocity_products(scene.model, q,
                                                        qd)).max())
        worst_tau = max(worst_tau, np.abs(inverse_dynamics(
            scene.model, q, qd, qdd)).max())
    assert worst_c < 1e-3 * worst_tau


def test_payload_equals_merged_last_link():
    """
    Check a payload against the parallel-axis theorem done by hand.

    A payload is a point mass + inertia on the tool.  Comparing with an
    extra massive link would need a new joint; instead compare with the
    parallel-axis theorem done by hand for a point mass on the axis.
    """
    arm = load_robot('planar_2r')
    m_p, r = 3.0, np.array([0.2, 0.0, 0.0])
    merged = with_payload(arm, m_p, r, np.zeros((3, 3)))
    q = np.array([0.3, -0.4])
    # gravity torque of a point mass m_p at the tool point plus r: add
    # m_p * g lever arms by hand
    c1, c12 = np.cos(q[0]), np.cos(q[0] + q[1])
    l1, l2 = arm.a
    x_p = l1 * c1 + (l2 + r[0]) * c12
    extra = np.array([m_p * 9.81 * x_p, m_p * 9.81 * (l2 + r[0]) * c12])
    np.testing.assert_allclose(gravity_torques(merged, q),
                               gravity_torques(arm, q) + extra, rtol=1e-12,
                               atol=1e-12)
    # inertia about joint 2's axis grows by m_p * (l2 + r)^2 exactly
    from newton_euler_ros.core import mass_matrix
    dD = mass_matrix(merged, q) - mass_matrix(arm, q)
    assert dD[1, 1] == pytest.approx(m_p * (l2 + r[0]) ** 2, rel=1e-12)


def test_payload_inertia_parallel_axis():
    arm = load_robot('planar_2r')
    Ip = np.diag([0.01, 0.02, 0.03])
    merged = with_payload(arm, 1.0, [0.0, 0.0, 0.0], Ip)
    m_l, c_l = arm.mass[-1], arm.com[-1]
    c = (m_l * c_l) / (m_l + 1.0)          # tool at the last frame origin
    d_l, d_p = c_l - c, -c
    expect = (arm.inertia[-1] + m_l * (d_l @ d_l * np.eye(3)
                                       - np.outer(d_l, d_l))
              + Ip + 1.0 * (d_p @ d_p * np.eye(3) - np.outer(d_p, d_p)))
    np.testing.assert_allclose(merged.inertia[-1], expect, rtol=1e-14)
    np.testing.assert_allclose(merged.com[-1], c, rtol=1e-14)


def test_friction_only_dissipates(default_scene):
    data, folder = bundled('puma_payload_press')
    data = copy.deepcopy(data)
    data['effects'] = {'gravity': True, 'velocity_products': True,
                       'friction': data['effects']['friction']}
    data['initial']['qd'] = [1.0, -0.8, 0.6, 2.0, -1.5, 3.0]
    scene = scene_from_dict(data, 'free.yaml', folder)
    n = scene.model.n

    def passive(t, q, qd):
        return np.zeros(n), np.zeros(n)
    r = simulate(scene, duration=0.5, controller=passive)
    friction_work = r.work[:, 1]
    assert np.all(np.diff(friction_work) <= 1e-12)
    assert friction_work[-1] < -1e-3
    # energy falls by the friction work.  Coulomb friction makes the
    # right-hand side jump when a joint velocity changes sign, so RK4 is
    # only first order at those steps: ~Tc |qd| dt per crossing, about
    # 1e-3 J here against an energy scale of ~180 J.  Bound: 1e-4 of scale.
    assert np.abs(r.drift).max() < 1e-4 * max(1.0, np.abs(r.energy).max())


def test_free_motion_rk4_conserves_energy():
    """
    Check that RK4 free motion conserves energy.

    RK4 at dt = 1 ms on the Puma with gravity and velocity products, no
    friction, no input: local error O(dt^5), so over 1 s the energy error
    stays below 1e-8 of the energy scale (measured ~1e-11).
    """
    data, folder = bundled('puma_payload_press')
    data = copy.deepcopy(data)
    data['effects'] = {'gravity': True, 'velocity_products': True,
                       'payload': data['effects']['payload'],
                       'armature': data['effects']['armature']}
    data['initial']['qd'] = [0.5, -0.5, 0.8, 1.0, -1.0, 2.0]
    scene = scene_from_dict(data, 'free.yaml', folder)

    def passive(t, q, qd):
        return np.zeros(6), np.zeros(6)
    r = simulate(scene, duration=1.0, controller=passive)
    scale = np.abs(r.energy).max()
    assert np.abs(r.energy - r.energy[0]).max() < 1e-8 * scale
    assert np.abs(r.work).max() == 0.0


def test_feedforward_tracks_10x_better_than_pd(default_scene):
    with_ff = simulate(default_scene, feedforward=True)
    pd_only = simulate(default_scene, feedforward=False)
    ratio = pd_only.summary['tracking_rms'] / with_ff.summary['tracking_rms']
    assert ratio >= 10.0, ratio
    # bookkeeping closes: work of torques, friction, wrench explain E
    assert with_ff.summary['energy_drift_relative'] < 1e-4


def test_semi_implicit_euler_runs_and_tracks(default_scene):
    r = simulate(default_scene, duration=1.0, integrator='semi_implicit_euler')
    assert r.integrator == 'semi_implicit_euler'
    assert r.summary['tracking_rms'] < 1e-2


def test_wrench_schedule_interpolates():
    data, folder = bundled('puma_payload_press')
    data = copy.deepcopy(data)
    data['effects']['wrench'] = {'frame': 'end_effector', 'schedule': [
        {'t': 0.0, 'wrench': [0, 0, 0, 0, 0, 0]},
        {'t': 1.0, 'wrench': [0, 0, 10, 0, 0, 2]}]}
    scene = scene_from_dict(data, 's.yaml', folder)
    assert scene.wrench.at(0.5).tolist() == [0, 0, 5, 0, 0, 1]
    assert scene.wrench.at(9.0).tolist() == [0, 0, 10, 0, 0, 2]


@pytest.mark.parametrize('change, message', [
    (lambda d: d['effects'].update(gravity='yes'),
     r'effects\.gravity: must be true, false or \[gx, gy, gz\]'),
    (lambda d: d['effects'].update(magnetism=True),
     r"effects: unknown key 'magnetism'"),
    (lambda d: d['effects']['payload'].update(mass=-1.0),
     r'effects\.payload\.mass: must be >= 0'),
    (lambda d: d['effects']['friction'].update(viscous=[1.0, 2.0]),
     r'effects\.friction\.viscous: must have 6 entries'),
    (lambda d: d['effects']['wrench'].update(frame='world'),
     r"effects\.wrench\.frame: must be 'base' or 'end_effector'"),
    (lambda d: d['integrator'].update(method='euler'),
     r'integrator\.method: must be one of rk4, semi_implicit_euler'),
    (lambda d: d['integrator'].update(step='1e-3x'),
     r'integrator\.step: must be a number'),
    (lambda d: d['integrator'].update(step=0.0),
     r'integrator\.step: must be > 0'),
    (lambda d: d['reference'].update(type='spline'),
     r"reference\.type: must be 'quintic' or 'sinusoid'"),
    (lambda d: d.update(robot='no_such_robot'), r'not a bundled robot'),
])
def test_bad_scene_names_the_field(change, message):
    data, folder = bundled('puma_payload_press')
    data = copy.deepcopy(data)
    change(data)
    with pytest.raises(RobotFileError, match=message):
        scene_from_dict(data, 'puma_payload_press.yaml', folder)


def test_numbers_as_strings_are_coerced():
    data, folder = bundled('puma_payload_press')
    data = copy.deepcopy(data)
    data['integrator']['step'] = '1e-3'     # how PyYAML reads 1e-3
    assert scene_from_dict(data, 's.yaml', folder).step == 1e-3


def test_live_wrench_equals_constant_wrench():
    """A topic-fed wrench, passed in, acts exactly like a constant one."""
    data, folder = bundled('puma_payload_press')
    live = copy.deepcopy(data)
    live['effects']['wrench'] = {'frame': 'end_effector', 'source': 'topic'}
    const = copy.deepcopy(data)
    w = [1.0, -2.0, 30.0, 0.1, 0.2, -0.3]
    const['effects']['wrench'] = {'frame': 'end_effector', 'constant': w}
    s_live = scene_from_dict(live, 'l.yaml', folder)
    s_const = scene_from_dict(const, 'c.yaml', folder)
    d_live, d_const = SceneDynamics(s_live), SceneDynamics(s_const)
    q, qd, tau = np.full(6, 0.3), np.full(6, -0.2), np.ones(6)
    # offline, a topic's wrench is zero
    assert np.array_equal(s_live.wrench_at(5.0)[0], np.zeros(6))
    offline = d_live.accelerations(q, qd, tau, *s_live.wrench_at(0.0))
    expected = d_const.accelerations(q, qd, tau, *s_const.wrench_at(0.0))
    np.testing.assert_array_equal(
        d_live.accelerations(q, qd, tau, np.array(w), 'end_effector'),
        expected)
    assert np.abs(offline - expected).max() > 1e-3
    # the wrench reaches the dynamics only as an argument
    assert not any('wrench' in k for k in vars(d_live))


@pytest.mark.parametrize('name', ['puma_payload_press', 'panda_orbit_slow',
                                  'panda_slow_earth'])
def test_scene_controller_is_stable_sampled_at_its_rate(name):
    """
    Check each bundled scene's gains with its controller sampled and held.

    The ROS graph runs the controller at the scene's rate and the
    simulator holds each command until the next; too high a kd against a
    small link inertia makes that loop diverge (kd T / I above about 2).
    The gains must track, and keep doing so at 1.5x as a margin.
    """
    import dataclasses

    from newton_euler_tools.accuracy.scenes import held_controller
    scene = load_scene(name)
    for gain in (1.0, 1.5):
        sc = dataclasses.replace(scene, kp=gain * scene.kp,
                                 kd=gain * scene.kd)
        with np.errstate(all='ignore'):
            result = simulate(sc, duration=min(sc.duration, 2.0),
                              controller=held_controller(
                                  SceneDynamics(sc), 1.0 / sc.rate))
        assert result.summary['tracking_max'] < 0.02, (name, gain)


def test_a_duration_under_half_a_step_is_one_step():
    """simulate() used to index out_tau[-2] of a one-sample result."""
    scene = load_scene('puma_payload_press')
    result = simulate(scene, duration=0.1 * scene.step)
    assert result.summary['steps'] == 1 and len(result.t) == 2
    with pytest.raises(ValueError, match='duration must be > 0'):
        simulate(scene, duration=0.0)


def test_friction_arrays_are_not_shared():
    scene = load_scene('panda_orbit_slow')
    assert scene.viscous is not scene.coulomb
