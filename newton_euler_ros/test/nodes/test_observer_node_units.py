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
The node's observer says when the efforts are not in the URDF's units.

Two inverse_dynamics_node processes over real DDS, each fed the same
recording of ``current_arm_example``'s UR5 (motor currents in A at
100 Hz, with stops, stiction, lost messages and gaps; read back from the
bag it wrote): one given the published UR5 URDF (example-robot-data's,
no torque constants), the other the URDF an identification gives (torque
constants within 3 %).  After 10 s of motion the first must say, in one
log line and on /diagnostics, that the efforts are not joint torques,
naming the torque constants as the ratios (near the true 12.9 and 10.2
of the loaded joints); the second must check the efforts and say
nothing.
"""
import os
import re
import warnings

import pytest

pytest.importorskip('rclpy')

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402, I100
from newton_euler_ros.core import load_robot  # noqa: E402
from newton_euler_ros.ident.bag import read_joint_states  # noqa: E402
from ros_harness import domain_id, id_node_cmd, NodeProcess, Probe  # noqa
from sensor_msgs.msg import JointState  # noqa: E402

pytestmark = pytest.mark.ros

NODE = '/inverse_dynamics_node'
SEED = 3


@pytest.fixture(scope='module')
def recording(tmp_path_factory):
    from newton_euler_tools import current_arm_example as example
    from newton_euler_tools.current_arm_model import write_identified
    from newton_euler_tools.current_arm_motions import point_to_point
    tmp = tmp_path_factory.mktemp('units')
    arm = example.real_arm(SEED)
    identified = write_identified(tmp / 'identified.urdf', arm, SEED)
    bag = str(tmp / 'moving')
    example.record(arm, bag, point_to_point(SEED, 25.0, dwell=(0.1, 0.4)),
                   seed=SEED)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot(example.ur5_path(), base='base_link', tip='tool0')
    rec = read_joint_states(bag, model.joint_names, '/joint_states')
    return {'tmp': tmp, 'published': example.ur5_path(),
            'identified': identified, 'names': list(model.joint_names),
            'rec': rec, 'constants': arm.constants}


def observer_status(diagnostics):
    for array in reversed(diagnostics):
        for status in array.status:
            if status.name.endswith(': observer'):
                return status
    return None


def test_currents_against_a_urdf_without_torque_constants(recording):
    tmp, rec = recording['tmp'], recording['rec']
    runs = []
    for k, urdf in enumerate((recording['published'],
                              recording['identified'])):
        domain = domain_id(97 + k)
        node = NodeProcess(id_node_cmd(
            None, '-p', f'robot_file:={urdf}', '-p', 'base_link:=base_link',
            '-p', 'tip_link:=tool0', '-p', 'observer.enabled:=true',
            '-p', 'observer.thresholds:=[5.0]',
            '-p', 'diagnostics_period:=0.5'), domain,
            os.path.join(str(tmp), f'node{k}.log'))
        probe = Probe(domain, f'probe{k}')
        runs.append((node, probe, probe.publisher(JointState, 'joint_states'),
                     probe.collect(DiagnosticArray, '/diagnostics')))
    try:
        for node, probe, js, _ in runs:
            assert probe.spin_until(lambda: js.get_subscription_count() > 0
                                    and '6 joints' in node.log(), 90.0), \
                node.log()
        # the recording's stamps, ending a second before now (the node
        # refuses stamps more than max_future ahead)
        now = runs[0][1].node.get_clock().now().nanoseconds
        stamps = rec.stamps_ns - rec.stamps_ns[-1] + now - 10**9
        msg = JointState(name=recording['names'])
        for i in range(len(stamps)):
            msg.header.stamp.sec = int(stamps[i] // 10**9)
            msg.header.stamp.nanosec = int(stamps[i] % 10**9)
            msg.position = rec.q[i].tolist()
            msg.velocity = rec.qd[i].tolist()
            msg.effort = rec.effort[i].tolist()
            for _, probe, js, _ in runs:
                js.publish(msg)
            if i % 4 == 3:
                for _, probe, _, _ in runs:
                    probe.spin_for(0.004)

        def checked(diagnostics):
            status = observer_status(diagnostics)
            units = {kv.key: kv.value for kv in status.values}.get(
                'effort_units', '') if status else ''
            return status if units and 'not checked' not in units else None
        found = []
        for node, probe, _, diagnostics in runs:
            assert probe.spin_until(lambda: checked(diagnostics), 20.0), \
                (node.log(), observer_status(diagnostics))
            found.append(checked(diagnostics))
    finally:
        for node, probe, _, _ in runs:
            node.stop()
            probe.close()
    published, identified = found
    print(f'\npublished URDF: {published.message}\nidentified URDF: '
          f'{[(kv.key, kv.value) for kv in identified.values][-1]}')
    log = runs[0][0].log()
    line = 'observer: the efforts are not joint torques in N m'
    assert log.count(line) == 1, log
    assert 'needs their torque_constant' in log, log
    assert published.level == published.WARN
    assert published.message.startswith(line[:-5]), published.message
    ratios = dict(re.findall(r'(\w+_joint) ([\d.]+)', published.message))
    true = dict(zip(recording['names'], recording['constants']))
    assert {'shoulder_lift_joint', 'elbow_joint'} <= set(ratios), ratios
    for name, ratio in ratios.items():
        assert abs(float(ratio) / true[name] - 1.0) < 0.25, (ratios, true)
    values = {kv.key: kv.value for kv in published.values}
    assert values['effort_units'] == 'not what the URDF says'
    # the identified URDF: checked, nothing said
    values = {kv.key: kv.value for kv in identified.values}
    assert values['effort_units'].startswith('N m per torque_constant '
                                             '(checked on'), values
    assert identified.level == identified.OK, identified.message
    log = runs[1][0].log()
    assert 'efforts' not in log.replace('efforts converted', ''), log
