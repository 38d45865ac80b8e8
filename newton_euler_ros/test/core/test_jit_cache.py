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
numba's cache is found again by a fresh checkout of the same sources.

numba names a cache directory after the absolute path of the source, so
every fresh clone (CI, a colcon build, a user's second checkout) would
compile everything again; ``kernels._jit`` names it after the file's
place in the package and the digest of the sources it is stamped with.
"""
import hashlib
import os
import shutil
import subprocess
import sys

from newton_euler_ros.core.kernels import _jit
import pytest

CALL = ('import newton_euler_ros.core as c; '
        'c.gravity_torques(c.load_robot("planar_2r"), [0.1, 0.2])')


def _run(env, cwd):
    proc = subprocess.run([sys.executable, '-W', 'ignore', '-c', CALL],
                          env=env, cwd=cwd, capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout + proc.stderr


def test_cache_names_do_not_depend_on_where_the_sources_are():
    stamp = _jit.package_stamp()
    kernel = os.path.join(_jit._DIR, 'crba.py')
    assert _jit.cache_subpath(kernel, stamp) == (
        f'newton_euler_ros.core.kernels-{stamp[:16]}')
    excite = os.path.join(_jit._ROOT, 'ident', 'excite.py')
    with open(excite, 'rb') as f:
        digest = hashlib.sha256(f.read()).hexdigest()
    assert _jit.cache_subpath(excite, stamp) == (
        f'newton_euler_ros.ident-{digest[:16]}')
    assert _jit.cache_subpath(__file__, stamp) is None    # not the package


@pytest.mark.slow
def test_a_copy_of_the_package_elsewhere_loads_what_the_first_compiled(
        tmp_path):
    # the cache make test uses (compiled there now if it was not yet)
    env = {k: v for k, v in os.environ.items() if k != 'PYTHONPATH'}
    env['NUMBA_DEBUG_CACHE'] = '1'
    first = _run(env, str(tmp_path))
    assert 'run_gravity_torques' in first
    copy = tmp_path / 'elsewhere'
    shutil.copytree(_jit._ROOT, copy / 'newton_euler_ros',
                    ignore=shutil.ignore_patterns('__pycache__'))
    env['PYTHONPATH'] = str(copy)
    second = _run(env, str(tmp_path))
    assert 'data saved' not in second, second[-3000:]
    assert 'data loaded' in second
    # and the copy really was the package imported
    probe = subprocess.run(
        [sys.executable, '-c', 'import newton_euler_ros; '
         'print(newton_euler_ros.__file__)'], env=env, cwd=str(tmp_path),
        capture_output=True, text=True, timeout=120)
    assert probe.stdout.strip().startswith(str(copy)), probe.stdout


def test_make_setup_compiled_the_kernels_ahead():
    """
    ``make setup`` ran ``python -m newton_euler_ros.precompile``.

    Its stamp for these sources is in the cache the tests use, and a
    second run returns at once, without importing numba.
    """
    from newton_euler_ros import precompile
    assert os.path.exists(precompile.stamp_path()), (
        'no precompile stamp: make setup did not compile the kernels ahead')
    code = ('import sys; from newton_euler_ros import precompile; '
            'assert precompile.main([]) == 0; '
            'assert "numba" not in sys.modules, "numba imported"')
    proc = subprocess.run([sys.executable, '-c', code], capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout == '', proc.stdout
