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

"""The identification benchmark's pieces run (its figures are not tested)."""
from newton_euler_tools import bench_identify


def test_synthetic_recording_is_identified(tmp_path):
    bag = str(tmp_path / 'synthetic')
    bench_identify.synthetic_bag(bag, seconds=12.0, rate=200.0)
    out = bench_identify.identify_once(bag)
    assert out['samples'] > 2000
    assert out['peak_mb'] > 0 and out['seconds'] > 0
    # efforts from the nominal model: the fit explains them but the noise
    assert out['mean_rel'] < 0.05
