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

"""ament_copyright (copyright and license headers) over package + tools/."""
import os

import pytest

# ament_copyright has no PyPI wheel: this runs under an apt (or source) ROS 2
# install and is skipped in the project's virtualenv.
main = pytest.importorskip('ament_copyright.main').main

PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))))
# the tools beside the package (tools/ of the repository), when present
TOOLS = os.path.join(os.pardir, 'tools')
PATHS = ['.'] + ([TOOLS] if os.path.isdir(os.path.join(PACKAGE_DIR, TOOLS))
                 else [])


@pytest.mark.copyright
@pytest.mark.linter
def test_copyright(monkeypatch):
    # Paths are relative to the package directory, not pytest's cwd.
    monkeypatch.chdir(PACKAGE_DIR)
    rc = main(argv=['.', 'test', *PATHS[1:]])
    assert rc == 0, 'Found errors'
