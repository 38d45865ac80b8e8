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
The report's figures: Pareto fronts and cost growth with n.

Every function takes records (plain dicts, see :mod:`.report`) and writes
one PNG; matplotlib is imported lazily with the Agg backend.
"""
import math
import os

# An exact result (error 0) is drawn on this line of the log axis.
ERROR_FLOOR = 1e-18

FAMILY_STYLE = {
    'ours': ('tab:blue', 'o'),
    'float32': ('tab:orange', 's'),
    'fd': ('tab:purple', 'v'),
    'peer': ('tab:gray', 'D'),
    'model': ('tab:green', '^'),
}


def _pyplot():
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    return plt


def pareto_front(points):
    """
    Return the points no other point beats in both time and error.

    ``points`` are (us, error, ...) tuples; the front is sorted by time.
    """
    front = []
    best = math.inf
    for p in sorted(points, key=lambda p: (p[0], p[1])):
        if p[1] < best:
            front.append(p)
            best = p[1]
    return front


def _panel(ax, points, title, xlabel='microseconds per call',
           ylabel='relative error vs 50-digit truth', floor=ERROR_FLOOR):
    """
    Scatter (us, error, label, family) points with their Pareto front.

    An error of 0 is drawn at ``floor``; labels of points that share a
    region are staggered so that they stay readable.
    """
    for k, (us, err, label, family) in enumerate(
            sorted(points, key=lambda p: (p[1], p[0]))):
        color, marker = FAMILY_STYLE.get(family, ('black', 'x'))
        y = max(err, floor)
        ax.scatter([us], [y], color=color, marker=marker, s=36, zorder=3)
        text = label if err > 0 else f'{label} (exact: 0)'
        ax.annotate(text, (us, y), textcoords='offset points',
                    xytext=(5, 3 - 9 * (k % 3)), fontsize=7)
    front = pareto_front([(max(p[0], 1e-9), max(p[1], floor))
                          for p in points])
    if len(front) > 1:
        xs = []
        ys = []
        for k, (x, y) in enumerate(front):
            if k:
                xs.append(x)
                ys.append(ys[-1])
            xs.append(x)
            ys.append(y)
        ax.plot(xs, ys, color='tab:red', lw=1, ls='--', zorder=2,
                label='Pareto front')
        ax.legend(fontsize=7, loc='upper right')
    ax.set_xscale('log')
    ax.set_yscale('log')
    # within a decade or two the minor ticks' labels ran into each other
    from matplotlib.ticker import NullFormatter, NullLocator
    ax.xaxis.set_minor_formatter(NullFormatter())
    # the errors span up to 18 decades: their minor ticks are a grey band,
    # and making them took half the report's time
    ax.yaxis.set_minor_locator(NullLocator())
    ax.set_title(title, fontsize=9, y=1.0)  # fixed: no measuring draw
    ax.set_xlabel(xlabel, fontsize=8)
    ax.set_ylabel(ylabel, fontsize=8)
    ax.grid(True, which='major', alpha=0.3)
    ax.tick_params(labelsize=7)
    xs = [max(p[0], 1e-9) for p in points]
    ax.set_xlim(min(xs) / 1.6, max(xs) * 6)


def robot_pareto(records, robot, path):
    """Panels (tau, D, C, g, FD): error against time for every method."""
    plt = _pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(15, 8.5))
    axes.flat[-1].set_visible(False)
    rows = [r for r in records if r['section'] == 'arithmetic'
            and r['robot'] == robot]
    dof = rows[0]['dof'] if rows else '?'
    for ax, quantity in zip(axes.flat, ('tau', 'D', 'C', 'g', 'FD')):
        points = [(r['us'], r['error'], r['method'], r['family'])
                  for r in rows if r['quantity'] == quantity]
        _panel(ax, points, {'tau': 'tau = inverse dynamics',
                            'D': 'D(q) mass matrix',
                            'C': 'C(q, qd) Coriolis matrix',
                            'g': 'g(q) gravity torques',
                            'FD': 'qdd = forward dynamics'}[quantity])
    fig.suptitle(f'{robot} ({dof} joints): error against time; lower left '
                 f'is better', fontsize=11)
    # fixed margins: tight_layout drew every log axis once more to measure
    # it, 60 % of the report's time (2.0 of 3.4 s a figure)
    fig.subplots_adjust(left=0.05, right=0.98, bottom=0.07, top=0.91,
                        wspace=0.25, hspace=0.32)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def model_pareto(records, scene, path):
    """Model fidelity: the torque error of each effect subset vs time."""
    plt = _pyplot()
    rows = [r for r in records if r['section'] == 'effects'
            and r['scene'] == scene and r.get('error') is not None
            and r.get('us') is not None]
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    nonzero = [r['error'] for r in rows if r['error'] > 0]
    floor = min(nonzero) / 10 if nonzero else ERROR_FLOOR
    _panel(ax, [(r['us'], r['error'], r['method'], 'model') for r in rows],
           f'{scene}: torque error of a simplified model along the '
           f'scene trajectory', ylabel='RMS torque error / RMS torque',
           floor=floor)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def scaling(records, exponents, path, fit_from):
    """Cost against the number of links, log-log, with fitted exponents."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8.5, 6))
    ops = list(dict.fromkeys(r['method'] for r in records))
    for op in ops:
        pts = sorted((r['dof'], r['us']) for r in records
                     if r['method'] == op)
        p = exponents.get(op)
        label = op if p is None else f'{op}: n^{p[0]:.2f}'
        style = '--' if op.startswith('Pinocchio') else '-'
        ax.plot([x for x, _ in pts], [y for _, y in pts], style,
                marker='o', ms=4, label=label)
    ax.axvline(fit_from, color='gray', lw=0.8, ls=':')
    ax.text(fit_from, ax.get_ylim()[1], f' fit from n={fit_from}',
            fontsize=7, va='top', color='gray')
    ax.set_xscale('log')
    ax.set_yscale('log')
    ax.set_xlabel('number of links n (random chains)')
    ax.set_ylabel('microseconds per call')
    ax.set_title('Cost growth with n; legend: fitted exponent p of c n^p',
                 y=1.0)
    ax.grid(True, which='both', alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def integrators(records, path):
    """Trajectory error and energy drift against cost, per scene."""
    plt = _pyplot()
    rows = [r for r in records if r['section'] == 'integrators']
    scenes = list(dict.fromkeys(r['scene'] for r in rows))
    if not scenes:
        return False
    fig, axes = plt.subplots(len(scenes), 2,
                             figsize=(11, 3.8 * len(scenes)), squeeze=False)
    for row, scene in zip(axes, scenes):
        for method in dict.fromkeys(r['method'] for r in rows
                                    if r['scene'] == scene):
            pts = sorted((r['cost'], r['error'], r['drift'], r['step'])
                         for r in rows
                         if r['scene'] == scene and r['method'] == method)
            xs = [p[0] for p in pts]
            row[0].plot(xs, [max(p[1], ERROR_FLOOR) for p in pts],
                        marker='o', label=method)
            row[1].plot(xs, [max(p[2], ERROR_FLOOR) for p in pts],
                        marker='o', label=method)
            for p in pts:
                row[0].annotate(f'{p[3] * 1e3:g} ms', (p[0], p[1]),
                                fontsize=6, xytext=(3, 2),
                                textcoords='offset points')
        for ax, ylabel in zip(row, ('max |q - q_converged| (rad or m)',
                                    'max |energy drift| / max |E|')):
            ax.set_xscale('log')
            ax.set_yscale('log')
            ax.set_xlabel('wall seconds per simulated second', fontsize=8)
            ax.set_ylabel(ylabel, fontsize=8)
            ax.set_title(scene, fontsize=9, y=1.0)
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def relpath(path, start):
    """Return ``path`` relative to ``start`` with forward slashes."""
    return os.path.relpath(path, start).replace(os.sep, '/')
