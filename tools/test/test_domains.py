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
The ROS tools start from the user's ROS_DOMAIN_ID when it is set.

``make demo``, ``make demo-pick`` and ``make latency`` use consecutive
domain ids, one per run or phase: from ROS_DOMAIN_ID when set, else their
documented defaults (1 + pid % 100 for the demos, 64 for the latency
benchmark).  An unusable ROS_DOMAIN_ID stops them at once with exit
status 2 and a line that names it.  (test_demo.py and
test_latency_bench.py check the ids the runs actually use.)
"""
import os
import subprocess
import sys

from newton_euler_tools.processes import first_domain, MAX_DOMAIN
import pytest


def test_first_domain_reads_ros_domain_id(monkeypatch):
    monkeypatch.delenv('ROS_DOMAIN_ID', raising=False)
    assert first_domain(64, 4) == 64
    monkeypatch.setenv('ROS_DOMAIN_ID', '')
    assert first_domain(7) == 7
    for value, count in (('0', 2), ('42', 4), (str(MAX_DOMAIN - 3), 4)):
        monkeypatch.setenv('ROS_DOMAIN_ID', value)
        assert first_domain(64, count) == int(value)
    for value, count in (('-1', 1), ('x', 1), ('1.5', 1),
                         (str(MAX_DOMAIN), 2)):
        monkeypatch.setenv('ROS_DOMAIN_ID', value)
        with pytest.raises(ValueError, match='ROS_DOMAIN_ID='):
            first_domain(64, count)


@pytest.mark.parametrize('module', ['demo', 'demo_pick', 'demo_identify',
                                    'latency_bench'])
def test_unusable_ros_domain_id_stops_at_once(module, tmp_path):
    proc = subprocess.run(
        [sys.executable, '-m', f'newton_euler_tools.{module}', '--quick',
         *(['--out', str(tmp_path)] if module != 'latency_bench' else [])],
        env={**os.environ, 'ROS_DOMAIN_ID': 'eleven'}, capture_output=True,
        text=True, timeout=120)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert "ROS_DOMAIN_ID='eleven'" in proc.stderr
    assert 'Traceback' not in proc.stderr
    assert proc.stderr.strip().splitlines()[-1].count('ROS_DOMAIN_ID') == 1
