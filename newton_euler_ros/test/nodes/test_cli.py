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

"""The newton-euler command (in the test process: cli_harness), and its cache."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest
from cli_harness import newton_euler  # noqa: E402, I100

PUMA_Q = ['0', '0.5', '-0.3', '0.1', '0.2', '0.3']
PUMA_QD = ['0.1', '0.2', '0.3', '0.4', '0.5', '0.6']


def run(*args, cwd=None):
    return newton_euler(*args, cwd=cwd)


def test_json_terms_satisfy_the_equation_of_motion():
    qdd = ['1', '-1', '0.5', '0', '2', '-0.5']
    wrench = ['10', '-5', '3', '0.5', '0.2', '-0.1']
    code, out, err = run('dynamics', 'puma560', '--q', *PUMA_Q, '--qd',
                         *PUMA_QD, '--qdd', *qdd, '--wrench', *wrench,
                         '--json')
    assert code == 0, err
    res = json.loads(out)
    assert set(res) == {'joint_names', 'tau', 'mass_matrix',
                        'coriolis_matrix', 'gravity', 'jacobian'}
    assert res['joint_names'] == [f'joint{i}' for i in range(1, 7)]
    D = np.array(res['mass_matrix'])
    C = np.array(res['coriolis_matrix'])
    J = np.array(res['jacobian'])
    assert D.shape == C.shape == (6, 6) and J.shape == (6, 6)
    rhs = (D @ np.array(qdd, float) + C @ np.array(PUMA_QD, float)
           + np.array(res['gravity']) + J.T @ np.array(wrench, float))
    np.testing.assert_allclose(res['tau'], rhs, rtol=0, atol=1e-12)


def test_table_is_readable():
    code, out, err = run('dynamics', 'puma560', '--q', *PUMA_Q, '--qd',
                         *PUMA_QD)
    assert code == 0, err
    assert 'puma560: 6 joints, standard DH' in out
    assert 'mass matrix D(q):' in out and 'Jacobian J(q)' in out
    # the published oddity of the Puma is a note for `check`, not repeated
    # on every use
    assert 'triangle' not in err
    code, out, err = run('check', 'puma560')
    assert code == 0 and 'warnings: 0' in out
    assert 'note: puma560.yaml: links[0] (joint1): inertia' in out


def test_states_file_keeps_order_and_fills_zeros(tmp_path):
    states = [{'q': [0.1, 0.2]}, {'q': [0.3, -0.4], 'qd': [1.0, 2.0],
                                  'qdd': [0.5, 0.0],
                                  'wrench': [1, 2, 3, 0, 0, 0]}]
    path = tmp_path / 'states.json'
    path.write_text(json.dumps(states))
    code, out, err = run('dynamics', 'planar_2r', '--states', str(path))
    assert code == 0, err
    res = json.loads(out)
    assert len(res) == 2
    for st, r in zip(states, res):
        code, out1, _ = run('dynamics', 'planar_2r', '--q',
                            *map(str, st['q']), '--json',
                            *(['--qd', *map(str, st['qd'])] if 'qd' in st
                              else []),
                            *(['--qdd', *map(str, st['qdd'])] if 'qdd' in st
                              else []),
                            *(['--wrench', *map(str, st['wrench'])]
                              if 'wrench' in st else []))
        assert json.loads(out1) == r


def test_check_summarises_or_fails():
    code, out, _ = run('check', 'stanford')
    assert code == 0
    assert 'joints: 6 (RRPRRR), standard DH' in out
    # what the total counts is said
    assert ('total mass: 20.77 kg (the links the joints move; the base not '
            'counted)') in out
    assert 'drive terms: none' in out


@pytest.mark.parametrize('args, message', [
    (['dynamics', 'puma560', '--q', '1', '2'],
     '--q needs 6 values (one per joint), got 2'),
    (['dynamics', 'puma560', '--q', *PUMA_Q[:5], 'nan'],
     '--q: must be finite'),
    (['dynamics', 'puma560', '--q', *PUMA_Q[:5], 'abc'],
     '--q: must be a number'),
    (['dynamics', 'puma560'], '--q is required (6 values'),
    (['dynamics', 'no_such_robot', '--q', '0'], 'not a bundled robot'),
    (['dynamics', 'puma560', '--q', *PUMA_Q, '--wrench', '1', '2'],
     'expected 6 arguments'),
    (['dynamics', 'puma560', '--q', *PUMA_Q, '--wrench-frame', 'tool'],
     "invalid choice: 'tool'"),
    (['check', 'missing.yaml'], 'missing.yaml: no such file'),
    (['frobnicate'], "invalid choice: 'frobnicate'"),
])
def test_errors_are_one_line_without_traceback(args, message):
    code, out, err = run(*args)
    assert code != 0
    lines = [ln for ln in err.splitlines() if not ln.startswith('warning:')]
    assert len(lines) == 1, err
    assert lines[0].startswith('newton-euler: error: ')
    assert message in lines[0]
    assert 'Traceback' not in err


def test_bad_robot_file_error_names_field(tmp_path):
    path = tmp_path / 'arm.yaml'
    path.write_text('name: arm\nconvention: standard\nlinks:\n'
                    '  - {name: j1, type: revolute, a: 1.0, alpha: 0.0, '
                    'd: 0.0, mass: -2.0, com: [0, 0, 0], '
                    'inertia: [1, 1, 1, 0, 0, 0]}\n')
    code, _, err = run('check', str(path))
    assert code == 2
    assert err.strip() == ('newton-euler: error: arm.yaml: links[0] (j1): '
                           'mass: must be >= 0, got -2.0')


def test_bad_states_file(tmp_path):
    path = tmp_path / 'states.json'
    path.write_text('[{"q": [0.1]}]')
    code, _, err = run('dynamics', 'planar_2r', '--states', str(path))
    assert code != 0
    assert 'state 0: q: must be a list of 2 numbers' in err


def test_package_imports_from_the_repository_root():
    """The newton_euler_ros/ folder must not shadow the installed package."""
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
        os.path.abspath(__file__)))))
    proc = subprocess.run(
        [sys.executable, '-c', 'import newton_euler_ros as p; '
                               'print(p.__file__, p.__version__)'],
        capture_output=True, text=True, timeout=60, cwd=root)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().endswith('__init__.py 0.1.0'), proc.stdout


def _hostile_files(tmp_path):
    """Files a person or a network might hand the CLI."""
    import yaml
    files = {}
    binary = tmp_path / 'binary.yaml'
    binary.write_bytes(bytes(range(256)) * 4)
    files['binary'] = (binary, 'not UTF-8 text')
    empty = tmp_path / 'empty.yaml'
    empty.write_text('')
    files['empty'] = (empty, 'the file is empty')
    folder = tmp_path / 'folder.yaml'
    folder.mkdir()
    files['directory'] = (folder, 'is a directory')
    deep = tmp_path / 'deep.yaml'
    deep.write_text('name: ' + '[' * 1000 + ']' * 1000 + '\n')
    files['deep'] = (deep, 'nested more than 32 levels deep')
    # a 2 kB alias bomb: 9 levels of 9 aliases each, 9^9 leaves
    lines = ['a0: &a0 [x, x, x, x, x, x, x, x, x]']
    lines += [f'a{i}: &a{i} [' + ', '.join([f'*a{i - 1}'] * 9) + ']'
              for i in range(1, 9)]
    bomb = tmp_path / 'bomb.yaml'
    bomb.write_text('\n'.join(lines + ['name: *a8']) + '\n')
    files['alias bomb'] = (bomb, 'anchors and aliases')
    big = tmp_path / 'big.yaml'
    with open(big, 'w') as fh:
        fh.write(yaml.safe_dump({'name': 'x'}))
        fh.write('# padding\n' * 300000)
    files['too large'] = (big, 'more than the 1048576 accepted')
    return files


@pytest.mark.parametrize('kind', ['binary', 'empty', 'directory', 'deep',
                                  'alias bomb', 'too large'])
def test_hostile_robot_and_scene_files_are_one_line(tmp_path, kind):
    path, message = _hostile_files(tmp_path)[kind]
    for command in (('check', str(path)), ('simulate', str(path)),
                    ('dynamics', 'puma560', '--states', str(path))):
        code, out, err = run(*command)
        assert code == 2, (command, err)
        assert err.count('\n') == 1, (command, err)
        assert 'Traceback' not in err and out == ''
        if command[0] == 'dynamics' and kind in ('deep', 'alias bomb',
                                                 'too large'):
            # the states file is JSON: YAML text is simply not JSON
            assert 'not valid JSON' in err
        else:
            assert message in err, (command, err)


def test_exit_statuses(tmp_path):
    assert run('dynamics', 'puma560', '--q', '0')[0] == 2     # count
    assert run('dynamics', 'puma560', '--q', *PUMA_Q[:5], 'x')[0] == 2
    assert run('frobnicate')[0] == 2
    assert run('dynamics', 'no_such_robot', '--q', '0')[0] == 2
    assert run('check', 'puma560')[0] == 0


def test_check_warns_when_the_mass_matrix_is_singular(tmp_path):
    import yaml
    data = yaml.safe_load(open(os.path.join(
        os.path.dirname(__file__), '..', '..', 'config', 'robots',
        'planar_2r.yaml')))
    data['links'][-1].update(mass=0.0, com=[0, 0, 0],
                             inertia=[0, 0, 0, 0, 0, 0])
    path = tmp_path / 'tail.yaml'
    path.write_text(yaml.safe_dump(data))
    code, out, err = run('check', str(path))
    assert code == 0
    assert ("warning: tail.yaml: joint 'joint2': the mass matrix D(q) is "
            'singular there') in out
    code, out, err = run('check', 'planar_2r')
    assert 'singular' not in out


def test_numba_cache_is_not_written_into_the_source_tree(tmp_path):
    """Outside make, compiled kernels go to the user's cache directory."""
    env = {k: v for k, v in os.environ.items() if k != 'NUMBA_CACHE_DIR'}
    env['XDG_CACHE_HOME'] = str(tmp_path)
    # the pose: the quickest kernel to compile (16 s against gravity's 26)
    code = ('import os, newton_euler_ros.core as c; '
            'c.end_effector_pose(c.load_robot("planar_2r"), [0.0, 0.0]); '
            'print(os.environ["NUMBA_CACHE_DIR"])')
    proc = subprocess.run([sys.executable, '-W', 'ignore', '-c', code],
                          capture_output=True, text=True, timeout=300,
                          env=env)
    assert proc.returncode == 0, proc.stderr
    cache = proc.stdout.strip()
    assert cache == str(tmp_path / 'newton_euler_ros' / 'numba')
    assert any(name.endswith('.nbi') for _, _, files in os.walk(cache)
               for name in files)


def test_simulate_says_a_diverging_integration_diverged(tmp_path):
    """Stiff gains on a light wrist: the step and gains, not 'overflows'."""
    import yaml
    scene = yaml.safe_load(open(os.path.join(
        os.path.dirname(__file__), '..', '..', 'config', 'scenes',
        'panda_orbit_slow.yaml')))
    scene['controller']['kp'][-1] = 1e6
    scene['controller']['kd'][-1] = 1e4
    scene['integrator']['duration'] = 0.5
    path = tmp_path / 'stiff.yaml'
    path.write_text(yaml.safe_dump(scene))
    code, out, err = run('simulate', str(path))
    assert code == 2 and out == ''
    assert err == ('newton-euler: error: panda_orbit_slow: the integration '
                   'diverged at t = 0.006 s (rk4, time step 0.002 s, gains '
                   'kp up to 1e+06 (joint7) and kd up to 10000 (joint7)): '
                   'use a smaller integrator step or lower controller '
                   'gains\n')
