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
The generalized-momentum observer: external torque, wrench and contact.

The modules, by what they hold:

- ``momentum``: the observer itself (:class:`MomentumObserver`, the
  residual's step :func:`observer_step`, :func:`observe_recording` over
  a whole recording, the drive terms taken out of the torques, the
  static friction allowance);
- ``contact``: the contact test on the residual, with hysteresis, and the
  rest reference (a push on a resting arm, felt early);
- ``motion``: the contact threshold that grows with a joint's speed and
  acceleration;
- ``thresholds``: thresholds suggested from a free-motion recording;
- ``wrench``: one end effector's wrench from the residual (damped least
  squares);
- ``wrenches``: the wrenches of several end effectors of a tree,
  estimated jointly.

Here are their public names; the modules import one another (``momentum``
uses ``contact`` and ``wrench``, ``contact`` uses ``motion``,
``thresholds`` uses ``contact``), never this package.
"""
from .contact import contact_step, ContactState, initial_contact, RestState
from .momentum import (ALLOWANCE_HOLD, drive_options, drive_terms,
                       DUPLICATE, initial_state, MomentumObserver,
                       observe_recording, observer_step, ObserverRecording,
                       ObserverState, RESTARTED, STARTED, UPDATED)
from .thresholds import beyond_friction, suggest_thresholds
from .wrench import external_wrench, felt_directions
from .wrenches import external_wrenches, own_joints, separability, Wrenches

__all__ = [
    'ALLOWANCE_HOLD', 'ContactState', 'DUPLICATE', 'MomentumObserver',
    'ObserverRecording', 'ObserverState', 'RESTARTED', 'RestState',
    'STARTED', 'UPDATED', 'Wrenches', 'beyond_friction', 'contact_step',
    'drive_options', 'drive_terms', 'external_wrench', 'external_wrenches',
    'felt_directions', 'initial_contact', 'initial_state',
    'observe_recording', 'observer_step', 'own_joints', 'separability',
    'suggest_thresholds',
]
