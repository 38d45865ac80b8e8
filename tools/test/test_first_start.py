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
The first start on a whole robot, as a user starts the node; latency.

TIAGo Pro from ``robot_file`` with the observer, states of its 33 joints
at 100 Hz from the moment the process starts: the kernels come from the
cache ``make setup`` filled (no warning, a 'kernels ready' line), the
first torques come, and every state after them is answered.  The time
is printed by the tool, not judged here.
"""
import subprocess
import sys

import pytest

pytest.importorskip('rclpy')

from ros_harness import domain_id, ros_env  # noqa: E402, I100

pytestmark = pytest.mark.ros


def test_first_start_loads_the_kernels_and_answers_every_state():
    proc = subprocess.run(
        [sys.executable, '-m', 'newton_euler_tools.first_start',
         '--observer'], env=ros_env(domain_id(19)), capture_output=True,
        text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    out = proc.stdout
    assert 'tiago_pro (33 moving joints), observer on' in out, out
    assert '(loaded from the cache)' in out, out
    assert 'not compiled ahead' not in out, out
    answered, sent = out.split('then ')[1].split(' answered')[0].split(' of ')
    assert int(answered) == int(sent) >= 90, out
    # the latency phase at 500 Hz, and the node's own time per update
    # from /diagnostics (figures printed, not judged)
    assert 'at 500 Hz: ' in out and "the node's time per update " \
        '(/diagnostics) median ' in out, out
