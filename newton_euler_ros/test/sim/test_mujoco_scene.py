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
Scenes in MuJoCo: two engines, one physics; a pusher's real contact.

The library's simulator and MuJoCo integrate the same scene (gravity, a
payload, viscous friction, rotor inertia, RK4 at the same step, the same
controller) to the same trajectory; a pusher presses a link of the
moving arm through a MuJoCo contact, and the momentum observer, run on
MuJoCo's motion and applied torques, reports it within 50 ms and at
MuJoCo's contact wrench, with no contact on a free motion it was not
tuned on.
"""
import copy
import dataclasses
import os
import subprocess
import sys

from newton_euler_ros.core import (load_robot, model_to_urdf,
                                   MomentumObserver, RobotFileError)
from newton_euler_ros.core.observer import (external_wrench,
                                            observe_recording)
from newton_euler_ros.core.robot_file import read_yaml
from newton_euler_ros.sim.mujoco_scene import scene_plant
from newton_euler_ros.sim.run import simulate
from newton_euler_ros.sim.scene import load_scene, scene_dirs, \
    scene_from_dict
from newton_euler_ros.sim.simulate import SceneDynamics, tracking_controller
import numpy as np
import pytest


def bundled(name):
    for folder in scene_dirs():
        path = os.path.join(folder, name + '.yaml')
        if os.path.isfile(path):
            return copy.deepcopy(read_yaml(path)), folder
    raise FileNotFoundError(name)


def test_both_engines_integrate_the_same_scene_to_the_same_motion():
    data, folder = bundled('panda_orbit_slow')
    data['effects'] = {
        'gravity': True, 'friction': {'viscous': 0.5}, 'armature': 0.1,
        'payload': {'mass': 2.0, 'com': [0.0, 0.02, 0.05],
                    'inertia': [0.01, 0.02, 0.015, 0.001, 0.0, 0.0]}}
    data['controller'] = {'kp': 400, 'kd': 40}
    runs = {}
    for engine in ('newton_euler', 'mujoco'):
        data['engine'] = engine
        scene = scene_from_dict(data, 'x.yaml', folder)
        runs[engine] = simulate(scene, duration=1.0)
    ours, theirs = runs['newton_euler'], runs['mujoco']
    assert theirs.summary['engine'] == 'mujoco'
    assert np.abs(ours.q - theirs.q).max() < 1e-9
    assert np.abs(ours.qd - theirs.qd).max() < 1e-8
    # without the payload in MuJoCo's world, the motions part
    data['effects'].pop('payload')
    scene = scene_from_dict(data, 'x.yaml', folder)
    assert np.abs(simulate(scene, duration=1.0).q - theirs.q).max() > 1e-4


def test_scene_engine_and_contacts_are_checked_in_one_line():
    data, folder = bundled('panda_orbit_slow')
    bad = [({'engine': 'bullet'}, r'x.yaml: engine: must be one of '
                                  r'newton_euler, mujoco'),
           ({'contacts': {'floor': {'height': 0}}},
            r'x.yaml: contacts: need engine: mujoco'),
           ({'engine': 'mujoco', 'contacts': {'tabel': {}}},
            r'x.yaml: contacts: unknown key'),
           ({'engine': 'mujoco', 'contacts': {'table': {'size': [1, 0, 1],
                                                        'position': [0] * 3}}},
            r'contacts.table.size: every side must be > 0'),
           ({'engine': 'mujoco', 'contacts': {'pusher': {
               'link': 'link4', 'direction': [0, 0, 0],
               'schedule': [{'t': 0, 'force': 1}]}}},
            r'contacts.pusher.direction: must be a nonzero vector'),
           ({'engine': 'mujoco', 'contacts': {'pusher': {
               'link': 'link4', 'direction': [1, 0, 0],
               'schedule': [{'t': 0, 'force': -1}]}}},
            r'contacts.pusher.schedule\[0\].force: must be >= 0 N')]
    for change, message in bad:
        d = dict(copy.deepcopy(data), **change)
        with pytest.raises(RobotFileError, match=message):
            scene_from_dict(d, 'x.yaml', folder)
    # velocity products cannot be left out of MuJoCo's world
    with pytest.raises(RobotFileError, match='MuJoCo always has them'):
        scene_from_dict(dict(copy.deepcopy(bundled('panda_slow_earth')[0]),
                             engine='mujoco'), 'x.yaml', folder)


PUSHED = 'link7'


def panda_scene(tmp_path, frequency, push=None):
    path = tmp_path / 'panda.urdf'
    if not path.exists():
        path.write_text(model_to_urdf(load_robot('panda')))
    data = {
        'name': 'panda_push', 'robot': str(path), 'engine': 'mujoco',
        'initial': {'q': [0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.8]},
        'reference': {'type': 'sinusoid', 'amplitude': [0.5] * 7,
                      'frequency': frequency},
        'controller': {'kp': [400] * 4 + [100] * 2 + [40],
                       'kd': [40] * 4 + [10] * 2 + [4]},
        'integrator': {'method': 'semi_implicit_euler', 'step': 1e-3,
                       'duration': 2.5}}
    if push is not None:
        data['contacts'] = {'pusher': {
            'link': PUSHED, 'point': [0.0, 0.0, 0.05],
            'direction': [0.0, 1.0, 0.0], 'schedule': push}}
    return scene_from_dict(data, 'panda_push.yaml', str(tmp_path))


def run(scene):
    """Run the scene at 1 kHz; return T, Q, QD, applied TAU, contact W."""
    plant = scene_plant(scene)
    control = tracking_controller(SceneDynamics(scene))
    steps = int(round(scene.duration / scene.step))
    T = np.arange(steps) * scene.step
    Q, QD, TAU = (np.zeros((steps, scene.model.n)) for _ in range(3))
    W = np.zeros((steps, 6))
    for k in range(steps):
        Q[k], QD[k] = plant.state()
        W[k] = plant.contact_wrenches().get(PUSHED, np.zeros(6))
        plant.advance(control(T[k], Q[k], QD[k])[0], scene.step)
        TAU[k] = plant.applied()
    return T, Q, QD, TAU, W


def test_the_observer_feels_a_pusher_on_the_moving_arm(tmp_path):
    # thresholds from one free motion (3x its largest residual), checked
    # on another, faster one, which is then pushed
    gain = 100.0
    scene = panda_scene(tmp_path, 0.5)
    T, Q, QD, TAU, W = run(scene)
    assert not W.any()
    free = observe_recording(MomentumObserver(scene.model, gain=gain,
                                              thresholds=1e9),
                             T, Q, QD, TAU)
    thresholds = np.maximum(3.0 * np.abs(free.residual).max(axis=0), 0.2)

    def observer():
        return MomentumObserver(scene.model, gain=gain,
                                thresholds=thresholds)

    held_out = panda_scene(tmp_path, 0.6)
    T, Q, QD, TAU, W = run(held_out)
    assert not observe_recording(observer(), T, Q, QD, TAU).contact.any()
    push = [{'t': 1.2, 'force': 0.0}, {'t': 1.22, 'force': 20.0},
            {'t': 1.9, 'force': 20.0}, {'t': 1.92, 'force': 0.0}]
    T, Q, QD, TAU, W = run(panda_scene(tmp_path, 0.6, push))
    obs = observer()
    rec = observe_recording(obs, T, Q, QD, TAU)
    touching = np.linalg.norm(W[:, :3], axis=1) > 0.5
    onset = T[np.argmax(touching)]
    assert 1.2 <= onset < 1.23
    assert not rec.contact[T < onset].any()
    assert T[np.argmax(rec.contact)] - onset <= 0.05
    # the residual is the external torque through a first-order lag of
    # gain K: compare with MuJoCo's contact wrench through the same lag
    a = np.exp(-gain * scene.step)
    lagged = np.zeros(6)
    worst = 0.0
    for k in range(len(T)):
        lagged = a * lagged + (1 - a) * W[k]
        if onset + 0.05 <= T[k] <= 1.9:
            F = external_wrench(obs, Q[k], rec.residual[k], frame=PUSHED)
            err = np.abs(F[:3] - lagged[:3]).max()
            worst = max(worst, err / (0.1 * np.linalg.norm(lagged[:3])
                                      + 1.0))
    assert worst <= 1.0


def test_simulate_engine_mujoco_from_the_command_line():
    cmd = [sys.executable, '-m', 'newton_euler_ros.cli', 'simulate',
           'panda_orbit_slow', '--engine', 'mujoco', '--duration', '0.5']
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert 'mujoco rk4 steps of 0.002 s' in out.stdout
    lib = subprocess.run(cmd[:-4] + ['--duration', '0.5'],
                         capture_output=True, text=True, timeout=120)
    rms = [line for line in out.stdout.splitlines() + lib.stdout.splitlines()
           if line.startswith('tracking error')]
    assert len(rms) == 2 and rms[0] == rms[1]       # one physics, two engines


def test_a_bundled_robot_mujoco_refuses_is_one_line_from_simulate():
    scene = load_scene('puma_pick_and_place')
    with pytest.raises(RobotFileError,
                       match=r'^puma560.yaml: MuJoCo refuses link .link1.: '):
        scene_plant(dataclasses.replace(scene, engine='mujoco'))
