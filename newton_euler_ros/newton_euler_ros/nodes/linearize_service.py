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
inverse_dynamics_node's ``~/linearize``: A, B and their discrete pair.

:func:`linearize` turns a request's named values into the node's
dynamics linearised at that state (``core.linearize.state_space``) with
the node's model (payload included), its drive terms, its latest wrench
and its gravity setting, exactly the dynamics ``~/compute_dynamics``
reports; :func:`answer_linearize` fills the ``Linearize`` response in the
output joint order.  The request's state is read and checked as
``~/compute_dynamics`` reads it (``FeedforwardComputer.request_state``,
``JointOrder.gather``): missing joints named, NaN refused, an empty
position the latest measured state.  Every rejection raises
``InputRejected``; the node answers it with ``success: false``.
"""
import math

import numpy as np

from ..core.drives import DEFAULT_COULOMB_WIDTH, Drives
from ..core.linearize import state_space
from ..joint_inputs import InputRejected


def linear_drives(ff):
    """
    Return the drive terms of a computer's dynamics, or None.

    The node's compensated drives (``drives.compensate``), and a scene's
    friction and rotor inertia when it enables them (its Coulomb friction
    by the library's smooth sign, tanh(qd / 0.02): sign(qd) has no
    derivative at rest).
    """
    dyn = ff.dyn
    n = ff.model.n
    zero = np.zeros(n)
    friction, armature = dyn.effects.friction, dyn.effects.armature
    if not (friction or armature):
        return ff.drives
    scene = Drives(dyn.viscous if friction else zero,
                   dyn.coulomb if friction else zero, zero,
                   dyn.armature if armature else zero,
                   np.full(n, DEFAULT_COULOMB_WIDTH))
    if ff.drives is None:
        return scene
    if friction and np.any(ff.drives.coulomb) and np.any(dyn.coulomb):
        raise InputRejected(
            'malformed', 'the scene and drives.compensate both give '
            'Coulomb friction: ~/linearize takes one of them')
    own = ff.drives
    coulomb, width = ((own.coulomb, own.coulomb_width)
                      if np.any(own.coulomb) else
                      (scene.coulomb, scene.coulomb_width))
    return Drives(own.viscous + scene.viscous, coulomb, own.offset,
                  own.armature + scene.armature, width)


def linearize(ff, names, position, velocity, effort, acceleration,
              time_step, now):
    """
    Return the node's dynamics linearised at a request's state.

    ``names`` label ``position``, ``velocity`` and one of ``effort`` and
    ``acceleration`` (sequences, empty when not given; see
    ``Linearize.srv``); ``time_step`` (s) > 0 adds the zero-order-hold
    pair.  Returns a ``core.linearize.StateSpace`` in model order, or
    raises InputRejected (or a NewtonEulerError of the dynamics).
    """
    if not ff.dyn.effects.velocity_products:
        raise InputRejected(
            'malformed', 'the scene leaves out the velocity products; '
            '~/linearize linearises the whole dynamics')
    if len(effort) and len(acceleration):
        raise InputRejected(
            'malformed', 'effort and acceleration both given: the point '
            'takes one of them (the other follows)')
    if not math.isfinite(time_step) or time_step < 0.0:
        raise InputRejected(
            'malformed' if math.isfinite(time_step) else 'non_finite',
            f'time_step must be finite and >= 0 s, got {time_step!r}')
    q, qd = ff.request_state(names, position, velocity)
    gather = ff.order.gather
    tau = gather(names, 'effort', effort) if len(effort) else None
    qdd = (gather(names, 'acceleration', acceleration)
           if len(acceleration) else None)
    w, frame = ff.wrench.current(now)
    lin = state_space(ff.model, q, qd, tau=tau, qdd=qdd,
                      dt=time_step or None,
                      wrench=w if ff.dyn.effects.wrench else None,
                      wrench_frame=frame, drives=linear_drives(ff),
                      ws=ff.ws, gravity=ff.dyn.effects.gravity)
    parts = [lin.A, lin.B, lin.tau0, lin.qdd0] + (
        [lin.Ad, lin.Bd] if lin.Ad is not None else [])
    if not all(np.isfinite(x).all() for x in parts):
        raise InputRejected('non_finite', 'dynamics produced a non-finite '
                            'value')
    return lin


def answer_linearize(response, ff, request, now):
    """
    Fill a Linearize response in output order (x = (q, qd) of its names).

    Raises what :func:`linearize` raises (the response then is the
    caller's to fill with ``inverse_dynamics_reports.failed``).
    """
    lin = linearize(ff, request.name, request.position, request.velocity,
                    request.effort, request.acceleration, request.time_step,
                    now)
    out = ff.order.to_output
    x = np.concatenate([out, out + ff.model.n])
    response.success = True
    response.message = ''
    response.name = list(ff.output_names)
    response.state_matrix = lin.A[np.ix_(x, x)].ravel().tolist()
    response.input_matrix = lin.B[np.ix_(x, out)].ravel().tolist()
    if lin.Ad is not None:
        response.discrete_state_matrix = lin.Ad[np.ix_(x, x)].ravel(
        ).tolist()
        response.discrete_input_matrix = lin.Bd[np.ix_(x, out)].ravel(
        ).tolist()
    response.effort = lin.tau0[out].tolist()
    response.acceleration = lin.qdd0[out].tolist()
    return response
