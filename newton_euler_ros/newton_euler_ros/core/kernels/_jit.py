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
The compiler switch of the kernel files: ``njit``, the entry options, caching.

Every kernel file takes ``njit`` from here.  Two copies of the kernel
package exist besides the compiled one, built by
:func:`newton_euler_ros.core.kernels.load_copy` from the same files: the
50-digit reference (``njit`` the identity, so the kernels run as plain
Python on mpmath numbers) and the type-map test's uncached compilation.
They inject ``__njit_override__`` into this module before it runs.

Caching.  Numba's on-disk cache (``cache=True``) stamps each function with
its own source file only, and an entry point carries compiled copies of
the helpers it calls from the other kernel files; so every kernel
function here is stamped with all the kernel files at once
(:func:`package_stamp`): editing any of them recompiles every entry point.
A compiled module outside the package that calls kernel functions (the
momentum observer) registers its file with :func:`uses_kernels` before
its functions are decorated: its functions are then stamped with its own
file and all the kernel files.

The stamps are the files' contents (numba hashes a function's own file;
the package stamp hashes the kernel files the same way), and every
compiled function of the package is cached under a directory named by
its place in the package, not by the absolute path of the source (numba's
default), and by the digest of the sources it is stamped with
(:func:`cache_subpath`): a fresh clone of the same sources finds the
compilations of the last one (``make`` keeps them in the user's cache);
an edited file recompiles only what it stamps, in a directory of its own;
kernel caches of older sources are removed after a day, the four newest
kept.  The package's locators (numba's own kinds, taking only the
package's files) are put first in numba's documented setting for its
locator list, ``NUMBA_CACHE_LOCATOR_CLASSES`` (:func:`package_locators`):
no private numba name is used.
"""
import hashlib
import os
import shutil
import time

try:  # a copy of the kernels (highprec, the type-map test) injects its own
    njit = __njit_override__  # noqa: F821
    _COPY = True
except NameError:
    from numba import njit  # noqa: F401 (the kernels import it from here)
    _COPY = False

# Entry points are compiled without numba's reference-counting runtime
# (NRT, option ``_nrt``): they allocate nothing and keep no array past the
# call, so it has nothing to do, yet with it every call wraps each array
# argument in a freshly allocated MemInfo and counts references to the
# arguments and views at every early return, atomically (measured: about
# 0.25 us of a 0.6 us call to ``run_mass_matrix_crba`` or
# ``run_gravity_torques``).  Without NRT an allocation in an entry point
# does not compile.
ENTRY = {'cache': True, '_nrt': False}
# batch loops long enough to share among threads (``core.batch.run_split``)
# release the GIL; a single call does not (it would cost ~0.1 us a call)
BATCH = {**ENTRY, 'nogil': True}

_DIR = os.path.dirname(os.path.abspath(__file__))
_ROOT = os.path.dirname(os.path.dirname(_DIR))   # the newton_euler_ros package
_USERS = set()      # files outside the package whose functions call kernels


def uses_kernels(path):
    """Stamp the compiled functions of file ``path`` with the kernel files."""
    _USERS.add(os.path.abspath(path))


def package_stamp():
    """Return the SHA-256 of every kernel source file's name and bytes."""
    digest = hashlib.sha256()
    for name in sorted(os.listdir(_DIR)):
        if name.endswith('.py'):
            with open(os.path.join(_DIR, name), 'rb') as f:
                data = f.read()
            digest.update(f'{name}\0{len(data)}\0'.encode())
            digest.update(data)
    return digest.hexdigest()


def _file_digest(path):
    with open(path, 'rb') as f:
        return hashlib.sha256(f.read()).hexdigest()


def cache_subpath(py_file, stamp):
    """
    Return the cache directory name of a function in ``py_file``.

    In the package: ``newton_euler_ros.<its folder>-<digest>``, the digest
    that of the kernel files (``stamp``) for a function stamped with them,
    else of its own file: the same for every checkout of the same sources,
    and never shared by two versions of them (two checkouts compiling at
    once cannot read each other's files).  Elsewhere None (numba's own
    name, from the absolute path).
    """
    path = os.path.abspath(py_file)
    rel = os.path.relpath(os.path.dirname(path), _ROOT)
    if rel.startswith(os.pardir) or os.path.isabs(rel):
        return None
    place = 'newton_euler_ros' + ('' if rel == os.curdir else
                                  '.' + rel.replace(os.sep, '.'))
    try:
        digest = (stamp if os.path.dirname(path) == _DIR or path in _USERS
                  else _file_digest(path))
    except OSError:
        return None
    return f'{place}-{digest[:16]}'


def _prune(cache_dir, current, keep=4, min_age=86400.0):
    """Remove all but the newest ``keep`` kernel caches a day old or more."""
    place = current.rsplit('-', 1)[0] + '-'
    try:
        names = [n for n in os.listdir(cache_dir)
                 if n.startswith(place) and n != current]
        dated = sorted(((os.stat(os.path.join(cache_dir, n)).st_mtime, n)
                        for n in names), reverse=True)
    except OSError:
        return
    now = time.time()
    for mtime, name in dated[keep - 1:]:
        if now - mtime >= min_age:
            shutil.rmtree(os.path.join(cache_dir, name), ignore_errors=True)


# numba's locators the package's stand before (the first that takes a
# file places its functions); a user's NUMBA_CACHE_LOCATOR_CLASSES stands
# after them instead, and otherwise numba's default list does (as numba
# 0.68 orders it)
_BASES = ('UserProvidedCacheLocator', 'InTreeCacheLocator',
          'UserWideCacheLocator')
_DEFAULTS = _BASES + ('IPythonCacheLocator', 'ZipCacheLocator')
_LOCATORS = []      # the package's locator classes, made once
_STAMP = [None]


def _stamped(base):
    """Return a locator of ``base``'s kind for the package's files only."""

    class Locator(base):
        def __init__(self, py_func, py_file):
            super().__init__(py_func, py_file)
            self.source_file = os.path.abspath(py_file)

        @classmethod
        def from_function(cls, py_func, py_file):
            if cache_subpath(py_file, _STAMP[0]) is None:
                return None         # not ours: numba's own locators
            return super().from_function(py_func, py_file)

        @classmethod
        def get_suitable_cache_subpath(cls, py_file):
            return cache_subpath(py_file, _STAMP[0])

        def get_source_stamp(self):
            own = super().get_source_stamp()    # this function's file
            path = self.source_file
            if os.path.dirname(path) != _DIR and path not in _USERS:
                return own
            return (_STAMP[0], own)

    Locator.__name__ = Locator.__qualname__ = f'KernelPackage{base.__name__}'
    return Locator


def package_locators():
    """
    Put the package's cache locators first in numba's configuration.

    Through numba's own setting, ``numba.core.config.CACHE_LOCATOR_CLASSES``
    (the ``NUMBA_CACHE_LOCATOR_CLASSES`` variable): a comma-separated
    list of locator classes, each named by its module path, the first
    that takes a function's file placing it.  The package's take only
    its own files, so every other function keeps numba's locators (the
    user's list, or numba's default one, after ours).  numba reads the
    setting when a function is decorated with ``cache=True``: called on
    import and again before each entry compiles (``core.calling``), since
    numba sets it back from the environment when a ``NUMBA_`` variable
    changes.  A numba without the setting keeps its own stamps (a fresh
    clone then recompiles).  Returns whether the setting is there.
    """
    from numba.core import config
    current = getattr(config, 'CACHE_LOCATOR_CLASSES', None)
    if current is None or _COPY:
        return False
    if not _LOCATORS:
        from numba.core import caching
        for name in _BASES:
            cls = _stamped(getattr(caching, name))
            globals()[cls.__name__] = cls   # numba imports it by this name
            _LOCATORS.append(cls)
    ours = [f'{__name__}.{cls.__name__}' for cls in _LOCATORS]
    names = [n.strip() for n in current.split(',') if n.strip()]
    if names[:len(ours)] != ours:
        rest = [n for n in names if n not in ours] or list(_DEFAULTS)
        config.CACHE_LOCATOR_CLASSES = ','.join(ours + rest)
    return True


def _install_package_stamp():
    """Stamp and place the package's cached functions (see above)."""
    _STAMP[0] = package_stamp()
    if not package_locators():
        return
    from numba.core import config
    if config.CACHE_DIR:
        _prune(config.CACHE_DIR, cache_subpath(os.path.join(_DIR, '_jit.py'),
                                               _STAMP[0]))


if not _COPY:
    _install_package_stamp()
