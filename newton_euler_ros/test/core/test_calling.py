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
The strict entries (``core.calling.StrictEntry``) and numba's public API.

A strict entry is compiled for one signature on its first call and then
closed to others, so numba answers any other argument type with its
``TypeError`` and never compiles a variant.  It uses only numba's public
dispatcher API.  The package's source names none of numba's private
dispatcher or cache members: the kernel cache's locators
(``core/kernels/_jit.py``) are put first in numba's documented setting
for its locator list, and every other function keeps numba's own.
"""
import ast
import importlib
import os
import pathlib
import subprocess
import sys
import threading
import warnings

from newton_euler_ros.core import (calling, gravity_torques,
                                   inverse_dynamics, load_robot, mass_matrix,
                                   Workspace)
from newton_euler_ros.core import kernels as K
from newton_euler_ros.core.errors import SlowInputWarning
from newton_euler_ros.core.observer import external_wrench, MomentumObserver
import numba
from numba.core import caching, dispatcher
import numpy as np
import pytest

PACKAGE = pathlib.Path(calling.__file__).resolve().parents[1]
# (file, name): private uses allowed (none)
ALLOWED = set()


def _private_numba_names():
    """Every single-underscore member of numba's dispatcher and caching."""
    names = set()
    for module in (dispatcher, caching):
        for obj in vars(module).values():
            if isinstance(obj, type) and obj.__module__ == module.__name__:
                names |= {n for n in vars(obj)
                          if n.startswith('_') and not n.startswith('__')}
        names |= {n for n in vars(module)
                  if n.startswith('_') and not n.startswith('__')}
    # names every Python object or our own classes have too
    return names - {'_abc_impl', '_lock', '_cache'}


def test_the_package_uses_no_private_numba_name():
    private = _private_numba_names()
    assert '_compile_for_args' in private       # the scan sees them
    assert '_search_new_conversions' in private
    found = []
    for path in sorted(PACKAGE.rglob('*.py')):
        tree = ast.parse(path.read_text(), str(path))
        for node in ast.walk(tree):
            name = None
            if isinstance(node, ast.Attribute):
                name = node.attr
            elif isinstance(node, ast.Constant) and isinstance(node.value,
                                                               str):
                name = node.value       # getattr(x, '_name')
            where = path.relative_to(PACKAGE).as_posix()
            if name in private and (where, name) not in ALLOWED:
                found.append(f'{where}:{node.lineno} {name}')
    assert not found, f'numba private names used: {found}'


def test_the_package_locators_stand_first_in_numbas_locator_setting():
    from numba.core import config
    ours = ['newton_euler_ros.core.kernels._jit.KernelPackage' + name
            for name in ('UserProvidedCacheLocator', 'InTreeCacheLocator',
                         'UserWideCacheLocator')]
    saved = config.CACHE_LOCATOR_CLASSES
    try:
        assert saved.split(',')[:3] == ours
        for path in ours:       # numba imports each by this name
            module, name = path.rsplit('.', 1)
            cls = getattr(importlib.import_module(module), name)
            assert issubclass(cls, getattr(caching, name[13:]))
        # numba sets the list back from the environment when a NUMBA_
        # variable changes: the package puts its own first again, before
        # numba's default list or before the user's
        config.CACHE_LOCATOR_CLASSES = ''
        assert K.package_locators()
        assert config.CACHE_LOCATOR_CLASSES.split(',') == ours + [
            'UserProvidedCacheLocator', 'InTreeCacheLocator',
            'UserWideCacheLocator', 'IPythonCacheLocator', 'ZipCacheLocator']
        config.CACHE_LOCATOR_CLASSES = 'InTreeCacheLocator'
        K.package_locators()
        assert config.CACHE_LOCATOR_CLASSES.split(',') == ours + [
            'InTreeCacheLocator']
        K.package_locators()        # once is enough
        assert config.CACHE_LOCATOR_CLASSES.split(',') == ours + [
            'InTreeCacheLocator']
    finally:
        config.CACHE_LOCATOR_CLASSES = saved


USER_MODULE = """
from numba import njit


@njit(cache=True)
def plus_one(x):
    return x + 1
"""


