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
What the MuJoCo plant costs: its largest real-time factor.

    python -m newton_euler_tools.bench_mujoco [--quick] [--seconds S]
                                              [--rounds R] [--json FILE]

On the bundled Panda (7 joints) at 1 kHz physics, side by side in one
run, best of several rounds:

- MuJoCo alone: ``mj_step`` with the torques held (the plant's physics);
- the plant as the node steps it: ``MujocoPlant.advance`` by one 2 ms
  tick (two physics steps) and reading the state, at 500 Hz;
- the closed loop offline: the same with the scene's PD plus the
  library's feedforward computed every millisecond (what
  ``simulate --engine mujoco`` does);
- with ``--loop`` (``make bench`` passes it), the closed loop over ROS 2:
  ``make demo``'s graph (mujoco_sim_node at 1 kHz physics and 250 Hz
  ticks, inverse_dynamics_node, tracking_controller_node, each its own
  process) on ``panda_mujoco_full`` for ``--loop-seconds`` of simulated
  time, paced at real time: the real-time factor the plant held, as its
  joint states arrived.

The real-time factor is simulated seconds per wall-clock second: above
1 the plant keeps up with real time, with that much of a core to spare.
"""
import argparse
import dataclasses
import json
import time

from newton_euler_ros.sim.mujoco_scene import scene_plant
from newton_euler_ros.sim.scene import load_scene
from newton_euler_ros.sim.simulate import SceneDynamics, tracking_controller
import numpy as np

SCENE = 'panda_orbit_slow'
STEP = 1e-3         # s, the physics step
TICK = 2e-3         # s, the node's publishing period (500 Hz)


def _scene():
    scene = load_scene(SCENE)
    return dataclasses.replace(scene, engine='mujoco', step=STEP)


def physics_alone(seconds):
    """Return the wall time of ``seconds`` of mj_step, torques held."""
    plant = scene_plant(_scene())
    m, d, step = plant.model, plant.data, plant.mujoco.mj_step
    steps = int(round(seconds / STEP))
    start = time.perf_counter()
    for _ in range(steps):
        step(m, d)
    return time.perf_counter() - start


def plant_ticks(seconds):
    """Return the wall time of ``seconds`` of plant ticks at 500 Hz."""
    plant = scene_plant(_scene())
    tau = np.zeros(plant.robot.n)
    ticks = int(round(seconds / TICK))
    start = time.perf_counter()
    for _ in range(ticks):
        plant.advance(tau, TICK)
        plant.state()
        plant.applied()
    return time.perf_counter() - start


def closed_loop(seconds):
    """Return the wall time of ``seconds`` of PD + feedforward at 1 kHz."""
    scene = _scene()
    plant = scene_plant(scene)
    control = tracking_controller(SceneDynamics(scene))
    steps = int(round(seconds / STEP))
    start = time.perf_counter()
    for k in range(steps):
        q, qd = plant.state()
        plant.advance(control(k * STEP, q, qd)[0], STEP)
    return time.perf_counter() - start


def ros_loop(seconds):
    """Run make demo's graph once; return the real-time factor it held."""
    import os
    import tempfile
    from .demo import base_domain, run_graph
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    with tempfile.TemporaryDirectory() as logs:
        run = run_graph('panda_mujoco_full', 'bench', True, seconds,
                        base_domain(1), logs, 'mujoco')
    return run['real_time_factor']


CASES = (('MuJoCo physics alone (mj_step, 1 kHz)', physics_alone),
         ('plant ticks as the node steps it (500 Hz, 2 steps each)',
          plant_ticks),
         ('closed loop offline (PD + feedforward every 1 ms)', closed_loop))


def run(seconds, rounds):
    """Return {label: best real-time factor} over ``rounds`` rounds."""
    best = {label: 0.0 for label, _ in CASES}
    closed_loop(0.05)       # compile or load the kernels first
    for _ in range(rounds):
        for label, fn in CASES:     # side by side, alternating
            best[label] = max(best[label], seconds / fn(seconds))
    return best


def main(argv=None):
    """Print the table; optionally write it as JSON."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[1])
    parser.add_argument('--quick', action='store_true',
                        help='1 s of simulated time a case, 2 rounds')
    parser.add_argument('--seconds', type=float, default=5.0,
                        help='simulated seconds a case and round (5)')
    parser.add_argument('--rounds', type=int, default=5,
                        help='rounds, the best kept (5)')
    parser.add_argument('--loop', action='store_true',
                        help="also run make demo's graph over ROS 2 and "
                             'report the real-time factor it held')
    parser.add_argument('--loop-seconds', type=float, default=2.5,
                        help='simulated seconds of the ROS 2 loop (2.5)')
    parser.add_argument('--json', metavar='FILE',
                        help='write the figures to FILE')
    args = parser.parse_args(argv)
    seconds, rounds = (1.0, 2) if args.quick else (args.seconds,
                                                   args.rounds)
    if not (seconds > 0 and rounds > 0):
        parser.error('--seconds and --rounds must be > 0')
    best = run(seconds, rounds)
    print(f'MuJoCo plant, bundled Panda (7 joints), physics step {STEP} s; '
          f'best of {rounds} rounds of {seconds:g} s simulated')
    print(f'{"case":<58} real-time factor')
    for label, rtf in best.items():
        print(f'{label:<58} {rtf:>8.1f}')
    loop = None
    if args.loop:
        loop = ros_loop(args.loop_seconds)
        print(f'{"closed loop over ROS 2, paced at real time (demo graph)":<58}'
              f' {loop:>8.2f}')
    if args.json:
        with open(args.json, 'w', encoding='utf-8') as fh:
            json.dump({'step': STEP, 'seconds': seconds, 'rounds': rounds,
                       'real_time_factor': best, 'ros_loop': loop}, fh,
                      indent=1)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
