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
One fit identifies both arms of a dual-arm robot, as a user runs it.

The robot is the published Baxter of example-robot-data perturbed as real
robots differ from their URDF, with friction, offsets and rotor inertia
per joint, static friction at stops, noise, jitter, gaps, lost and
repeated messages, 100 Hz, every joint in the messages (the mimic fingers
and a fixed joint too); its efforts come from Pinocchio's RNEA with
``mimic=True`` (``newton_euler_tools.dual_arm_example``).  Both arms, the
head and the grippers move at once.  ``newton-euler identify`` without
``--tip`` fits the whole tree (17 coordinates, 19 bodies) from one
recording; ``replay`` on another recording, with stops, measures it.
"""
import json
import warnings
import xml.etree.ElementTree as ET

from newton_euler_ros.core import inverse_dynamics_batch, load_robot
from newton_euler_ros.core.drives import DRIVES_NS, model_drives
from newton_euler_ros.core.regressor import link_parameters, pseudo_inertia
from newton_euler_ros.core.urdf import parse_urdf
from newton_euler_ros.ident.bag import read_joint_states
from newton_euler_tools.dual_arm_example import (BASE, EXTRA, KNOWN_MASS,
                                                 make_example, PAYLOAD,
                                                 TOOL_LINK)
import numpy as np
import pytest
from cli_harness import newton_euler  # noqa: E402, I100

ARMS = [f'{side}_{j}' for side in ('right', 'left')
        for j in ('s0', 's1', 'e0', 'e1', 'w0', 'w1', 'w2')]
FINGERS = ['r_gripper_l_finger_joint', 'l_gripper_l_finger_joint']


def run(*args):
    return newton_euler(*args)


def table(stdout, title):
    """{joint: [numbers]} of the per-joint table after ``title``."""
    lines = stdout.splitlines()
    start = next(i for i, x in enumerate(lines) if x.startswith(title))
    out = {}
    for line in lines[start + 2:]:
        words = line.split()
        if not line.startswith('  ') or len(words) < 2:
            break
        out[words[0]] = [float('nan') if w == '-' else float(w)
                         for w in words[1:]]
        if words[0] == 'mean':
            break
    return out


def quiet_load(path, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot(path, **kw)


@pytest.fixture(scope='module')
def dual(tmp_path_factory):
    root = tmp_path_factory.mktemp('baxter')
    paths = make_example(str(root), seed=2)
    out = root / 'baxter_identified.urdf'
    ident = run('identify', paths['urdf'], paths['excitation'], '--base',
                BASE, '-o', out, '--validate', paths['validation'])
    assert ident[0] == 0, ident[2]
    replays = {}
    for label, urdf in (('identified', out), ('nominal', paths['urdf'])):
        code, stdout, err = run('replay', urdf, paths['validation'],
                                '--base', BASE, '--csv',
                                root / f'{label}.csv')
        assert code == 0, err
        replays[label] = table(stdout, 'model against')
    with open(paths['truth'], encoding='utf-8') as f:
        truth = json.load(f)
    return {'paths': paths, 'identified': str(out), 'identify': ident,
            'replay': replays, 'truth': truth, 'root': root}


def test_one_fit_identifies_both_arms(dual):
    stdout = dual['identify'][1]
    assert "whole tree below 'base': 17 joints, 19 bodies" in stdout
    ident, nominal = dual['replay']['identified'], dual['replay']['nominal']
    raw = {j: v[1] for j, v in ident.items()}       # rel % over all samples
    moving = {j: v[2] for j, v in ident.items()}    # where the joint moves
    # the published URDF is far off on the validation recording
    assert nominal['mean'][1] > 20.0, nominal
    # where the joints move, as the Panda's targets
    assert moving['mean'] <= 5.0, ident
    assert np.nanmax([moving[j] for j in ARMS + ['head_pan']]) <= 10.0
    # over every sample, stops held by static friction included
    assert raw['mean'] <= 6.0, ident
    assert max(raw[j] for j in ARMS + ['head_pan']) <= 12.0, ident
    # a gripper finger's effort is friction at a few cm/s: the worst joint
    assert max(raw[j] for j in FINGERS) <= 25.0, ident
    assert all(raw[j] < nominal[j][1] / 3 for j in raw if j != 'mean')


def test_every_body_is_physical_the_mimic_fingers_too(dual):
    model = quiet_load(dual['paths']['urdf'], base=BASE)
    _, _, links, _ = parse_urdf(open(dual['identified']).read())
    bodies = model.info['urdf']['links']
    assert len(bodies) == 19 and 'l_gripper_r_finger' in bodies
    for name in bodies:
        lk = links[name]
        J = pseudo_inertia(link_parameters(lk.mass, lk.com, lk.inertia))
        assert lk.mass > 0, name
        assert np.linalg.eigvalsh(J).min() >= -1e-9 * np.abs(J).max(), name


def test_drive_terms_recovered(dual):
    back = quiet_load(dual['identified'], base=BASE)
    drives = model_drives(back)
    truth = dual['truth']['drives']
    assert dual['truth']['joints'] == list(back.joint_names)
    sel = [back.joint_names.index(j) for j in ARMS + ['head_pan']]
    for key, rtol in (('viscous', 0.2), ('coulomb', 0.1)):
        np.testing.assert_allclose(getattr(drives, key)[sel],
                                   np.asarray(truth[key])[sel], rtol=rtol,
                                   atol=0.05, err_msg=key)


def test_the_identified_urdf_reads_back_and_pinocchio_agrees(dual):
    import pinocchio as pin
    from newton_euler_tools.peers import PinocchioTree
    back = quiet_load(dual['identified'], base=BASE)
    peer = PinocchioTree(dual['identified'], back)
    rng = np.random.default_rng(4)
    Q, QD, QDD = rng.uniform(-1, 1, (3, 5, back.n))
    for j in (back.joint_names.index(f) for f in FINGERS):
        Q[:, j] = rng.uniform(0.0, 0.02, 5)
    ours = inverse_dynamics_batch(back, Q, QD, QDD)
    for i in range(5):
        theirs = pin.rnea(peer.model, peer.data, peer.config(Q[i]),
                          peer.vector(QD[i]), peer.vector(QDD[i]))[peer.iv]
        np.testing.assert_allclose(ours[i], theirs, rtol=1e-9, atol=1e-9)
    # drive terms on the 17 coordinates, none on the mimic fingers
    joints = {e.get('name'): e for e in ET.parse(
        dual['identified']).getroot().findall('joint')}
    tag = f'{{{DRIVES_NS}}}drive'
    assert all(joints[j].find(tag) is not None for j in back.joint_names)
    assert joints['l_gripper_r_finger_joint'].find(tag) is None


def test_the_payload_on_one_gripper(dual):
    paths = dual['paths']
    code, stdout, err = run('payload', dual['identified'], paths['payload'],
                            '--base', BASE, '--link', TOOL_LINK, '--json')
    assert code == 0, err
    est = json.loads(stdout)
    assert est['payload.mass'] == pytest.approx(PAYLOAD['mass'], rel=0.05)
    # a tree with several tips: which link is one line
    code, _, err = run('payload', dual['identified'], paths['payload'],
                       '--base', BASE)
    assert code == 2 and 'several tips' in err and 'left_gripper' in err
    assert len(err.splitlines()) == 1, err


def test_currents_with_a_known_mass_on_one_arm(tmp_path):
    # 40 s recordings (not the example's 60): the constants come out
    # within 0.1 % on the left and 1 % on the right either way
    paths = make_example(str(tmp_path), seed=1, effort='current',
                         payload=False, validation_seconds=10.0,
                         seconds=40.0)
    out = tmp_path / 'identified.urdf'
    common = (paths['urdf'], paths['excitation'], '--base', BASE, '-o', out)
    code, _, err = run('identify', *common)
    assert code == 2 and '--effort current' in err
    code, stdout, err = run('identify', *common, '--effort', 'current',
                            '--known-mass', paths['known_mass'], KNOWN_MASS,
                            '--known-mass-link', TOOL_LINK)
    assert code == 0, err
    with open(paths['truth'], encoding='utf-8') as f:
        truth = json.load(f)
    K = model_drives(quiet_load(str(out), base=BASE)).torque_constant
    true = np.asarray(truth['drives']['constant'])
    names = truth['joints']
    left = [names.index(f'left_{j}') for j in ('s0', 's1', 'e0', 'e1')]
    right = [names.index(f'right_{j}') for j in ('s0', 's1', 'e0', 'e1')]
    # the mass on the left gripper fixes the left arm's constants; the
    # right arm shares no parameter with it: the nominal model's scale
    np.testing.assert_allclose(K[left], true[left], rtol=0.03)
    np.testing.assert_allclose(K[right], true[right], rtol=0.2)
    assert 'keep the nominal model' in err and 'right_s0' in err


def test_the_messages_are_a_drivers(dual):
    js = read_joint_states(dual['paths']['validation'],
                           ['l_gripper_l_finger_joint',
                            'l_gripper_r_finger_joint', *EXTRA, 'left_s0'])
    # the follower mirrors its leader; the fixed joint reads 0
    np.testing.assert_allclose(js.q[:, 1], -js.q[:, 0])
    assert not js.q[:, 2].any()
    # stops: the arm exactly at rest for a while in the middle
    assert js.qd is not None
    still = np.abs(js.qd[:, 3]) < 0.01
    t = js.stamps[still]
    assert ((t > 3.0) & (t < js.stamps[-1] - 3.0)).sum() > 20
    steps = np.diff(js.stamps)
    assert steps.min() > 0 and steps.max() > 0.2     # jitter and a gap


def test_a_torso_carrying_both_arms(tmp_path):
    """PR2: a prismatic torso lift (0.013 m/s) under both arms and the head."""
    from newton_euler_ros.ident.constants import coupled_groups
    paths = make_example(str(tmp_path), seed=2, robot='pr2', payload=False,
                         validation_seconds=20.0)
    model = quiet_load(paths['urdf'], base='base_link')
    assert model.joint_names[0] == 'torso_lift_joint'
    # the torso's row holds every body: one group of shared parameters
    assert len(coupled_groups(model)) == 1
    torso = {}
    for label, tip in (('tree', None), ('left', 'l_gripper_palm_link'),
                       ('right', 'r_gripper_palm_link')):
        extra = () if tip is None else ('--tip', tip)
        code, stdout, err = run('identify', paths['urdf'],
                                paths['excitation'], '--base', 'base_link',
                                *extra, '-o', tmp_path / f'{label}.urdf',
                                '--validate', paths['validation'])
        assert code == 0, err
        torso[label] = table(stdout, f'on {paths["validation"]}')[
            'torso_lift_joint']
    # the slow torso is fitted (a tenth of its velocity limit counts as
    # moving), and identified: far below the published URDF
    nominal_rms, nominal_rel, rms, rel = torso['tree']
    assert rel <= 1.0 and rms <= nominal_rms / 8, torso
    # one fit sees both arms move the torso; a chain through one arm
    # carries the other as a rigid body at rest
    assert torso['left'][2] >= 1.25 * rms, torso
    assert torso['right'][2] >= 1.25 * rms, torso
