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
Tests of the tools (tools/newton_euler_tools): benchmarks, report, demos.

They run in ``make test`` with the package's tests (``pytest.ini``'s
testpaths) and share the package's test helpers (``ros_harness``), whose
folder is put on sys.path here.
"""
import os
import sys

HELPERS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), 'newton_euler_ros', 'test')
if HELPERS not in sys.path:
    sys.path.insert(0, HELPERS)
