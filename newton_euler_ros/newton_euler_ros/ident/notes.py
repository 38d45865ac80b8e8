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
saw that still moved far from the prior, torque constants that say the
efforts were torques already, constants whose common scale only the
nominal model's masses set; and the warning for a validation recording
whose efforts are in another unit than those identified from.
"""
import math

import numpy as np

from ..core.regressor import N_INERTIAL
from ..core.text import clip

#: a body's mass this many times (or this fraction of) the prior's is noted
FAR = 3.0
#: identified constants this close to 1 on average: the efforts are torques.
#: Without a known mass the constants' common scale is the nominal model's
#: masses' (a UR10e's came out 23-30 % low that way), with one 13-18 % high:
#: torques identified as currents come out within a factor of about 1.6 of
#: 1, while a current-sensing arm's constants are 2-15 N m/A (UR 8-13)
TORQUE_LIKE = (1 / 1.6, 1.6)


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


def nominal_scale(result, known_mass):
    """Return a note when only the nominal masses set the constants' scale."""
    if result.constants != 'identified' or known_mass is not None:
        return []
    return ["the torque constants' common scale is weakly determined: the "
            'recordings fit the constants and the inertials scaled together '
            "equally well, so only the nominal model's masses set it, and "
            "every constant is off by as much as they are (a UR10e's came "
            'out 23-30 % low); add --known-mass BAG KG (a recording with a '
            'known mass at the tip) to fix it']


def validation_units(model, path, topic):
    """
    Return a warning when the validation bag's efforts are in another unit.

    The identified ``model``'s torque (its drive terms included) against
    the recording's efforts times the identified constants (as they are
    without), by :func:`core.effort_units.sample_ratios`: near 1 when the
    validation recording is in the unit identified from; about K (or 1/K)
    when one is in motor currents and the other in torques, and then the
    validation table compares different units.
    """
    from .bag import read_joint_states
    from .effort import MIN_EXPLAINED, sample_ratios, TORQUE_BAND
    from .signals import prepare
    from .torques import predict
    from ..core.drives import model_drives
    if path is None:
        return []
    js = read_joint_states(path, model.joint_names, topic)
    prep = prepare(js.stamps, js.q, js.qd, js.effort)
    if prep is None:
        return []
    drives = model_drives(model)
    if drives is None:
        return []
    K, explained = sample_ratios(
        predict(model, drives, prep.q, prep.qd, prep.qdd),
        drives.effort_to_torque(prep.effort), prep.qd)
    counts = explained >= MIN_EXPLAINED
    off = counts & ((K < TORQUE_BAND[0]) | (K > TORQUE_BAND[1]))
    if not counts.any() or off.sum() * 2 < counts.sum():
        return []
    cells = ', '.join(f'{model.joint_names[j]} {K[j]:.3g}'
                      for j in np.flatnonzero(off))
    times = '' if drives.torque_constant is None else ' x the constants'
    return [f'{path} (--validate): its efforts are not in the unit of the '
            f"recordings identified from: the identified model's torque / "
            f'(effort{times}) is {cells} (near 1 expected; one recording in '
            f'motor currents, the other in torques?): its validation table '
            f'compares different units']


def report(model, result, known_mass, validate, topic):
    """[(kind, line)]: what ``identify`` prints after the fit, on stderr."""
    return ([('warning', x) for x in validation_units(result.model,
                                                      validate, topic)]
            + [('note', x) for x in result.notes + far_masses(model, result)
               + torque_like(result) + nominal_scale(result, known_mass)])
