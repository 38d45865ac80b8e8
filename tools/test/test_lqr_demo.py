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

"""lqr_demo --quick runs; LQR's errors are below PD's on every plant."""
from newton_euler_tools import lqr_demo


def test_quick_demo_prints_lqr_below_pd(capsys):
    assert lqr_demo.main(['--quick']) == 0
    out = capsys.readouterr().out
    rows = {}
    for line in out.splitlines():
        words = line.split()
        if len(words) > 4 and words[-1] == 'rad' and words[-2] != 'N':
            law = 'LQR' if ' LQR ' in line else 'PD'
            plant = line.split(f' {law} ')[0].strip()
            rows[plant, law] = (float(words[-2]),
                                float(line.split(f' {law} ')[1].split()[0]))
    plants = {p for p, _ in rows}
    assert 'library forward dynamics' in plants, out
    for plant in plants:
        lqr_rms, pd_rms = rows[plant, 'LQR'][1], rows[plant, 'PD'][1]
        lqr_late, pd_late = rows[plant, 'LQR'][0], rows[plant, 'PD'][0]
        assert lqr_rms < pd_rms and lqr_late < 0.2 * pd_late, out
