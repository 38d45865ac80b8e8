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
A model's joint torques at prepared states: rigid body plus drive terms.

What a URDF says the efforts should be, compared with a recording's
(``effort.recording_mismatch``, ``newton-euler replay``).  It imports
nothing of ``ident``: the steps above it (``effort``, ``fit``) import it.
"""


def predict(model, drives, Q, QD, QDD):
    """Model torques (rigid body + drives) at (m, n) states."""
    from ..core import inverse_dynamics_batch
    tau = inverse_dynamics_batch(model, Q, QD, QDD)
    if drives is not None:
        tau += drives.torques(QD, QDD)
    return tau
