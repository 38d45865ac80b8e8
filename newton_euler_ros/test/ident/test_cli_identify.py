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

"""``newton-euler identify`` and ``replay`` (in the test process: cli_harness)."""
import csv
import shutil
import warnings

from newton_euler_ros.core import (inverse_dynamics_batch, load_robot,
                                   load_urdf)
from newton_euler_ros.core.drives import DRIVES_NS
from newton_euler_ros.ident.bag import read_joint_states
from newton_euler_ros.ident.bag_write import write_joint_states
from newton_euler_tools.ident_example import (BASE, make_example,
                                              panda_path, TIP)
import numpy as np
import pytest
from cli_harness import newton_euler  # noqa: E402, I100

CHAIN = ['--base', BASE, '--tip', TIP]


def run(*args, cwd=None):
    return newton_euler(*args, cwd=cwd)


def one_line_error(err, *names):
    lines = [x for x in err.splitlines()
             if not x.startswith(('warning:', 'note:'))]
    assert len(lines) == 1, err
    assert lines[0].startswith('newton-euler: error: '), err
    assert 'Traceback' not in err
    for name in names:
        assert str(name) in lines[0], (name, lines[0])
    return lines[0]


@pytest.fixture(scope='module')
def example(tmp_path_factory):
    out = tmp_path_factory.mktemp('cli')
    return make_example(str(out), seconds=16.0, rate=250.0, seed=5,
                        validation_seconds=8.0, validation_storage='sqlite3')


@pytest.fixture(scope='module')
def panda():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot(panda_path(), base=BASE, tip=TIP)


def small_bag(path, model, m=600, rate=250.0, names=None, effort=True,
              still=False, storage='mcap'):
    """Write a quick recording whose efforts come from the nominal model."""
    rng = np.random.default_rng(1)
    t = np.arange(m) / rate
    n = model.n
    phase = rng.uniform(0, 6, n)
    amp = 0.0 if still else 0.4
    q = -0.5 + amp * np.sin(1.3 * t[:, None] + phase)
    q[:, 3] -= 1.5
    qd = amp * 1.3 * np.cos(1.3 * t[:, None] + phase)
    qdd = -amp * 1.69 * np.sin(1.3 * t[:, None] + phase)
    tau = inverse_dynamics_batch(model, q, qd, qdd)
    tau += rng.normal(0, 0.02, tau.shape)
    names = list(model.joint_names) if names is None else names
    k = len(names)
    stamps = 10**9 + np.round(t * 1e9).astype(np.int64)
    write_joint_states(path, stamps, names, q[:, :k], qd[:, :k],
                       tau[:, :k] if effort else None, storage=storage)
    return path


def test_identify_and_replay(example, tmp_path):
    out = tmp_path / 'identified.urdf'
    code, stdout, err = run('identify', example['urdf'],
                            example['recording'], *CHAIN, '-o', out,
                            '--validate', example['validation'])
    assert code == 0, err
    assert 'Traceback' not in err
    for word in ('rank ', 'condition number', 'nominal rel %',
                 'identified rel %', 'validation', 'identified in '):
        assert word in stdout, word
    assert out.exists()
    csv_path = tmp_path / 'replay.csv'
    png = tmp_path / 'replay.png'
    code, stdout, err = run('replay', out, example['validation'], *CHAIN,
                            '--csv', csv_path, '--plot', png)
    assert code == 0, err
    assert png.stat().st_size > 1000
    with open(csv_path, newline='') as f:
        rows = list(csv.reader(f))
    names = [f'panda_joint{k}' for k in range(1, 8)]
    assert rows[0] == ['time'] + [f'{x}.{s}' for x in names
                                  for s in ('measured', 'model')]
    js = read_joint_states(example['validation'], names)
    # one row per message (filter edges left out), its stamp to the ns
    stamps = {f'{t // 10**9}.{t % 10**9:09d}' for t in js.stamps_ns}
    assert all(r[0] in stamps for r in rows[1:])
    assert 0.8 * len(js) < len(rows) - 1 <= len(js)
    data = np.array(rows[1:], dtype=float)[:, 1:]
    meas, model = data[:, 0::2], data[:, 1::2]
    rel = np.sqrt(np.mean((meas - model) ** 2, axis=0) / np.mean(
        meas ** 2, axis=0))
    assert rel.mean() < 0.1
    assert 'rel % raw' in stdout


