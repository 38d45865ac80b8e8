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
newton-euler on a whole robot (a URDF without --tip), in the test process (cli_harness).

Baxter from example-robot-data (two arms, a head, a mimic finger in
each gripper): ``dynamics`` against Pinocchio's reading of the same URDF
(``mimic=True``, joints by name), a wrench at a named link against its
Jacobian, ``check``'s tree against the URDF's own parent links,
``feedforward`` of one arm with the others held, ``simulate`` of a scene
whose robot is the whole tree.
"""
import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from cli_harness import newton_euler  # noqa: E402, I100

BAXTER = 'baxter_description/urdf/baxter.urdf'
LEFT = ['left_s0', 'left_s1', 'left_e0', 'left_e1', 'left_w0', 'left_w1',
        'left_w2']


def run(*args):
    return newton_euler(*args)


@pytest.fixture(scope='module')
def baxter():
    import warnings

    from newton_euler_ros.core import load_urdf
    from newton_euler_tools.peers import example_robot_urdf, PinocchioTree
    path = example_robot_urdf(BAXTER)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_urdf(path)
    return path, model, PinocchioTree(path, model)


def test_dynamics_of_the_whole_tree_against_pinocchio(baxter):
    path, model, peer = baxter
    rng = np.random.default_rng(8)
    q, qd, qdd = rng.uniform(-0.8, 0.8, (3, model.n))
    code, out, err = run('dynamics', path, '--base', 'base', '--q', *q,
                         '--qd', *qd, '--qdd', *qdd, '--json')
    assert code == 0, err
    res = json.loads(out)
    assert res['joint_names'] == list(model.joint_names)
    assert res['jacobian'] is None          # several tips: no end effector
    theirs = peer.terms(q, qd, qdd, ['left_gripper'])
    for key, name in (('tau', 'tau'), ('D', 'mass_matrix'),
                      ('C', 'coriolis_matrix'), ('g', 'gravity')):
        np.testing.assert_allclose(res[name], theirs[key], rtol=0,
                                   atol=1e-10 * max(1, np.abs(
                                       theirs[key]).max()))
    # a wrench needs a link on a tree with several tips
    F = [3.0, -2.0, 10.0, 0.2, 0.1, -0.3]
    code, out, err = run('dynamics', path, '--q', *q, '--wrench', *F)
    assert code == 2 and err.strip().splitlines() == [
        'newton-euler: error: baxter has several tips and no end effector: '
        'give --link LINK for --wrench']
    code, out, err = run('dynamics', path, '--q', *q, '--qd', *qd, '--qdd',
                         *qdd, '--wrench', *F, '--link', 'left_gripper',
                         '--wrench-frame', 'end_effector', '--json')
    assert code == 0, err
    res = json.loads(out)
    J = theirs['J left_gripper link']       # the gripper's own axes
    np.testing.assert_allclose(res['jacobian'], J, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res['tau'], theirs['tau'] + J.T @ F, rtol=0,
                               atol=1e-9)
    code, out, err = run('dynamics', path, '--q', *q, '--link', 'left_grip')
    assert code == 2 and "closest: 'left_gripper'" in err


def test_a_whole_robots_matrices_stay_readable(baxter):
    """
    D, C and J of 17 joints: blocks of numbered columns, 100 wide at most.

    Every entry is still printed (as --json gives it).
    """
    path, model, _ = baxter
    q = [str(0.1 * k) for k in range(model.n)]
    code, out, err = run('dynamics', path, '--q', *q, '--qd', *q)
    assert code == 0, err
    code, js, err = run('dynamics', path, '--q', *q, '--qd', *q, '--json')
    res = json.loads(js)
    lines = out.splitlines()
    start = lines.index('mass matrix D(q):')
    assert max(len(line) for line in lines[start:]) <= 100
    assert lines[start + 1] == ('  (columns: the joints numbered in order, '
                                '5 to a block; --json gives it whole)')
    for title, key in (('mass matrix D(q):', 'mass_matrix'),
                       ('Coriolis matrix C(q, qd) (Christoffel form):',
                        'coriolis_matrix')):
        at = lines.index(title)
        rows = {}
        for line in lines[at + 2:]:
            if not line.strip():
                break
            parts = line.split()
            if parts[0].isdigit() and len(parts) > 1 and \
                    parts[1] in model.joint_names:
                rows.setdefault(parts[1], []).extend(map(float, parts[2:]))
        assert list(rows) == list(model.joint_names)
        np.testing.assert_allclose([rows[j] for j in model.joint_names],
                                   res[key], rtol=1e-5, atol=1e-12)


def test_check_prints_the_tree_by_depth(baxter):
    path, model, _ = baxter
    code, out, err = run('check', path)
    assert code == 0, err
    assert ('joints: 17 (RRRRRRRRPRRRRRRRP), URDF tree below base (several '
            'tips; 19 moving joints, 2 of them mimic)') in out
    lines = out.splitlines()
    start = lines.index('    base')
    parent_of = {j.get('name'): (j.find('parent').get('link'),
                                 j.find('child').get('link'))
                 for j in ET.parse(path).getroot().findall('joint')}
    depth = {'base': 4}       # indentation of each link's line
    shown = []
    for line in lines[start + 1:]:
        if not line.startswith('      '):
            break
        indent = len(line) - len(line.lstrip())
        joint, rest = line.strip().split(' (', 1)
        kind, child = rest.rsplit(') -> ', 1)
        parent, urdf_child = parent_of[joint]
        assert child == urdf_child and depth[parent] == indent - 2, line
        depth[child] = indent
        shown.append((joint, kind))
    kinds = dict(shown)
    assert sorted(kinds) == sorted(parent_of)       # every joint, once
    assert kinds['r_gripper_r_finger_joint'] == \
        'prismatic, mimic: -1 x r_gripper_l_finger_joint'
    assert kinds['left_e1'] == 'revolute'
    assert kinds['left_endpoint'] == 'fixed, merged'
    # the model's joint order is the tree's, depth first
    moving = [j for j, k in shown if not k.startswith('fixed')]
    assert moving == list(model.moving_joints)


def test_feedforward_of_one_arm_holds_the_others_at_zero(baxter, tmp_path):
    path, model, peer = baxter
    times = [0.0, 0.5, 1.0]
    rng = np.random.default_rng(9)
    Q = rng.uniform(-0.8, 0.8, (3, 7))
    trajectory = {'joint_names': LEFT[::-1], 'points': [
        {'time_from_start': t, 'positions': q[::-1].tolist(),
         'velocities': [0.0] * 7, 'accelerations': [0.0] * 7}
        for t, q in zip(times, Q)]}
    file = tmp_path / 'left.json'
    file.write_text(json.dumps(trajectory))
    code, out, err = run('feedforward', path, file)
    assert code == 0, err
    assert err.startswith('note: joints not in the trajectory held at 0, '
                          'at rest: head_pan, right_s0')
    arm = [model.joint_names.index(j) for j in LEFT]
    for q, point in zip(Q, json.loads(out)['points']):
        x = np.zeros(model.n)
        x[arm] = q
        expected = peer.terms(x, 0 * x, 0 * x)['tau'][arm]
        np.testing.assert_allclose(point['effort'][::-1], expected, rtol=0,
                                   atol=1e-9)
    # a trajectory that fails: its error is the one line, no note first
    trajectory['points'][1]['positions'] = [0.0]
    file.write_text(json.dumps(trajectory))
    code, out, err = run('feedforward', path, file)
    assert code == 2 and out == ''
    assert err.count('\n') == 1, err
    assert err.startswith(f'newton-euler: error: {file}: '), err


def test_simulate_a_scene_of_the_whole_tree(baxter, tmp_path):
    path, model, _ = baxter
    n = model.n
    goal = np.random.default_rng(10).uniform(-0.3, 0.3, n)
    goal[[model.joint_names.index(j) for j in model.joint_names
          if 'finger' in j]] = 0.01
    scene = tmp_path / 'baxter.yaml'
    scene.write_text(json.dumps({
        'name': 'baxter_move', 'robot': path,
        'effects': {'gravity': True, 'velocity_products': True,
                    'payload': {'mass': 1.0, 'link': 'left_gripper'}},
        'reference': {'type': 'quintic', 'goal': goal.tolist(),
                      'duration': 0.5},
        'controller': {'kp': [50.0] * n, 'kd': [5.0] * n,
                       'feedforward': True},
        'integrator': {'method': 'rk4', 'step': 1e-3, 'duration': 0.6,
                       'rate': 250.0}}))
    code, out, err = run('simulate', scene, '--json')
    assert code == 0, err
    summary = json.loads(out)
    assert summary['energy_drift_relative'] < 1e-9
    assert summary['tracking_max'] < 1e-3       # feedforward of the tree
    np.testing.assert_allclose(summary['final_q'], goal, atol=1e-3)
    # a scene wrench acts at the end effector: Baxter has none
    data = json.loads(scene.read_text())
    data['effects']['wrench'] = {'frame': 'base',
                                 'constant': [0, 0, -5.0, 0, 0, 0]}
    scene.write_text(json.dumps(data))
    code, out, err = run('simulate', scene)
    assert code == 2 and err.strip() == (
        'newton-euler: error: baxter.yaml: effects.wrench: baxter is a tree '
        'with several tips: no end effector for the wrench to act at')
