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
ament_pep257 (docstring conventions) over the package + tools/.

Each file is checked once per content (``lint_record``).
"""
import os

from ament_pep257.main import main
from lint_record import not_passed, python_files, record_passed, \
    record_path
import pytest

PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))))
# the tools beside the package (tools/ of the repository), when present
TOOLS = os.path.join(os.pardir, 'tools')
PATHS = ['.'] + ([TOOLS] if os.path.isdir(os.path.join(PACKAGE_DIR, TOOLS))
                 else [])


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257(monkeypatch):
    # Paths are relative to the package directory, not pytest's cwd.
    monkeypatch.chdir(PACKAGE_DIR)
    record = record_path('pep257', test_pep257)
    files = not_passed(record, python_files(PATHS))
    print(f'{len(files)} files to check (the others passed as they are)')
    if not files:
        return
    rc = main(argv=files)
    assert rc == 0, 'Found code style errors / warnings'
    record_passed(record, files)
