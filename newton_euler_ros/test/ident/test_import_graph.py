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
Imports inside ``ident`` and ``core`` point one way.

Every module of each package is parsed with ``ast`` (imports inside
functions count: a deferred import hides a cycle from Python, not from a
reader), the package's own import graph is built and searched for a
cycle, which the failure prints (``constants -> effort -> fit ->
constants`` before ``fit.predict`` moved to ``ident.torques``).  ``sim``
is not checked yet: ``simulate`` imports ``mujoco_scene`` in a function
and ``mujoco_scene`` imports ``simulate``.
"""
import ast
import os

import pytest

PACKAGE = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), 'newton_euler_ros')


def _modules(part):
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


def _imports(dotted, path, modules):
    """Return the modules of ``modules`` one module imports, anywhere in it."""
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
            targets = [f'{base}.{a.name}' if f'{base}.{a.name}' in modules
                       else base for a in node.names]
        else:
            continue
        found.update(t for t in targets if t in modules and t != dotted)
    return found


def _cycle(graph):
    """One cycle of ``graph`` as [a, b, ..., a], or None."""
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


def _graph(modules):
    return {m: _imports(m, p, modules) for m, p in modules.items()}


@pytest.mark.parametrize('part', ['ident', 'core'])
def test_no_import_cycle(part):
    modules = _modules(part)
    assert len(modules) > 3, modules        # the walk sees the package
    cycle = _cycle(_graph(modules))
    assert cycle is None, (f'import cycle in {part}: ' + ' -> '.join(
        m.removeprefix(f'newton_euler_ros.{part}.') for m in cycle))


def test_ident_steps_import_in_one_direction():
    """The edges this layout relies on (the old circle's own modules)."""
    graph = _graph(_modules('ident'))
    ident = 'newton_euler_ros.ident.'
    assert ident + 'effort' in graph[ident + 'fit']
    assert ident + 'constants' in graph[ident + 'fit']
    assert ident + 'effort' in graph[ident + 'constants']
    assert ident + 'fit' not in graph[ident + 'effort']
    assert graph[ident + 'torques'] == set()


def test_the_cycle_check_sees_a_cycle(tmp_path):
    """A circle closed by an import inside a function, and a package's."""
    mods = {'newton_euler_ros.ident': tmp_path / '__init__.py',
            'newton_euler_ros.ident.a': tmp_path / 'a.py',
            'newton_euler_ros.ident.b': tmp_path / 'b.py',
            'newton_euler_ros.ident.c': tmp_path / 'c.py'}
    mods['newton_euler_ros.ident'].write_text('')
    mods['newton_euler_ros.ident.a'].write_text(
        'from . import b as other\nfrom .c import h\n')
    mods['newton_euler_ros.ident.b'].write_text(
        'def f():\n    from .a import g\n')
    mods['newton_euler_ros.ident.c'].write_text('import numpy\n')
    graph = _graph({m: str(p) for m, p in mods.items()})
    assert graph == {
        'newton_euler_ros.ident': set(),
        'newton_euler_ros.ident.a': {'newton_euler_ros.ident.b',
                                     'newton_euler_ros.ident.c'},
        'newton_euler_ros.ident.b': {'newton_euler_ros.ident.a'},
        'newton_euler_ros.ident.c': set()}
    assert _cycle(graph) == ['newton_euler_ros.ident.a',
                             'newton_euler_ros.ident.b',
                             'newton_euler_ros.ident.a']
    del graph['newton_euler_ros.ident.b']
    graph['newton_euler_ros.ident.a'].discard('newton_euler_ros.ident.b')
    assert _cycle(graph) is None
