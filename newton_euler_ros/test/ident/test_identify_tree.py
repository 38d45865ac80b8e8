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
Identification of a whole tree, through the library (``ident.fit``).

The Panda loaded without a tip is a tree: the arm, the hand and two
fingers, the second a mimic of the first (8 coordinates, 9 bodies).  The
"real" Panda's recording (``ident_example``: Pinocchio's efforts on the
perturbed URDF, noise, jitter, lost and repeated messages) names the
fingers, which stay at 0 with no effort, as a gripper nobody moved.  The
tree is identified from it: every body physical (the follower's too),
drive terms on the coordinates only, the held-out targets of the chain
met on the arm, the written URDF read back identically by us and by
Pinocchio (``mimic=True``); the payload's link on a tree; base
parameters on the tree's limits.
"""
import os
import warnings
import xml.etree.ElementTree as ET

from newton_euler_ros.core import inverse_dynamics_batch, load_robot
from newton_euler_ros.core.drives import DRIVES_NS, model_drives
from newton_euler_ros.core.regressor import (inertial_parameters,
                                             link_parameters, pseudo_inertia)
from newton_euler_ros.core.urdf import parse_urdf
from newton_euler_ros.ident.base import random_states
from newton_euler_ros.ident.fit import fixed_parts, identify
from newton_euler_ros.ident.payload import carrying, LinkError, payload_frame
from newton_euler_ros.ident.urdf_out import atomic_write, identified_urdf
from newton_euler_tools.ident_example import BASE, make_example
import numpy as np
import pytest

ARM = [f'panda_joint{k}' for k in range(1, 8)]


def quiet_load(path, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot(path, **kw)


@pytest.fixture(scope='module')
def tree(tmp_path_factory):
    out = tmp_path_factory.mktemp('panda_tree')
    paths = make_example(str(out), seconds=30.0, rate=500.0, seed=5,
                         validation_seconds=15.0)
    with open(paths['urdf'], encoding='utf-8') as f:
        text = f.read()
    model = quiet_load(paths['urdf'], base=BASE)      # no tip: the tree
    result = identify(model, paths['recording'],
                      validate=paths['validation'], urdf_text=text)
    path = os.path.join(str(out), 'identified.urdf')
    atomic_write(path, identified_urdf(
        text, model, result.theta, fixed_parts(model, text), result.drives))
    return {'paths': paths, 'text': text, 'model': model, 'result': result,
            'identified': path}


def test_the_tree_has_the_fingers(tree):
    model = tree['model']
    assert model.n == 8 and model.nb == 9
    assert model.joint_names[-1] == 'panda_finger_joint1'
    assert model.mimic[8] == (7, 1.0, 0.0)
    result = tree['result']
    assert len(result.theta) == 10 * model.nb + 4 * model.n
    assert len(result.drives.viscous) == model.n


def test_held_out_targets_on_the_arm(tree):
    result = tree['result']
    arm = slice(0, 7)
    rel0 = result.validate_stats['nominal'][1][arm]
    rel = result.validate_stats['identified'][1][arm]
    assert rel0.mean() > 0.2
    assert rel.mean() <= 0.05, rel
    assert rel.max() <= 0.10, rel
    # the finger's effort is 0 throughout: no relative error to give
    assert np.isnan(result.validate_stats['identified'][1][7])


def test_every_body_is_physical_the_followers_too(tree):
    _, _, links, _ = parse_urdf(open(tree['identified']).read())
    for name in tree['model'].info['urdf']['links']:
        lk = links[name]
        J = pseudo_inertia(link_parameters(lk.mass, lk.com, lk.inertia))
        assert lk.mass > 0, name
        assert np.linalg.eigvalsh(J).min() >= -1e-9 * np.abs(J).max(), name
    assert 'panda_rightfinger' in tree['model'].info['urdf']['links']


def test_reads_back_identically_here_and_in_pinocchio(tree):
    import pinocchio as pin
    from newton_euler_tools.peers import PinocchioTree
    back = quiet_load(tree['identified'], base=BASE)
    result = tree['result']
    np.testing.assert_allclose(inertial_parameters(back),
                               inertial_parameters(result.model),
                               rtol=1e-9, atol=1e-12)
    drives = model_drives(back)
    for key in ('viscous', 'coulomb', 'offset', 'armature'):
        np.testing.assert_allclose(getattr(drives, key),
                                   getattr(result.drives, key), rtol=1e-12)
    peer = PinocchioTree(tree['identified'], back)
    rng = np.random.default_rng(1)
    Q, QD, QDD = rng.uniform(-1, 1, (3, 4, back.n))
    Q[:, 7] = rng.uniform(0.0, 0.04, 4)         # the finger, in its range
    ours = inverse_dynamics_batch(back, Q, QD, QDD)
    for i in range(4):
        theirs = pin.rnea(peer.model, peer.data, peer.config(Q[i]),
                          peer.vector(QD[i]), peer.vector(QDD[i]))[peer.iv]
        np.testing.assert_allclose(ours[i], theirs, rtol=1e-9, atol=1e-9)


def test_drive_terms_on_coordinates_and_the_follower_untouched(tree):
    before = ET.fromstring(tree['text'])
    after = ET.fromstring(open(tree['identified'], 'rb').read())
    ext = f'{{{DRIVES_NS}}}drive'
    joints = {e.get('name'): e for e in after.findall('joint')}
    for name in tree['model'].joint_names:
        assert joints[name].find(ext) is not None, name
    old = {e.get('name'): e for e in before.findall('joint')}
    follower = 'panda_finger_joint2'
    assert joints[follower].find(ext) is None
    assert ET.canonicalize(ET.tostring(joints[follower])) == \
        ET.canonicalize(ET.tostring(old[follower]))


def test_the_payload_link_of_a_tree(tree):
    model = tree['model']
    with pytest.raises(LinkError, match='several tips.*panda_leftfinger'):
        payload_frame(model)
    with pytest.raises(LinkError, match="no link 'nope'"):
        payload_frame(model, 'nope')
    with pytest.raises(LinkError, match='fixed to the base'):
        payload_frame(model, 'panda_link0')
    body, pose, _ = payload_frame(model, 'panda_hand')
    assert model.moving_joints[body] == 'panda_joint7'
    assert carrying(model, body) == list(range(7))
    # a mass on the follower's finger moves the arm and the leader
    body, _, _ = payload_frame(model, 'panda_rightfinger')
    assert carrying(model, body) == list(range(8))
    chain = quiet_load(tree['paths']['urdf'], base=BASE, tip='panda_link8')
    body, pose, link = payload_frame(chain)
    assert (body, link) == (6, 'panda_link8')
    np.testing.assert_array_equal(pose, chain.tool)


def test_random_states_keep_each_coordinates_limits(tree):
    model = tree['model']
    Q, _, _ = random_states(model, 500)
    lo = [model.limits[b]['lower'] for b in model.independent]
    hi = [model.limits[b]['upper'] for b in model.independent]
    assert (Q >= lo).all() and (Q <= hi).all()
    assert Q[:, 7].max() <= 0.04
