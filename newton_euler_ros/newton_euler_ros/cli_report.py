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
What ``newton-euler dynamics`` and ``check`` print: tables and the tree.

A whole robot's matrices are printed in blocks of columns no wider than
WIDTH; joint types name continuous joints as such.
"""
import numpy as np


def _fmt(x, width=13):
    return f'{x:>{width}.6g}'


#: a matrix wider than this is printed in blocks of columns
WIDTH = 100


def _matrix_lines(title, names, M, col_names=None):
    """
    Return a matrix as lines no wider than WIDTH, when it is wide.

    A wide matrix (a whole robot's D, C and J) has its columns numbered
    in joint order (a square one's rows too) and printed in blocks of
    columns, every row in each block, as numpy does; ``--json`` gives
    the matrices whole.
    """
    col_names = list(col_names or names)
    w = max(12, *(len(x) for x in names))       # names are never cut
    cw = max(13, *(len(c) + 1 for c in col_names))
    n = len(col_names)
    if w + 2 + n * cw <= WIDTH:
        blocks, lines = [range(n)], [title]
    else:
        if col_names == list(names):          # rows are joints too
            digits = len(str(n))
            names = [f'{k + 1:>{digits}} {x}' for k, x in enumerate(names)]
            w = max(12, *(len(x) for x in names))
        col_names = [str(k + 1) for k in range(n)]
        cw = 13
        per = max(1, (WIDTH - w - 2) // cw)
        blocks = [range(a, min(n, a + per)) for a in range(0, n, per)]
        lines = [title, f'  (columns: the joints numbered in order, {per} '
                        f'to a block; --json gives it whole)']
    for cols in blocks:
        lines.append(' ' * (w + 2) + ''.join(f'{col_names[k]:>{cw}}'
                                             for k in cols))
        for name, row in zip(names, M):
            lines.append(f'  {name:<{w}}'
                         + ''.join(_fmt(row[k], cw) for k in cols))
    return lines


def source(model):
    if model.is_dh:
        return f'{model.convention} DH'
    report = model.info.get('urdf', {})
    if report.get('tree'):
        mimic = len(report.get('mimic', ()))
        return (f'URDF tree below {report.get("base", "?")} ('
                + (f'one tip, {report["tip"]}' if report.get('tip') else
                   'several tips')
                + (f'; {model.nb} moving joints, {mimic} of them mimic'
                   if mimic else '') + ')')
    return (f'URDF chain {report.get("base", "?")} -> '
            f'{report.get("tip", "?")}')


def types_of(model):
    """
    Return the joint type of each coordinate (a tree's independent joints).

    A URDF's continuous joints (revolute without limits) are 'continuous'.
    """
    continuous = set((model.info.get('urdf') or {}).get('continuous', ()))
    return ['continuous' if model.moving_joints[b] in continuous
            else model.joint_types[b] for b in model.independent]


def mass_counted(model):
    """Say what ``model.total_mass`` counts: the links the joints move."""
    report = model.info.get('urdf') or {}
    base = f'{report["base"]} and the links fixed to it' \
        if report.get('base') else 'the base'
    return f'the links the joints move; {base} not counted'


def format_table(model, result, q, qd, qdd, wrench, wrench_frame,
                 link=None):
    """Return a human-readable, multi-line report of one evaluation."""
    names = result['joint_names']
    types = types_of(model)
    D = np.array(result['mass_matrix'])
    C = np.array(result['coriolis_matrix'])
    g = np.array(result['gravity'])
    J = None if result['jacobian'] is None else np.array(result['jacobian'])
    jtf = J.T @ wrench if wrench is not None else np.zeros(len(names))
    lines = [f'{model.name}: {model.n} joints, {source(model)}, '
             f'gravity {model.gravity.tolist()} m/s^2 (base frame)']
    where = 'end-effector' if link is None else f'{link!r}'
    axes = wrench_frame if link is None or wrench_frame == 'base' else \
        'its own'
    if wrench is not None:
        lines.append(f'{where} wrench (exerted by the robot, '
                     f'{axes} axes): {wrench.tolist()}')
    lines.append('')
    head = ('joint', 'type', 'q', 'qd', 'qdd', 'D qdd', 'C qd', 'g',
            'J^T F', 'tau')
    w = max(12, *(len(x) + 1 for x in names))  # names are never cut
    lines.append(f'{head[0]:<{w}}{head[1]:<11}' + ''.join(f'{h:>13}'
                                                          for h in head[2:]))
    for j, name in enumerate(names):
        unit = 'N' if types[j] == 'prismatic' else 'N m'
        row = (q[j], qd[j], qdd[j], (D @ qdd)[j], (C @ qd)[j], g[j], jtf[j],
               result['tau'][j])
        lines.append(f'{name:<{w}}{types[j]:<11}'
                     + ''.join(_fmt(v) for v in row) + f'  {unit}')
    lines.append('tau = D qdd + C qd + g + J^T F  (N m for revolute and '
                 'continuous, N for prismatic joints)')
    lines.append('')
    lines += _matrix_lines('mass matrix D(q):', names, D)
    lines.append('')
    lines += _matrix_lines('Coriolis matrix C(q, qd) (Christoffel form):',
                           names, C)
    lines.append('')
    rows = ['vx', 'vy', 'vz', 'wx', 'wy', 'wz']
    if J is None:
        lines.append('(no Jacobian: the tree has several tips; --link '
                     'LINK names one)')
    else:
        origin = 'the end-effector origin' if link is None else \
            f'the origin of {link!r}'
        lines += _matrix_lines(f'Jacobian J(q) of {origin} ({axes} axes):',
                               rows, J, names)
    return '\n'.join(lines)


def tree_lines(model, report):
    """
    Return the tree below the base, one joint a line, indented by depth.

    Each line: the joint, its type (a mimic joint's multiplier, leader
    and offset; a fixed joint merged into its parent's body) and the
    link it carries.
    """
    depth = {report['base']: 0}
    kinds = dict(zip(model.moving_joints, model.joint_types))
    kinds.update((j, 'continuous') for j in report['continuous'])
    base = report['base']
    lines = [f"tree below {base} (depth first, each link's joints in URDF "
             f"order: the model's joint order):",
             f'  {report["base"]}']
    for jname, link in zip(report['chain'], report['chain_links']):
        d = depth[report['parent_links'][jname]] + 1
        depth[link] = d
        if jname in report['mimic']:
            leader, mult, offset = report['mimic'][jname]
            kind = (f'{kinds[jname]}, mimic: {mult:g} x {leader}'
                    + (f' {"+" if offset >= 0 else "-"} {abs(offset):g}'
                       if offset else ''))
        else:
            kind = kinds.get(jname, 'fixed, merged')
        lines.append(f'{"  " * (d + 1)}{jname} ({kind}) -> {link}')
    return lines
