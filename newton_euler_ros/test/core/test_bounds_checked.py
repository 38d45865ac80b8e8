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
The kernels read only what they are given: numba's bounds checks on.

numba does not check indices: an offset off by one, or an argument
shorter than what a recursion reads, silently reads the neighbouring
memory (``gravity_torques`` once passed a 6-entry row as the joint
velocities of Centauro's 39 joints; the result matched Pinocchio only
because what was read there was not used).  Here every public call of
the core (``bounds_calls.py``) runs in a child process with
``NUMBA_BOUNDSCHECK=1`` on Centauro's whole tree (branches and mimic
joints, link wrenches in both axes) and on the UR5 chain (the tool
wrench in both axes), where any such read raises ``IndexError``.

The checked kernels are other machine code than the fast ones, so they
are cached in their own directory beside numba's (``...-boundscheck``):
compiled once per change of the kernels' sources (a few minutes), then
loaded.
"""
import os
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(os.path.dirname(HERE), 'bounds_calls.py')
ROBOTS = ('centauro_description/urdf/centauro.urdf',
          'ur_description/urdf/ur5_robot.urdf')
CHAINS = ('', ':base_link:tool0')    # the UR5 as a chain: a tool frame


def _cache_dir():
    base = os.environ.get('NUMBA_CACHE_DIR') or os.path.join(
        os.environ.get('XDG_CACHE_HOME') or os.path.expanduser('~/.cache'),
        'newton_euler_ros', 'numba')
    return base.rstrip(os.sep) + '-boundscheck'


@pytest.mark.slow
def test_every_call_reads_within_its_arguments():
    from newton_euler_tools.peers import example_robot_urdf
    paths = [example_robot_urdf(r) + c for r, c in zip(ROBOTS, CHAINS)]
    env = dict(os.environ, NUMBA_BOUNDSCHECK='1',
               NUMBA_CACHE_DIR=_cache_dir())
    res = subprocess.run([sys.executable, SCRIPT, *paths], env=env,
                         capture_output=True, text=True, timeout=1500)
    lines = res.stdout.splitlines()
    failed = [x for x in lines if ': FAIL ' in x]
    assert not failed and res.returncode == 0, (
        '\n'.join(failed) or res.stderr[-3000:])
    # every call ran, on both robots (a call that is not reached checks
    # nothing)
    assert sum(x.startswith('centauro: ') for x in lines) >= 10, lines
    assert any('tool wrench (end_effector): ok' in x for x in lines), lines
