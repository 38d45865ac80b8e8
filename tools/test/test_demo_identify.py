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

"""``make demo-identify`` in its quick variant, real nodes over DDS."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip('rclpy')

from ros_harness import domain_id, ros_env  # noqa: E402, I100


def test_quick_identification_loop(tmp_path):
    """Excite, record, identify, track again, estimate a payload."""
    out = tmp_path / 'loop'
    proc = subprocess.run(
        [sys.executable, '-m', 'newton_euler_tools.demo_identify', '--quick',
         '--out', str(out)],
        env=ros_env(domain_id(81)), capture_output=True, text=True,
        timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    result = json.loads((out / 'summary.json').read_text())
    runs = result['runs']
    published = runs['published URDF']
    identified = runs['identified URDF + drive compensation']
    untold = runs['2 kg payload, node not told']
    told = runs['2 kg payload, estimate applied']
    # the identified model's feedforward is much closer to the plant's
    # torque (about a tenth of the published URDF's error)
    assert identified['ff_rms'] < 0.5 * published['ff_rms']
    # a payload the node does not know costs tracking; its estimate
    # brings the error back to the identified model's
    assert untold['tracking_rms'] > 3 * told['tracking_rms']
    assert told['ff_rms'] < 0.25 * untold['ff_rms']
    assert told['ff_rms'] < 1.5 * identified['ff_rms']
    # the estimate, as the issue asks of payload: mass within 3 %,
    # centre of mass within 15 mm
    est, true = result['payload_estimate'], result['payload_true']
    assert est['payload.mass'] == pytest.approx(true['mass'], rel=0.03)
    com_error = np.linalg.norm(np.subtract(est['payload.com'], true['com']))
    assert com_error < 0.015, com_error
    # the files of every step: a real rosbag2, URDF, trajectory, report
    for name in ('summary.md', 'tracking.png', 'torques.png',
                 'excitation.json', 'panda_identified.urdf'):
        assert os.path.getsize(out / name) > 0, name
    for bag in ('recording', 'payload_recording'):
        assert (out / bag / 'metadata.yaml').is_file()
    table = [x for x in (out / 'summary.md').read_text().splitlines()
             if x.startswith('|')]
    assert len(table) == 2 + 4
