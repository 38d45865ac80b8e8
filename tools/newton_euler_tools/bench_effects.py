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
What each effect of a scene costs: time per inverse-dynamics call.

    python -m newton_euler_tools.bench_effects [SCENE ...] [--quick]

For each scene, times the scene's feedforward torques (the call the
inverse-dynamics node and the simulator's controller make) with every
effect, with each effect left out in turn, and with none (inertia only),
side by side in one run; and the same for one simulation step.
"""
import argparse
import dataclasses
import warnings

from newton_euler_ros.sim.scene import load_scene
from newton_euler_ros.sim.simulate import SceneDynamics
import numpy as np

from .timing import min_time

EFFECTS = ('gravity', 'velocity_products', 'payload', 'wrench', 'friction',
           'armature')


def _min_time(fn, number, repeat):
    """Return the best time per call of ``fn`` in microseconds."""
    return min_time(fn, number, repeat) * 1e6


def variants(scene):
    """Yield (label, scene) with all effects, each one left out, none."""
    on = [e for e in EFFECTS if getattr(scene.effects, e)]
    yield f'all {len(on)} of the scene', scene
    for name in on:
        if name == 'payload':
            continue          # merged into the model at load: costs nothing
        effects = dataclasses.replace(scene.effects, **{name: False})
        yield f'without {name}', dataclasses.replace(scene, effects=effects)
    none = dataclasses.replace(scene.effects,
                               **dict.fromkeys(EFFECTS, False))
    yield 'none (D qdd only)', dataclasses.replace(scene, effects=none)


def bench_scene(name, number, repeat):
    """Print the table for one scene; return its rows."""
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        scene = load_scene(name)
    rng = np.random.default_rng(0)
    n = scene.model.n
    q, qd, qdd = rng.uniform(-1.0, 1.0, size=(3, n))
    tau = np.zeros(n)
    rows = []
    for label, sc in variants(scene):
        dyn = SceneDynamics(sc)
        t_ff = _min_time(
            lambda: dyn.torques(q, qd, qdd, *sc.wrench_at(0.0)),
            number, repeat)
        t_fd = _min_time(
            lambda: dyn.accelerations(q, qd, tau, *sc.wrench_at(0.0)),
            number // 4 or 1, repeat)
        rows.append((label, t_ff, t_fd))
    full_ff, full_fd = rows[0][1], rows[0][2]
    print(f'\n{scene.name} ({scene.model.name}, {n} joints): microseconds '
          f'per call, best of {repeat}')
    print(f'effects: {", ".join(scene.effects.names()) or "none"}')
    print(f'{"effects":<34}{"feedforward tau":>16}{"saves":>9}'
          f'{"forward dyn.":>14}{"saves":>9}')
    for label, t_ff, t_fd in rows:
        print(f'{label:<34}{t_ff:>16.2f}{full_ff - t_ff:>9.2f}'
              f'{t_fd:>14.2f}{full_fd - t_fd:>9.2f}')
    return rows


def main(argv=None):
    """Run the effect benchmark for the given (or bundled) scenes."""
    parser = argparse.ArgumentParser(prog='bench_effects',
                                     description=__doc__.strip().split(
                                         '\n')[0])
    parser.add_argument('scenes', nargs='*',
                        default=['puma_payload_press', 'panda_orbit_slow',
                                 'panda_slow_earth'])
    parser.add_argument('--quick', action='store_true',
                        help='fewer repetitions')
    args = parser.parse_args(argv)
    number, repeat = (500, 3) if args.quick else (4000, 7)
    print('cost of each effect ("saves" = time saved by leaving it out; '
          'payload is merged into the last link at load and costs nothing)')
    for name in args.scenes:
        bench_scene(name, number, repeat)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
