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
What an identification's result says that its tables do not.

Notes ``identify`` prints after the fit: masses the recordings hardly
saw that still moved far from the prior, and torque constants that say
the efforts were torques already.
"""
import math

import numpy as np

from ..core.regressor import N_INERTIAL
from ..core.text import clip

#: a body's mass this many times (or this fraction of) the prior's is noted
FAR = 3.0
#: identified constants this close to 1 on average: the efforts are torques
TORQUE_LIKE = (0.8, 1.25)


def far_masses(model, result):
    """
    Return a note on bodies whose mass moved far from the prior's, or [].

    The recordings see some masses only weakly (where no joint's gravity
    or motion turns on them alone): the fit keeps every body physical
    and the torques right, but such a mass may go anywhere that fits.
    """
    names = model.info['urdf']['links']
    m = result.theta[0:N_INERTIAL * model.nb:N_INERTIAL]
    m0 = result.theta0[0:N_INERTIAL * model.nb:N_INERTIAL]
    far = [f'{names[k]} {m[k]:.3g} kg (prior {m0[k]:.3g})'
           for k in range(model.nb)
           if m0[k] > 0.0 and not 1.0 / FAR <= m[k] / m0[k] <= FAR]
    if not far:
        return []
    return [f"masses more than {FAR:g}x from the prior's: "
            + clip(', '.join(far), 400)
            + f'; in all {m.sum():.3g} kg (prior {m0.sum():.3g}): the '
            f'recordings hardly see them; the torques are right, these '
            f'masses are not (docs/identification.md)']


def torque_like(result):
    """Return a note when identified constants say efforts are torques."""
    if result.constants != 'identified':
        return []
    seen = [k for j, k in enumerate(result.torque_constant)
            if j not in result.undetermined_k]
    mean = float(np.exp(np.mean(np.log(seen)))) if seen else math.nan
    if not TORQUE_LIKE[0] <= mean <= TORQUE_LIKE[1]:
        return []
    return [f'the torque constants are {mean:.2f} N m per effort unit on '
            f'average: the efforts may be torques already (then identify '
            f'without --effort current)']
