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
Write the entry points (``entries*.py``) from the row steps (``entry.py``).

    python -m newton_euler_ros.core.kernels.generate --write
    python -m newton_euler_ros.core.kernels.generate --check

A *row step* (``entry.py``) is a term written once: the kernel call on one
state, ``<term>_row(links, frames, <arguments>)``, returning a status code
(-1 success).  ``entry.ENTRIES`` lists the entry points to write, each a
name and a row step.  The arguments are known by name (:data:`SHAPES`):
the inputs ``q``, ``qd``, ``qdd``/``tau``, ``wrench`` (input a = 0, 1, 2,
3 of the status codes), the workspaces, and last the output; any other
name is a switch passed through (``flags``, ``crba``).  From it:

- a name ``run_<term>`` gets the single-state entry point
  ``run_<term>(P, <arguments>)``: the model split from ``P``, every
  array's size checked against the model (``SIZE + a`` for input a,
  ``SIZE + 4`` for the output, ``SIZE + 5`` for a workspace), every input
  checked finite (``NONFINITE * a + i``), then the row step;
- a name ending in ``_batch`` gets the batch loop ``(P, <arguments>,
  status)``: the row step on row k of (m, ...) inputs and output (their
  names in capitals), the other arguments shared; it returns -1, or the
  first row whose code is not -1 (that code in ``status[0]``).  The
  caller checks shapes and finiteness once, in numpy.  It is compiled to
  release the GIL (``_jit.BATCH``), so a caller may share a batch among
  threads (``core.batch.run_split``).

