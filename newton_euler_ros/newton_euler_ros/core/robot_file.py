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
Robot description files (YAML): loading, validation, bundled robots.

The format is documented in the README ("Robot files").  Every error is a
:class:`RobotFileError` whose message names the file, the link and the
field.  Numbers may be written as YAML numbers, as strings that parse as
numbers (PyYAML reads ``1e-5`` without a dot as a string) or as simple
expressions of ``pi`` such as ``-pi/2`` or ``3*pi/4``.
"""
import ast
import math
import operator
import os
import sys
import warnings

import numpy as np
import yaml

from .calling import first_singular_pivot
from .dynamics import mass_matrix
from .errors import DynamicsInputError, RobotFileError, RobotFileWarning
from .inertia import (format_moments, inertia_matrix, is_symmetric, Note,
                      principal_moments, triangle_note)
from .model import (make_model, MODIFIED, pose_matrix, PRISMATIC, REVOLUTE,
                    STANDARD)
from .text import clip_repr as _short, MAX_FILE_BYTES, read_text
from .urdf import inspect_urdf

__all__ = ['MAX_FILE_BYTES', 'Note', 'RobotFileWarning', 'read_text',
           'triangle_note', 'bundled_robots', 'inspect_robot', 'load_robot',
           'robot_from_dict']

TOP_KEYS = {'name', 'description', 'source', 'convention', 'gravity', 'base',
            'tool', 'links'}
LINK_KEYS = {'name', 'description', 'type', 'a', 'alpha', 'd', 'theta',
             'mass', 'com', 'inertia', 'limits'}
LINK_REQUIRED = ('name', 'type', 'a', 'alpha', 'd', 'mass', 'com', 'inertia')
LIMIT_KEYS = {'lower', 'upper', 'velocity', 'effort'}
POSE_KEYS = {'xyz', 'rpy'}


def bundled_dirs():
    """Folders searched for bundled robot files, in order."""
    here = os.path.dirname(os.path.abspath(__file__))
    return [
        os.path.normpath(os.path.join(here, '..', '..', 'config', 'robots')),
        os.path.join(sys.prefix, 'share', 'newton_euler_ros', 'config',
                     'robots'),
    ]


def bundled_robots():
    """Names of the bundled robots (file names without ``.yaml``)."""
    names = set()
    for folder in bundled_dirs():
        if os.path.isdir(folder):
            names.update(f[:-5] for f in os.listdir(folder)
                         if f.endswith('.yaml'))
    return sorted(names)


def resolve_robot_path(name_or_path):
    """Return the path of an existing file, or of the bundled robot so named."""
    path = os.fspath(name_or_path)
    if os.path.isfile(path):
        return path
    if os.path.isdir(path):
        raise RobotFileError(f'{_short(path)}: is a directory, not a robot '
                             f'file')
    if os.sep not in path and not path.endswith(('.yaml', '.yml')):
        for folder in bundled_dirs():
            candidate = os.path.join(folder, path + '.yaml')
            if os.path.isfile(candidate):
                return candidate
    raise RobotFileError(
        f'{_short(path)}: no such file, and not a bundled robot '
        f'(bundled: {", ".join(bundled_robots()) or "none found"})')


MAX_DEPTH = 32                   # they nest 4 levels deep


class _SafeLoader(yaml.SafeLoader):
    """
    SafeLoader for files from people and networks.

    Rejects a key given twice in one mapping, anchors and aliases (a robot
    file has no use for them, and they are how a few bytes expand into
    gigabytes) and nesting deeper than MAX_DEPTH (which would otherwise
    end in a RecursionError).
    """

    def compose_node(self, parent, index):
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent) or getattr(
                event, 'anchor', None) is not None:
            raise yaml.constructor.ConstructorError(
                None, None, 'anchors and aliases (& and *) are not '
                'accepted', event.start_mark)
        self._depth = getattr(self, '_depth', 0) + 1
        try:
            if self._depth > MAX_DEPTH:
                raise yaml.constructor.ConstructorError(
                    None, None, f'nested more than {MAX_DEPTH} levels deep',
                    event.start_mark)
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


def _construct_mapping(loader, node, deep=False):
    seen = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise yaml.constructor.ConstructorError(
                None, None, f'key {_short(key)!r} appears twice',
                key_node.start_mark)
        seen.add(key)
    return loader.construct_mapping(node, deep)


_SafeLoader.add_constructor(
    yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)


def read_yaml(path):
    """Parse a YAML file, with errors that name the file and the line."""
    text = read_text(path, what='YAML file')
    try:
        data = yaml.load(text, Loader=_SafeLoader)
    except yaml.YAMLError as exc:
        where = ''
        mark = getattr(exc, 'problem_mark', None)
        if mark is not None:
            where = f' (line {mark.line + 1}, column {mark.column + 1})'
        problem = getattr(exc, 'problem', None) or str(exc)
        raise RobotFileError(f'{_short(path)}: not valid YAML{where}: '
                             f'{_short(problem)}') from None
    except RecursionError:      # belt and braces: the loader caps depth
        raise RobotFileError(f'{_short(path)}: nested too deeply') from None
    if not isinstance(data, dict):
        raise RobotFileError(f'{_short(path)}: must be a mapping of keys '
                             f'(name, links, ...), not a '
                             f'{type(data).__name__}')
    return data


_OPS = {ast.Add: operator.add, ast.Sub: operator.sub,
        ast.Mult: operator.mul, ast.Div: operator.truediv}


def _eval_expr(node):
    if isinstance(node, ast.Expression):
        return _eval_expr(node.body)
    if isinstance(node, ast.Constant) and type(node.value) in (int, float):
        return float(node.value)
    if isinstance(node, ast.Name) and node.id == 'pi':
        return math.pi
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub,
                                                              ast.UAdd)):
        value = _eval_expr(node.operand)
        return -value if isinstance(node.op, ast.USub) else value
    if isinstance(node, ast.BinOp) and type(node.op) in _OPS:
        return _OPS[type(node.op)](_eval_expr(node.left),
                                   _eval_expr(node.right))
    raise ValueError('not a number')


def to_number(value, where):
    """Return a finite float from a YAML value; raise RobotFileError naming where."""
    if isinstance(value, bool) or value is None:
        raise RobotFileError(f'{where}: must be a number, got {_short(value)!r}')
    if isinstance(value, (int, float)):
        result = float(value)
    elif isinstance(value, str):
        text = value.strip()
        try:
            result = float(text)
        except ValueError:
            try:
                result = _eval_expr(ast.parse(text, mode='eval'))
            except (SyntaxError, ValueError, ZeroDivisionError,
                    RecursionError):
                raise RobotFileError(
                    f'{where}: must be a number (or an expression of pi '
                    f'like "-pi/2"), got {_short(value)!r}') from None
    else:
        raise RobotFileError(
            f'{where}: must be a number, got {type(value).__name__} '
            f'{_short(value)!r}')
    if not math.isfinite(result):
        raise RobotFileError(f'{where}: must be finite, got {_short(value)!r}')
    return result


def to_vector(value, size, where):
    """Return a YAML list of ``size`` numbers as a list of finite floats."""
    if not isinstance(value, (list, tuple)):
        raise RobotFileError(
            f'{where}: must be a list of {size} numbers, got {_short(value)!r}')
    if len(value) != size:
        raise RobotFileError(
            f'{where}: must have {size} entries, got {len(value)}')
    return [to_number(x, f'{where}[{i}]') for i, x in enumerate(value)]


def _check_keys(data, allowed, where):
    if not isinstance(data, dict):
        raise RobotFileError(f'{where}: must be a mapping, got {_short(data)!r}')
    unknown = sorted(set(map(str, data)) - allowed)
    if unknown:
        raise RobotFileError(
            f'{where}: unknown key {_short(unknown[0])!r} '
            f'(allowed: {", ".join(sorted(allowed))})')


def _pose(data, where):
    _check_keys(data, POSE_KEYS, where)
    xyz = to_vector(data.get('xyz', [0.0, 0.0, 0.0]), 3, f'{where}.xyz')
    rpy = to_vector(data.get('rpy', [0.0, 0.0, 0.0]), 3, f'{where}.rpy')
    return pose_matrix(xyz, rpy)


def _inertia(value, where):
    if isinstance(value, (list, tuple)) and len(value) == 3 and all(
            isinstance(r, (list, tuple)) for r in value):
        rows = [to_vector(r, 3, f'{where}[{i}]') for i, r in enumerate(value)]
        inertia = np.array(rows)
        if not is_symmetric(inertia):
            raise RobotFileError(f'{where}: must be symmetric, got {rows}')
        inertia = 0.5 * (inertia + inertia.T)
    else:
        inertia = inertia_matrix(*to_vector(value, 6, where))
    eig, valid = principal_moments(inertia)
    if not valid:
        raise RobotFileError(
            f'{where}: must be positive semidefinite (principal moments '
            f'{format_moments(eig)})')
    return inertia, eig


def _limits(data, where):
    _check_keys(data, LIMIT_KEYS, where)
    out = {k: to_number(v, f'{where}.{k}') for k, v in data.items()}
    if 'lower' in out and 'upper' in out and out['lower'] > out['upper']:
        raise RobotFileError(
            f'{where}: lower ({out["lower"]}) is above upper '
            f'({out["upper"]})')
    for key in ('velocity', 'effort'):
        if key in out and out[key] <= 0.0:
            raise RobotFileError(f'{where}.{key}: must be > 0, '
                                 f'got {out[key]}')
    return out


def robot_from_dict(data, origin='<robot>'):
    """
    Validate a parsed robot description; return (model, warnings).

    ``origin`` (usually the file name) starts every error message.
    """
    found = []
    _check_keys(data, TOP_KEYS, origin)
    for key in ('name', 'convention', 'links'):
        if key not in data:
            raise RobotFileError(f'{origin}: missing required key {key!r}')
    name = data['name']
    if not isinstance(name, str) or not name.strip():
        raise RobotFileError(f'{origin}: name: must be a non-empty string')
    convention = data['convention']
    if convention not in (STANDARD, MODIFIED):
        raise RobotFileError(
            f"{origin}: convention: must be 'standard' or 'modified', "
            f'got {_short(convention)!r}')
    gravity = to_vector(data.get('gravity', [0.0, 0.0, -9.81]), 3,
                        f'{origin}: gravity')
    base = _pose(data['base'], f'{origin}: base') if 'base' in data else None
    tool = _pose(data['tool'], f'{origin}: tool') if 'tool' in data else None
    links = data['links']
    if not isinstance(links, list) or not links:
        raise RobotFileError(f'{origin}: links: must be a non-empty list')
    cols = {k: [] for k in ('joint_names', 'joint_types', 'a', 'alpha', 'd',
                            'theta', 'mass', 'com', 'inertia', 'limits')}
    for j, link in enumerate(links):
        label = link.get('name') if isinstance(link, dict) else None
        where = f'{origin}: links[{j}]' + (f' ({label})' if label else '')
        _check_keys(link, LINK_KEYS, where)
        for key in LINK_REQUIRED:
            if key not in link:
                raise RobotFileError(f'{where}: missing required key {key!r}')
        jname = link['name']
        if not isinstance(jname, str) or not jname.strip():
            raise RobotFileError(f'{where}: name: must be a non-empty string')
        if jname in cols['joint_names']:
            raise RobotFileError(
                f'{where}: name: {_short(jname)!r} is used by an earlier link; '
                f'joint names must be unique')
        jtype = link['type']
        if jtype not in (REVOLUTE, PRISMATIC):
            raise RobotFileError(
                f"{where}: type: must be 'revolute' or 'prismatic', "
                f'got {_short(jtype)!r}')
        cols['joint_names'].append(jname)
        cols['joint_types'].append(jtype)
        for key in ('a', 'alpha', 'd'):
            cols[key].append(to_number(link[key], f'{where}: {key}'))
        cols['theta'].append(to_number(link.get('theta', 0.0),
                                       f'{where}: theta'))
        mass = to_number(link['mass'], f'{where}: mass')
        if mass < 0.0:
            raise RobotFileError(f'{where}: mass: must be >= 0, got {mass}')
        cols['mass'].append(mass)
        com = to_vector(link['com'], 3, f'{where}: com')
        cols['com'].append(com)
        inertia, eig = _inertia(link['inertia'], f'{where}: inertia')
        cols['inertia'].append(inertia)
        note = triangle_note(f'{where}: inertia', eig)
        if note:
            found.append(note)
        if mass == 0.0 and any(c != 0.0 for c in com):
            found.append(f'{where}: com: given for a link of zero mass; '
                         f'it has no effect')
        cols['limits'].append(_limits(link['limits'], f'{where}: limits')
                              if 'limits' in link else {})
    model = make_model(name=name, convention=convention, gravity=gravity,
                       base=base, tool=tool, **cols)
    return model, found


def singular_joint_warning(model, origin, samples=3, seed=0):
    """
    Return a warning when D(q) is singular everywhere (naming the joint).

    D loses rank when the links from some joint to the tip carry no mass
    or inertia that the joint can move (a massless tail, a zero-inertia
    last link on a revolute joint).  Inverse dynamics still works; forward
    dynamics, the simulator and ``check``'s condition number cannot.
    Tested at a few random configurations (singular at all of them, not
    at an isolated pose).
    """
    rng = np.random.default_rng(seed)
    joints = set()
    for _ in range(samples):
        q = rng.uniform(-1.0, 1.0, model.n)
        try:
            D = mass_matrix(model, q)
        except DynamicsInputError:
            return None
        bad = first_singular_pivot(D)
        if bad is None:
            return None
        joints.add(bad)
    j = min(joints)
    return (f'{origin}: joint {model.joint_names[j]!r}: the mass matrix D(q) '
            f'is singular there (the links it moves carry no mass or '
            f'inertia about its axis): inverse dynamics works, forward '
            f'dynamics and simulation do not')


def is_urdf(name_or_path):
    """
    Return True for a path that names a URDF file.

    A ``.urdf`` path, or a file of any other name whose text starts with
    ``<`` (XML, which a robot YAML file never is): a URDF saved as
    ``.xml``, or a xacro file, which the URDF reader then refuses in one
    line.
    """
    path = os.fspath(name_or_path)
    if path.lower().endswith('.urdf'):
        return True
    if not os.path.isfile(path):
        return False
    try:
        with open(path, 'rb') as fh:
            head = fh.read(4096)
    except OSError:
        return False            # the YAML reader says why
    return head.decode('utf-8', 'ignore').lstrip('\ufeff \t\r\n') \
        .startswith('<')


def inspect_robot(name_or_path, base=None, tip=None):
    """
    Load and validate a robot; return (model, warnings, path).

    A URDF file (:func:`is_urdf`: ``.urdf``, or XML under another name)
    is read by :func:`~newton_euler_ros.core.urdf.inspect_urdf` with its
    ``base`` and ``tip`` links (what it made of the tree is in
    ``model.info['urdf']``); anything else is a robot YAML file or a
    bundled name, for which ``base`` and ``tip`` must be None.
    """
    if is_urdf(name_or_path):
        model, found, _ = inspect_urdf(name_or_path, base=base, tip=tip)
        path = str(name_or_path)
    else:
        if base is not None or tip is not None:
            raise RobotFileError(f'{name_or_path}: base and tip links apply '
                                 f'to URDF robots only')
        path = resolve_robot_path(name_or_path)
        data = read_yaml(path)
        model, found = robot_from_dict(data, os.path.basename(path))
    singular = singular_joint_warning(model, os.path.basename(path))
    if singular:
        found.append(singular)
    return model, found, path


def load_robot(name_or_path, base=None, tip=None):
    """
    Load a robot: a YAML file, a bundled name (``'puma560'``) or a URDF.

    A ``.urdf`` file gives the chain from ``base`` to ``tip`` (defaults:
    the root link, and the single leaf below it); see
    :mod:`newton_euler_ros.core.urdf`.  Warnings are issued as
    :class:`RobotFileWarning`; notes on data accepted as published (the
    Puma 560's inertias that break the triangle inequality) are not: they
    are in :func:`inspect_robot`'s list and ``newton-euler check``'s
    output.  Errors raise :class:`RobotFileError`.
    """
    model, found, _ = inspect_robot(name_or_path, base=base, tip=tip)
    for message in found:
        if not isinstance(message, Note):
            warnings.warn(message, RobotFileWarning, stacklevel=2)
    return model
