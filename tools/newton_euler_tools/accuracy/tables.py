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
The tables of the accuracy report, shared by the terminal and the markdown.

Formatting of times, errors and ratios; the per-robot arithmetic table,
the scaling table and the scene tables, built from the records alone, so
that :mod:`.report` (which measures) and :mod:`.markdown` (which writes
the report) both use them without importing each other.
"""
import json

import numpy as np

from .scaling import fit_start

QUANTITY_LABELS = {'tau': 'tau', 'D': 'D(q)', 'C': 'C(q,qd)', 'g': 'g(q)',
                   'FD': 'qdd (FD)'}


# --------------------------------------------------------------------------
# formatting


def fmt_us(x):
    """Format microseconds with three significant figures."""
    if x is None:
        return '-'
    if x >= 1000:
        return f'{x:,.0f}'
    return f'{x:.3g}'


def fmt_err(x):
    """Format a relative error (0 shown as 0)."""
    if x is None:
        return '-'
    if x == 0:
        return '0'
    return f'{x:.1e}'


def fmt_ratio(x):
    """Format a time ratio."""
    return '-' if x is None else f'{x:.2f}x'


def text_table(header, rows):
    """Return a fixed-width text table."""
    cells = [header] + [[str(c) for c in row] for row in rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]
    lines = ['  '.join(c.ljust(w) if i == 0 or i == 1 else c.rjust(w)
                       for i, (c, w) in enumerate(zip(r, widths)))
             for r in cells]
    lines.insert(1, '  '.join('-' * w for w in widths))
    return '\n'.join(lines)


def md_table(header, rows):
    """Return a GitHub-flavoured markdown table."""
    out = ['| ' + ' | '.join(header) + ' |',
           '|' + '|'.join('---' for _ in header) + '|']
    out += ['| ' + ' | '.join(str(c) for c in row) + ' |' for row in rows]
    return '\n'.join(out)


ARITH_HEADER = ['quantity', 'method', 'us/call', 'time vs float64',
                'rel. error', 'error / eps']


def arithmetic_rows(records, robot):
    """Rows of the per-robot table, in measurement order."""
    rows = []
    for r in records:
        if r['section'] == 'arithmetic' and r['robot'] == robot:
            rows.append([QUANTITY_LABELS[r['quantity']], r['method'],
                         fmt_us(r['us']), fmt_ratio(r['ratio']),
                         fmt_err(r['error']),
                         f'{r["error_eps"]:.3g}'])
    return rows


def find(records, **kw):
    """Return the first record matching every key, or None."""
    for r in records:
        if all(r.get(k) == v for k, v in kw.items()):
            return r
    return None


# --------------------------------------------------------------------------
# tables shared by the terminal and the markdown


def scaling_rows(records, exponents, sizes):
    """Rows: operation, us at each n, fitted exponent."""
    rows = []
    for op in dict.fromkeys(r['method'] for r in records):
        times = {r['dof']: r['us'] for r in records if r['method'] == op}
        p = exponents.get(op)
        rows.append([op] + [fmt_us(times.get(n)) for n in sizes]
                    + ['-' if p is None else f'{p[0]:.2f}'])
    return rows


def scaling_header(sizes, fit_from):
    """Return the header of the scaling table."""
    return ['operation'] + [f'n={n}' for n in sizes] + [
        f'exponent (n>={fit_from})']


def scaling_text(records, exponents, sizes):
    """Return the scaling table as text."""
    return text_table(scaling_header(sizes, fit_start(sizes)),
                      scaling_rows(records, exponents, sizes))


def _notes(rows):
    """Return the distinct notes of ``rows``, per scene, in order."""
    out = []
    for r in rows:
        line = f'{r["scene"]}: {r["note"]}' if r.get('note') else ''
        if line and line not in out:
            out.append(line)
    return out


def scene_tables(records):
    """[(title, header, rows, notes)] for the scene sections measured."""
    tables = []
    eff = [r for r in records if r['section'] == 'effects']
    if eff:
        tables.append((
            'effect subsets: cost and torque error along the scene '
            "trajectory (truth: full + wrench; * the scene's own model)",
            ['scene', 'model', 'us/call', 'RMS error / RMS torque',
             'max error (N m or N)'],
            [[r['scene'], r['method'] + (' *' if r.get('scene_model')
                                         else ''),
              fmt_us(r['us']), fmt_err(r['error']),
              fmt_err(r.get('abs_error'))] for r in eff], _notes(eff)))
    bat = [r for r in records if r['section'] == 'batch']
    if bat:
        tables.append((
            'single state vs batched over the trajectory',
            ['scene', 'method', 'us/state', 'max |difference| (relative)'],
            [[r['scene'], r['method'], fmt_us(r['us']), fmt_err(r['error'])]
             for r in bat], _notes(bat)))
    ff = [r for r in records if r['section'] == 'feedforward']
    if ff:
        tables.append((
            'feedforward at the desired vs the measured state',
            ['scene', 'feedforward', 'us/step', 'tracking RMS (rad)',
             'RMS, second half', 'tracking max (rad)'],
            [[r['scene'], r['method'], fmt_us(r['us']),
              fmt_err(r.get('tracking_rms')),
              fmt_err(r.get('tracking_rms_late')),
              fmt_err(r.get('tracking_max'))] for r in ff], _notes(ff)))
    integ = [r for r in records if r['section'] == 'integrators']
    if integ:
        tables.append((
            'integrators and step sizes',
            ['scene', 'integrator', 'step (ms)', 'us/step',
             's per simulated s', 'max |q - converged|',
             'energy drift (rel.)', 'tracking RMS'],
            [[r['scene'], r['method'], f'{r["step"] * 1e3:g}',
              fmt_us(r['us']), f'{r["cost"]:.3g}', fmt_err(r['error']),
              fmt_err(r['drift']), fmt_err(r.get('tracking_rms'))]
             for r in integ], _notes(integ)))
    return tables


def save_records(records, context, path):
    """Write every record and the context as JSON."""
    def default(x):
        if isinstance(x, (np.floating, np.integer, np.bool_)):
            return x.item()
        if isinstance(x, np.ndarray):
            return x.tolist()
        raise TypeError(f'not JSON serialisable: {type(x).__name__}')
    with open(path, 'w', encoding='utf-8') as fh:
        json.dump({'context': context, 'records': records}, fh, indent=1,
                  default=default)
