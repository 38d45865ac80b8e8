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
Scene files: a robot, the physical effects present, and a task.

A scene names the robot file, which effects exist (gravity, velocity
products, a payload, an end-effector wrench, joint friction, rotor
inertia), the initial state, a reference trajectory, a tracking
controller and the integrator.  The format is in the README ("Scene
files"); errors name the file and the field, like robot files.
"""
from dataclasses import dataclass
import math
import os

import numpy as np

from ..core.effects import Effects
from ..core.errors import RobotFileError
from ..core.inertia import inertia_matrix, principal_moments
from ..core.model import with_payload
from ..core.robot_file import (_check_keys, _short, inspect_robot, read_yaml,
                               to_number, to_vector)

SCENE_KEYS = {'name', 'description', 'robot', 'effects', 'initial',
              'reference', 'controller', 'integrator', 'engine',
              'contacts'}
ENGINES = ('newton_euler', 'mujoco')
EFFECT_KEYS = {'gravity', 'velocity_products', 'payload', 'wrench',
               'friction', 'armature'}
INTEGRATORS = ('rk4', 'semi_implicit_euler')


@dataclass(frozen=True)
class WrenchSchedule:
    """
    An end-effector wrench over time (exerted by the robot).

    ``kind`` is ``constant``, ``schedule`` (piecewise-linear in time) or
    ``topic`` (live from the ROS ``wrench`` topic; offline it is zero).
    """

    kind: str
    frame: str
    times: np.ndarray
    values: np.ndarray

    def at(self, t):
        """Return the wrench at time ``t`` (s), a (6,) array."""
        if self.kind == 'topic':
            return np.zeros(6)
        if len(self.times) == 1:
            return self.values[0].copy()
        return np.array([np.interp(t, self.times, self.values[:, k])
                         for k in range(6)])


@dataclass(frozen=True)
class Reference:
    """A desired joint trajectory: quintic rest-to-rest or sinusoid."""

    kind: str
    start: np.ndarray
    goal: np.ndarray
    duration: float
    amplitude: np.ndarray
    frequency: np.ndarray
    phase: np.ndarray

    def at(self, t):
        """Desired (q, qd, qdd) at time ``t``."""
        if self.kind == 'quintic':
            T = self.duration
            s = min(max(t / T, 0.0), 1.0)
            p = 10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5
            dp = (30 * s ** 2 - 60 * s ** 3 + 30 * s ** 4) / T
            ddp = (60 * s - 180 * s ** 2 + 120 * s ** 3) / T ** 2
            if t < 0.0 or t > T:
                dp = ddp = 0.0
            delta = self.goal - self.start
            return self.start + p * delta, dp * delta, ddp * delta
        w = 2.0 * math.pi * self.frequency
        arg = w * t + self.phase
        return (self.start + self.amplitude * np.sin(arg),
                self.amplitude * w * np.cos(arg),
                -self.amplitude * w ** 2 * np.sin(arg))


@dataclass(frozen=True)
class Scene:
    """A validated scene; ``model`` already carries the payload."""

    name: str
    description: str
    path: str
    robot_path: str
    model: object
    effects: Effects
    viscous: np.ndarray
    coulomb: np.ndarray
    armature: np.ndarray
    wrench: object
    q0: np.ndarray
    qd0: np.ndarray
    reference: Reference
    kp: np.ndarray
    kd: np.ndarray
    feedforward: bool
    integrator: str
    step: float
    duration: float
    rate: float
    warnings: tuple = ()
    engine: str = 'newton_euler'
    contacts: object = None
    payload: tuple = None   # (mass, com, inertia, link) as given

    def wrench_at(self, t):
        """
        Return (wrench or None, frame): the scene's own wrench at time t.

        None when the scene has no wrench effect.  A wrench read from a
        topic is zero here; the ROS adapter passes the live one instead.
        """
        if not self.effects.wrench:
            return None, 'base'
        return self.wrench.at(t), self.wrench.frame


def _flag_or_block(value, where):
    """Return (enabled, block): true/false, null (off) or a mapping (on)."""
    if value is None or value is False:
        return False, None
    if value is True:
        return True, None
    if isinstance(value, (dict, list)):
        return True, value
    raise RobotFileError(f'{where}: must be true, false or a mapping, '
                         f'got {_short(value)!r}')


def _per_joint(value, n, where, minimum=0.0):
    if isinstance(value, (int, float, str)) and not isinstance(value, bool):
        x = [to_number(value, where)] * n
    else:
        x = to_vector(value, n, where)
    for i, v in enumerate(x):
        if v < minimum:
            raise RobotFileError(f'{where}[{i}]: must be >= {minimum}, '
                                 f'got {v}')
    return np.array(x)


def _wrench(block, where):
    _check_keys(block, {'frame', 'constant', 'schedule', 'source'}, where)
    frame = block.get('frame', 'base')
    if frame not in ('base', 'end_effector'):
        raise RobotFileError(f"{where}.frame: must be 'base' or "
                             f"'end_effector', got {_short(frame)!r}")
    kinds = [k for k in ('constant', 'schedule', 'source') if k in block]
    if len(kinds) != 1:
        raise RobotFileError(f'{where}: give exactly one of constant, '
                             f'schedule or source')
    if 'constant' in block:
        w = to_vector(block['constant'], 6, f'{where}.constant')
        return WrenchSchedule('constant', frame, np.zeros(1), np.array([w]))
    if 'source' in block:
        if block['source'] != 'topic':
            raise RobotFileError(f"{where}.source: must be 'topic', got "
                                 f"{_short(block['source'])!r}")
        return WrenchSchedule('topic', frame, np.zeros(1), np.zeros((1, 6)))
    rows = block['schedule']
    if not isinstance(rows, list) or not rows:
        raise RobotFileError(f'{where}.schedule: must be a non-empty list '
                             f'of {{t, wrench}}')
    times, values = [], []
    for i, row in enumerate(rows):
        w_i = f'{where}.schedule[{i}]'
        _check_keys(row, {'t', 'wrench'}, w_i)
        times.append(to_number(row.get('t'), f'{w_i}.t'))
        values.append(to_vector(row.get('wrench'), 6, f'{w_i}.wrench'))
    if any(b < a for a, b in zip(times, times[1:])):
        raise RobotFileError(f'{where}.schedule: times must not decrease')
    return WrenchSchedule('schedule', frame, np.array(times),
                          np.array(values))


def _reference(block, n, q0, where):
    _check_keys(block, {'type', 'start', 'goal', 'duration', 'amplitude',
                        'frequency', 'phase', 'offset'}, where)
    kind = block.get('type')
    zeros = np.zeros(n)
    if kind == 'quintic':
        start = (np.array(to_vector(block['start'], n, f'{where}.start'))
                 if 'start' in block else q0.copy())
        if 'goal' not in block:
            raise RobotFileError(f"{where}: missing required key 'goal'")
        goal = np.array(to_vector(block['goal'], n, f'{where}.goal'))
        duration = to_number(block.get('duration'), f'{where}.duration')
        if duration <= 0.0:
            raise RobotFileError(f'{where}.duration: must be > 0')
        return Reference('quintic', start, goal, duration, np.zeros(n),
                         np.zeros(n), np.zeros(n))
    if kind == 'sinusoid':
        offset = (np.array(to_vector(block['offset'], n, f'{where}.offset'))
                  if 'offset' in block else q0.copy())
        amp = np.array(to_vector(block.get('amplitude'), n,
                                 f'{where}.amplitude'))
        freq = _per_joint(block.get('frequency'), n, f'{where}.frequency')
        phase = (np.array(to_vector(block['phase'], n, f'{where}.phase'))
                 if 'phase' in block else zeros)
        return Reference('sinusoid', offset, offset, 0.0, amp, freq, phase)
    raise RobotFileError(f"{where}.type: must be 'quintic' or 'sinusoid', "
                         f'got {_short(kind)!r}')


def _gravity(value, model, w):
    """Return (model, on): ``gravity`` true, false or [gx, gy, gz]."""
    if isinstance(value, list):
        return model.replace(gravity=to_vector(value, 3,
                                               f'{w}.gravity')), True
    if not isinstance(value, bool):
        raise RobotFileError(f'{w}.gravity: must be true, false or '
                             f'[gx, gy, gz], got {_short(value)!r}')
    return model, value


def _payload(block, model, w):
    """Return the model carrying the ``payload`` block's body, and it."""
    if not isinstance(block, dict):
        raise RobotFileError(f'{w}.payload: must give mass, com, inertia')
    _check_keys(block, {'mass', 'com', 'inertia', 'link'}, f'{w}.payload')
    mass = to_number(block.get('mass'), f'{w}.payload.mass')
    if mass < 0.0:
        raise RobotFileError(f'{w}.payload.mass: must be >= 0')
    com = to_vector(block.get('com', [0.0] * 3), 3, f'{w}.payload.com')
    inertia = inertia_matrix(*to_vector(block.get('inertia', [0.0] * 6),
                                        6, f'{w}.payload.inertia'))
    if not principal_moments(inertia)[1]:
        raise RobotFileError(f'{w}.payload.inertia: must be positive '
                             f'semidefinite')
    link = block.get('link')
    if link is not None and not isinstance(link, str):
        raise RobotFileError(f'{w}.payload.link: must be a link name')
    try:
        return (with_payload(model, mass, com, inertia, link),
                (mass, np.array(com), inertia, link))
    except ValueError as exc:       # no end effector, or no such link
        raise RobotFileError(f'{w}.payload: {exc}') from None


def _friction(block, n, w):
    """Return (viscous, coulomb) per joint from the ``friction`` block."""
    if not isinstance(block, dict):
        raise RobotFileError(f'{w}.friction: must give viscous and/or '
                             f'coulomb')
    _check_keys(block, {'viscous', 'coulomb'}, f'{w}.friction')
    return (_per_joint(block.get('viscous', 0.0), n,
                       f'{w}.friction.viscous'),
            _per_joint(block.get('coulomb', 0.0), n,
                       f'{w}.friction.coulomb'))


def _effects(eff, model, origin):
    """
    Read the ``effects`` block; return (model, effects, extras).

    ``extras`` holds the per-joint viscous, coulomb and armature arrays
    (zeros where off) and the wrench (None where off).
    """
    w = f'{origin}: effects'
    _check_keys(eff, EFFECT_KEYS, w)
    n = model.n
    model, gravity = _gravity(eff.get('gravity', True), model, w)
    velocity = eff.get('velocity_products', True)
    if not isinstance(velocity, bool):
        raise RobotFileError(f'{w}.velocity_products: must be true or false')
    payload_on, block = _flag_or_block(eff.get('payload'), f'{w}.payload')
    payload = None
    if payload_on:
        model, payload = _payload(block, model, w)
    wrench_on, block = _flag_or_block(eff.get('wrench'), f'{w}.wrench')
    wrench = None
    if wrench_on:
        if not isinstance(block, dict):
            raise RobotFileError(f'{w}.wrench: must give frame and one of '
                                 f'constant, schedule, source')
        wrench = _wrench(block, f'{w}.wrench')
        if model.tool_body is None:
            raise RobotFileError(
                f'{w}.wrench: {model.name} is a tree with several tips: no '
                f'end effector for the wrench to act at')
    friction_on, block = _flag_or_block(eff.get('friction'),
                                        f'{w}.friction')
    viscous, coulomb = (_friction(block, n, w) if friction_on
                        else (np.zeros(n), np.zeros(n)))
    armature_on = eff.get('armature') not in (None, False)
    armature = (_per_joint(eff['armature'], n, f'{w}.armature')
                if armature_on else np.zeros(n))
    effects = Effects(gravity, velocity, payload_on, wrench_on, friction_on,
                      armature_on)
    return model, effects, {'viscous': viscous, 'coulomb': coulomb,
                            'armature': armature, 'wrench': wrench,
                            'payload': payload}


def _initial(init, n, origin):
    """Return (q0, qd0) of the ``initial`` block (zeros by default)."""
    _check_keys(init, {'q', 'qd'}, f'{origin}: initial')
    return (np.array(to_vector(init.get('q', [0.0] * n), n,
                               f'{origin}: initial.q')),
            np.array(to_vector(init.get('qd', [0.0] * n), n,
                               f'{origin}: initial.qd')))


def _controller(ctrl, n, origin):
    """Return {kp, kd, feedforward} of the ``controller`` block."""
    _check_keys(ctrl, {'kp', 'kd', 'feedforward'}, f'{origin}: controller')
    gains = {key: _per_joint(ctrl.get(key, 0.0), n,
                             f'{origin}: controller.{key}')
             for key in ('kp', 'kd')}
    feedforward = ctrl.get('feedforward', True)
    if not isinstance(feedforward, bool):
        raise RobotFileError(f'{origin}: controller.feedforward: must be '
                             f'true or false')
    return dict(gains, feedforward=feedforward)


def _integrator(integ, origin):
    """Return {integrator, step, duration, rate} of the ``integrator`` block."""
    _check_keys(integ, {'method', 'step', 'duration', 'rate'},
                f'{origin}: integrator')
    method = integ.get('method', 'rk4')
    if method not in INTEGRATORS:
        raise RobotFileError(f'{origin}: integrator.method: must be one of '
                             f'{", ".join(INTEGRATORS)}, got {_short(method)!r}')
    values = {'step': to_number(integ.get('step'),
                                f'{origin}: integrator.step'),
              'duration': to_number(integ.get('duration'),
                                    f'{origin}: integrator.duration'),
              'rate': to_number(integ.get('rate', 250.0),
                                f'{origin}: integrator.rate')}
    for key, value in values.items():
        if value <= 0.0:
            raise RobotFileError(f'{origin}: integrator.{key}: must be > 0, '
                                 f'got {value}')
    return dict(values, integrator=method)


def scene_from_dict(data, origin, base_dir='.'):
    """Validate a parsed scene; ``base_dir`` resolves a relative robot."""
    _check_keys(data, SCENE_KEYS, origin)
    for key in ('name', 'robot', 'integrator'):
        if key not in data:
            raise RobotFileError(f'{origin}: missing required key {key!r}')
    robot = str(data['robot'])
    candidate = os.path.join(base_dir, robot)
    model, found, robot_path = inspect_robot(
        candidate if os.path.isfile(candidate) else robot)
    model, effects, extras = _effects(data.get('effects') or {}, model,
                                      origin)
    q0, qd0 = _initial(data.get('initial') or {}, model.n, origin)
    ref_block = data.get('reference') or {'type': 'quintic',
                                          'goal': q0.tolist(),
                                          'duration': 1.0}
    reference = _reference(ref_block, model.n, q0, f'{origin}: reference')
    controller = _controller(data.get('controller') or {}, model.n, origin)
    integrator = _integrator(data['integrator'], origin)
    name = data['name']
    if not isinstance(name, str) or not name:
        raise RobotFileError(f'{origin}: name: must be a non-empty string')
    engine = data.get('engine', 'newton_euler')
    if engine not in ENGINES:
        raise RobotFileError(f'{origin}: engine: must be one of '
                             f'{", ".join(ENGINES)}, got {_short(engine)!r}')
    contacts = None
    if data.get('contacts') is not None:
        if engine != 'mujoco':
            raise RobotFileError(f'{origin}: contacts: need engine: mujoco '
                                 f'(the library simulates no contacts)')
        from .contacts import read_contacts
        contacts = read_contacts(data['contacts'], f'{origin}: contacts')
    if engine == 'mujoco' and not effects.velocity_products:
        raise RobotFileError(f'{origin}: effects.velocity_products: MuJoCo '
                             f'always has them (engine: mujoco simulates '
                             f'every rigid-body effect)')
    return Scene(name=name, description=str(data.get('description', '')),
                 path=origin, robot_path=robot_path, model=model,
                 effects=effects, q0=q0, qd0=qd0, reference=reference,
                 warnings=tuple(found), engine=engine, contacts=contacts,
                 **extras, **controller, **integrator)


def scene_dirs():
    """Folders searched for bundled scenes."""
    from ..core.robot_file import bundled_dirs
    return [os.path.join(os.path.dirname(d), 'scenes')
            for d in bundled_dirs()]


def load_scene(name_or_path):
    """Load a scene file (a path, or a bundled scene's name)."""
    path = os.fspath(name_or_path)
    if os.path.isdir(path):
        raise RobotFileError(f'{_short(path)}: is a directory, not a scene '
                             f'file')
    if not os.path.isfile(path):
        for folder in scene_dirs():
            candidate = os.path.join(folder, path + '.yaml')
            if os.path.isfile(candidate):
                path = candidate
                break
        else:
            raise RobotFileError(f'{_short(path)}: no such file, and not a '
                                 f'bundled scene')
    data = read_yaml(path)
    return scene_from_dict(data, os.path.basename(path),
                           os.path.dirname(os.path.abspath(path)))
