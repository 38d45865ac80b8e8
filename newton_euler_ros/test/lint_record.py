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
Lint passes recorded per file, so a file is linted once per content.

flake8 (with every plugin ament_flake8 enables) and pydocstyle read one
file at a time: a file that passed before, byte for byte the same, under
the same path, with the same installed linters and configuration, passes
again.  Linting all of the package and tools/ costs about 100 s of CPU on
this machine, most of it on files nobody changed.  The record is a list
of such files' digests under a digest of the linters' versions (every
installed distribution's name and version, Python's, and the caller's
own source, which holds its options), in the user's cache beside
numba's.  ``NEWTON_EULER_RECHECK=1`` lints every file again.
"""
import hashlib
import importlib.metadata
import inspect
import os
import sys


def python_files(paths):
    """
    Return the .py files below ``paths``, as the ament linters find them.

    Folders whose names start with '.' or '_' are skipped (both linters
    skip them, and __pycache__ with them); the order is sorted.
    """
    found = []
    for top in paths:
        for dirpath, dirnames, filenames in os.walk(top):
            dirnames[:] = sorted(d for d in dirnames if d[0] not in '._')
            found.extend(os.path.join(dirpath, f) for f in sorted(filenames)
                         if f.endswith('.py'))
    return found


def _file_digest(path):
    digest = hashlib.sha256(os.path.normpath(path).encode() + b'\0')
    with open(path, 'rb') as fh:
        digest.update(fh.read())
    return digest.hexdigest()


def record_path(tool, caller):
    """Return the record of ``tool``'s passes for the linters installed."""
    digest = hashlib.sha256(sys.version.encode())
    for dist in sorted(f'{d.metadata["Name"]}=={d.version}'
                       for d in importlib.metadata.distributions()):
        digest.update(dist.encode() + b'\0')
    digest.update(inspect.getsource(caller).encode())
    with open(__file__, 'rb') as fh:
        digest.update(fh.read())
    base = os.environ.get('XDG_CACHE_HOME') or os.path.expanduser('~/.cache')
    return os.path.join(base, 'newton_euler_ros', 'lint-passed',
                        f'{tool}-{digest.hexdigest()[:32]}')


def not_passed(record, files):
    """Return the files of ``files`` the record has no pass for."""
    if os.environ.get('NEWTON_EULER_RECHECK') == '1':
        return list(files)
    try:
        with open(record, encoding='ascii') as fh:
            passed = set(fh.read().split())
    except OSError:
        passed = set()
    return [f for f in files if _file_digest(f) not in passed]


def record_passed(record, files):
    """Add ``files`` (each just passed) to the record, if it can be kept."""
    try:
        os.makedirs(os.path.dirname(record), exist_ok=True)
        with open(record, 'a', encoding='ascii') as fh:
            fh.write(''.join(_file_digest(f) + '\n' for f in files))
    except OSError:         # a read-only cache: the next run lints again
        pass
