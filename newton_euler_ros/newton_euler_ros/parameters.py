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
Node parameters from one schema file per node, without ROS.

``<node>_parameters.yaml`` beside this module (inverse_dynamics,
robot_sim, tracking_controller, mujoco_sim) lists every parameter of that
node with its type, default, description, ``read_only`` flag and
validation rules, in the style of generate_parameter_library.  This
module reads it, validates values and renders the README table; each
node declares its parameters from the same :class:`ParameterSpec` list
(:func:`..nodes.common.declare_parameters`).

    python -m newton_euler_ros.parameters --markdown [NODE]

It also writes each node's ``--help`` (:func:`node_help`): the node's
module docstring (what it does, its topics and services) and its
parameters, without importing ROS.
"""
import ast
import math
import os
import sys
import textwrap

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
NODES = ('inverse_dynamics_node', 'robot_sim_node', 'tracking_controller_node',
         'mujoco_sim_node')
#: each node's reference page (topics, parameters), in the repository
NODE_PAGES = {'inverse_dynamics_node': 'docs/node.md',
              'robot_sim_node': 'docs/scenes-and-demos.md',
              'tracking_controller_node': 'docs/scenes-and-demos.md',
              'mujoco_sim_node': 'docs/node.md'}


def schema_path(node_name):
    """Return the schema file of ``node_name`` (e.g. robot_sim_node)."""
    base = node_name[:-len('_node')] if node_name.endswith('_node') \
        else node_name
    return os.path.join(HERE, f'{base}_parameters.yaml')


SCHEMA = schema_path('inverse_dynamics_node')
TYPES = {'string': str, 'double': float, 'int': int, 'bool': bool,
         'string_array': list, 'double_array': list}


class ParameterSpec:
    """One declared parameter: name (dotted), type, default, rules."""

    def __init__(self, name, entry, path=SCHEMA):
        self.name = name
        self.type = entry['type']
        if self.type not in TYPES:
            raise ValueError(f'{path}: {name}: unknown type {self.type!r}')
        self.default = entry['default_value']
        self.description = entry['description']
        self.read_only = bool(entry.get('read_only', False))
        self.validation = entry.get('validation') or {}

    def check(self, value):
        """'' when ``value`` is valid, else a one-line reason."""
        if self.type == 'double' and isinstance(value, int) and \
                not isinstance(value, bool):
            value = float(value)
        want = TYPES[self.type]
        if not isinstance(value, want) or (want is int and
                                           isinstance(value, bool)):
            return f'{self.name}: must be of type {self.type}, got {value!r}'
        if self.type == 'double' and not math.isfinite(value):
            return f'{self.name}: must be finite, got {value!r}'
        if self.type == 'string_array' and not all(isinstance(v, str)
                                                   for v in value):
            return f'{self.name}: must be a list of strings, got {value!r}'
        if self.type == 'double_array':
            bad = [v for v in value if isinstance(v, bool) or not isinstance(
                v, (int, float)) or not math.isfinite(v)]
            if bad:
                return (f'{self.name}: must be a list of finite numbers, '
                        f'got {bad[0]!r}')
        for rule, args in self.validation.items():
            reason = _RULES[rule](value, *(args or []))
            if reason:
                return f'{self.name}: {reason}'
        return ''


def _one_of(value, choices):
    return '' if value in choices else (
        f'must be one of {", ".join(map(repr, choices))}, got {value!r}')


def _gt(value, bound):
    return '' if value > bound else f'must be > {bound}, got {value!r}'


def _gt_eq(value, bound):
    return '' if value >= bound else f'must be >= {bound}, got {value!r}'


def _not_empty(value):
    return '' if len(value) else 'must not be empty'


def _fixed_size(value, size):
    return '' if len(value) == size else (
        f'must have {size} entries, got {len(value)}')


def _unique(value):
    dup = [v for i, v in enumerate(value) if v in value[:i]]
    return '' if not dup else f'{dup[0]!r} is listed twice'


_RULES = {'one_of<>': _one_of, 'gt<>': _gt, 'gt_eq<>': _gt_eq,
          'not_empty<>': _not_empty, 'unique<>': _unique,
          'fixed_size<>': _fixed_size}


def _flatten(tree, path, prefix=''):
    for key, entry in tree.items():
        name = f'{prefix}{key}'
        if isinstance(entry, dict) and 'type' in entry:
            yield ParameterSpec(name, entry, path)
        else:
            yield from _flatten(entry, path, name + '.')


def load_specs(node_name='inverse_dynamics_node', path=None):
    """Return the parameters of ``node_name`` as a list of ParameterSpec."""
    path = path or schema_path(node_name)
    # our own file: libyaml's loader when there is one (3 ms against 36
    # for the node's schema, at every start)
    loader = getattr(yaml, 'CSafeLoader', yaml.SafeLoader)
    with open(path, encoding='utf-8') as fh:
        schema = yaml.load(fh, Loader=loader)
    return list(_flatten(schema[node_name], path))


def validate(values, specs):
    """Reasons (possibly none) why a {name: value} mapping is invalid."""
    return [r for r in (s.check(values[s.name]) for s in specs
                        if s.name in values) if r]


def markdown_table(specs):
    """Render the specs as the Markdown parameter table of the README."""
    lines = ['| parameter | type | default | read-only | description |',
             '|---|---|---|---|---|']
    for s in specs:
        default = yaml.safe_dump(s.default, default_flow_style=True).strip()
        if default.endswith('...'):
            default = default[:-3].strip()
        rules = '; '.join(f'{k[:-2]} {v}' if v else k[:-2]
                          for k, v in s.validation.items())
        desc = s.description + (f' *Validation: {rules}.*' if rules else '')
        lines.append(f'| `{s.name}` | {s.type} | `{default}` | '
                     f'{"yes" if s.read_only else "no"} | {desc} |')
    return '\n'.join(lines)


def help_requested(argv):
    """Return True when ``-h`` or ``--help`` comes before ``--ros-args``."""
    for token in argv:
        if token in ('--ros-args', '--'):
            return False
        if token in ('-h', '--help'):
            return True
    return False


def _default_text(spec):
    default = yaml.safe_dump(spec.default, default_flow_style=True,
                             width=1000).strip()
    return default[:-3].strip() if default.endswith('...') else default


def _rule_text(rule, args):
    if rule == 'one_of<>':
        return 'one of ' + ', '.join(repr(v) for v in args[0])
    return f'{rule[:-2]} {", ".join(map(str, args))}' if args else rule[:-2]


def node_help(node_name):
    """
    Return the ``--help`` text of a node: what it does, topics, parameters.

    The description and the topic lists are the node module's docstring
    (read from its source: nothing is imported, ROS does not start); the
    parameters come from the node's schema.
    """
    source = os.path.join(HERE, 'nodes', f'{node_name}.py')
    with open(source, encoding='utf-8') as fh:
        doc = ast.get_docstring(ast.parse(fh.read())) or node_name
    lines = [f'usage: {node_name} [-h] [--ros-args [-p NAME:=VALUE]... '
             f'[--params-file FILE]... [-r FROM:=TO]...]', '', doc, '',
             f'Reference: {NODE_PAGES[node_name]} in the newton_euler_ros '
             f'repository.', '',
             *textwrap.wrap(
                 f'Parameters (-p NAME:=VALUE, or --params-file FILE with '
                 f'a section {node_name}: or /**:; an unknown name stops '
                 f"the node; ROS 2's own are accepted: use_sim_time, "
                 f'start_type_description_service and qos_overrides.TOPIC.'
                 f"publisher|subscription.POLICY, applied to the node's "
                 f'topics):', 78)]
    for spec in load_specs(node_name):
        flags = ', read-only' if spec.read_only else ''
        lines.append(f'  {spec.name} ({spec.type}, default '
                     f'{_default_text(spec)}{flags})')
        rules = '; '.join(_rule_text(k, v)
                          for k, v in spec.validation.items())
        text = spec.description + (f' Validation: {rules}.' if rules else '')
        lines += textwrap.wrap(text, 76, initial_indent='      ',
                               subsequent_indent='      ')
    return '\n'.join(lines) + '\n'


def print_help(node_name):
    """Print :func:`node_help` on stdout."""
    sys.stdout.write(node_help(node_name))
    sys.stdout.flush()


if __name__ == '__main__':
    if sys.argv[1:2] != ['--markdown'] or len(sys.argv) > 3 or \
            sys.argv[2:] and sys.argv[2] not in NODES:
        print('usage: python -m newton_euler_ros.parameters --markdown '
              f'[{"|".join(NODES)}]', file=sys.stderr)
        sys.exit(2)
    print(markdown_table(load_specs(*sys.argv[2:])))