def test_replay_of_a_recording_without_efforts_says_so(panda, tmp_path):
    """All-zero efforts: one line, exit 2; one silent joint: '-'."""
    bag = small_bag(tmp_path / 'moving', panda)
    js = read_joint_states(bag, panda.joint_names)
    names = list(panda.joint_names)
    zero = np.zeros_like(js.effort)
    write_joint_states(tmp_path / 'zero', js.stamps_ns, names, js.q, js.qd,
                       zero)
    csv_path, png = tmp_path / 'zero.csv', tmp_path / 'zero.png'
    code, stdout, err = run('replay', panda_path(), tmp_path / 'zero',
                            *CHAIN, '--csv', csv_path, '--plot', png)
    assert code == 2, (stdout, err)
    line = one_line_error(err, tmp_path / 'zero')
    assert line.endswith('no effort to compare: every effort on '
                         '/joint_states is zero'), line
    assert stdout == '' and not csv_path.exists() and not png.exists()
    # one joint whose driver reports no effort: no number for it, said
    zero[:, :6] = js.effort[:, :6]
    write_joint_states(tmp_path / 'one', js.stamps_ns, names, js.q, js.qd,
                       zero)
    code, stdout, err = run('replay', panda_path(), tmp_path / 'one',
                            *CHAIN, '--csv', csv_path)
    assert code == 0, err
    row = next(x for x in stdout.splitlines()
               if x.split()[:1] == ['panda_joint7'])
    assert row.split()[2:] == ['-', '-', '-'], row
    table = [x.split() for x in stdout.splitlines()
             if x.split()[:1] and x.split()[0] in names + ['mean']]
    assert len(table) == 8 and max(len(cell) for row in table
                                   for cell in row) < 20, stdout
    assert 'note: every effort of panda_joint7 is zero: nothing to ' \
           'compare there (-)' in err, err


def test_replay_plot_axes_carry_units(panda):
    """Time in s; N m, N on a prismatic joint, the effort unit with K."""
    from newton_euler_ros.cli_identify import effort_units, replay_figure
    from newton_euler_ros.core.drives import model_drives
    assert effort_units(panda, model_drives(panda)) == ['torque (N m)'] * 7
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        finger = load_robot(panda_path(), base=BASE, tip='panda_leftfinger')
    assert effort_units(finger, model_drives(finger)) == \
        ['torque (N m)'] * 7 + ['force (N)']
    # a URDF whose drives give torque constants: efforts in their unit
    with open(panda_path(), encoding='utf-8') as f:
        text = f.read().replace(
            'xmlns:xacro=', f'xmlns:ne="{DRIVES_NS}" xmlns:xacro=', 1)
    for k in range(1, 8):
        head = f'<joint name="panda_joint{k}" type="revolute">'
        text = text.replace(head, head + f'<ne:drive torque_constant='
                                         f'"{9 + k / 4}"/>', 1)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        current = load_urdf(text, base=BASE, tip=TIP)
    labels = effort_units(current, model_drives(current))
    assert labels == [f'effort (unit = {9 + k / 4:.4g} N m)'
                      for k in range(1, 8)], labels
    t = np.linspace(0.0, 1.0, 5)
    y = np.zeros((5, 7))
    fig = replay_figure(t, current.joint_names, y, y, y, labels)
    try:
        axes = fig.get_axes()
        assert [ax.get_ylabel() for ax in axes] == [
            f'{name}\n{label}'
            for name, label in zip(current.joint_names, labels)]
        assert axes[-1].get_xlabel() == 'time since the first message (s)'
    finally:
        import matplotlib.pyplot as plt
        plt.close(fig)


def test_refuses_to_overwrite_the_input(example, tmp_path):
    urdf = tmp_path / 'panda.urdf'
    shutil.copyfile(example['urdf'], urdf)
    before = urdf.read_bytes()
    code, _, err = run('identify', urdf, example['recording'], *CHAIN,
                       '-o', urdf)
    assert code == 2
    one_line_error(err, urdf, 'overwrite')
    assert urdf.read_bytes() == before


def test_impossible_nominal_inertials_are_a_prior_with_a_note(example,
                                                              tmp_path):
    text = open(example['urdf'], encoding='utf-8').read()
    # link 5's principal moments break the triangle inequality
    start = text.index('<link name="panda_link5">')
    i = text.index('<inertia ', start)
    j = text.index('/>', i)
    text = text[:i] + ('<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" '
                       'iyz="0" izz="0.05"') + text[j:]
    urdf = tmp_path / 'odd.urdf'
    urdf.write_text(text)
    out = tmp_path / 'out.urdf'
    code, stdout, err = run('identify', urdf, example['recording'], *CHAIN,
                            '-o', out)
    assert code == 0, err
    assert 'note:' in err and 'triangle' in err
    assert out.exists()


