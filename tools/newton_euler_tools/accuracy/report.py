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
Run every measurement; print the table; write the report and its plots.

    python -m newton_euler_tools.accuracy [--quick] [--out DIR] [--no-peers]
                                        [--robot NAME ...] [--no-scenes]
    python -m newton_euler_tools.accuracy --from-records JSON [--out DIR]

Writes ``DIR/accuracy-vs-time.md`` (default ``docs/``), its PNGs under
``DIR/accuracy/`` and every record as ``DIR/accuracy/records.json``.
``--quick`` (one state per robot, short repeats and simulations) is a
smoke test that finishes in under a minute; its figures are noisier.
"""
import datetime
import json
import os
import platform
import sys
import time
import warnings

from newton_euler_ros.core import load_robot
from newton_euler_ros.core.robot_file import bundled_robots
import numpy as np

from .arithmetic import EPS, measure_robot
from .chains import random_chain, random_states
from .markdown import write_report
from .scaling import fit_start, FULL_SIZES, measure_scaling, QUICK_SIZES
from .tables import (ARITH_HEADER, arithmetic_rows, scaling_text,
                     scene_tables, text_table)
from .truth import GroundTruth
from .. import peers
from ..bench import Timer
from ..timing import tool_parser

CHAIN_SIZES = (6, 30, 100)


# --------------------------------------------------------------------------
# measurements


def robot_list(names, quick):
    """[(model, states)] for the bundled robots and the random chains."""
    out = []
    per_robot = 1 if quick else 5
    for name in names:
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            model = load_robot(name)
        out.append((model, random_states(model, per_robot)))
    for n in CHAIN_SIZES:
        model = random_chain(n)
        count = 1 if quick else {6: 5, 30: 3}.get(n, 2)
        out.append((model, random_states(model, count)))
    return out


def run(args, log):
    """Measure everything; return (records, context)."""
    timer = Timer(args.quick)
    notes = []
    records = []
    names = args.robot or bundled_robots()
    start = time.perf_counter()
    for model, states in robot_list(names, args.quick):
        t0 = time.perf_counter()
        truth = GroundTruth(model, states)
        truth.evaluate_all()
        t_truth = time.perf_counter() - t0
        robot_notes = []
        rows = measure_robot(model, truth, timer, use_peers=args.peers,
                             notes=robot_notes)
        for note in robot_notes:
            if note not in notes:
                notes.append(note)
        records += rows
        log(f'\n=== {model.name}: {model.n} joints, {model.convention} DH; '
            f'{len(states)} state(s); truth in {t_truth:.1f} s ===')
        log(text_table(ARITH_HEADER, arithmetic_rows(records, model.name)))

    sizes = QUICK_SIZES if args.quick else FULL_SIZES
    log(f'\n=== cost growth with n (random chains, n = '
        f'{", ".join(map(str, sizes))}) ===')
    scale_records, exponents = measure_scaling(timer, sizes,
                                               use_peers=args.peers,
                                               notes=notes)
    records += scale_records
    log(scaling_text(scale_records, exponents, sizes))

    if args.scenes:
        from . import scenes
        log('\n=== scenes: effect subsets, batching, feedforward, '
            'integrators ===')
        scene_records = scenes.run_all(args.quick)
        records += scene_records
        for title, header, rows, _ in scene_tables(scene_records):
            log(f'\n--- {title} ---')
            log(text_table(header, rows))
    context = {'notes': notes, 'exponents': exponents, 'sizes': sizes,
               'fit_from': fit_start(sizes),
               'elapsed_s': time.perf_counter() - start}
    return records, context


# --------------------------------------------------------------------------
# main


def main(argv=None):
    """Run the report from the command line; return the exit status."""
    parser = tool_parser(
        'accuracy', 'Measure what accuracy costs in time and write '
                    'docs/accuracy-vs-time.md with its plots.',
        'smoke test: one state per robot, short repeats and simulations '
        '(under a minute)')
    parser.add_argument('--out', default='docs', metavar='DIR',
                        help='where the report goes (default: docs)')
    parser.add_argument('--robot', action='append', metavar='NAME',
                        help='bundled robot to measure (repeatable; '
                             'default: all bundled robots)')
    parser.add_argument('--no-peers', dest='peers', action='store_false',
                        help='leave Pinocchio and Robotics Toolbox out')
    parser.add_argument('--no-scenes', dest='scenes', action='store_false',
                        help='skip the scene and simulator measurements')
    parser.add_argument('--from-records', metavar='JSON',
                        help='measure nothing: rewrite the report and its '
                             'plots from the records.json of an earlier run')
    args = parser.parse_args(argv)
    if args.from_records:
        return rerender(args.from_records, args.out)

    def log(line=''):
        print(line, flush=True)

    import numba
    versions = {'python': platform.python_version(), 'numpy': np.__version__,
                'numba': numba.__version__}
    if args.peers:
        versions.update(peers.versions())
    log('newton_euler_ros accuracy vs time  ' + '  '.join(
        f'{k} {v}' for k, v in versions.items()))
    log(f'mode: {"quick (smoke test)" if args.quick else "full"}; '
        f'float64 eps = {EPS:.3g}')
    records, context = run(args, log)
    context.update(versions=versions, quick=args.quick,
                   date=datetime.date.today().isoformat(),
                   machine=f'{platform.machine()}, {os.cpu_count()} cpus, '
                           f'{platform.platform()}',
                   command='python -m newton_euler_tools.accuracy'
                           + (' --quick' if args.quick else ''))
    path = write_report(records, context, args.out)
    for note in context['notes']:
        log(f'note: {note}')
    log(f'\nwrote {path} (measurements took {context["elapsed_s"]:.0f} s)')
    return 0


def rerender(path, out_dir):
    """Rewrite the report from saved records; return the exit status."""
    try:
        with open(path, encoding='utf-8') as fh:
            data = json.load(fh)
        records, context = data['records'], data['context']
        context['exponents'] = {k: tuple(v) for k, v in
                                context['exponents'].items()}
    except (OSError, ValueError, KeyError, TypeError) as exc:
        print(f'error: cannot read records from {path}: {exc}',
              file=sys.stderr)
        return 2
    print(f'wrote {write_report(records, context, out_dir)} from {path}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
