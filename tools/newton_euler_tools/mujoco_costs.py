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
What accuracy costs, measured against MuJoCo's full physics.

    python -m newton_euler_tools.mujoco_costs [SCENE] [--quick] [--json FILE]

The plant is MuJoCo with every effect of the scene (default
``panda_mujoco_full``: gravity, velocity products, a payload, a wrench,
friction, rotor inertia). The controller is the scene's PD plus the
library's feedforward computed with every effect, with each effect left
out in turn, and with none (D q̈ alone), and PD alone. For each: the
time of one feedforward call (µs, best of several rounds, side by side in
one run) and the tracking error on MuJoCo. A payload merged into the
model at load costs nothing to compute; leaving it out means the model
without it.
"""
import argparse
import dataclasses
import json
import warnings

from newton_euler_ros.core import load_robot
from newton_euler_ros.sim.mujoco_scene import simulate_mujoco
from newton_euler_ros.sim.scene import load_scene
from newton_euler_ros.sim.simulate import SceneDynamics, tracking_controller
import numpy as np

from .bench_effects import EFFECTS
from .timing import min_time

SCENE = 'panda_mujoco_full'


def variants(scene, bare):
    """Yield (label, controller scene) for every feedforward variant."""
    on = [e for e in EFFECTS if getattr(scene.effects, e)]
    yield f'all {len(on)} effects', scene
    for name in on:
        effects = dataclasses.replace(scene.effects, **{name: False})
        model = bare.model if name == 'payload' else scene.model
        yield f'without {name}', dataclasses.replace(scene, effects=effects,
                                                     model=model)
    none = dataclasses.replace(scene.effects,
                               **dict.fromkeys(EFFECTS, False))
    yield 'none (D qdd only)', dataclasses.replace(scene, effects=none,
                                                   model=bare.model)


def without_payload(scene):
    """Return the scene with its robot's model without the payload."""
    model = load_robot(scene.robot_path).replace(gravity=scene.model.gravity)
    return dataclasses.replace(scene, model=model)


def measure(scene, number, repeat, duration=None):
    """Return rows (label, µs per feedforward call, tracking RMS, max)."""
    bare = without_payload(scene)
    rng = np.random.default_rng(0)
    n = scene.model.n
    q, qd, qdd = rng.uniform(-1.0, 1.0, size=(3, n))
    cases = [(label, sc, SceneDynamics(sc))
             for label, sc in variants(scene, bare)]
    best = [np.inf] * len(cases)
    for _ in range(repeat):         # side by side, alternating
        for i, (_, sc, dyn) in enumerate(cases):
            wrench = sc.wrench_at(0.0)
            best[i] = min(best[i], min_time(
                lambda: dyn.torques(q, qd, qdd, *wrench), number, 1))
    rows = []
    for (label, _, dyn), seconds in zip(cases, best):
        control = tracking_controller(dyn, feedforward=True)
        summary = simulate_mujoco(scene, duration, controller=control).summary
        rows.append((label, seconds * 1e6, summary['tracking_rms'],
                     summary['tracking_max']))
    summary = simulate_mujoco(scene, duration, feedforward=False).summary
    rows.append(('PD alone', 0.0, summary['tracking_rms'],
                 summary['tracking_max']))
    return rows


def main(argv=None):
    """Print the table; optionally write it as JSON."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[1])
    parser.add_argument('scene', nargs='?', default=SCENE)
    parser.add_argument('--quick', action='store_true',
                        help='fewer timing repetitions, 1 s simulated')
    parser.add_argument('--json', metavar='FILE',
                        help='write the rows to FILE')
    args = parser.parse_args(argv)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        scene = load_scene(args.scene)
    scene = dataclasses.replace(scene, engine='mujoco')
    number, repeat = (500, 3) if args.quick else (4000, 7)
    rows = measure(scene, number, repeat, 1.0 if args.quick else None)
    print(f'{scene.name} ({scene.model.name}, {scene.model.n} joints) on '
          f'MuJoCo with every effect: {", ".join(scene.effects.names())}')
    print(f'{"feedforward computed with":<28}{"us/call":>9}'
          f'{"tracking RMS (rad)":>20}{"max (rad)":>12}')
    for label, us, rms, top in rows:
        cost = f'{us:9.2f}' if us else f'{"-":>9}'
        print(f'{label:<28}{cost}{rms:>20.3e}{top:>12.3e}')
    if args.json:
        with open(args.json, 'w', encoding='utf-8') as fh:
            json.dump([dict(zip(('label', 'us', 'tracking_rms',
                                 'tracking_max'), row)) for row in rows],
                      fh, indent=1)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