def test_masses_far_from_the_prior_are_said_in_one_note(example):
    from types import SimpleNamespace
    from newton_euler_ros.ident.notes import far_masses
    from newton_euler_ros.core.urdf import inspect_urdf
    from newton_euler_ros.ident.fit import nominal_theta
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model, _, _ = inspect_urdf(example['urdf'], base=BASE, tip=TIP)
    theta0 = nominal_theta(model)
    same = SimpleNamespace(theta=theta0, theta0=theta0)
    assert far_masses(model, same) == []
    theta = theta0.copy()
    theta[10 * 1] *= 4.0            # the second body's mass alone
    theta[10 * 5] /= 2.5            # within the factor: not named
    notes = far_masses(model, SimpleNamespace(theta=theta, theta0=theta0))
    assert len(notes) == 1 and '\n' not in notes[0]
    name = model.info['urdf']['links'][1]
    assert notes[0].startswith(f"masses more than 3x from the prior's: "
                               f'{name} '), notes[0]
    assert model.info['urdf']['links'][5] not in notes[0]


def bad_case(case, tmp_path, example, panda):
    """Return (args, names the error must contain)."""
    urdf = example['urdf']
    bag = tmp_path / 'bag'
    topic = []
    if case == 'missing':
        pass
    elif case == 'corrupt':
        bag.mkdir()
        (bag / 'metadata.yaml').write_text('rosbag2_bagfile_information: [')
    elif case == 'truncated':
        shutil.copytree(example['validation'], bag)
        db = next(p for p in bag.iterdir() if p.suffix == '.db3')
        raw = db.read_bytes()
        db.write_bytes(raw[:len(raw) // 3])
    elif case == 'truncated_mcap':
        shutil.copytree(example['recording'], bag)
        data = next(p for p in bag.iterdir() if p.suffix == '.mcap')
        raw = data.read_bytes()
        data.write_bytes(raw[:len(raw) // 3])
    elif case == 'topic':
        small_bag(bag, panda)
        topic = ['--topic', '/arm/joint_states']
    elif case == 'effort':
        small_bag(bag, panda, effort=False)
    elif case == 'joint':
        small_bag(bag, panda, names=list(panda.joint_names[:6]))
    elif case == 'short':
        small_bag(bag, panda, m=30)
    elif case == 'still':
        small_bag(bag, panda, m=2500, still=True)
    elif case == 'urdf':
        urdf = tmp_path / 'nope.urdf'
        small_bag(bag, panda)
        return [urdf, bag] + topic, [urdf]
    elif case == 'swapped':         # the bag (a folder) given as the URDF
        small_bag(bag, panda)
        return [bag, bag] + topic, [bag]
    return [urdf, bag] + topic, [bag]


BAD = [('missing', 'no such bag'), ('corrupt', 'cannot open'),
       ('topic', "no topic '/arm/joint_states'"), ('effort', 'no effort'),
       ('joint', 'panda_joint7'), ('short', 'too short'),
       ('still', 'does not excite'), ('urdf', 'no such URDF'),
       ('swapped', 'is a directory, not a URDF file')]


@pytest.mark.parametrize('case, words', BAD)
def test_bad_input_is_one_line_exit_2(case, words, tmp_path, example,
                                      panda):
    args, names = bad_case(case, tmp_path, example, panda)
    out = tmp_path / 'out.urdf'
    code, stdout, err = run('identify', *args[:2], *CHAIN, '-o', out,
                            *args[2:])
    assert code == 2, (stdout, err)
    line = one_line_error(err, *names)
    assert words in line
    assert not out.exists()
    if case in ('missing', 'effort'):
        csv_path = tmp_path / 'r.csv'
        code, _, err = run('replay', args[0], args[1], *CHAIN, '--csv',
                           csv_path, *args[2:])
        assert code == 2
        assert words in one_line_error(err, *names)
        assert not csv_path.exists()


@pytest.mark.parametrize('case', ['truncated', 'truncated_mcap'])
def test_a_truncated_bag_is_identified_up_to_the_cut(case, tmp_path,
                                                     example, panda):
    # a third of the file: read up to its last intact message, and said
    args, _ = bad_case(case, tmp_path, example, panda)
    out = tmp_path / 'out.urdf'
    code, stdout, err = run('identify', *args[:2], *CHAIN, '-o', out)
    assert code == 0, err
    said = [x for x in err.splitlines() if 'recovered' in x]
    assert len(said) == 1 and said[0].startswith(
        f'warning: recording {args[1]}: ') and 'cut short' in said[0], err
    assert out.exists()


def test_validate_bag_errors_name_it(example, tmp_path):
    out = tmp_path / 'out.urdf'
    missing = tmp_path / 'nothing'
    code, _, err = run('identify', example['urdf'], example['recording'],
                       *CHAIN, '-o', out, '--validate', missing)
    assert code == 2
    one_line_error(err, missing)
    assert not out.exists()
