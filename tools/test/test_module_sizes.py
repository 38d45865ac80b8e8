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

"""No module of the tools is longer than MAX_LINES."""
from pathlib import Path

import newton_euler_tools

MAX_LINES = 600


def test_no_tools_module_is_too_long():
    root = Path(newton_euler_tools.__file__).parent
    long = {}
    for path in sorted(root.rglob('*.py')):
        name = path.relative_to(root).as_posix()
        lines = len(path.read_text(encoding='utf-8').splitlines())
        if lines > MAX_LINES:
            long[name] = lines
    assert not long, (f'modules over {MAX_LINES} lines (split them into '
                      f'set-up, measure and report): {long}')
