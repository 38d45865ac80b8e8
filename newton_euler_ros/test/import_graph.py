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
The package's own import graph, read from its sources (test helper).

Every module is parsed with ``ast``; imports inside functions count (a
deferred import hides a cycle from Python, not from a reader).
"""
import ast
import os

PACKAGE = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                       os.pardir, 'newton_euler_ros')
PACKAGE = os.path.normpath(PACKAGE)


def modules(part):
    """{dotted name: path} of every module of ``newton_euler_ros.part``."""
    root = os.path.join(PACKAGE, part)
    out = {}
    for folder, _, files in os.walk(root):
        for name in sorted(files):
            if name.endswith('.py'):
                path = os.path.join(folder, name)
                rel = os.path.relpath(path, PACKAGE)
                dotted = 'newton_euler_ros.' + rel[:-3].replace(os.sep, '.')
                out[dotted.removesuffix('.__init__')] = path
    return out


def imports(dotted, path, known):
    """Return the modules of ``known`` one module imports, anywhere in it."""
    is_package = path.endswith('__init__.py')
    package = dotted if is_package else dotted.rsplit('.', 1)[0]
    with open(path, encoding='utf-8') as fh:
        tree = ast.parse(fh.read(), path)
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.rsplit('.', node.level - 1)[0] \
                    if node.level > 1 else package
                base = f'{base}.{node.module}' if node.module else base
            else:
                base = node.module or ''
            # "from X import Y" imports X.Y when that is a module, else X
            targets = [f'{base}.{a.name}' if f'{base}.{a.name}' in known
                       else base for a in node.names]
        else:
            continue
        found.update(t for t in targets if t in known and t != dotted)
    return found


def cycle(graph):
    """Return one cycle of ``graph`` as [a, b, ..., a], or None."""
    state = {}

    def visit(m, stack):
        state[m] = 'open'
        for t in sorted(graph[m]):
            if state.get(t) == 'open':
                return stack[stack.index(t):] + [t]
            if t not in state:
                found = visit(t, stack + [t])
                if found:
                    return found
        state[m] = 'done'
        return None

    for m in sorted(graph):
        if m not in state:
            found = visit(m, [m])
            if found:
                return found
    return None


def graph(known):
    """Return {module: the modules of ``known`` it imports}."""
    return {m: imports(m, p, known) for m, p in known.items()}
