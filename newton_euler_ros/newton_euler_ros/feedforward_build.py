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
A FeedforwardComputer for a model and a node's parameters, free of ROS.

Everything the node builds off the hot path, at start-up, when a
``robot_description`` arrives or when the payload changes: the payload
merged into the model (:func:`payload_model`, checked by
:func:`check_payload`), the joint order, the torque bounds, the wrench
input, the reference and, on a whole robot (:func:`is_whole_robot`), the
joint-state merger; then the computer, warm (:func:`build_computer`).
"""
import dataclasses
import math

import numpy as np

from .core.inertia import format_moments, inertia_matrix, principal_moments
from .core.model import with_payload
from .core.text import clip
from .feedforward import FeedforwardComputer
from .joint_inputs import JointOrder, ReferenceTrajectory
from .safety import effort_bounds
from .whole_robot import followers_of, JointStateMerger
from .wrenches import wrench_input

#: the payload's parameters, in the order of :func:`payload_model`
PAYLOAD = ('payload.mass', 'payload.com', 'payload.inertia', 'payload.link')


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


def is_whole_robot(model, tip_link=''):
    """Say whether a model is a whole robot (a URDF tree, no tip link)."""
    report = model.info.get('urdf') if isinstance(model.info, dict) \
        else None
    return bool(report and report.get('tree') and not tip_link)


def locked_joints(model, p, commanded):
    """Return {joint: position} of joint_states.lock; ValueError."""
    names = list(p['joint_states.lock'])
    values = list(p['joint_states.lock_positions'])
    if len(names) != len(values):
        raise ValueError(
            f'joint_states.lock_positions: {len(values)} values for the '
            f'{len(names)} joints of joint_states.lock')
    for name, value in zip(names, values):
        if name not in model.joint_names:
            follower = name in model.moving_joints
            raise ValueError(
                f'joint_states.lock: {name!r} is '
                + ('a mimic joint: lock its leader' if follower else
                   f'not a joint of {model.name} (its joints: '
                   f'{clip(list(model.joint_names), 300)})'))
        if name in commanded:
            raise ValueError(f'joint_states.lock: {name!r} is commanded '
                             f'(joints): a commanded joint cannot be locked')
        if not math.isfinite(value):
            raise ValueError(f'joint_states.lock_positions: {name!r} at '
                             f'{value!r}: must be finite')
    return dict(zip(names, values))


def build_computer(params, mode, model, payload, scene=None, previous=None):
    """
    Joint order, wrench input and a warm computer for a model.

    ``params`` are a node's parameters, ``mode`` its torque mode,
    ``payload`` the values of :data:`PAYLOAD`, merged into ``model`` (the
    model without it, kept as ``ff.bare_model``).  With ``previous`` (same
    joints) its joint order, wrench, reference and merger carry over, so a
    payload change rebuilds only the model and its workspace.  Bad
    settings raise ValueError.
    """
    p = params
    bare = model
    model = payload_model(bare, *payload)
    if scene is not None:
        scene = dataclasses.replace(scene, model=model)
    whole = is_whole_robot(bare, p['tip_link']) and scene is None
    if previous is not None:
        order, wrench = previous.order, previous.wrench
        reference = previous.reference
    else:
        order = JointOrder(model.joint_names, p['joints'] or None,
                           p['limits.max_names'], subset=whole,
                           followers=followers_of(model))
        wrench = None
        reference = (ReferenceTrajectory(order)
                     if mode == 'full' else None)
    # torque bounds: the parameter (output order), the robot's, or
    # derived from the model (with its payload)
    override = p['limits.effort']
    if len(override) and len(override) != model.n:
        raise ValueError(f'limits.effort: must have {model.n} values '
                         f'(one per joint), got {len(override)}')
    if len(override):
        model_order = np.empty(model.n)
        model_order[order.to_output] = override
        override = model_order
    bounds, sources = effort_bounds(model, override)
    if wrench is None:
        wrench = wrench_input(p, model, bounds, whole)
    ff = FeedforwardComputer.from_parameters(
        p, model, order, wrench, bounds, sources, reference, scene,
        mode, bare_model=bare,
        bare_scene=scene if previous is None else previous.bare_scene)
    if previous is not None:
        ff.merger = previous.merger
    elif whole:
        ff.merger = JointStateMerger(
            model, order.output_joints[:order.command],
            p['joint_states.hold'], p['joint_states.mimic_tolerance'],
            p['limits.max_names'],
            locked_joints(model, p, order.output_joints[:order.command]))
    return ff