def test_a_users_cached_function_keeps_numbas_own_cache_place(tmp_path):
    folder = tmp_path / 'user_code'
    folder.mkdir()
    (folder / 'user_kernels.py').write_text(USER_MODULE)
    cache = tmp_path / 'cache'
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache),
               PYTHONPATH=os.pathsep.join(
                   [str(folder), os.environ.get('PYTHONPATH', '')]))
    code = ('import newton_euler_ros.core.kernels; import user_kernels; '
            'assert user_kernels.plus_one(1) == 2')
    proc = subprocess.run([sys.executable, '-W', 'ignore', '-c', code],
                          env=env, cwd=str(tmp_path), capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    place = caching.UserProvidedCacheLocator.get_suitable_cache_subpath(
        str(folder / 'user_kernels.py'))
    assert any(p.name.startswith('user_kernels.plus_one')
               for p in (cache / place).iterdir()), sorted(
        p.name for p in cache.iterdir())
    # and the package's functions have the package's places (made as
    # they are decorated: nothing of the package compiled here)
    assert any(p.name.startswith('newton_euler_ros.core.kernels-')
               for p in cache.iterdir())


def _gravity_entry(home=None):
    return calling.StrictEntry(K.run_gravity_torques, calling.PACKED,
                               calling.VEC, calling.MAT, calling.VEC,
                               home=home)


def test_one_signature_compiled_on_first_call_and_every_other_type_refused():
    arm = load_robot('puma560')
    ws = Workspace(arm)
    home = {}
    home['entry'] = entry = _gravity_entry(home)
    assert entry.dispatcher is None             # nothing made yet
    q = np.linspace(-1.0, 1.0, arm.n)
    tau = np.empty(arm.n)
    assert entry(arm.packed, q, ws.ws, tau) == -1
    # the name now holds numba's dispatcher itself
    assert home['entry'] is entry.dispatcher
    assert isinstance(home['entry'], numba.core.registry.CPUDispatcher)
    # the same torques as the public call
    np.testing.assert_array_equal(tau, gravity_torques(arm, q))
    assert len(entry.dispatcher.signatures) == 1
    read_only = q.copy()
    read_only.setflags(write=False)
    for bad in (list(q), q.astype(np.float32), np.repeat(q, 2)[::2],
                read_only, q.astype(np.int64), q.reshape(1, -1)):
        with pytest.raises(TypeError):
            home['entry'](arm.packed, bad, ws.ws, tau)
    with pytest.raises(TypeError):
        home['entry'](arm.packed, q, ws.ws, np.empty(arm.n, np.float32))
    assert len(entry.dispatcher.signatures) == 1, 'a miss compiled another'


def test_a_first_call_of_another_type_still_compiles_the_one_signature():
    arm = load_robot('puma560')
    ws = Workspace(arm)
    entry = _gravity_entry()
    with pytest.raises(TypeError):
        entry(arm.packed, [0.0] * arm.n, ws.ws, np.empty(arm.n))
    assert [str(t) for t in entry.dispatcher.signatures[0]] == [
        str(t) for t in entry.signature.args]


def test_threads_loading_one_entry_at_once_make_one_dispatcher():
    entry = _gravity_entry()
    got = []
    threads = [threading.Thread(target=lambda: got.append(entry.load()))
               for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len({id(d) for d in got}) == 1 and got[0] is entry.dispatcher


def test_the_public_calls_run_numba_dispatchers_once_loaded():
    from newton_euler_ros.core import dynamics
    arm = load_robot('puma560')
    mass_matrix(arm, np.zeros(arm.n))
    assert isinstance(dynamics._crba, numba.core.registry.CPUDispatcher)


@pytest.mark.filterwarnings('ignore::newton_euler_ros.core.errors.'
                            'SlowInputWarning')
@pytest.mark.parametrize('make', [
    lambda q: q.copy(),
    lambda q: list(q),
    lambda q: tuple(q),
    lambda q: q.astype(np.float32),
    lambda q: np.repeat(q, 2)[::2],                 # strided
    lambda q: np.frombuffer(q.tobytes()),           # read-only
])
def test_every_input_form_gives_the_same_bits(make):
    arm = load_robot('puma560')
    q = np.linspace(-1.0, 1.0, arm.n)
    qd = np.linspace(0.5, -0.5, arm.n)
    r = np.linspace(1.0, 2.0, arm.n)
    # values float32 holds exactly, so every form means the same numbers
    q, qd, r = (x.astype(np.float32).astype(np.float64) for x in (q, qd, r))
    expected = (inverse_dynamics(arm, q, qd, qd), mass_matrix(arm, q))
    got = (inverse_dynamics(arm, make(q), make(qd), make(qd)),
           mass_matrix(arm, make(q)))
    for e, g in zip(expected, got):
        assert g.dtype == np.float64
        np.testing.assert_array_equal(g, e)
    obs = MomentumObserver(arm, gain=50.0)
    np.testing.assert_array_equal(external_wrench(obs, make(q), make(r)),
                                  external_wrench(obs, q, r))


def test_an_input_numba_refuses_is_named_once_and_gives_the_same_result(
        monkeypatch):
    monkeypatch.setattr(calling, '_SLOW_SAID', [])
    arm = load_robot('puma560')
    q = np.linspace(-1.0, 1.0, arm.n)
    read_only = np.frombuffer(q.tobytes())
    with pytest.warns(SlowInputWarning, match=r'^q is a read-only array'):
        got = inverse_dynamics(arm, read_only, q)
    np.testing.assert_array_equal(got, inverse_dynamics(arm, q, q))
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        inverse_dynamics(arm, read_only, q)         # said once
        monkeypatch.setattr(calling, '_SLOW_SAID', [])
        # lists are converted before any try: nothing to say
        inverse_dynamics(arm, list(q), list(q))
        mass_matrix(arm, list(q))
    with pytest.warns(SlowInputWarning, match=r'^qd is a strided'):
        inverse_dynamics(arm, q, np.repeat(q, 2)[::2])
    monkeypatch.setattr(calling, '_SLOW_SAID', [])
    with pytest.warns(SlowInputWarning, match=r'^q is a float32 array'):
        mass_matrix(arm, q.astype(np.float32))
