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

"""The benchmarks run (smoke tests: their figures are not judged here)."""


def test_effect_benchmark_runs(capsys):
    """Smoke test: the effect benchmark runs (its figures are not judged)."""
    from newton_euler_tools import bench_effects
    assert bench_effects.main(['puma_payload_press', '--quick']) == 0
    out = capsys.readouterr().out
    assert 'without friction' in out and 'none (D qdd only)' in out


def test_bench_compare_refuses_what_is_not_a_checkout(tmp_path, capsys):
    from newton_euler_tools import bench_compare
    assert bench_compare.main([str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'not a checkout of this repository' in err[0]


def test_trajectory_benchmark_runs(capsys):
    """Smoke test: one row per robot, three positive figures each."""
    from newton_euler_tools import bench_trajectory
    assert bench_trajectory.main(['--quick']) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines()
            if line.startswith(('puma560', 'panda'))]
    assert [r[0] for r in rows] == ['puma560', 'panda']
    assert all(float(x) > 0.0 for r in rows for x in r[1:])
