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
Payload estimation from recordings made by an independent source.

The recordings (``newton_euler_tools.payload_example``): the published
Panda URDF (example-robot-data) with drive terms, a known rigid payload
added to Pinocchio's last joint inertia, torques from Pinocchio's RNEA
plus friction, offsets, rotor inertia and noise, lost messages, stamp
jitter and the fingers in the message.
"""
import json
import shutil
import warnings

from newton_euler_ros.core import load_robot
from newton_euler_ros.core.regressor import (link_parameters, pseudo_inertia,
                                             regressor_batch)
from newton_euler_ros.ident.payload import tip_to_link
from newton_euler_tools.ident_example import BASE, TIP
from newton_euler_tools.payload_example import make_example
import numpy as np
import pytest
from cli_harness import newton_euler  # noqa: E402, I100


def run_cli(*args):
    return newton_euler(*args)


def payload_cli(paths, *extra):
    return run_cli('payload', paths['urdf'], paths['bag'], '--base', BASE,
                   '--tip', TIP, *extra)


@pytest.fixture(scope='module')
def loaded(tmp_path_factory):
    return make_example(str(tmp_path_factory.mktemp('loaded')),
                        mass=1.5, com=(0.01, -0.02, 0.06), seconds=20.0,
                        seed=4)


@pytest.fixture(scope='module')
def empty(tmp_path_factory):
    return make_example(str(tmp_path_factory.mktemp('empty')), mass=0.0,
                        seconds=15.0, seed=5)


def test_tip_to_link_is_the_rigid_transform():
    rng = np.random.default_rng(0)
    from scipy.spatial.transform import Rotation
    X = np.eye(4)
    X[:3, :3] = Rotation.random(random_state=1).as_matrix()
    X[:3, 3] = rng.normal(size=3) * 0.1
    m, c = 2.0, rng.normal(size=3) * 0.05
    A = rng.normal(size=(3, 3))
    Ic = A @ A.T * 0.01
    pi_tip = link_parameters(m, c, Ic)
    R, p = X[:3, :3], X[:3, 3]
    want = link_parameters(m, R @ c + p, R @ Ic @ R.T)
    np.testing.assert_allclose(tip_to_link(X) @ pi_tip, want, atol=1e-12)
    J = pseudo_inertia(tip_to_link(X) @ pi_tip)
    np.testing.assert_allclose(J, X @ pseudo_inertia(pi_tip) @ X.T,
                               atol=1e-12)


def test_tip_columns_move_the_payload_like_with_payload():
    # Y_tip T pi_p is the torque change of merging the payload into the
    # last link (core.model.with_payload, the node's own merge)
    from newton_euler_ros.core import inverse_dynamics_batch
    from newton_euler_ros.core.model import with_payload
    from newton_euler_tools.ident_example import panda_path
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot(panda_path(), base=BASE, tip=TIP)
    rng = np.random.default_rng(2)
    Q, QD, QDD = (rng.normal(size=(5, 7)) for _ in range(3))
    c = np.array([0.02, -0.01, 0.05])
    Ic = np.diag([3e-3, 2e-3, 1e-3])
    loaded = with_payload(model, 1.2, c, Ic)
    diff = (inverse_dynamics_batch(loaded, Q, QD, QDD)
            - inverse_dynamics_batch(model, Q, QD, QDD))
    Y = regressor_batch(model, Q, QD, QDD)[:, :, 60:]
    pred = Y @ (tip_to_link(model.tool) @ link_parameters(1.2, c, Ic))
    np.testing.assert_allclose(pred, diff, atol=1e-9)


def test_mass_and_com_from_a_recording(loaded):
    code, out, err = payload_cli(loaded, '--json')
    assert code == 0, err
    assert 'effort' not in err, err     # torques, and the URDF says so
    est = json.loads(out)
    with open(loaded['truth'], encoding='utf-8') as f:
        truth = json.load(f)
    assert set(est) == {'payload.mass', 'payload.com', 'payload.inertia',
                        'undetermined', 'uncertainty'}
    assert len(est['payload.com']) == 3 and len(est['payload.inertia']) == 6
    # this motion determines the mass and the centre of mass: numbers
    assert est['payload.mass'] is not None
    assert None not in est['payload.com']
    assert est['payload.mass'] == pytest.approx(truth['payload.mass'],
                                                rel=0.03)
    err_com = np.linalg.norm(np.subtract(est['payload.com'],
                                         truth['payload.com']))
    assert err_com <= 0.015, err_com
    # physically consistent: the inertia about the com is PSD with the
    # triangle inequality
    # the inertia: null where undetermined (a small body at the tip), and
    # every number given physically consistent
    inertia = est['payload.inertia']
    if None in inertia:
        assert 'payload.inertia' in est['undetermined']
    else:
        Ixx, Iyy, Izz, Ixy, Iyz, Ixz = inertia
        Ic = np.array([[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz, Izz]])
        ev = np.linalg.eigvalsh(Ic)
        assert ev.min() >= -1e-9
        assert ev.sum() - 2 * ev.max() >= -1e-9


def test_each_value_is_within_its_uncertainty(loaded):
    # issue 37: the confidence behind each value, as numbers; the truth
    # within three standard uncertainties of every value given
    code, out, err = payload_cli(loaded, '--json')
    assert code == 0, err
    est = json.loads(out)
    with open(loaded['truth'], encoding='utf-8') as f:
        truth = json.load(f)
    u = est['uncertainty']
    for key in ('payload.mass', 'payload.com', 'payload.inertia'):
        got, want, sd = (np.atleast_1d(np.asarray(x, dtype=float))
                         for x in (est[key], truth[key], u[key]))
        given = ~np.isnan(got)
        assert np.all(sd > 0), (key, sd)
        assert np.all(np.abs(got - want)[given] <= 3 * sd[given]), (
            key, got, want, sd)
    # the mass and the centre of mass come out well inside the 15 mm a
    # payload's com is asked for (the errors are a tenth of a millimetre)
    assert max(u['payload.com']) <= 1e-3, u['payload.com']


def test_uncertainty_shrinks_with_a_longer_recording(loaded, tmp_path):
    # issue 37: the bound was the whole residual's norm through
    # (A^T A)^-1, the same for 5 s as for 20 s (7 mm on both), so a longer
    # recording never determined more.  The first 5 s of the same motion:
    # four times the samples give about half the uncertainty
    short = make_example(str(tmp_path / 'short'), mass=1.5,
                         com=(0.01, -0.02, 0.06), seconds=5.0, seed=4)
    u = {}
    for name, paths in (('short', short), ('long', loaded)):
        code, out, err = payload_cli(paths, '--json')
        assert code == 0, err
        u[name] = json.loads(out)['uncertainty']
    assert u['long']['payload.mass'] <= 0.75 * u['short']['payload.mass']
    for a, b in zip(u['long']['payload.com'], u['short']['payload.com']):
        assert a <= 0.75 * b, (u['long'], u['short'])


def test_a_heavy_payload_is_not_taken_for_currents(tmp_path):
    # 10 kg on a Panda (beyond its rating; a physics check): the arm's
    # own model is about a third of the torque on most joints, below the
    # torques' band, so the unit check runs on the model with the payload
    # found (on the arm alone it would say the efforts are not torques)
    paths = make_example(str(tmp_path), mass=10.0, com=(0.0, 0.0, 0.05),
                         seconds=12.0, seed=6)
    code, out, err = payload_cli(paths, '--json')
    assert code == 0, err
    assert json.loads(out)['payload.mass'] == pytest.approx(10.0, rel=0.05)
    assert 'effort' not in err, err


def test_summary_says_what_is_determined(loaded):
    code, out, err = payload_cli(loaded)
    assert code == 0, err
    assert 'mass' in out and 'kg' in out and 'com' in out
    assert 'undetermined' not in out.split('com')[0]


def test_no_payload_gives_mass_near_zero_never_negative(empty):
    code, out, err = payload_cli(empty, '--json')
    assert code == 0, err
    est = json.loads(out)
    assert 0.0 <= est['payload.mass'] <= 0.03
    assert 'no payload' in err
    # no payload: its centre of mass and inertia are null, with the reason
    assert est['payload.com'] == [None] * 3
    assert est['payload.inertia'] == [None] * 6
    assert 'no payload' in est['undetermined']['payload.com']
    code, out, err = payload_cli(empty)
    assert code == 0 and 'no payload' in out


def test_poor_motion_reports_undetermined_quantities(tmp_path):
    paths = make_example(str(tmp_path / 'poor'), seconds=12.0, seed=6,
                         only_base=True)
    code, out, err = payload_cli(paths)
    assert code == 0, err
    inertia_line = [x for x in out.splitlines() if 'inertia about' in x][0]
    assert inertia_line.count('undetermined') == 6
    assert 'rotate the wrist' in out
    # the mass still comes out (gravity on the shoulder joints)
    code, out, err = payload_cli(paths, '--json')
    est = json.loads(out)
    assert est['payload.mass'] == pytest.approx(1.5, rel=0.03)
    assert 'undetermined' in err
    # the inertia the motion cannot tell is null in the JSON, not a guess
    # a user would paste into payload.inertia
    assert est['payload.inertia'] == [None] * 6
    assert 'rotate the wrist' in est['undetermined']['payload.inertia']


def one_line(code, err, *words):
    assert code == 2, err
    # the URDF's notes (a lumped hand) may come first; one error line
    lines = [x for x in err.strip().splitlines()
             if not x.startswith(('warning:', 'note:'))]
    assert len(lines) == 1, err
    assert 'Traceback' not in err
    for w in words:
        assert str(w) in lines[0], (w, lines[0])


def test_bad_inputs_one_line_exit_2(loaded, tmp_path):
    urdf, bag = loaded['urdf'], loaded['bag']
    code, _, err = run_cli('payload', tmp_path / 'none.urdf', bag, '--base',
                           BASE, '--tip', TIP)
    one_line(code, err, 'none.urdf')
    code, _, err = run_cli('payload', urdf, tmp_path / 'nobag', '--base',
                           BASE, '--tip', TIP)
    one_line(code, err, 'nobag')
    code, _, err = run_cli('payload', urdf, bag, '--base', BASE, '--tip',
                           TIP, '--topic', '/other', '--json')
    one_line(code, err, '/other')
    code, _, err = run_cli('payload', urdf, bag, '--base', BASE, '--tip',
                           'no_such_link', '--json')
    one_line(code, err, 'no_such_link')
    broken = tmp_path / 'broken'
    shutil.copytree(bag, broken)
    for f in broken.iterdir():
        if f.suffix == '.mcap':
            f.write_bytes(f.read_bytes()[:200])
    code, _, err = run_cli('payload', urdf, broken, '--base', BASE, '--tip',
                           TIP, '--json')
    one_line(code, err, 'broken')
