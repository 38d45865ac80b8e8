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
(``_PackageStamp``): editing any of them recompiles every entry point.
A compiled module outside the package that calls kernel functions (the
momentum observer) registers its file with :func:`uses_kernels` before
its functions are decorated: its functions are then stamped with its own
file and all the kernel files.
"""
import os

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

_DIR = os.path.dirname(os.path.abspath(__file__))
_USERS = set()      # files outside the package whose functions call kernels


def uses_kernels(path):
    """Stamp the compiled functions of file ``path`` with the kernel files."""
    _USERS.add(os.path.abspath(path))


def package_stamp():
    """Return (name, mtime, size) of every kernel source file, sorted."""
    stamp = []
    for name in sorted(os.listdir(_DIR)):
        if name.endswith('.py'):
            st = os.stat(os.path.join(_DIR, name))
            stamp.append((name, st.st_mtime, st.st_size))
    return tuple(stamp)


def _install_package_stamp():
    """Stamp cached kernel functions with every kernel file (see above)."""
    from numba.core import caching

    stamp = package_stamp()

    def stamped(base):
        class Locator(base):
            @classmethod
            def from_function(cls, py_func, py_file):
                path = os.path.abspath(py_file)
                if os.path.dirname(path) != _DIR and path not in _USERS:
                    return None
                return super().from_function(py_func, py_file)

            def get_source_stamp(self):
                own = super().get_source_stamp()    # this function's file
                return (stamp, own)

        Locator.__name__ = f'KernelPackage{base.__name__}'
        return Locator

    impl = getattr(caching, 'CacheImpl', None) or getattr(
        caching, '_CacheImpl', None)
    classes = getattr(impl, '_locator_classes', None)
    if classes is None:     # another numba: per-file stamps, as numba has
        return
    if not any(c.__name__.startswith('KernelPackage') for c in classes):
        bases = [caching.UserProvidedCacheLocator,
                 caching.InTreeCacheLocator,
                 caching.UserWideCacheLocator]
        classes[:0] = [stamped(b) for b in bases]


if not _COPY:
    _install_package_stamp()
