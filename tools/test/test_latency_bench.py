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
The latency benchmark (``make latency``), quick mode, as a subprocess.

It starts inverse_dynamics_node and the echo node as real processes on
loopback DDS; its figures are not judged here.
"""
import subprocess
import sys

import pytest

pytest.importorskip('rclpy')

from ros_harness import domain_id, ros_env  # noqa: E402, I100

pytestmark = pytest.mark.ros


def test_latency_benchmark_runs(tmp_path):
    """Smoke test: `make latency` runs end to end (figures not judged)."""
    import json
    out = tmp_path / 'latency.json'
    proc = subprocess.run(
        [sys.executable, '-m', 'newton_euler_tools.latency_bench', '--quick',
         '--json', str(out)],
        env=ros_env(domain_id(53)), capture_output=True, text=True,
        timeout=240)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    # no --domain: the phases use ROS_DOMAIN_ID and the next three ids
    assert json.loads(out.read_text())['domain'] == domain_id(53)
    assert 'p99 < 1 ms' in proc.stdout
    assert 'executor trade-off: ' in proc.stdout
    assert 'child exit codes after SIGINT: inverse_dynamics_node 0' in \
        proc.stdout
    # the observer phase ran the observer: a wrench for every answer
    assert 'observer off / on (inverse_dynamics_node' in proc.stdout
    phases = {p['key']: p for p in json.loads(out.read_text())['phases']}
    seen = phases['observer']['observer']
    assert seen['answered'] > 0
    assert seen['wrenches'] >= 0.5 * seen['answered']
    assert seen['wrench_finite']
    assert phases['observer']['domain'] == domain_id(53) + 4


def _raw(stamp_ns):
    """Return a serialized message that starts with a header (CDR, LE)."""
    import struct
    return b'\x00\x01\x00\x00' + struct.pack(
        '<iI', stamp_ns // 1_000_000_000, stamp_ns % 1_000_000_000) + \
        b'\x00' * 8


def test_an_observer_phase_without_wrenches_fails():
    """A node that did not run the observer: the phase fails, not passes."""
    from newton_euler_tools.latency_bench import BenchError, observer_check
    stamps = [1_700_000_000_000_000_000 + k * 1_000_000 for k in range(50)]
    send = {'stamps': stamps}
    received = [(s + 300_000, _raw(s)) for s in stamps]
    with pytest.raises(BenchError, match='the observer did not run'):
        observer_check(send, received, {})
    with pytest.raises(BenchError, match='measured nothing'):
        observer_check(send, [], {})


def test_walk_efforts_are_the_model_torques_and_quiet_the_observer():
    """The bench's efforts move the model as the walk does: no contact."""
    import numpy as np
    from newton_euler_ros.core import inverse_dynamics
    from newton_euler_ros.core.observer import (MomentumObserver,
                                                observe_recording)
    from newton_euler_tools.latency_bench import (joint_limits, puma_model,
                                                  random_walk)
    model = puma_model()
    limits = joint_limits(model)
    walk = random_walk(5000, 1000.0, 1, limits, model)
    Q, QD, TAU = (np.array(x) for x in (walk.positions, walk.velocities,
                                        walk.efforts))
    lo, hi = np.array(limits).T
    assert ((Q > lo) & (Q < hi)).all() and np.abs(QD).max() <= 2.0
    # the efforts are tau(q, qd, qdd) with qdd the walk's own acceleration
    qdd = (QD[1] - QD[0]) * 1000.0
    np.testing.assert_allclose(TAU[1], inverse_dynamics(model, Q[1], QD[1],
                                                        qdd), atol=1e-9)
    out = observe_recording(MomentumObserver(model, 50.0), np.arange(
        len(Q)) * 1e-3, Q, QD, TAU)
    assert out.contacts == 0 and np.abs(out.residual).max() < 5.0
