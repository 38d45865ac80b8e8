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
The entry points written from the row steps keep the kernels' contract.

Each single-state entry point returns ``SIZE + a`` for input a of the
wrong size (4 the output, 5 a workspace) and ``NONFINITE * a + i`` for
the first non-finite entry of input a; each batch loop returns the first
failing row with its code in ``status[0]`` (the codes that
``calling.status_error`` decodes).
"""
import inspect
import os

from newton_euler_ros.core import kernels as K
from newton_euler_ros.core import load_robot, Workspace
from newton_euler_ros.core.kernels import generate
import numpy as np
import pytest


@pytest.fixture(scope='module')
def args():
    """Arguments for every entry point, by name, for a 2-joint arm."""
    model = load_robot('planar_2r')
    n = model.n
    ws = Workspace(model)
    q = np.array([0.3, -0.2])
    return model, {
        'P': model.packed, 'q': q, 'qd': q.copy(), 'qdd': q.copy(),
        'tau': q.copy(), 'wrench': np.zeros(6), 'flags': 3, 'crba': True,
        'composite': True, 'local': False, 'body': n - 1,
        'target': model.frames_array[K.F_TOOL], 'fext': ws.fext,
        'fall': ws.fall,
        'ws': ws.ws, 'aw': ws.aw,
        'cw': ws.cw, 'scratch': ws.scratch, 'Ts': ws.frames,
        'D': np.empty((n, n)), 'C': np.empty((n, n)), 'J': np.empty((6, n)),
        'terms': np.empty((3, n)), 'dw': ws.dw, 'wext': ws.wext,
        'damping': ws.zeros, 'armature': ws.zeros, 'chol': ws.chol,
        'dtau': np.empty((2, n, n)), 'dqdd': np.empty((3, n, n)),
    }


def _call(name, given, **changed):
    kernel = K.RUN[name]
    params = list(inspect.signature(kernel.py_func).parameters)
    values = dict(given, **changed)
    if params[-1] in ('tau', 'qdd'):      # the output of tau, g, fd
        values[params[-1]] = np.empty(len(given['q']))
    return kernel(*[values[p] for p in params])


SINGLE = [name for name in generate.SOURCES if not name.endswith('_batch')]


def test_every_entry_point_is_generated():
    assert set(K.RUN) == set(generate.SOURCES)
    for name, kernel in K.RUN.items():
        assert kernel.py_func.__name__ == name
        # a batch loop releases the GIL (threads may share a batch); a
        # single call does not (releasing it costs more than it saves)
        nogil = kernel.targetoptions.get('nogil', False)
        assert nogil == name.endswith('_batch'), name


@pytest.mark.parametrize('name', SINGLE)
def test_sizes_and_non_finite_inputs_give_the_same_codes(args, name):
    model, given = args
    assert _call(name, given) == -1
    params = list(inspect.signature(K.RUN[name].py_func).parameters)
    for a, arg in enumerate(('q', 'qd', 'qdd' if 'qdd' in params[:-1]
                             else 'tau', 'wrench')):
        if arg not in params[:-1]:
            continue
        bad = np.append(given[arg], 0.0)
        assert _call(name, given, **{arg: bad}) == K.SIZE + a, arg
        nan = given[arg].copy()
        nan[1] = np.nan
        assert _call(name, given, **{arg: nan}) == K.NONFINITE * a + 1, arg
    small = np.zeros((1, K.W_WIDTH))
    assert _call(name, given, ws=small) == K.SIZE + 5


def test_batch_loops_return_the_first_failing_row():
    model = load_robot('planar_rp')
    ws = Workspace(model)
    Q = np.zeros((3, 2))
    Q[1, 1] = 1e200         # a prismatic joint: D overflows
    DD = np.empty((3, 2, 2))
    assert K.run_mass_matrix_batch(model.packed, Q, ws.ws, DD,
                                   ws.status) == 1
    assert ws.status[0] == K.OVERFLOW
    Q[1, 1] = np.nan        # (the callers check finiteness first)
    TAU = np.empty((3, 2))
    ws.status[0] = -1
    assert K.run_gravity_torques_batch(model.packed, Q, ws.ws, TAU,
                                       ws.status) == 1
    assert ws.status[0] == K.OVERFLOW
    Q[1, 1] = 0.0
    assert K.run_gravity_torques_batch(model.packed, Q, ws.ws, TAU,
                                       ws.status) == -1


def test_the_entry_points_are_the_checked_in_file_compiled():
    text = generate.SOURCES['run_gravity_torques_batch']
    assert 'gravity_torques_row(links, frames, Q[k], ws, TAU[k])' in text
    code = K.run_gravity_torques.py_func.__code__
    assert code.co_filename == os.path.join(generate.HERE, 'entries.py')
    assert K.run_gravity_torques.py_func.__module__.endswith('.entries')
    for name, kernel in K.RUN.items():      # each in the file it belongs to
        assert os.path.basename(kernel.py_func.__code__.co_filename) == \
            generate.module_of(name)


def test_the_checked_in_entries_files_are_what_the_generator_writes():
    """Regenerate after editing entry.py: ``generate --write``."""
    written = generate.render()
    assert sorted(map(os.path.basename, written)) == sorted(generate.FILES)
    for path, text in written.items():
        with open(path, encoding='utf-8') as fh:
            checked_in = fh.read()
        assert checked_in == text, (
            f'{path} is stale: run {generate.COMMAND}')
    assert generate.main(['--check']) == 0


def test_an_edited_row_step_without_regenerating_is_caught():
    with open(generate.ENTRY_FILE, encoding='utf-8') as fh:
        source = fh.read()
    edited = source.replace('def gravity_torques_row(links, frames, q, ws, '
                            'tau):', 'def gravity_torques_row(links, '
                            'frames, q, qd, ws, tau):')
    assert edited != source
    assert generate.render(edited) != generate.render(source)
    assert 'if qd.shape[0] != n:' in generate.sources(edited)[
        'run_gravity_torques']
    renamed = source.replace("('run_link_poses', link_poses_row)",
                             "('run_link_poses', link_pose_row)")
    with pytest.raises(ValueError, match='no row step link_pose_row'):
        generate.render(renamed)
