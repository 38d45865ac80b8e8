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
Imports inside ``ident``, ``core`` and ``sim`` point one way.

Every module of each package is parsed with ``ast`` (imports inside
functions count: a deferred import hides a cycle from Python, not from a
reader), the package's own import graph is built and searched for a
cycle, which the failure prints (``constants -> effort -> fit ->
constants`` before ``fit.predict`` moved to ``ident.torques``; in
``sim``, ``simulate -> mujoco_scene -> simulate`` before the engine
choice moved to ``sim.run``).  Inside ``core``, the packages
``observer`` and ``urdf`` re-export their modules' names, and no module
of theirs imports its own package.
"""
import import_graph as ig
import pytest


@pytest.mark.parametrize('part', ['ident', 'core', 'sim'])
def test_no_import_cycle(part):
    modules = ig.modules(part)
    assert len(modules) > 3, modules        # the walk sees the package
    cycle = ig.cycle(ig.graph(modules))
    assert cycle is None, (f'import cycle in {part}: ' + ' -> '.join(
        m.removeprefix(f'newton_euler_ros.{part}.') for m in cycle))


def test_ident_steps_import_in_one_direction():
    """The edges this layout relies on (the old circle's own modules)."""
    graph = ig.graph(ig.modules('ident'))
    ident = 'newton_euler_ros.ident.'
    assert ident + 'effort' in graph[ident + 'fit']
    assert ident + 'constants' in graph[ident + 'fit']
    assert ident + 'effort' in graph[ident + 'constants']
    assert ident + 'fit' not in graph[ident + 'effort']
    assert graph[ident + 'torques'] == set()


@pytest.mark.parametrize('package, modules', [
    ('observer', {'momentum', 'contact', 'motion', 'thresholds', 'wrench',
                  'wrenches'}),
    ('urdf', {'read', 'chain', 'tree', 'whole', 'writer'}),
])
def test_core_packages_import_their_modules_never_themselves(package,
                                                             modules):
    """``core.observer``, ``core.urdf``: the package re-exports, one way."""
    graph = ig.graph(ig.modules('core'))
    top = f'newton_euler_ros.core.{package}'
    members = {m for m in graph if m.startswith(top + '.')}
    assert members == {f'{top}.{m}' for m in modules}
    assert graph[top] <= members
    assert [m for m in members if top in graph[m]] == []


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
    graph = ig.graph({m: str(p) for m, p in mods.items()})
    assert graph == {
        'newton_euler_ros.ident': set(),
        'newton_euler_ros.ident.a': {'newton_euler_ros.ident.b',
                                     'newton_euler_ros.ident.c'},
        'newton_euler_ros.ident.b': {'newton_euler_ros.ident.a'},
        'newton_euler_ros.ident.c': set()}
    assert ig.cycle(graph) == ['newton_euler_ros.ident.a',
                               'newton_euler_ros.ident.b',
                               'newton_euler_ros.ident.a']
    del graph['newton_euler_ros.ident.b']
    graph['newton_euler_ros.ident.a'].discard('newton_euler_ros.ident.b')
    assert ig.cycle(graph) is None
