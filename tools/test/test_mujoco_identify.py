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

"""``make demo-identify-mujoco`` in its quick variant: MuJoCo's physics."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip('mujoco')

JOINTS = [f'panda_joint{i}' for i in range(1, 8)]


@pytest.fixture(scope='module')
def loop(tmp_path_factory):
    """Run the quick loop once; return (output folder, summary)."""
    out = tmp_path_factory.mktemp('mujoco_identify') / 'loop'
    proc = subprocess.run(
        [sys.executable, '-m', 'newton_euler_tools.mujoco_identify',
         '--quick', '--out', str(out)],
        capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    # the table is printed: a header, a rule and one row per model
    table = [x for x in proc.stdout.splitlines() if x.startswith('|')]
    assert len(table) == 4, proc.stdout
    return out, json.loads((out / 'summary.json').read_text())


def test_identified_model_predicts_the_held_out_torques(loop):
    """On a recording not fitted, identify's and replay's errors drop."""
    _, result = loop
    held = result['held_out_torque_error']
    # measured: 0.10 against 0.74 N m (mean over the joints)
    assert held['identified_rms'] < 0.35 * held['nominal_rms'], held
    assert held['identified_rel'] < 10.0, held
    replay = result['replay_rms']
    assert replay['identified'] < 0.35 * replay['published'], replay


def test_identified_feedforward_tracks_better_on_mujoco(loop):
    """The issue's target: at least 3x better tracking than the published."""
    _, result = loop
    tracking = result['tracking']
    published, identified = tracking['published'], tracking['identified']
    assert identified['rms'] < published['rms']
    assert tracking['ratio'] >= 3.0, tracking
    # better on every joint, not on average only
    assert all(i < p for i, p in zip(identified['per_joint'],
                                     published['per_joint'])), tracking


def test_mujoco_friction_constraint_is_identified_as_coulomb(loop):
    """
    Identify MuJoCo's frictionloss (a constraint) as Coulomb friction.

    The true robot's URDF gives MuJoCo the friction and rotor inertia; the
    identified URDF's Coulomb terms are within 20 % of them (measured:
    within 8 %), and its viscous terms of the right size.
    """
    from newton_euler_ros.core.drives import model_drives
    from newton_euler_tools.demo_identify import COULOMB, quiet_load, VISCOUS
    from newton_euler_tools.mujoco_identify_plant import load_plant
    out, _ = loop
    robot = load_plant(str(out / 'panda_real.urdf'), JOINTS)
    m = robot.model
    np.testing.assert_allclose(m.dof_frictionloss[robot.dof], COULOMB)
    np.testing.assert_allclose(m.dof_damping[robot.dof], VISCOUS)
    published = model_drives(quiet_load(str(out / 'panda_published.urdf')))
    assert published is None or np.all(published.coulomb == 0.0)
    found = model_drives(quiet_load(str(out / 'panda_identified.urdf')))
    np.testing.assert_allclose(found.coulomb, COULOMB, rtol=0.2)
    np.testing.assert_allclose(found.viscous, VISCOUS, rtol=0.6)


def test_recordings_are_a_drivers(loop):
    """rosbag2 at 500 Hz, at rest at both ends, noisy, efforts in bounds."""
    from newton_euler_ros.ident.bag import read_joint_states
    out, result = loop
    assert result['recording']['rate'] == 500.0
    for bag in ('recording', 'heldout_recording'):
        assert (out / bag / 'metadata.yaml').is_file()
        js = read_joint_states(str(out / bag), JOINTS)
        np.testing.assert_allclose(np.diff(js.stamps), 0.002, atol=1e-6)
        t = js.stamps - js.stamps[0]
        rest = result['recording']['rest_seconds']
        for still in (t < rest[0] - 0.05, t > t[-1] - rest[1] + 0.05):
            assert np.abs(js.qd[still]).max() < 0.03
        moving = np.abs(js.qd).max(axis=0)
        assert np.all(moving > 0.5), moving
        # the Panda's effort limits (87 N m, 12 N m on the wrist) hold
        bound = np.array([87.0] * 4 + [12.0] * 3) + 0.5
        assert np.all(np.abs(js.effort) <= bound)
    for name in ('summary.md', 'panda_real.urdf', 'panda_identified.urdf',
                 'excitation.json', 'heldout.json', 'identify.txt',
                 'replay_published.csv', 'replay_identified.csv'):
        assert os.path.getsize(out / name) > 0, name
    assert set(result['times']) == {'plant', 'excite', 'record',
                                    'identify', 'track'}
