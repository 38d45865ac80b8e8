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
Write a term's entry point and batch loop from its row step.

A *row step* (``entry.py``) is a term written once: the kernel call on one
state, ``<term>_row(links, frames, <arguments>)``, returning a status code
(-1 success).  Its arguments are known by name (:data:`SHAPES`): the
inputs ``q``, ``qd``, ``qdd``/``tau``, ``wrench`` (input a = 0, 1, 2, 3 of
the status codes), the workspaces, and last the output; any other name is
a switch passed through (``flags``, ``crba``).  From it:

- :func:`entry` writes ``run_<term>(P, <arguments>)``: the model split
  from ``P``, every array's size checked against the model (``SIZE + a``
  for input a, ``SIZE + 4`` for the output, ``SIZE + 5`` for a
  workspace), every input checked finite (``NONFINITE * a + i``), then
  the row step;
- :func:`batch` writes ``run_<term>_batch(P, <arguments>, status)``: the
  row step on row k of (m, ...) inputs and output (their names in
  capitals), the other arguments shared; it returns -1, or the first row
  whose code is not -1 (that code in ``status[0]``).  The caller checks
  shapes and finiteness once, in numpy.

The source is generated as text, compiled with the file and first line of
the row step (so numba's on-disk cache and its error messages point
there) and with the row step's module as its globals, and decorated with
that module's ``njit`` (the compiled kernels, or a copy's replacement:
``kernels.load_copy``).  :data:`SOURCES` keeps the text of each.
"""
import ast
import inspect

from ._jit import ENTRY, njit

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

SOURCES = {}    # name -> the generated source of each entry point


def _parts(row):
    """Return (python function, argument names, inputs, output) of a row."""
    func = getattr(row, 'py_func', row)
    names = list(inspect.signature(func).parameters)
    if names[:2] != ['links', 'frames'] or not func.__name__.endswith('_row'):
        raise ValueError(f'{func.__name__}: a row step is '
                         f'<term>_row(links, frames, ...)')
    args = names[2:]
    inputs = [a for a in args[:-1] if a in INPUTS]
    return func, args, inputs, args[-1]


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


def _compile(row, name, text):
    """Compile ``text`` (defining ``name``) where the row step is."""
    func = getattr(row, 'py_func', row)
    tree = ast.parse(text)
    line = func.__code__.co_firstlineno
    for node in ast.walk(tree):     # every line: the row step's first
        if hasattr(node, 'lineno'):
            node.lineno = node.end_lineno = line
    namespace = func.__globals__
    exec(compile(tree, func.__code__.co_filename, 'exec'),  # noqa: S102
         namespace)
    SOURCES[name] = text
    return njit(**ENTRY)(namespace.pop(name))


def entry(row):
    """Return ``run_<term>`` for a row step: checks, then the row step."""
    func, args, inputs, out = _parts(row)
    name = 'run_' + func.__name__[:-len('_row')]
    summary = (func.__doc__ or '').strip().splitlines()[:1]
    lines = [f'def {name}(P, {", ".join(args)}):',
             f'    """{summary[0] if summary else name}"""',
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
    lines.append(f'    return {func.__name__}(links, frames, '
                 f'{", ".join(args)})')
    return _compile(row, name, '\n'.join(lines) + '\n')


def batch(row, name=None):
    """Return ``run_<term>_batch`` (or ``name``): the row step per row."""
    func, args, inputs, out = _parts(row)
    name = name or 'run_' + func.__name__[:-len('_row')] + '_batch'
    per_row = set(inputs) | {out}
    params = [a.upper() if a in per_row else a for a in args]
    call = [a.upper() + '[k]' if a in per_row else a for a in args]
    text = (f'def {name}(P, {", ".join(params)}, status):\n'
            f'    """{func.__name__} for each row k (see generate.py)."""\n'
            f'    links, frames = _split(P)\n'
            f'    for k in range({params[args.index(inputs[0])]}.shape[0]):\n'
            f'        code = {func.__name__}(links, frames, '
            f'{", ".join(call)})\n'
            f'        if code >= 0:\n'
            f'            status[0] = code\n'
            f'            return k\n'
            f'    return -1\n')
    return _compile(row, name, text)
