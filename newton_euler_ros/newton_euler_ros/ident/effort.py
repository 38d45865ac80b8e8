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
What a recording's efforts are: joint torques, or proportional to them.

``JointState.effort`` is a joint torque for some drivers (Franka: the
link-side torque; KUKA FRI: the measured torque) and a motor current for
others (UR's ROS 2 driver by default, Dynamixel-based arms), the torque
being K_j times it with an unknown constant per joint.  Fitting torques
to currents as if they were torques gives a model scaled by 1/K: a
plausible-looking URDF with every mass ten times too small.

The nominal model tells them apart.  Per joint j, the least-squares ratio
K_j of the nominal torque to the effort, e_j = tau_nom,j / K_j, both
less what the joint's drive terms (viscous and Coulomb friction, offset,
armature) explain, since a published URDF has no friction but the effort
has: K_j is about 1 when the efforts are torques the nominal model
roughly predicts, about the torque constant when they are currents.  A
joint counts when the two agree in shape (squared correlation at least
``MIN_EXPLAINED``: a joint whose nominal torque is small or wrong says
nothing); the efforts are refused as torques when at least
half of the joints that count are outside ``TORQUE_BAND``, and as
anything proportional to torque when a joint that counts has a negative
ratio (the driver's sign convention, or joints swapped).

Here on the reduced recording (``reduce.Reduced``: inner products of
columns are inner products of their images by R); on samples, and the
decision, in ``core.effort_units``.
"""
import numpy as np

from .reduce import IdentificationError
from ..core.effort_units import (CURRENT_FIX, describe,  # noqa: F401
                                 MIN_EXPLAINED, sample_ratios, TORQUE_BAND,
                                 URDF_FIX)


def ratios(red, u, drive_columns):
    """
    Per joint: (K, explained) of the least-squares ratio.

    ``red`` a ``reduce.Reduced`` whose last column is the effort; ``u``
    the column coefficients giving the nominal torque (without the
    effort); ``drive_columns(j)`` the indices of joint j's drive columns.
    Both the nominal torque t and the effort e are taken less their
    projection on the drive columns (t1, e1); the effort is regressed on
    the torque, e1 = t1 / K (so noise and stiction in the effort do not
    bias K), and ``explained`` is the squared correlation of t1 and e1.
    """
    n = red.n
    K = np.zeros(n)
    explained = np.zeros(n)
    for j in range(n):
        Rj = red.R[j]
        if Rj.shape[0] == 0:
            continue
        Q, _ = np.linalg.qr(Rj[:, drive_columns(j)])
        t = Rj[:, :-1] @ u
        e = Rj[:, -1]
        t = t - Q @ (Q.T @ t)
        e = e - Q @ (Q.T @ e)
        te, tt, ee = float(t @ e), float(t @ t), float(e @ e)
        if not (tt > 0 and ee > 0 and te != 0):
            continue
        K[j] = tt / te
        explained[j] = te * te / (tt * ee)
    return K, explained


def check(label, names, K, explained, mode, urdf=None, fix=CURRENT_FIX):
    """
    Raise IdentificationError (one line) when the effort cannot be ``mode``.

    The line is :func:`core.effort_units.describe`'s.
    """
    line = describe(label, names, K, explained, mode, urdf, fix)
    if line is not None:
        raise IdentificationError(line)


def mismatch(label, names, tau, effort, qd, drives, urdf, fix):
    """
    Return the one line saying the efforts are not what the URDF says.

    ``tau`` the model's torque (N m) at the samples, ``effort`` the
    recorded efforts there; the URDF's drives (``drives``, None: none)
    say torques, or currents times their ``torque_constant``.  None when
    the efforts can be that (:func:`check`, ``fix`` ending the line).
    """
    given = drives is not None and drives.torque_constant is not None
    meas = drives.effort_to_torque(effort) if given else effort
    K, explained = sample_ratios(tau, meas, qd)
    return describe(label, names, K, explained,
                    'given' if given else 'torque', urdf, fix)


def recording_mismatch(label, model, stamps, q, qd, effort, urdf, fix):
    """
    :func:`mismatch` on a recording (stamps, q, qd or None, effort).

    The state filtered as identification filters it (``signals.prepare``),
    the model's torque with its drive terms (``torques.predict``); None when
    the efforts can be what the model's URDF says, or the recording is
    too short to tell.
    """
    from ..core.drives import model_drives
    from .signals import prepare
    from .torques import predict
    try:
        prep = prepare(stamps, q, qd, effort)
    except ValueError:              # too short or too slow to filter
        return None
    if prep is None:
        return None
    drives = model_drives(model)
    tau = predict(model, drives, prep.q, prep.qd, prep.qdd)
    return mismatch(label, model.joint_names, tau, prep.effort, prep.qd,
                    drives, urdf, fix)
