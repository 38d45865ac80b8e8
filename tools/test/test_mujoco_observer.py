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
The node's observer against MuJoCo's pusher, over DDS (issue 36).

mujoco_sim_node (the push scene, and it without its pusher),
inverse_dynamics_node with its observer and the tracking controller run
as real processes on loopback DDS, in this test's domains; thresholds
come from the free run alone.  The push of MuJoCo's contact is reported
within 50 ms of its onset, the node's wrench at link 7 is MuJoCo's
contact force through the observer's lag within 10 % + 1 N, and no
contact is reported during the free motion at full speed.
"""
import json
import subprocess
import sys

import pytest

pytest.importorskip('rclpy')
pytest.importorskip('mujoco')

from ros_harness import domain_id, ros_env  # noqa: E402, I100

pytestmark = pytest.mark.ros


def test_the_nodes_observer_feels_mujocos_pusher_over_dds(tmp_path):
    out = tmp_path / 'observer'
    domain = domain_id(57)
    proc = subprocess.run(
        [sys.executable, '-m', 'newton_euler_tools.mujoco_observer',
         '--quick', '--out', str(out)],
        env=ros_env(domain), capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert f'[free] nodes up in domain {domain};' in proc.stdout
    assert f'[push] nodes up in domain {domain + 1};' in proc.stdout
    s = json.loads((out / 'summary.json').read_text())
    # MuJoCo's contact begins on the schedule's ramp (0 to 20 N from 1.2 s)
    assert 1.2 <= s['onset_s'] < 1.23
    # the node's residual is the library's observer on the same samples
    assert s['residual_agreement_nm'] < 1e-6 + 1e-3 * max(s['thresholds'])
    # the three targets
    assert 0.0 <= s['onset_delay_s'] <= 0.05
    w = s['wrench']
    assert w['compared'] > 100 and w['missing'] == 0
    assert 15.0 < w['lagged_force_peak_n'] < 30.0      # the 20 N push
    assert w['worst_ratio'] <= 1.0
    # MuJoCo's wrench is the tick's mean, from the scene replayed on the
    # run's efforts: in lockstep the replay is the run itself
    assert s['replay_max_position_error_rad'] < 1e-9
    assert s['false_contacts_push_run'] == []
    # at full speed: the sinusoid's 0.5 rad at 0.6 Hz is 1.9 rad/s
    assert s['max_speed_rad_s'] > 1.5
    # what the probe heard on ~/contact is what the node's residual says
    assert s['contacts_heard'] == s['contacts_replayed']
    assert all(s['targets'].values())
