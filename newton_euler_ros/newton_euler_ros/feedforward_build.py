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
The payload of a node's model, free of ROS.

:func:`check_payload` checks a payload's values, :func:`payload_model`
merges it into a model, off the hot path (start-up, a payload change).
"""
import math

import numpy as np

from .core.inertia import format_moments, inertia_matrix, principal_moments
from .core.model import with_payload


def check_payload(mass, com, inertia6):
    """
    Validate payload values; return (mass, com, 3x3 inertia) or ValueError.

    ``inertia6`` is [Ixx, Iyy, Izz, Ixy, Iyz, Ixz] about the payload's
    centre of mass ``com`` (end-effector frame).
    """
    mass = float(mass)
    com = np.asarray(com, dtype=np.float64).reshape(-1)
    values = np.asarray(inertia6, dtype=np.float64).reshape(-1)
    if not (mass >= 0.0 and math.isfinite(mass)):
        raise ValueError(f'payload.mass: must be >= 0 and finite, got {mass}')
    if com.shape != (3,) or not np.isfinite(com).all():
        raise ValueError(f'payload.com: must be 3 finite numbers, got '
                         f'{com.tolist()}')
    if values.shape != (6,) or not np.isfinite(values).all():
        raise ValueError(f'payload.inertia: must be 6 finite numbers, got '
                         f'{values.tolist()}')
    inertia = inertia_matrix(*values)
    eig, valid = principal_moments(inertia)
    if not valid:
        raise ValueError(f'payload.inertia: not positive semi-definite '
                         f'(principal moments {format_moments(eig)})')
    return mass, com, inertia


def payload_model(model, mass, com, inertia6, link=''):
    """
    Return the model with a payload on the end effector, or ValueError.

    Merged into the last link (or the body carrying ``link``, a link of a
    URDF model) by :func:`~newton_euler_ros.core.model.with_payload`, the
    scenes' code; no payload (all zeros) returns ``model`` itself.
    """
    mass, com, inertia = check_payload(mass, com, inertia6)
    if mass == 0.0 and not inertia.any():
        return model
    return with_payload(model, mass, com, inertia, link or None)
