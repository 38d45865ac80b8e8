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
Tests of newton_euler_ros, in the layers of the package.

    core/     model, kernels, dynamics, robot files, URDF, precision
    sim/      scenes and simulation
    nodes/    the nodes (over DDS), their ROS-free helpers, the CLI
    linters/  flake8, pep257, copyright (over this package and tools/)

The helpers shared by the folders stay here: ``ros_harness`` (child
nodes on loopback DDS, a probe node) and ``reference_dynamics`` (the
independent Euler-Lagrange oracle).  This directory is put on sys.path so
that tests in any folder import them by name, whichever way pytest is
started (``make test`` from the repository root, or from this package).
"""
import os
import sys

HELPERS = os.path.dirname(os.path.abspath(__file__))
if HELPERS not in sys.path:
    sys.path.insert(0, HELPERS)
