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
Ground truth: the Newton-Euler recursion at 50 significant digits.

:class:`~newton_euler_ros.core.highprec.HighPrecisionModel` runs the very
source of the float64 kernels over mpmath numbers, taking the model's
float64 parameters and the float64 states as exact.  Its results, rounded
once to float64, are the truth every method here is measured against
(their own rounding is 1e-50, far below any float64 error).
"""
from newton_euler_ros.core.highprec import HighPrecisionModel

# FD: the accelerations for the state's qdd vector taken as the torques
QUANTITIES = ('tau', 'D', 'C', 'g', 'FD')


class GroundTruth:
    """tau, D, C, g and FD of one model at a list of states, in mpmath."""

    def __init__(self, model, states, dps=50):
        self.model = model
        self.states = list(states)
        self.hp = HighPrecisionModel(model, dps=dps)
        self._cache = {}

    def value(self, quantity, k):
        """Return the exact ``quantity`` at state k, an object array."""
        key = (quantity, k)
        if key not in self._cache:
            q, qd, qdd = self.states[k]
            hp = self.hp
            if quantity == 'tau':
                out = hp.inverse_dynamics(q, qd, qdd)
            elif quantity == 'D':
                out = hp.mass_matrix(q)
            elif quantity == 'C':
                out = hp.coriolis_matrix(q, qd)
            elif quantity == 'g':
                out = hp.inverse_dynamics(q)
            elif quantity == 'FD':
                # D and the bias at 50 digits, solved by LU: independent of
                # both float64 methods
                out = hp.forward_dynamics(q, qd, qdd, method='cholesky')
            else:
                raise ValueError(f'unknown quantity {quantity!r}; one of '
                                 f'{", ".join(QUANTITIES)}')
            self._cache[key] = out
        return self._cache[key]

    def evaluate_all(self):
        """Evaluate every quantity at every state (the slow part)."""
        for quantity in QUANTITIES:
            for k in range(len(self.states)):
                self.value(quantity, k)
