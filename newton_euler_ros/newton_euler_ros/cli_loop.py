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
                        --start Q1 ... QN [--period S] [--harmonics K]
                        [--seconds S] [--seed N] [--rate HZ] [--budget S]
                        [--evaluations N] [--range JOINT LO HI]
                        [--max-velocity V [V ...]]
                        [--max-acceleration A [A ...]] [--clearance M]
                        [--floor Z | --no-floor] [--plane NX NY NZ D]
                        [--box XMIN YMIN ZMIN XMAX YMAX ZMAX]
    newton-euler payload MODEL.urdf BAG --base LINK [--tip LINK]
                         [--link LINK] [--json] [--topic T] [--cutoff HZ]

``payload`` without ``--tip`` takes the whole tree below ``--base``; the
payload is fixed to ``--link`` (default: the tip, the tree's single one).

Every problem with an input is one line on stderr naming the file or the
option, exit status 2.  Files are written atomically.
"""
import json
import math
import os
import sys

import numpy as np

# one line on stderr and exit status 2, as identify and replay
from .cli_identify import (_describe, _fail, _load_urdf, _one_line_exit_2,
                           _payload_link)
from .cli_options import json_option, model_argument, recording_options


def register(subparsers):
    """Add the ``excite`` and ``payload`` commands to ``subparsers``."""
    exc = subparsers.add_parser(
        'excite', help='write an excitation trajectory (Fourier series '
                       'optimised for identification) as JointTrajectory '
                       'JSON')
    model_argument(exc, 'the URDF whose limits the trajectory keeps')
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
                     required=True,
                     help="the arm's pose now, one value per joint: the "
                          'trajectory starts and ends there at rest')
    exc.add_argument('--rate', type=float, default=50.0, metavar='HZ',
                     help='trajectory points per second (default 50)')
    exc.add_argument('--budget', type=float, default=40.0, metavar='S',
                     help='optimisation time budget, s (default 40)')
    exc.add_argument('--evaluations', type=int, metavar='N',
                     help='stop the optimisation after N evaluations of '
                     'the condition number (the same motion on any '
                     'machine for a seed; default: the time budget only)')
    exc.add_argument('--range', nargs=3, action='append', default=[],
                     metavar=('JOINT', 'LO', 'HI'),
                     help='keep JOINT in [LO, HI], inside its URDF limits '
                          '(repeat for more joints)')
    exc.add_argument('--max-velocity', type=float, nargs='+', metavar='V',
                     help='speed limit, one value or one per joint (the '
                          "URDF's where it is lower)")
    exc.add_argument('--max-acceleration', type=float, nargs='+',
                     metavar='A', help='acceleration limit, one value or '
                     'one per joint (default 4 rad/s^2, 1 m/s^2)')
    exc.add_argument('--clearance', type=float, default=0.05, metavar='M',
                     help='least distance of every link from the floor '
                          'and the planes, m (default 0.05)')
    flo = exc.add_mutually_exclusive_group()
    flo.add_argument('--floor', type=float, default=0.0, metavar='Z',
                     help="keep above the base frame's plane z = Z "
                          '(default 0: the mounting surface)')
    flo.add_argument('--no-floor', action='store_true',
                     help='no floor (an arm mounted over nothing)')
    exc.add_argument('--plane', type=float, nargs=4, action='append',
                     default=[], metavar=('NX', 'NY', 'NZ', 'D'),
                     help='keep on the side n . p >= D of a plane of the '
                          'base frame (a wall; repeat for more)')
    exc.add_argument('--box', type=float, nargs=6, metavar=('XMIN', 'YMIN',
                     'ZMIN', 'XMAX', 'YMAX', 'ZMAX'),
                     help='keep inside this box of the base frame, m')
    exc.set_defaults(func=_one_line_exit_2(cmd_excite))
    pay = subparsers.add_parser(
        'payload', help='estimate the mass, centre of mass and inertia of '
                        'a payload at the tip (or a link) from a recording')
    model_argument(pay, 'the arm without the payload (identified URDF)')
    pay.add_argument('bag', metavar='BAG', help='rosbag2 directory')
    recording_options(pay, 'last link of the chain (default: the whole '
                           'tree below --base); the payload is fixed to it '
                           'unless --link says otherwise',
                      'low-pass cutoff (default as identify)')
    pay.add_argument('--link', metavar='LINK',
                     help='the link the payload is fixed to; com and '
                          'inertia in its frame (default: the tip; needed '
                          'on a tree with several tips)')
    json_option(pay, "print the node's payload.* parameters as JSON (null "
                     'where the motion does not determine a value; '
                     '"undetermined" says why)')
    pay.set_defaults(func=_one_line_exit_2(cmd_payload))


def _model(path, base, tip):
    return _load_urdf(path, base, tip)


def cmd_excite(args):
    """Run ``newton-euler excite``."""
    from .core import NewtonEulerError
    from .ident.excite import (excite, model_limits, narrowed,
                               trajectory_json)
    from .ident.urdf_out import atomic_write
    out = os.path.abspath(args.output)
    if not os.path.isdir(os.path.dirname(out)):
        _fail(f'{args.output}: the directory does not exist')
    for opt, v in (('--seconds', args.seconds), ('--rate', args.rate),
                   ('--budget', args.budget)):
        if v is not None and not (v > 0 and math.isfinite(v)):
            _fail(f'{opt} must be a positive number, got {v:g}')
    if args.evaluations is not None and args.evaluations < 1:
        _fail(f'--evaluations must be at least 1, got {args.evaluations}')
    model, text, notes = _model(args.model, args.base, args.tip)
    for line in notes:
        print(line, file=sys.stderr)
    try:
        limits = narrowed(model, model_limits(model), _ranges(args.range),
                          args.max_velocity, args.max_acceleration)
        clearance = _clearance(args, model, text)
        exc = excite(model, period=args.period, harmonics=args.harmonics,
                     seed=args.seed, start=args.start, budget=args.budget,
                     limits=limits, clearance=clearance,
                     evaluations=args.evaluations)
    except NewtonEulerError as exc_:
        _fail(f'{args.model}: {exc_}')
    for line in exc.limits.notes:
        print(f'note: {line}', file=sys.stderr)
    traj = trajectory_json(exc, args.seconds, args.rate)
    rows = _checked_clearance(args, clearance, traj)
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
    _print_limits(exc, model)
    if rows:
        _print_clearance(exc, rows)
    print(f'wrote {args.output}')
    return 0


def _print_limits(exc, model):
    m, lim = exc.margins, exc.limits
    print('limits used (margin 5 %: position 5 % of the range inside each '
          'limit, speed and acceleration at most 95 %):')
    w = max(len(x) for x in model.joint_names) + 2
    print(f'  {"joint":<{w}}{"q min":>9}{"q max":>9}{"pos margin":>12}'
          f'{"|qd|/limit":>12}{"|qdd|/limit":>13}{"qd limit":>10}'
          f'{"qdd limit":>11}')
    for j, name in enumerate(model.joint_names):
        pm = m['position'][j]
        pos = '-' if not np.isfinite(pm) else f'{100 * pm:.1f} %'
        print(f'  {name:<{w}}{m["q_min"][j]:>9.3f}{m["q_max"][j]:>9.3f}'
              f'{pos:>12}{100 * m["velocity"][j]:>10.1f} %'
              f'{100 * m["acceleration"][j]:>11.1f} %'
              f'{lim.velocity[j]:>10.3g}{lim.acceleration[j]:>11.3g}')


def _ranges(raw):
    out = []
    for name, lo, hi in raw:
        try:
            out.append((name, float(lo), float(hi)))
        except ValueError:
            _fail(f'--range {name} {lo} {hi}: LO and HI must be numbers')
    return out


def _clearance(args, model, text):
    """Return the Clearance the options ask for, or None; notes on stderr."""
    from .ident.clearance import box, Clearance, floor, Plane
    if not (args.clearance >= 0 and math.isfinite(args.clearance)):
        _fail(f'--clearance must be a number >= 0, got {args.clearance:g}')
    try:
        planes = [] if args.no_floor else [floor(args.floor)]
        planes += [Plane.make(p[:3], p[3], 'plane ' + ' '.join(
            f'{x:g}' for x in p)) for p in args.plane]
        if args.box:
            planes += box(args.box[:3], args.box[3:])
    except ValueError as exc:
        _fail(f'--floor/--plane/--box: {exc}')
    if not planes:
        return None
    cl = Clearance.of_urdf(model, text, args.model, planes, args.clearance)
    if cl.bare:
        names = [name for name, _ in cl.bare]
        shown = ', '.join(names[:6]) + (' ...' if len(names) > 6 else '')
        why = cl.bare[0][1] or 'no geometry'
        print(f'note: no readable geometry for {len(names)} link(s) '
              f'({shown}; {names[0]}: {why}): bounded by their origins',
              file=sys.stderr)
    return cl


def _checked_clearance(args, cl, traj):
    """Check every written point by forward kinematics; report rows."""
    if cl is None:
        return []
    Q = np.array([p['positions'] for p in traj['points']])
    t = np.array([p['time_from_start'] for p in traj['points']])
    rows = cl.report(Q, t)
    bad = [r for r in rows if r[3] < r[5] - 1e-9]
    if bad:
        plane, body, _, least, when, need = min(
            bad, key=lambda r: r[3] - r[5])
        _fail(f'{args.model}: the trajectory would bring {body} to '
              f'{least:.4f} m from the {plane} at t = {when:.2f} s '
              f'(needs {need:.4f}); nothing written')
    return rows


def _print_clearance(exc, rows):
    cl = exc.clearance
    print(f'clearance kept at every written point (forward kinematics; '
          f'links bounded by their geometry and origins; margin '
          f'{cl.margin:g} m'
          + ('' if exc.shrink >= 1 else f'; the motion scaled to '
             f'{100 * exc.shrink:.0f} % to keep it') + '):')
    nearest = {}
    for row in rows:
        if row[1] not in nearest or row[3] < nearest[row[1]][3]:
            nearest[row[1]] = row
    w = max(len(b) for b in nearest) + 2
    pw = max(len(r[0]) for r in nearest.values()) + 2
    print(f'  {"link":<{w}}{"nearest plane":<{pw}}{"at start":>10}'
          f'{"least":>9}{"at t":>8}{"kept >=":>9}')
    for body, (plane, _, start, least, when, need) in nearest.items():
        held = ' (held: within the margin at the start)' \
            if need < cl.margin else ''
        print(f'  {body:<{w}}{plane:<{pw}}{start:>10.3f}{least:>9.3f}'
              f'{when:>8.2f}{need:>9.3f}{held}')


def cmd_payload(args):
    """Run ``newton-euler payload``."""
    from .core import NewtonEulerError
    from .ident.payload import estimate_payload
    model, _, notes = _model(args.model, args.base, args.tip)
    if not args.json:
        for line in notes:
            print(line, file=sys.stderr)
    _, _, link = _payload_link(model, args.link, args.model, '--link')
    if not args.json and _describe(model):
        print(_describe(model))
    try:
        est = estimate_payload(model, args.bag, topic=args.topic,
                               cutoff=args.cutoff, link=args.link)
    except (NewtonEulerError, ValueError) as exc:
        text = str(exc)
        _fail(text if text.startswith(str(args.bag))
              else f'{args.bag}: {text}')
    if args.json:
        print(json.dumps(est.parameters()))
        for line in est.undetermined_lines():
            print(f'warning: {line}', file=sys.stderr)
    else:
        for line in est.summary_lines(link):
            print(line)
    _payload_unit_warning(args, model, est)
    return 0


def _payload_unit_warning(args, model, est):
    """
    Warn in one line when the efforts cannot be what the URDF says.

    Identify's check on the model with the payload found (a heavy payload
    would otherwise pull the model's torque off the effort's scale): with
    currents read as torques the fit finds no such payload, and the
    efforts stay some torque constant off the model's torque.
    """
    from .feedforward_build import payload_model
    from .ident import effort as units
    from .ident.bag import read_joint_states
    from .ident.payload import INERTIA_KEYS
    try:
        loaded = payload_model(model, est.mass, est.com,
                               [est.inertia[a, b] for a, b in INERTIA_KEYS],
                               args.link or '')
    except ValueError:      # no payload the node could take: nothing to say
        return
    js = read_joint_states(args.bag, model.joint_names, args.topic)
    line = units.recording_mismatch(
        args.bag, loaded, js.stamps, js.q, js.qd, js.effort, args.model,
        units.URDF_FIX + '; the payload found is meaningless')
    if line:
        print(f'warning: {line}', file=sys.stderr)