The entry points are written into checked-in modules (:data:`FILES`:
``entries.py``, and ``entries_derivatives.py`` for the derivatives),
compiled by numba and cached on disk like the other kernel files; a
reader opens them and a traceback points into them.
``test_entry_points.py`` fails when they differ from what :func:`render`
writes.  The generator reads ``entry.py`` as text (``ast``: it imports
nothing, so it runs even when a generated file is stale and the package
does not import: then run this file by its path).  :data:`SOURCES` holds the text
of each entry point (for reading: ``print(SOURCES['run_gravity_torques'])``).
"""
import argparse
import ast
import os
import re
import sys

# The size of each argument by name, per axis: an expression in n (the
# number of coordinates: independent joints) or nb (the number of bodies:
# moving joints, mimic ones included) that the axis must equal, or '>='
# one it must reach.
SHAPES = {
    'q': ('n',), 'qd': ('n',), 'qdd': ('n',), 'tau': ('n',),
    'wrench': ('6',), 'fext': ('nb', '6'), 'target': ('12',),
    'D': ('n', 'n'), 'C': ('n', 'n'), 'J': ('6', 'n'),
    'ws': ('>=nb', 'W_WIDTH'), 'aw': ('>=nb + 1', 'A_WIDTH'),
    'cw': ('>=nb + 1', 'CW_WIDTH'), 'scratch': ('3', '>=n'),
    'Ts': ('nb + 2', '12'),
    'terms': ('3', 'n'),
    'line': ('>=nb', '6'), 'acc': ('>=10 * nb', '6'),
    'Y': ('n', '10 * nb + 4 * n if drives else 10 * nb'),
    'wext': ('nb', '15'), 'fall': ('nb', '6'), 'dw': ('>=nb + 1', 'DW_WIDTH'),
    'damping': ('n',), 'armature': ('n',), 'chol': ('n', 'n'),
    'dtau': ('2', 'n', 'n'), 'dqdd': ('3', 'n', 'n'),
}
# input a of the status codes (``calling.INPUTS``, ``calling.FD_INPUTS``)
INPUTS = {'q': 0, 'qd': 1, 'qdd': 2, 'tau': 2, 'wrench': 3, 'fext': 4,
          'wext': 4, 'fall': 4}
# sizes checked as a workspace's (SIZE + 5): scratch and per-joint constants
WORKSPACES = ('ws', 'aw', 'cw', 'dw', 'scratch', 'Ts', 'line', 'acc', 'chol',
              'damping', 'armature')

HERE = os.path.dirname(os.path.abspath(__file__))
ENTRY_FILE = os.path.join(HERE, 'entry.py')
# the generated files (a module each stays under the 600 lines of the
# core's modules): their subject, and which entry points they hold
FILES = {
    'entries.py': ('the dynamics, the matrices and the kinematics',
                   lambda name: '_derivatives' not in name),
    'entries_derivatives.py': ('the derivatives',
                               lambda name: '_derivatives' in name),
}
COMMAND = 'python -m newton_euler_ros.core.kernels.generate --write'
WIDTH = 79      # the linters' line length

# what the generated code may name, by the module it comes from
_IMPORTS = (
    ('.layout', ('A_WIDTH', 'CW_WIDTH', 'DW_WIDTH', 'NONFINITE', 'SIZE',
                 'W_WIDTH')),
    ('.status', ('first_nonfinite', 'first_nonfinite_entry')),
)


def read_rows(source):
    """
    Return (row steps, entries) of ``entry.py``'s text.

    Row steps: {name: (argument names after links and frames, first line
    of the docstring)}; entries: [(entry point name, row step name)] in the
    order of ``ENTRIES``.
    """
    tree = ast.parse(source)
    rows, entries = {}, None
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name.endswith('_row'):
            names = [a.arg for a in node.args.args]
            if names[:2] != ['links', 'frames']:
                raise ValueError(f'{node.name}: a row step is '
                                 f'<term>_row(links, frames, ...)')
            doc = (ast.get_docstring(node) or node.name).splitlines()[0]
            rows[node.name] = (names[2:], doc)
        elif (isinstance(node, ast.Assign) and len(node.targets) == 1
              and getattr(node.targets[0], 'id', None) == 'ENTRIES'):
            entries = [(e.elts[0].value, e.elts[1].id)
                       for e in node.value.elts]
    if entries is None:
        raise ValueError('entry.py has no ENTRIES table')
    for name, row in entries:
        if row not in rows:
            raise ValueError(f'{name}: no row step {row} in entry.py')
        if not name.startswith('run_'):
            raise ValueError(f'{name}: entry points are named run_<term>')
    return rows, entries


def _wrap(prefix, items, suffix, width=WIDTH):
    """Lines of ``prefix item, item, ...suffix``, broken after commas."""
    lines, line = [], prefix
    pad = ' ' * len(prefix)
    for i, item in enumerate(items):
        piece = item + (suffix if i == len(items) - 1 else ',')
        glue = '' if line.endswith('(') or line == pad else ' '
        if line != prefix and line != pad and \
                len(line) + len(glue) + len(piece) > width:
            lines.append(line)
            line, glue = pad, ''
        line += glue + piece
    lines.append(line)
    return lines


def _size_checks(name, code, prefix=''):
    """Lines returning ``code`` unless array ``name`` has its SHAPES."""
    lines = []
    for axis, want in enumerate(SHAPES[name]):
        axis += len(prefix)
        if want.startswith('>='):
            test = f'{name}.shape[{axis}] < {want[2:]}'
        else:
            test = f'{name}.shape[{axis}] != {want}'
        lines += [f'    if {test}:', f'        return {code}']
    return lines


def _inputs(args):
    return [a for a in args[:-1] if a in INPUTS]


def entry(name, row, args, doc):
    """Return the text of entry point ``name``: checks, then row ``row``."""
    inputs, out = _inputs(args), args[-1]
    lines = _wrap(f'def {name}(', ['P'] + args, '):')
    lines += [f'    """{doc}"""',
              '    links, frames = _split(P)',
              '    nb = links.shape[0]',
              '    n = _coordinates(frames)']
    for a in inputs:
        lines += _size_checks(a, f'SIZE + {INPUTS[a]}')
    for a in args:
        if a in WORKSPACES:
            lines += _size_checks(a, 'SIZE + 5')
        elif a == out:
            lines += _size_checks(a, 'SIZE + 4')
    if 'body' in args:
        lines += ['    if body < -1 or body >= nb:', '        return SIZE + 5']
    for a in inputs:
        check = ('first_nonfinite_entry' if len(SHAPES[a]) == 2
                 else 'first_nonfinite')
        lines += [f'    i = {check}({a})', '    if i >= 0:',
                  f'        return NONFINITE * {INPUTS[a]} + i']
    lines += _wrap(f'    return {row}(', ['links', 'frames'] + args, ')')
    return '\n'.join(lines) + '\n'


def batch(name, row, args):
    """Return the text of batch loop ``name``: row ``row`` on each row."""
    inputs, out = _inputs(args), args[-1]
    per_row = set(inputs) | {out}
    params = [a.upper() if a in per_row else a for a in args]
    call = [a.upper() + '[k]' if a in per_row else a for a in args]
    lines = _wrap(f'def {name}(', ['P'] + params + ['status'], '):')
    lines += [f'    """{row} for each row k (see generate.py)."""',
              '    links, frames = _split(P)',
              f'    for k in range({params[args.index(inputs[0])]}'
              f'.shape[0]):']
    lines += _wrap(f'        code = {row}(', ['links', 'frames'] + call, ')')
    lines += ['        if code >= 0:',
              '            status[0] = code',
              '            return k',
              '    return -1']
    return '\n'.join(lines) + '\n'


def sources(source=None):
    """Return {entry point name: its text}, in the order of ``ENTRIES``."""
    if source is None:
        with open(ENTRY_FILE, encoding='utf-8') as fh:
            source = fh.read()
    rows, entries = read_rows(source)
    out = {}
    for name, row in entries:
        args, doc = rows[row]
        out[name] = (batch(name, row, args) if name.endswith('_batch')
                     else entry(name, row, args, doc))
    return out


def _header():
    """Return the copyright lines of this file (the generated file's)."""
    with open(os.path.abspath(__file__), encoding='utf-8') as fh:
        lines = fh.read().splitlines()
    return '\n'.join(lines[:lines.index('')]) + '\n'


def module_of(name):
    """Return the file name (in :data:`FILES`) entry point ``name`` is in."""
    for file, (_, test) in FILES.items():
        if test(name):
            return file
    raise ValueError(name)


def render(source=None):
    """Return {path: text} of the generated files (what ``--write`` writes)."""
    texts = sources(source)
    return {os.path.join(HERE, file): _module(
        what, {k: t for k, t in texts.items() if module_of(k) == file})
        for file, (what, _) in FILES.items()}


def _module(what, texts):
    """Return the text of one generated file: ``texts`` and their imports."""
    body = '\n\n'.join(
        ('@njit(**BATCH)\n' if name.endswith('_batch') else '@njit(**ENTRY)\n')
        + t for name, t in texts.items())
    used = set(re.findall(r'\b\w+\b', body))
    rows = sorted({r for r in used if r.endswith('_row')}
                  | ({'_coordinates'} & used) | {'_split'})
    lines = [
        _header(),
        '"""',
        f'The entry points of {what}: GENERATED, do not edit.',
        '',
        f'Written by ``{COMMAND}``',
        'from the row steps and the ``ENTRIES`` table of ``entry.py`` (see',
        '``generate.py`` for what each checks); ``test_entry_points.py`` '
        'fails',
        'when this file differs from what the generator writes.',
        '"""']
    lines.append('from ._jit import ' + ', '.join(
        [n for n in ('BATCH', 'ENTRY') if f'**{n}' in body] + ['njit']))
    lines += _wrap('from .entry import (', sorted(rows, key=str.lower), ')')
    for module, names in _IMPORTS:
        names = [n for n in names if n in used]
        if names:
            lines += _wrap(f'from {module} import (', sorted(
                names, key=str.lower), ')')
    return '\n'.join(lines) + '\n\n\n' + body


SOURCES = sources()     # the text of each entry point, for reading


def main(argv=None):
    """Write the generated files (``--write``) or check them (``--check``)."""
    parser = argparse.ArgumentParser(
        prog='python -m newton_euler_ros.core.kernels.generate',
        description="Write the kernels' entry points (entries*.py) from "
                    'the row steps of entry.py.')
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument('--write', action='store_true',
                      help='rewrite the generated files')
    mode.add_argument('--check', action='store_true',
                      help='exit 1 if a generated file is not what '
                           '--write writes')
    args = parser.parse_args(argv)
    stale = []
    for path, text in render().items():
        try:
            with open(path, encoding='utf-8') as fh:
                current = fh.read()
        except FileNotFoundError:
            current = None
        if current == text:
            continue
        stale.append(path)
        if args.write:
            with open(path, 'w', encoding='utf-8') as fh:
                fh.write(text)
            print(f'wrote {path}')
    if args.check and stale:
        print(f'stale: {", ".join(stale)}: run {COMMAND}', file=sys.stderr)
        return 1
    if not stale:
        print('the entry points are up to date')
    return 0


if __name__ == '__main__':
    sys.exit(main())
