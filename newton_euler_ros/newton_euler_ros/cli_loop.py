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
``newton-euler excite`` and ``newton-euler payload``: the loop's ends.

    newton-euler excite MODEL.urdf --base LINK --tip LINK -o TRAJECTORY.json
                        [--period S] [--harmonics K] [--seconds S]
                        [--seed N] [--start Q1 ... QN] [--rate HZ]
    newton-euler payload MODEL.urdf BAG --base LINK --tip LINK [--json]
                         [--topic T] [--cutoff HZ]

Every problem with an input is one line on stderr naming the file or the
option, exit status 2.  Files are written atomically.
"""
import json
import math
import os
import sys

import numpy as np

# one line on stderr and exit status 2, as identify and replay
from .cli_identify import _fail, _load_urdf, _one_line_exit_2


def register(subparsers):
    """Add the ``excite`` and ``payload`` commands to ``subparsers``."""
    exc = subparsers.add_parser(
        'excite', help='write an excitation trajectory (Fourier series '
                       'optimised for identification) as JointTrajectory '
                       'JSON')
    exc.add_argument('model', metavar='MODEL.urdf')
    exc.add_argument('--base', metavar='LINK', required=True,
                     help='first link of the chain')
    exc.add_argument('--tip', metavar='LINK', required=True,
                     help='last link of the chain')
    exc.add_argument('-o', '--output', metavar='TRAJECTORY.json',
                     required=True)
    exc.add_argument('--period', type=float, default=10.0, metavar='S',
                     help='period of the series, s (default 10)')
    exc.add_argument('--harmonics', type=int, default=5, metavar='K',
                     help='harmonics per joint (default 5)')
    exc.add_argument('--seconds', type=float, metavar='S',
                     help='duration, rounded up to whole periods (default '
                          'one period)')
    exc.add_argument('--seed', type=int, default=0, metavar='N',
                     help='seed of the random series the optimiser starts '
                          'from (default 0)')
    exc.add_argument('--start', type=float, nargs='+', metavar='Q',
                     help='rest configuration at both ends (default: the '
                          'middle of the limits of each joint)')
    exc.add_argument('--rate', type=float, default=50.0, metavar='HZ',
                     help='trajectory points per second (default 50)')
    exc.add_argument('--budget', type=float, default=40.0, metavar='S',
                     help='optimisation time budget, s (default 40)')
    exc.set_defaults(func=_one_line_exit_2(cmd_excite))
    pay = subparsers.add_parser(
        'payload', help='estimate the mass, centre of mass and inertia of '
                        'a payload at the tip from a recording')
    pay.add_argument('model', metavar='MODEL.urdf',
                     help='the arm without the payload (identified URDF)')
    pay.add_argument('bag', metavar='BAG', help='rosbag2 directory')
    pay.add_argument('--base', metavar='LINK', required=True)
    pay.add_argument('--tip', metavar='LINK', required=True,
                     help='the payload is fixed to this link; com in its '
                          'frame')
    pay.add_argument('--topic', default='/joint_states')
    pay.add_argument('--cutoff', type=float, metavar='HZ',
                     help='low-pass cutoff (default as identify)')
    pay.add_argument('--json', action='store_true',
                     help="print the node's payload.* parameters as JSON "
                          '(null where the motion does not determine a '
                          'value; "undetermined" says why)')
    pay.set_defaults(func=_one_line_exit_2(cmd_payload))


def _model(path, base, tip):
    return _load_urdf(path, base, tip)


def cmd_excite(args):
    """Run ``newton-euler excite``."""
    from .core import NewtonEulerError
    from .ident.excite import excite, trajectory_json
    from .ident.urdf_out import atomic_write
    out = os.path.abspath(args.output)
    if not os.path.isdir(os.path.dirname(out)):
        _fail(f'{args.output}: the directory does not exist')
    for opt, v in (('--seconds', args.seconds), ('--rate', args.rate),
                   ('--budget', args.budget)):
        if v is not None and not (v > 0 and math.isfinite(v)):
            _fail(f'{opt} must be a positive number, got {v:g}')
    model, _, notes = _model(args.model, args.base, args.tip)
    for line in notes:
        print(line, file=sys.stderr)
    try:
        exc = excite(model, period=args.period, harmonics=args.harmonics,
                     seed=args.seed, start=args.start, budget=args.budget)
    except NewtonEulerError as exc_:
        _fail(f'{args.model}: {exc_}')
    for line in exc.limits.notes:
        print(f'note: {line}', file=sys.stderr)
    traj = trajectory_json(exc, args.seconds, args.rate)
    try:
        atomic_write(out, json.dumps(traj, separators=(',', ':')))
    except OSError as err:
        _fail(f'{args.output}: cannot write: {err.strerror or err}')
    total = traj['points'][-1]['time_from_start']
    print(f'{model.n} joints, period {exc.period:g} s, {exc.harmonics} '
          f'harmonics, {total:g} s ({len(traj["points"])} points), at rest '
          f'at both ends')
    print(f'condition number of the base regressor ({exc.base_count} base '
          f'parameters, inertial + drive): {exc.condition:.3g} optimised, '
          f'{exc.condition_random:.3g} for the random series of seed '
          f'{args.seed} ({exc.evaluations} evaluations, '
          f'{exc.seconds:.1f} s)')
    m = exc.margins
    print('limits used (margin 5 %: position 5 % of the range inside each '
          'limit, speed and acceleration at most 95 %):')
    w = max(len(x) for x in model.joint_names) + 2
    print(f'  {"joint":<{w}}{"q min":>9}{"q max":>9}{"pos margin":>12}'
          f'{"|qd|/limit":>12}{"|qdd|/limit":>13}')
    for j, name in enumerate(model.joint_names):
        pm = m['position'][j]
        pos = '-' if not np.isfinite(pm) else f'{100 * pm:.1f} %'
        print(f'  {name:<{w}}{m["q_min"][j]:>9.3f}{m["q_max"][j]:>9.3f}'
              f'{pos:>12}{100 * m["velocity"][j]:>10.1f} %'
              f'{100 * m["acceleration"][j]:>11.1f} %')
    print(f'wrote {args.output}')
    return 0


def cmd_payload(args):
    """Run ``newton-euler payload``."""
    from .core import NewtonEulerError
    from .ident.payload import estimate_payload
    model, _, notes = _model(args.model, args.base, args.tip)
    if not args.json:
        for line in notes:
            print(line, file=sys.stderr)
    try:
        est = estimate_payload(model, args.bag, topic=args.topic,
                               cutoff=args.cutoff)
    except (NewtonEulerError, ValueError) as exc:
        text = str(exc)
        _fail(text if text.startswith(str(args.bag))
              else f'{args.bag}: {text}')
    if args.json:
        print(json.dumps(est.parameters()))
        for line in est.undetermined_lines():
            print(f'warning: {line}', file=sys.stderr)
        return 0
    for line in est.summary_lines(args.tip):
        print(line)
    return 0
