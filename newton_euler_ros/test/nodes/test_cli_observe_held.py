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
``newton-euler observe`` on a recording where the arm never moves.

A UR user's free recordings were all held poses: the thresholds they
suggest bound only the noise at rest, and the unit check on motion has
nothing to go on.  The current-sensing example arm
(``newton_euler_tools.current_arm_example``) held at one pose for 8 s,
its efforts in amperes and (times its torque constants) in N m, against
the published UR5 URDF (no constants).
"""
import json

from newton_euler_ros.ident.bag import read_joint_states
from newton_euler_ros.ident.bag_write import write_joint_states
from newton_euler_tools import current_arm_example as arm_example
import numpy as np
import pytest
from cli_harness import newton_euler  # noqa: E402, I100

pytest.importorskip('rosbags')

CHAIN = ['--base', arm_example.BASE, '--tip', arm_example.TIP]


def run(*args):
    return newton_euler('observe', *args, *CHAIN)


@pytest.fixture(scope='module')
def held(tmp_path_factory):
    tmp = tmp_path_factory.mktemp('held')
    arm = arm_example.real_arm(0)
    pose = arm_example.CENTRE.copy()

    def still(t):
        q = np.tile(pose, (np.size(t), 1))
        return q, np.zeros_like(q), np.zeros_like(q)
    still.seconds = 8.0
    current = tmp / 'current'
    arm_example.record(arm, current, still, seed=5)
    js = read_joint_states(current, arm_example.JOINTS)
    torque = tmp / 'torque'
    write_joint_states(torque, js.stamps_ns, arm_example.JOINTS, js.q, js.qd,
                       js.effort * arm.constants)
    return {'urdf': arm_example.ur5_path(), 'current': current,
            'torque': torque, 'K': arm.constants}


@pytest.fixture(scope='module')
def observed(held):
    """Run observe twice: the currents as text, the torques as JSON."""
    return (run(held['urdf'], held['current']),
            run(held['urdf'], held['torque'], '--json'))


def test_currents_at_rest_are_told_from_torques_by_gravity(held, observed):
    # the nominal URDF on currents: the check on motion had nothing to go
    # on (silent, 99.8 % in contact); where the arm holds still, g(q)
    # against the effort gives the torque constants on the loaded joints
    (code, out, err), (code_t, _, err_t) = observed
    assert code == 0, err
    warned = [x for x in err.splitlines() if x.startswith('warning:')]
    assert len(warned) == 1, err
    line = warned[0]
    for word in (str(held['current']), 'holds still', 'g(q)',
                 'not joint torques', 'torque_constant', 'meaningless'):
        assert word in line, (word, line)
    for j in (1, 2):        # the shoulder and the elbow carry the arm
        name = arm_example.JOINTS[j]
        ratio = float(line.split(f'{name} ')[1].split()[0].rstrip(',)'))
        assert ratio == pytest.approx(held['K'][j], rel=0.3), line
    # the same efforts in N m: no warning
    assert code_t == 0 and 'warning' not in err_t, err_t


def test_a_held_recording_says_what_its_thresholds_cannot_tell(observed):
    (code, out, err), (code_t, out_t, err_t) = observed
    notes = [x for x in out.splitlines() if 'held poses' in x]
    assert len(notes) == 1, out
    assert notes[0].startswith('note: ') and \
        "not the model's error while moving" in notes[0], notes[0]
    summary = json.loads(out_t)
    assert [x for x in summary['notes'] if 'held poses' in x], summary
