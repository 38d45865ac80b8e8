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

"""package.xml declares every module the installed package imports."""
import ast
import os
import re
import sys
import xml.etree.ElementTree as ET  # noqa: N817 (our own file)

PACKAGE = os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))))
SOURCE = os.path.join(PACKAGE, 'newton_euler_ros')


def imported_modules():
    """{top-level third-party module: first file importing it}."""
    found = {}
    for folder, _, files in os.walk(SOURCE):
        for name in sorted(files):
            if not name.endswith('.py'):
                continue
            path = os.path.join(folder, name)
            with open(path, encoding='utf-8') as fh:
                tree = ast.parse(fh.read(), path)
            for node in ast.walk(tree):
                if isinstance(node, ast.Import):
                    names = [a.name for a in node.names]
                elif isinstance(node, ast.ImportFrom) and node.level == 0:
                    names = [node.module]
                else:
                    continue
                for top in (n.split('.')[0] for n in names):
                    if top not in sys.stdlib_module_names \
                            and top != 'newton_euler_ros':
                        found.setdefault(top, os.path.relpath(path, PACKAGE))
    return found


def rosdep_key(module):
    """Return the rosdep key of a module: a ROS package's name, else python3-."""
    ros = module in ('rclpy', 'rcl_interfaces') or module.endswith(
        ('_msgs', '_interfaces'))
    return module if ros else f'python3-{module}'


def test_every_imported_module_is_declared_or_named():
    text = open(os.path.join(PACKAGE, 'package.xml'), encoding='utf-8').read()
    root = ET.fromstring(text)
    exec_keys = {e.text for e in root.findall('exec_depend')}
    # the comment that names what is imported but not declared
    comments = ' '.join(c for c in re.findall(r'<!--(.*?)-->', text, re.S)
                        if 'Not declared here' in c)
    missing = {m: where for m, where in imported_modules().items()
               if rosdep_key(m) not in exec_keys
               and not re.search(rf'\b{re.escape(m)}\b', comments)}
    assert not missing, (
        'package.xml: add an <exec_depend> (or name the module in its '
        f'comment, when it is optional or pip-only) for {missing}')
    # the check sees what it must: the core's own dependencies
    assert {'numpy', 'numba', 'rclpy', 'rosbags'} <= set(imported_modules())
