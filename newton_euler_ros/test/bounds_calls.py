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
Every public float64 call of the core once, on the robot files given.

    NUMBA_BOUNDSCHECK=1 python bounds_calls.py URDF[:BASE:TIP] ...

(a whole tree, or the chain from BASE to TIP, which has a tool frame)

Run by ``core/test_bounds_checked.py`` with numba's bounds checks on: an
offset off by one or an argument shorter than the recursion reads raises
``IndexError`` instead of reading the neighbouring memory.  Prints one
line per call, ``ok`` or ``FAIL <error>``, and exits 1 if any failed.
"""
import sys
import warnings

import numpy as np


def calls(core, m, rng):
    """Yield (name, thunk) for each public call on model ``m``."""
    n = m.n
    q, qd, qdd = rng.normal(size=(3, n))
    Q, QD, QDD = rng.normal(size=(3, 3, n))
    links = list(m.link_frames or {})
    wrenches = {links[-1]: rng.normal(size=6), links[len(links) // 2]:
                rng.normal(size=6)} if links else None
    wrench = rng.normal(size=6) if m.tool_body is not None else None
    yield 'gravity_torques', lambda: core.gravity_torques(m, q)
    yield 'inverse_dynamics', lambda: core.inverse_dynamics(m, q, qd, qdd)
    yield 'velocity_products', lambda: core.velocity_products(m, q, qd)
    yield 'mass_matrix', lambda: core.mass_matrix(m, q)
    yield 'coriolis_matrix', lambda: core.coriolis_matrix(m, q, qd)
    yield 'forward_dynamics', lambda: core.forward_dynamics(m, q, qd, qdd)
    yield 'batches', lambda: (core.inverse_dynamics_batch(m, Q, QD, QDD),
                              core.gravity_torques_batch(m, Q),
                              core.mass_matrix_batch(m, Q))
    yield 'derivatives', lambda: (
        core.inverse_dynamics_derivatives(m, q, qd, qdd),
        core.forward_dynamics_derivatives(m, q, qd, qdd),
        core.inverse_dynamics_derivatives_batch(m, Q, QD, QDD, threads=2),
        core.forward_dynamics_derivatives_batch(m, Q, QD, QDD, threads=2))
    if wrenches:
        for frame in ('base', 'link'):
            yield f'link wrenches ({frame})', lambda frame=frame: (
                core.inverse_dynamics(m, q, qd, qdd, wrenches, frame),
                core.forward_dynamics(m, q, qd, qdd, wrenches, frame),
                core.inverse_dynamics_derivatives(m, q, qd, qdd, wrenches,
                                                  frame))
    if wrench is not None:
        for frame in ('base', 'end_effector'):
            yield f'tool wrench ({frame})', lambda frame=frame: (
                core.inverse_dynamics(m, q, qd, qdd, wrench, frame),
                core.forward_dynamics(m, q, qd, qdd, wrench, frame),
                core.jacobian(m, q))


def main(paths):
    from newton_euler_ros import core
    failed = 0
    for given in paths:
        path, *chain = given.split(':')
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            m = core.load_urdf(path, *chain)
        for name, thunk in calls(core, m, np.random.default_rng(0)):
            try:
                thunk()
                print(f'{m.name}: {name}: ok', flush=True)
            except Exception as exc:        # the report is the point
                failed += 1
                print(f'{m.name}: {name}: FAIL {type(exc).__name__}: {exc}',
                      flush=True)
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
