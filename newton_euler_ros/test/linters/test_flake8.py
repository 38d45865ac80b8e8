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
ament_flake8 (the ROS 2 flake8 configuration) over the package + tools/.

Each file is linted once per content (``lint_record``): a file that
passed with the same bytes and linters passes again unread.
"""
import os

from ament_flake8.main import main_with_errors
from lint_record import not_passed, python_files, record_passed, \
    record_path
import pytest

PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))))
# the tools beside the package (tools/ of the repository), when present
TOOLS = os.path.join(os.pardir, 'tools')
PATHS = ['.'] + ([TOOLS] if os.path.isdir(os.path.join(PACKAGE_DIR, TOOLS))
                 else [])


@pytest.mark.flake8
@pytest.mark.linter
def test_flake8(monkeypatch):
    # ament_flake8 lints the current directory; `make test` runs pytest from
    # the repository root, so lint from the package directory instead.
    monkeypatch.chdir(PACKAGE_DIR)
    record = record_path('flake8', test_flake8)
    files = not_passed(record, python_files(PATHS))
    print(f'{len(files)} files to lint (the others passed as they are)')
    if not files:
        return
    rc, errors = main_with_errors(argv=files)
    assert rc == 0, \
        'Found %d code style errors / warnings:\n' % len(errors) + \
        '\n'.join(errors)
    record_passed(record, files)
