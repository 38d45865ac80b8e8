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
Bodies the fit leaves on the edge of physical consistency read back.

A weakly excited link comes out of the semidefinite fit as a point mass,
a rod or a plate (its pseudo-inertia singular).  Written as mass, centre
of mass and inertia about it, rounding can tip such a body a hair past
the edge, and the URDF ``identify`` wrote would be refused by the
package's own reader (seen on a real KUKA LWR 4+ recording).
"""
import warnings

from newton_euler_ros.core import inverse_dynamics_batch, load_robot
from newton_euler_ros.core.drives import Drives
from newton_euler_ros.core.regressor import (link_parameters, N_DRIVE,
                                             pseudo_inertia, with_parameters)
from newton_euler_ros.core.urdf import inspect_urdf, model_to_urdf
from newton_euler_ros.ident.fit import _clean, CONE_MARGIN, fixed_parts
from newton_euler_ros.ident.urdf_out import identified_urdf
import numpy as np
from scipy.spatial.transform import Rotation


def _edge_body(rng, kind):
    """Return a body whose pseudo-inertia has a zero eigenvalue (or more)."""
    m = rng.uniform(0.5, 5.0)
    c = rng.uniform(-0.4, 0.4, 3)
    s = {'point': [0.0, 0.0, 0.0], 'rod': [0.0, 0.0, 1.0],
         'plate': [0.0, 1.0, 1.0]}[kind] * rng.uniform(1e-4, 1e-2, 3) * m
    R = Rotation.random(random_state=rng).as_matrix()
    second = R @ np.diag(s) @ R.T       # about the centre of mass
    Ic = np.trace(second) * np.eye(3) - second
    return link_parameters(m, c, Ic)


def test_edge_bodies_are_written_inside_and_read_back_without_a_note():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        text = model_to_urdf(load_robot('puma560'))
        model, _, _ = inspect_urdf(text, tip='tool0')
    fixed = fixed_parts(model, text)
    rng = np.random.default_rng(7)
    for trial in range(30):
        kind = ('point', 'rod', 'plate')[trial % 3]
        pi = np.concatenate([_edge_body(rng, kind) for _ in range(model.nb)])
        theta = np.concatenate([pi, np.zeros(N_DRIVE * model.n)])
        clean = _clean(theta, fixed, model.nb, model.n)
        for k in range(model.nb):
            lam = np.linalg.eigvalsh(pseudo_inertia(clean[10 * k:10 * k + 10]))
            assert lam.min() >= 0.99 * CONE_MARGIN * lam.max()
        # the change is of the margin's size: nothing a torque would show
        rng_q = np.random.default_rng(trial)
        Q, QD, QDD = rng_q.normal(size=(3, 20, model.n))
        tau = inverse_dynamics_batch(with_parameters(model, pi), Q, QD, QDD)
        tau_c = inverse_dynamics_batch(
            with_parameters(model, clean[:10 * model.nb]), Q, QD, QDD)
        assert np.abs(tau_c - tau).max() <= 1e-6 * np.abs(tau).max()
        body = identified_urdf(text, model, clean, fixed,
                               Drives.zeros(model.n))
        _, found, _ = inspect_urdf(body, tip='tool0')   # raises if refused
        assert not [f for f in found if 'triangle' in f], (trial, found)
