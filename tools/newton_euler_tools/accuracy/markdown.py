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
Write ``accuracy-vs-time.md``: tables, plots and findings from the records.

Every number in the report is formatted from the records of the run that
writes it; the sentences under "Findings" are computed the same way, so
regenerating the report can never leave a stale figure behind.
"""
import os

from . import plots
from .arithmetic import EPS
from .tables import (ARITH_HEADER, arithmetic_rows, find, fmt_err, fmt_us,
                     md_table, save_records, scaling_header, scaling_rows,
                     scene_tables)

HEADLINE_ROBOT = 'puma560'


def _robots(records):
    return list(dict.fromkeys(r['robot'] for r in records
                              if r['section'] == 'arithmetic'))


def _span(values, fmt):
    values = [v for v in values if v is not None]
    if not values:
        return '-'
    lo, hi = min(values), max(values)
    return fmt(lo) if fmt(lo) == fmt(hi) else f'{fmt(lo)} to {fmt(hi)}'


def _ratio(records, robot, quantity, method, base):
    a = find(records, section='arithmetic', robot=robot, quantity=quantity,
             method=method)
    b = find(records, section='arithmetic', robot=robot, quantity=quantity,
             method=base)
    if a is None or b is None:
        return None, None, None
    return a['us'] / b['us'], a, b


def _compare(records, pairs):
    """
    Compare method a with method b over (robot, quantity, a, b) tuples.

    Return (time ratios a/b, errors of a, errors of b, dofs) over the
    pairs that were both measured.
    """
    out = ([], [], [], [])
    for robot, quantity, a, b in pairs:
        ratio, ra, rb = _ratio(records, robot, quantity, a, b)
        if ratio is not None:
            for column, value in zip(out, (ratio, ra['error'], rb['error'],
                                           (ra['dof'], robot))):
                column.append(value)
    return out


BASE_METHOD = {'tau': 'float64', 'D': 'float64, CRBA',
               'C': 'float64, composite, O(n^2)', 'g': 'float64',
               'FD': 'float64, ABA, O(n)'}
FLOAT32_METHOD = {'FD': 'float32, ABA'}


def findings(records, context):
    """Return the findings as markdown bullet lines, computed from records."""
    robots = _robots(records)
    out = []
    t_ratio, errs32, errs64, _ = _compare(records, [
        (robot, q, FLOAT32_METHOD.get(q, base.replace('float64', 'float32')),
         base) for robot in robots for q, base in BASE_METHOD.items()])
    if t_ratio:
        typical = sorted(t_ratio)[len(t_ratio) // 2]
        verdict = ('float32 buys no time' if typical > 0.9 else
                   f'float32 saves {100 * (1 - typical):.0f}% of the time')
        out.append(
            f'- **{verdict}.** Over every robot and quantity the float32 '
            f'path takes {_span(t_ratio, lambda x: f"{x:.2f}x")} the float64 '
            f'time (median {typical:.2f}x; this is scalar code, where one '
            f'float32 operation costs what one float64 operation costs), '
            f'while its error is {_span(errs32, fmt_err)} against '
            f'{_span(errs64, fmt_err)} in float64.')
    for quantity, fast, slow, what, than in (
            ('D', 'float64, CRBA', 'float64, n recursions',
             'D(q): the composite-rigid-body algorithm',
             'n Newton-Euler recursions'),
            ('C', 'float64, composite, O(n^2)', 'float64, n recursions',
             'C(q, qd): the composite-body algorithm', 'n recursions'),
            ('FD', 'float64, ABA, O(n)', 'float64, Cholesky of D',
             'Forward dynamics: the articulated-body algorithm',
             'Cholesky of D')):
        t_ratio, e_fast, e_slow, dofs = _compare(records, [
            (robot, quantity, fast, slow) for robot in robots])
        if t_ratio:
            k = max(range(len(dofs)), key=lambda i: dofs[i][0])
            out.append(
                f'- **{what}** takes {_span(t_ratio, lambda x: f"{x:.2f}x")} '
                f'the time of {than} ({t_ratio[k]:.2f}x on '
                f'{dofs[k][1]}, {dofs[k][0]} links), at an error of '
                f'{_span(e_fast, fmt_err)} against {_span(e_slow, fmt_err)}.')
    t_ratio, e_fd, e_ex, _ = _compare(records, [
        (robot, 'C', 'central differences of D', 'float64, n recursions')
        for robot in robots])
    if t_ratio:
        out.append(
            f'- **C(q, qd) by finite differences of D** costs '
            f'{_span(t_ratio, lambda x: f"{x:.0f}x")} the n recursions '
            f'and loses digits: error {_span(e_fd, fmt_err)} (central '
            f'differences at the optimal step) against '
            f'{_span(e_ex, fmt_err)} exact.')
    # peers
    arith = [r for r in records if r['section'] == 'arithmetic']
    largest = max(arith, key=lambda r: r['dof'])['robot'] if arith else None
    for robot in dict.fromkeys((HEADLINE_ROBOT, largest)):
        lines = []
        for q, peer in (('tau', 'Pinocchio rnea'), ('D', 'Pinocchio crba'),
                        ('C', 'Pinocchio computeCoriolisMatrix'),
                        ('g', 'Pinocchio computeGeneralizedGravity'),
                        ('FD', 'Pinocchio aba')):
            ratio, a, b = _ratio(records, robot, q, BASE_METHOD[q], peer)
            if ratio is not None:
                lines.append(f'{q} {ratio:.2f}x (error '
                             f'{fmt_err(a["error"])} vs '
                             f'{fmt_err(b["error"])})')
        if lines:
            out.append(f'- **Against Pinocchio** on {robot}, our time over '
                       "Pinocchio's: " + '; '.join(lines) + '.')
    # scaling
    exps = context.get('exponents', {})
    tau3 = find(records, section='scaling', method='tau')
    bat3 = find(records, section='scaling', method='tau, batched (per state)')
    if exps and tau3 and bat3:
        out.append(
            f'- **A call from Python has a fixed cost.** At n = '
            f'{tau3["dof"]} one tau takes {fmt_us(tau3["us"])} us alone and '
            f'{fmt_us(bat3["us"])} us per state batched: the difference is '
            f'argument checking and dispatch, the same for every n, which '
            f'flattens the single-call exponents below; the batched '
            "exponent is the algorithm's.")
    if exps:
        out.append('- **Growth with n** (fitted exponents, n >= '
                   f'{context["fit_from"]}): ' + '; '.join(
                       f'{op} n^{p:.2f}' for op, (p, _) in exps.items())
                   + '.')
    # effect subsets
    for scene in dict.fromkeys(r['scene'] for r in records
                               if r['section'] == 'effects'):
        rows = [r for r in records if r['section'] == 'effects'
                and r['scene'] == scene and r.get('error') is not None]
        if rows:
            out.append(f'- **{scene}**: ' + '; '.join(
                f'{r["method"]} {fmt_us(r["us"])} us, error '
                f'{r["error"] * 100:.3g}%' for r in rows) + '.')
    return out


def write_report(records, context, out_dir):
    """Write the plots, the JSON records and the markdown; return its path."""
    img_dir = os.path.join(out_dir, 'accuracy')
    os.makedirs(img_dir, exist_ok=True)
    images = {}
    for robot in _robots(records):
        path = os.path.join(img_dir, f'pareto-{robot}.png')
        plots.robot_pareto(records, robot, path)
        images[robot] = plots.relpath(path, out_dir)
    scale = [r for r in records if r['section'] == 'scaling']
    scaling_img = None
    if scale:
        path = os.path.join(img_dir, 'scaling.png')
        plots.scaling(scale, context['exponents'], path,
                      context['fit_from'])
        scaling_img = plots.relpath(path, out_dir)
    scene_imgs = {}
    for scene in dict.fromkeys(r['scene'] for r in records
                               if r['section'] == 'effects'):
        path = os.path.join(img_dir, f'effects-{scene}.png')
        plots.model_pareto(records, scene, path)
        scene_imgs[scene] = plots.relpath(path, out_dir)
    integ_img = None
    path = os.path.join(img_dir, 'integrators.png')
    if plots.integrators(records, path):
        integ_img = plots.relpath(path, out_dir)
    save_records(records, context, os.path.join(img_dir, 'records.json'))

    md = render(records, context, images, scaling_img, scene_imgs, integ_img)
    path = os.path.join(out_dir, 'accuracy-vs-time.md')
    with open(path, 'w', encoding='utf-8') as fh:
        fh.write(md)
    return path


def render(records, context, images, scaling_img, scene_imgs, integ_img):
    """Return the markdown text of the report."""
    v = context['versions']
    lines = [
        '# What accuracy costs in time',
        '',
        f'Generated by `{context["command"]}` (`make accuracy`) on '
        f'{context["date"]}; machine: {context["machine"]}; '
        + ', '.join(f'{k} {val}' for k, val in v.items())
        + f'. Measurements took {context["elapsed_s"]:.0f} s.'
        + (' **Quick mode: one state per robot and short repeats; figures '
           'are noisy.**' if context['quick'] else ''),
        '',
        '## How to read this report',
        '',
        '- **Error** is the normwise relative error against ground truth: '
        '`max |x - x_true| / max |x_true|` over the entries of tau, D, C '
        'or g and over the states measured. The truth is the same '
        'Newton-Euler recursion evaluated with mpmath at 50 significant '
        'digits (`newton_euler_ros.core.highprec`) from the exact float64 '
        f'inputs. float64 eps is {EPS:.3g}; "error / eps" counts it.',
        '- **Time** is microseconds per call from Python, warm (JIT '
        'compilation excluded): the minimum over repeats of a timed loop, '
        'all methods of one quantity with their repeats interleaved in the '
        'same run. "time vs float64" divides by our default float64 method.',
        '- In the plots, lower left is better; the dashed red line is the '
        'Pareto front (no other method is both faster and more accurate). '
        'Exact results (error 0) sit on the bottom line.',
        '- Differences of a few eps between float64 methods are round-off '
        'noise, not a ranking: every float64 method here is accurate to '
        'the last few bits.',
        '- Peers (Pinocchio, Robotics Toolbox for Python) run models built '
        'from ours by `newton_euler_tools.peers`; their error includes '
        'rebuilding the DH geometry as transforms.',
        '',
        '## Findings',
        '',
        *findings(records, context),
        '',
    ]
    if context['notes']:
        lines += ['Notes: ' + ' '.join(context['notes']), '']
    head = images.get(HEADLINE_ROBOT)
    if head:
        lines += [f'![{HEADLINE_ROBOT}: error against time]({head})', '']
    lines += ['## Arithmetic and algorithms, per robot', '']
    for robot, img in images.items():
        rec = find(records, section='arithmetic', robot=robot)
        lines += [f'### {robot} ({rec["dof"]} joints, {rec["states"]} '
                  f'state(s))', '',
                  md_table(ARITH_HEADER, arithmetic_rows(records, robot)),
                  '']
        notes = sorted({r['method'] + ': ' + r['note'] for r in records
                        if r['section'] == 'arithmetic'
                        and r['robot'] == robot and r['note']})
        if notes:
            lines += ['; '.join(notes) + '.', '']
        if robot != HEADLINE_ROBOT:
            lines += [f'![{robot}]({img})', '']
    scale = [r for r in records if r['section'] == 'scaling']
    if scale:
        lines += ['## Cost growth with the number of links', '',
                  'Random chains (`newton_euler_tools.accuracy.chains`), one '
                  'state each; the exponent is the least-squares slope of '
                  f'log time on log n for n >= {context["fit_from"]} (the '
                  'three largest chains; below them the fixed cost of a '
                  'call from Python hides the growth).', '',
                  md_table(scaling_header(context['sizes'],
                                          context['fit_from']),
                           scaling_rows(scale, context['exponents'],
                                        context['sizes'])), '']
        if scaling_img:
            lines += [f'![cost against n]({scaling_img})', '']
    tables = scene_tables(records)
    if tables:
        lines += ['## Scenes: model fidelity, batching, feedforward, '
                  'integrators', '']
        for title, header, rows, notes in tables:
            lines += [f'### {title[0].upper()}{title[1:]}', '',
                      md_table(header, rows), '']
            if title.startswith('effect subsets'):
                lines += [f'![{s}]({img})' for s, img in scene_imgs.items()]
                lines += ['']
            if title.startswith('integrators') and integ_img:
                lines += [f'![integrators]({integ_img})', '']
            if notes:
                lines += [f'- {n}' for n in notes] + ['']
    return '\n'.join(lines)
