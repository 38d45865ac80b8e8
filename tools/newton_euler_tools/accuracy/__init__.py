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
What accuracy costs in time: the measured accuracy/speed report.

    python -m newton_euler_tools.accuracy [--quick] [--out DIR] [--no-peers]

Every figure pairs a time (microseconds per call, measured in this run)
with an error against ground truth: the same Newton-Euler recursion
evaluated by :mod:`newton_euler_ros.core.highprec` at 50 significant
digits from the exact float64 inputs.  Modules:

- :mod:`.chains`: seeded random DH chains (6, 30, 100 links, ...);
- :mod:`.truth`: the ground truth of tau, D, C and g at given states;
- :mod:`.arithmetic`: float64 vs float32, CRBA vs n recursions for D,
  finite differences of D vs the exact C, and the peers, per robot;
- :mod:`.scaling`: cost growth with the number of links;
- :mod:`.scenes`: effect subsets, single vs batched, feedforward at the
  desired vs the measured state, integrators and step sizes;
- :mod:`.plots` and :mod:`.report`: the PNGs, the terminal table and
  ``docs/accuracy-vs-time.md``.
"""
