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

"""What accuracy costs in MuJoCo: every effect left out tracks worse."""
import json

from newton_euler_tools import mujoco_costs


def test_leaving_out_any_effect_tracks_worse_on_mujoco(tmp_path, capsys):
    out = tmp_path / 'costs.json'
    assert mujoco_costs.main(['--quick', '--json', str(out)]) == 0
    rows = {row['label']: row for row in json.loads(out.read_text())}
    full = rows.pop('all 6 effects')
    pd = rows.pop('PD alone')
    assert len(rows) == 7       # six left out in turn, and none
    for label, row in rows.items():
        # the plant has every effect: a feedforward without one is wrong
        # by that effect's torque, and tracks worse
        assert row['tracking_rms'] > 2 * full['tracking_rms'], label
        assert row['us'] > 0
    assert pd['tracking_rms'] > 100 * full['tracking_rms']
    assert 'without friction' in capsys.readouterr().out
