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
The kernels' array layouts are declared once and used within their fields.

Each array's columns are one ordered declaration in ``kernels/layout.py``
(``LINKS``, ``WS``, ``AW``, ``CW``, ``DW`` and the others): here every
module-level ``L_*`` (``W_*``, ...) must be a declared field, the fields
must tile the row without overlap or gap, a row filled by field names
must name every field at its width, and every column name the kernel
files use must be declared, with every constant the kernels add to it
inside the field (``L_BODY + 9`` reads the body field's tenth column;
``L_COM + 3`` would read the next field).
"""
import ast
import os

from newton_euler_ros.core import kernels as K
from newton_euler_ros.core.kernels import layout
import pytest

CORE = os.path.dirname(os.path.abspath(K.__file__.replace(
    os.sep + 'kernels' + os.sep + '__init__.py', os.sep + 'tree.py')))
KERNELS = os.path.dirname(os.path.abspath(K.__file__))
SOURCES = sorted(os.path.join(KERNELS, f) for f in os.listdir(KERNELS)
                 if f.endswith('.py')) + [
    os.path.join(CORE, f) for f in ('tree.py', 'frames.py', 'model.py')]
# the prefixes of the declarations (the scratch rows CS_, DS_ share the
# rows of cw and dw; F_ names rows of ``frames``)
PREFIXES = {c.prefix: c for c in layout.DECLARATIONS}
# the name each declaration's width is bound to (None: not bound; the
# scratch rows and the rows of ``frames`` have 12 or more columns)
TOTALS = {'F_': 'F_ROWS', 'T_': None, 'C_': None, 'CS_': None, 'DS_': None}


def _total(columns):
    return TOTALS.get(columns.prefix, columns.prefix + 'WIDTH')


def _declared_names(columns, namespace):
    """Module-level ints named with the prefix of ``columns``."""
    return {k: v for k, v in vars(namespace).items()
            if k.startswith(columns.prefix) and isinstance(v, int)
            and not any(k.startswith(p) and len(p) > len(columns.prefix)
                        for p in PREFIXES)}


def tiling_errors(columns, namespace):
    """List what is wrong with the module-level names of ``columns``."""
    errors = []
    names = _declared_names(columns, namespace)
    fields = columns.offsets()
    total = _total(columns)
    if total is not None and names.get(total) != columns.width:
        errors.append(f'{total} is {names.get(total)}, the fields sum to '
                      f'{columns.width}')
    for name, value in names.items():
        if name == total:
            continue
        if name not in fields:
            errors.append(f'{name} = {value} is not a declared field')
        elif fields[name][0] != value:
            errors.append(f'{name} = {value}, declared at {fields[name][0]}')
    end = 0
    for name, (offset, width) in sorted(fields.items(),
                                        key=lambda x: x[1]):
        if offset < end:
            errors.append(f'{name} overlaps the field before it')
        elif offset > end:
            errors.append(f'a gap before {name}')
        end = offset + width
    if end != columns.width:
        errors.append(f'the fields end at {end}, not at {columns.width}')
    return errors


@pytest.mark.parametrize('columns', layout.DECLARATIONS,
                         ids=lambda c: c.prefix)
def test_every_name_is_a_declared_field_and_the_fields_tile_the_row(
        columns):
    assert tiling_errors(columns, layout) == []
    assert tiling_errors(columns, K) == []      # the package's exports


def test_a_hand_numbered_overlapping_or_gapped_column_is_reported():
    class Fake:
        pass
    fake = Fake()
    links = layout.Columns('L_', 'links row')
    for name, value in vars(layout).items():
        if name.startswith('L_') and isinstance(value, int):
            setattr(fake, name, value)
    for name, _, width, meaning in layout.LINKS.fields:
        links.add(name, width, meaning)
    assert tiling_errors(links, fake) == []
    fake.L_EXTRA = 15                       # inside L_COM, by hand
    assert tiling_errors(links, fake) == [
        'L_EXTRA = 15 is not a declared field']
    del fake.L_EXTRA
    fake.L_INERTIA = 16                     # off by one
    assert tiling_errors(links, fake) == ['L_INERTIA = 16, declared at 17']
    links.fields[5] = ('inertia', 16, 9, '')     # a declaration overlapping
    assert 'L_INERTIA overlaps the field before it' in tiling_errors(
        links, fake)
    links.fields[5] = ('inertia', 18, 9, '')     # or leaving a gap
    assert 'a gap before L_INERTIA' in tiling_errors(links, fake)


def test_the_scratch_rows_fit_their_arrays_and_the_constants_their_row():
    assert layout.CS.width <= layout.CW_WIDTH
    assert layout.DS.width <= layout.DW_WIDTH
    assert len(layout.CONSTANTS) == layout.CONST.width
    assert layout.TREE.width <= 12 and layout.CONST.width <= 12


def _row_values():
    return {name: [0.0] * width if width > 1 else 0.0
            for name, _, width, _ in layout.LINKS.fields}


def test_a_row_is_filled_by_field_names():
    values = _row_values()
    values['com'] = [1.0, 2.0, 3.0]
    values['mass'] = 4.0
    row = layout.LINKS.row(0.0, **values)
    assert len(row) == K.L_WIDTH
    assert row[K.L_COM:K.L_COM + 3] == [1.0, 2.0, 3.0]
    assert row[K.L_MASS] == 4.0


@pytest.mark.parametrize('change, message', [
    ({'com': None}, "field 'com' (L_COM, 3 column(s)) is not given"),
    ({'com': [1.0, 2.0]}, "field 'com' (L_COM) takes 3 value(s), got 2"),
    ({'mass': [1.0, 2.0]}, "field 'mass' (L_MASS) takes 1 value(s), got 2"),
    ({'drag': 1.0}, 'no field(s) drag declared'),
])
def test_a_missing_or_wrong_width_field_is_an_error_naming_it(change,
                                                              message):
    values = _row_values()
    for name, value in change.items():
        if value is None:
            del values[name]
        else:
            values[name] = value
    with pytest.raises(ValueError) as err:
        layout.LINKS.row(0.0, **values)
    assert message in str(err.value)


def test_the_compiled_links_are_the_declared_fields():
    from newton_euler_ros.core import load_robot
    model = load_robot('planar_rp')
    links = model.links_array
    assert links.shape == (2, K.L_WIDTH)
    assert links[1, K.L_TYPE] == 1.0 and links[0, K.L_TYPE] == 0.0
    assert list(links[:, K.L_PARENT]) == [-1.0, 0.0]
    assert list(links[:, K.L_MASS]) == list(model.mass)


def _field_of(name):
    """(offset, width) of a column name, or None when not a column."""
    for prefix in sorted(PREFIXES, key=len, reverse=True):
        if name.startswith(prefix):
            columns = PREFIXES[prefix]
            if name == _total(columns):
                return None
            return columns.offsets().get(name, 'undeclared')
    return None


def _uses(path):
    """Yield (line, name, constant added or None, in a slice's end)."""
    with open(path, encoding='utf-8') as fh:
        tree = ast.parse(fh.read(), path)
    ends = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Slice) and node.upper is not None:
            ends.add(id(node.upper))
    for node in ast.walk(tree):
        name = None
        if isinstance(node, ast.Name):
            name = node.id
        elif isinstance(node, ast.Attribute):
            name = node.attr
        elif isinstance(node, ast.alias):
            name = node.asname or node.name
        if name is not None and _field_of(name) is not None:
            yield node.lineno if hasattr(node, 'lineno') else 0, name, \
                None, False
        if (isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add)
                and isinstance(node.right, ast.Constant)
                and isinstance(node.right.value, int)):
            left = node.left
            name = getattr(left, 'id', None) or getattr(left, 'attr', None)
            if name is not None and _field_of(name) is not None:
                yield node.lineno, name, node.right.value, id(node) in ends


def test_every_column_the_kernels_use_is_declared_and_read_within_it():
    bad = []
    seen = set()
    for path in SOURCES:
        for line, name, added, slice_end in _uses(path):
            field = _field_of(name)
            where = f'{os.path.basename(path)}:{line}'
            if field == 'undeclared':
                bad.append(f'{where}: {name} is not declared in layout.py')
                continue
            seen.add(name)
            if added is None:
                continue
            width = field[1]
            if added > width or (added == width and not slice_end):
                bad.append(f'{where}: {name} + {added} reads past the '
                           f'field ({width} wide)')
    assert bad == []
    # the check saw the kernels' columns (a walk that finds nothing
    # checks nothing)
    assert {'L_COM', 'L_BODY', 'W_X', 'A_IA', 'CW_S', 'DW_W'} <= seen
