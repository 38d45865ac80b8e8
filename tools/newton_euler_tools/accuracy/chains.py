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
Seeded random serial chains for the accuracy and scaling measurements.

A chain mixes revolute and prismatic joints, arbitrary twists, offsets
and physically valid inertias (positive definite, triangle inequality),
with a tool frame and gravity along -z.  The same (n, seed) always gives
the same chain.
"""
import math

from newton_euler_ros.core.model import make_model, pose_matrix, rpy_matrix
import numpy as np


def random_inertia(rng, mass, size):
    """Return a random physical inertia about the com (a rotated box)."""
    second = mass * rng.uniform(0.05, 1.0, 3) * size ** 2
    principal = np.array([second[1] + second[2], second[0] + second[2],
                          second[0] + second[1]])
    R = rpy_matrix(*rng.uniform(-math.pi, math.pi, 3))
    return R @ np.diag(principal) @ R.T


def random_chain(n, seed=0, convention='standard', prismatic=0.2,
                 masses=None, name=None, rng=None):
    """
    Return a random n-link chain, about a fifth of its joints prismatic.

    Links are 0.05-0.3 m with 0.5-5 kg (or the given ``masses``), so a
    100-link chain is long and heavy, as the stress of a long chain should
    be.  The draws come from ``rng`` when given (the stress tests pass
    their own), else from a generator seeded by (n, seed).
    """
    if rng is None:
        rng = np.random.default_rng([n, seed])
    types = ['prismatic' if rng.random() < prismatic else 'revolute'
             for _ in range(n)]
    alpha = rng.choice([0.0, math.pi / 2, -math.pi / 2, 1.0], n)
    alpha = np.where(alpha == 1.0, rng.uniform(-math.pi, math.pi, n), alpha)
    mass = (rng.uniform(0.5, 5.0, n) if masses is None
            else np.asarray(masses, dtype=float))
    size = rng.uniform(0.05, 0.3, n)
    inertia = np.array([random_inertia(rng, m, s) for m, s in zip(mass, size)])
    return make_model(
        name or f'chain{n}', convention, [f'j{k}' for k in range(n)], types,
        a=rng.uniform(-0.3, 0.3, n), alpha=alpha,
        d=rng.uniform(-0.3, 0.3, n), theta=rng.uniform(-math.pi, math.pi, n),
        mass=mass, com=rng.uniform(-0.15, 0.15, (n, 3)), inertia=inertia,
        gravity=(0.0, 0.0, -9.81),
        tool=pose_matrix(rng.uniform(-0.1, 0.1, 3),
                         rng.uniform(-math.pi, math.pi, 3)))


def random_states(model, count, seed=0):
    """
    Return ``count`` states (q, qd, qdd) within the joint limits.

    Revolute angles are uniform in the limits (or [-pi, pi]); prismatic
    positions in the limits (or [-0.5, 0.5] m); velocities and
    accelerations standard normal.
    """
    rng = np.random.default_rng([model.n, seed, 7])
    n = model.n
    lo = np.empty(n)
    hi = np.empty(n)
    for j in range(n):
        lim = model.limits[j] if j < len(model.limits) else {}
        default = math.pi if model.joint_types[j] == 'revolute' else 0.5
        lo[j] = lim.get('lower', -default)
        hi[j] = lim.get('upper', default)
    return [(rng.uniform(lo, hi), rng.normal(size=n), rng.normal(size=n))
            for _ in range(count)]
