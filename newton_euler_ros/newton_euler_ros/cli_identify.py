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
``newton-euler identify`` and ``newton-euler replay``.

    newton-euler identify NOMINAL.urdf BAG [BAG ...] --base LINK [--tip LINK]
                          -o IDENTIFIED.urdf [--topic T] [--validate BAG2]
                          [--effort torque|current] [--known-mass BAG KG]
                          [--known-mass-link LINK] [--coulomb-width EPS]
                          [--cutoff HZ] [--overwrite]
    newton-euler replay MODEL.urdf BAG --base LINK [--tip LINK] --csv OUT.csv
                        [--plot OUT.png] [--topic T] [--cutoff HZ]

Without ``--tip`` the model is the whole tree below ``--base`` (both arms
of a dual-arm robot, a torso with arms, an arm with its fingers): every
body is identified, and every independent joint's drive terms; mimic
followers move with their leaders (their JointState entries are not
read).

Every problem with an input (a bag that is missing, corrupt or truncated,
lacks the topic, the effort or a chain joint, has efforts that are all
zero (``replay``: no effort to compare), is too short or does not
excite the arm, has efforts that cannot be in the unit ``--effort`` says;
a known-mass recording that does not excite the mass; an unusable URDF;
an output that would overwrite the input) is one line on stderr naming
the file, exit status 2, and nothing is written.  Every file
written (URDF, CSV, plot) is written atomically.  The identification
pipeline (``newton_euler_ros.ident``) is imported only by these
commands, never by the nodes.
"""
import os
import sys
import textwrap
import time

import numpy as np

from .cli_options import model_argument, overwrite_option, recording_options

EXIT_BAD_INPUT = 2


def register(subparsers):
    """Add the ``identify`` and ``replay`` commands to ``subparsers``."""
    ide = subparsers.add_parser(
        'identify', help='identify inertials and drive terms from a rosbag2 '
                         'recording of /joint_states; write a URDF')
    ide.add_argument('nominal', metavar='NOMINAL.urdf',
                     help='the URDF to start from (the prior)')
    ide.add_argument('bag', metavar='BAG', nargs='+',
                     help='rosbag2 directory (MCAP or sqlite3); several are '
                          'fitted together')
    _common(ide)
    ide.add_argument('-o', '--output', metavar='IDENTIFIED.urdf',
                     required=True, help='URDF to write')
    ide.add_argument('--validate', metavar='BAG2',
                     help='a second recording to report the models on')
    ide.add_argument('--effort', choices=('torque', 'current'),
                     default='torque',
                     help='what JointState.effort is: joint torque in N m '
                          '(default; Franka, KUKA) or proportional to it, '
                          "a motor current (UR's default): the torque "
                          'constants are identified and written')
    ide.add_argument('--known-mass', nargs=2, metavar=('BAG', 'KG'),
                     help='a recording with a known mass added at the tip '
                          'link (its centre of mass and inertia need not be '
                          "known): fixes the torque constants' scale")
    ide.add_argument('--known-mass-link', metavar='LINK',
                     help='the link the known mass is fixed to (default: '
                          'the tip; needed on a tree with several tips)')
    ide.add_argument('--coulomb-width', type=float, metavar='EPS',
                     help='Coulomb smoothing width of tanh(qd / EPS), rad/s '
                          '(default: chosen on held-out blocks among 0.005 '
                          "... 0.1 and the nominal URDF's)")
    overwrite_option(ide, 'allow -o to be the input URDF')
    ide.set_defaults(func=_one_line_exit_2(cmd_identify))
    rep = subparsers.add_parser(
        'replay', help="the model's torques along a recording, against the "
                       'measured efforts (CSV, plot)')
    model_argument(rep, 'the URDF whose torques are replayed')
    rep.add_argument('bag', metavar='BAG', help='rosbag2 directory (MCAP or '
                                                'sqlite3)')
    _common(rep)
    rep.add_argument('--csv', metavar='OUT.csv', required=True,
                     help='one row per JointState message: time, then '
                          'NAME.measured and NAME.model per joint')
    rep.add_argument('--plot', metavar='OUT.png',
                     help='draw measured against model per joint')
    rep.set_defaults(func=_one_line_exit_2(cmd_replay))


def _common(parser):
    recording_options(parser, 'last link of the chain (default: the whole '
                              'tree below --base)',
                      'low-pass cutoff (default min(10 Hz, a fifth of the '
                      'sample rate))')


class _BadInput(Exception):
    """One line for stderr; the command exits with status 2."""


def _fail(message):
    raise _BadInput(message)


def _one_line_exit_2(command):
    """Run ``command(args)``; a _BadInput becomes one line and status 2."""
    def run(args):
        try:
            return command(args)
        except _BadInput as exc:
            print(f'newton-euler: error: {exc}', file=sys.stderr)
            return EXIT_BAD_INPUT
    run.__doc__ = command.__doc__
    return run


def _load_urdf(path, base, tip, prior=False):
    """
    Return (model, text, notes) or fail with one line.

    ``prior=True``: the URDF is identify's prior, read leniently
    (``core.urdf``: impossible inertials and negative friction accepted,
    each with a note).
    """
    from .core import NewtonEulerError
    from .core.robot_file import Note
    from .core.urdf import inspect_urdf, read_urdf_text
    if os.path.isdir(path):
        _fail(f'{path}: is a directory, not a URDF file')
    if not os.path.isfile(path):
        _fail(f'{path}: no such URDF file')
    try:
        text, label = read_urdf_text(path)
        model, found, _ = inspect_urdf(text, base=base, tip=tip,
                                       label=path, prior=prior)
    except NewtonEulerError as exc:
        _fail(str(exc))
    notes = []
    for message in found:
        kind = 'note' if isinstance(message, Note) or 'triangle' in str(
            message) else 'warning'
        notes.append(f'{kind}: {message}')
    return model, text, notes


def _cell(fmt, value):
    """Format a number, or '-' where there is none (NaN: no sample)."""
    return fmt.format(value) if np.isfinite(value) else '-'


def _table(title, names, columns):
    """
    Print a per-joint table; columns: [(header, values, fmt)].

    A NaN value (a joint that never moves, in a "moving" column) is '-'
    and left out of the mean.
    """
    print(title)
    width = max(len(n) for n in names) + 2
    heads = ''.join(f'{h:>18}' for h, _, _ in columns)
    print(f'  {"joint":<{width}}' + heads)
    for j, name in enumerate(names):
        print(f'  {name:<{width}}' + ''.join(
            f'{_cell(fmt, v[j]):>18}' for _, v, fmt in columns))

    def mean(v):
        v = np.asarray(v, dtype=np.float64)
        return float(np.mean(v[np.isfinite(v)])) if np.isfinite(
            v).any() else float('nan')
    print(f'  {"mean":<{width}}' + ''.join(
        f'{_cell(fmt, mean(v)):>18}' for _, v, fmt in columns))


def _stats_table(title, names, stats):
    rms0, rel0 = stats['nominal']
    rms1, rel1 = stats['identified']
    _table(title, names, [('nominal RMS', rms0, '{:.4g}'),
                          ('nominal rel %', rel0 * 100, '{:.2f}'),
                          ('identified RMS', rms1, '{:.4g}'),
                          ('identified rel %', rel1 * 100, '{:.2f}')])
    both = np.isfinite(rel0) & np.isfinite(rel1)
    return float(np.mean(rel0[both])), float(np.mean(rel1[both]))


def _known_mass(args):
    """Return (bag, kg) of --known-mass, or None; one line if bad."""
    if args.known_mass is None:
        if getattr(args, 'known_mass_link', None) is not None:
            _fail('--known-mass-link needs --known-mass BAG KG')
        return None
    bag, kg = args.known_mass
    try:
        mass = float(kg)
    except ValueError:
        mass = float('nan')
    if not (mass > 0 and np.isfinite(mass)):
        _fail(f'--known-mass {bag} {kg}: the mass must be a positive number '
              f'of kg')
    return bag, mass


def _identify_or_fail(model, text, args):
    from .core import NewtonEulerError
    from .ident.fit import identify
    known = _known_mass(args)
    try:
        return identify(model, args.bag, topic=args.topic,
                        validate=args.validate,
                        coulomb_width=args.coulomb_width,
                        cutoff=args.cutoff, urdf_text=text,
                        effort=args.effort, known_mass=known,
                        urdf_label=args.nominal,
                        known_mass_link=args.known_mass_link)
    except (NewtonEulerError, ValueError) as exc:
        line = str(exc)
        files = list(args.bag) + [args.validate, known and known[0]]
        named = any(line.startswith(str(p)) for p in files if p)
        _fail(line if named else f'{args.bag[0]}: {line}')


def _payload_link(model, link, path, option):
    """Check that ``link`` can carry a mass (payload_frame); one line."""
    from .ident.payload import LinkError, payload_frame
    try:
        return payload_frame(model, link, f'{option} LINK')
    except LinkError as exc:
        _fail(f'{path}: {exc}')


def _describe(model):
    """One line on a tree: coordinates, bodies, mimic followers."""
    report = (model.info or {}).get('urdf') or {}
    if not report.get('tree'):
        return None
    mimic = report.get('mimic') or {}
    follow = ', '.join(f'{f} = {s:g} x {lead}' + (f' + {o:g}' if o else '')
                       for f, (lead, s, o) in mimic.items())
    return (f'whole tree below {report["base"]!r}: {model.n} joints, '
            f'{model.nb} bodies' + (f'; mimic joints move with their '
                                    f'leader ({follow})' if follow else ''))


def _print_constants(result, names, tip_frame='the tip frame'):
    K = result.torque_constant
    if K is None:
        return
    how = {'given': 'as given in the nominal URDF',
           'identified': 'identified'}[result.constants]
    print(f'torque constants (N m per effort unit), {how}:')
    for j, name in enumerate(names):
        tag = ('  (not determined by the recordings: the mean of the '
               'others)' if j in result.undetermined_k else '')
        print(f'  {name:<24}{K[j]:>10.4g}{tag}')
    if result.payload is not None:
        c = result.payload['com']
        seen = ('' if result.mass_excitation is None else
                f'its torque changes by up to '
                f'{result.mass_excitation.max():.2g} residual RMS; ')
        print(f'known mass {result.payload["mass"]:g} kg: {seen}centre of '
              f'mass found at ({1000 * c[0]:.0f}, {1000 * c[1]:.0f}, '
              f'{1000 * c[2]:.0f}) mm in {tip_frame}')


#: relative torque errors this close count as the same (no WORSE warning)
SAME = 0.01


def _compare(nominal, identified, where, worse, level):
    """File ``where`` under worse (beyond SAME) or level (within it)."""
    if identified > nominal * (1.0 + SAME):
        worse.append(where)
    elif identified >= nominal * (1.0 - SAME):
        level.append(where)


def _listed(items):
    return (items[0] if len(items) == 1 else
            f'{", ".join(items[:-1])} and {items[-1]}')


def _reads_back(body, args):
    """Fail, writing nothing, if the URDF to write would be refused."""
    from .core import NewtonEulerError
    from .core.urdf import inspect_urdf
    try:
        inspect_urdf(body, base=args.base, tip=args.tip, label=args.output)
    except NewtonEulerError as exc:
        _fail(f'{args.output}: not written: the identified model would be '
              f'refused on reading ({exc}); please report this')


def cmd_identify(args):
    """Run ``newton-euler identify``."""
    start = time.perf_counter()
    src = os.path.abspath(args.nominal)
    out = os.path.abspath(args.output)
    if os.path.exists(out) and os.path.exists(src) and (
            os.path.samefile(src, out)) and not args.overwrite:
        _fail(f'{args.output}: is the input URDF; refusing to overwrite it '
              f'(choose another -o, or add --overwrite)')
    if not os.path.isdir(os.path.dirname(out)):
        _fail(f'{args.output}: the directory does not exist')
    if args.coulomb_width is not None and not args.coulomb_width > 0:
        _fail(f'--coulomb-width must be > 0, got {args.coulomb_width:g}')
    _known_mass(args)
    model, text, notes = _load_urdf(args.nominal, args.base, args.tip,
                                    prior=True)
    for line in notes:
        print(line, file=sys.stderr)
    if args.known_mass is not None:
        _payload_link(model, args.known_mass_link, args.nominal,
                      '--known-mass-link')
    from .ident.fit import fixed_parts
    from .ident.problem import REST_FRACTION, REST_SPEED, rest_speeds
    from .ident.notes import report
    from .ident.urdf_out import atomic_write, identified_urdf
    result = _identify_or_fail(model, text, args)
    names = model.joint_names
    tree = _describe(model)
    if tree:
        print(tree)
    for path, info in result.recordings:
        print(f'recording {path}: {info["samples"]} samples over '
              f'{info["duration"]:.1f} s at {info["rate"]:.0f} Hz, low-pass '
              f'{info["cutoff"]:g} Hz, fit on every {info["step"]} '
              f'sample(s)')
    count = ('10 inertial + 4 drive per joint' if model.nb == model.n
             else f'10 inertial per body, {model.nb} bodies, + 4 drive per '
                  f'joint, {model.n} joints')
    print(f'rank {result.rank} of {result.structural_rank} base parameters '
          f'(of {10 * model.nb + 4 * model.n}: {count}); '
          f'condition number {result.condition:.3g}')
    print(f'prior weight {result.lam:g}, Coulomb width '
          f'{result.coulomb_width:g} rad/s (both chosen on held-out blocks'
          + (')' if args.coulomb_width is None else '; the width given)'))
    print(f'fitted where each joint moves (|qd| >= {REST_SPEED:g} rad/s: at '
          f'rest static friction holds any torque in its band); the tables '
          f'cover every sample')
    slow = [f'{names[j]} {v:.2g}' for j, v in enumerate(rest_speeds(model))
            if v < REST_SPEED]
    if slow:
        print(f'  slower joints: {REST_FRACTION:g} of their velocity limit '
              f'({", ".join(slow)})')
    _print_constants(result, names, 'the tip frame'
                     if args.known_mass_link is None
                     else f'the {args.known_mass_link} frame')
    unit = ('N m' if result.torque_constant is None else
            'N m: the effort times the torque constants')
    _stats_table(f'torque residual on the recording ({unit}; relative to '
                 f'the RMS effort):', names, {
                     'nominal': result.fit_stats['nominal'],
                     'identified': result.fit_stats['identified']})
    worse, level = [], []
    if 'held_out_nominal' in result.fit_stats:
        n0, n1 = _stats_table('on the held-out blocks (not fitted):', names, {
            'nominal': result.fit_stats['held_out_nominal'],
            'identified': result.fit_stats['held_out_identified']})
        _compare(n0, n1, 'the held-out blocks', worse, level)
    if result.validate_stats:
        n0, n1 = _stats_table(f'on {args.validate} (validation):', names,
                              result.validate_stats)
        _compare(n0, n1, args.validate, worse, level)
    f0 = float(np.nanmean(result.fit_stats['nominal'][1]))
    f1 = float(np.nanmean(result.fit_stats['identified'][1]))
    _compare(f0, f1, 'the recording', worse, level)
    fixed = fixed_parts(model, text, prior=True)
    body = identified_urdf(text, model, result.theta, fixed, result.drives)
    _reads_back(body, args)
    try:
        atomic_write(out, body)
    except OSError as exc:
        _fail(f'{args.output}: cannot write: {exc.strerror or exc}')
    for kind, line in report(model, result, args.known_mass, args.validate,
                             args.topic):
        print(f'{kind}: {line}', file=sys.stderr)
    if worse:
        print(f'warning: the identified model does WORSE than the nominal on '
              f'{_listed(worse)}: check the recording (excitation, effort '
              f'units, joint names)', file=sys.stderr)
    if level:
        print(f'note: the identified model is no better than the nominal '
              f'(within {SAME:.0%}) on {_listed(level)}: the nominal may '
              f'already be identified from like recordings', file=sys.stderr)
    print(f'wrote {args.output}')
    print(f'identified in {result.seconds:.2f} s'
          + (f', validated in {result.validate_seconds:.2f} s'
             if result.validate_stats else '')
          + f' (whole command {time.perf_counter() - start:.2f} s)')
    return 0


def cmd_replay(args):
    """Run ``newton-euler replay``."""
    from .core import NewtonEulerError
    from .core.drives import model_drives
    from .ident.bag import read_joint_states
    from .ident.signals import prepare
    from .ident.torques import predict
    for opt, path in (('--csv', args.csv), ('--plot', args.plot)):
        if path is not None and not os.path.isdir(
                os.path.dirname(os.path.abspath(path))):
            _fail(f'{path}: the directory does not exist ({opt})')
    model, _, notes = _load_urdf(args.model, args.base, args.tip)
    for line in notes:
        print(line, file=sys.stderr)
    drives = model_drives(model)
    try:
        js = read_joint_states(args.bag, model.joint_names, args.topic)
        prep = prepare(js.stamps, js.q, js.qd, js.effort, cutoff=args.cutoff)
    except (NewtonEulerError, ValueError) as exc:
        _fail(str(exc) if str(exc).startswith(str(args.bag))
              else f'{args.bag}: {exc}')
    if not np.any(js.effort):
        _fail(f'{args.bag}: no effort to compare: every effort on '
              f'{args.topic} is zero')
    if prep is None:
        _fail(f'{args.bag}: too short: nothing is left after filtering')
    model_tau = predict(model, drives, prep.q, prep.qd, prep.qdd)
    current = drives is not None and drives.torque_constant is not None
    _unit_warning(args, model, drives, model_tau, prep)
    if current:     # compared in the effort's own unit
        model_tau = drives.torque_to_effort(model_tau)
    # the messages inside the filtered stretches (edges left out)
    i = np.clip(np.searchsorted(prep.t, js.stamps), 1, len(prep.t) - 1)
    near = np.minimum(np.abs(prep.t[i] - js.stamps),
                      np.abs(prep.t[i - 1] - js.stamps))
    keep = near <= 1.0 / prep.rate
    n = model.n
    at = js.stamps[keep]
    mod, low, speed = (np.column_stack([np.interp(at, prep.t, X[:, j])
                                        for j in range(n)])
                       for X in (model_tau, prep.effort, prep.qd))
    meas = js.effort[keep]
    ns = js.stamps_ns[keep]
    names = model.joint_names
    _write_replay_csv(args.csv, names, ns, meas, mod)
    moving = np.abs(speed) > MOVING
    silent = [name for j, name in enumerate(names) if not meas[:, j].any()]
    if _describe(model):
        print(_describe(model))
    print(f'{args.bag}: {len(ns)} of {len(js)} messages (filter edges and '
          f'gaps left out); model {args.model}'
          + ('' if drives is not None else ' (no drive terms)'))
    unit = ("the effort's unit: the model torque / torque_constant"
            if current else 'N m')
    _table(f'model against the measured effort ({unit}; relative to the '
           f'RMS effort; "moving": samples where the joint turns faster '
           f'than {MOVING:g} rad/s):', names,
           [('RMS raw', _rms(mod - meas), '{:.4g}'),
            ('rel % raw', 100 * _rel(mod, meas), '{:.2f}'),
            ('rel % moving', 100 * _rel(mod, meas, moving), '{:.2f}'),
            (f'rel % {prep.cutoff:g} Hz', 100 * _rel(mod, low), '{:.2f}')])
    print(textwrap.fill(
        f'(the {prep.cutoff:g} Hz column compares with the effort '
        f'low-passed like the state: free of noise, but smoothed where a '
        f"joint reverses, while the model's friction still switches "
        f'sharply there, so on a joint with friction and little noise '
        f'it can exceed the raw one; docs/identification.md)', 78,
        initial_indent='  ', subsequent_indent='   '))
    if silent:
        print(f'note: every effort of {", ".join(silent)} is zero: '
              f'nothing to compare there (-)', file=sys.stderr)
    print(f'wrote {args.csv}')
    if args.plot:
        _plot(args.plot, replay_figure((ns - ns[0]) * 1e-9, names, meas,
                                       mod, low, effort_units(model,
                                                              drives)))
        print(f'wrote {args.plot}')
    return 0


MOVING = 0.05       # rad/s (m/s): a joint moves faster than this


def _unit_warning(args, model, drives, tau, prep):
    """Warn in one line when the efforts cannot be what the URDF says."""
    from .ident import effort as units
    line = units.mismatch(args.bag, model.joint_names, tau, prep.effort,
                          prep.qd, drives, args.model,
                          units.URDF_FIX + '; the percentages below compare '
                          'different units')
    if line:
        print(f'warning: {line}', file=sys.stderr)


def _rms(err, mask=None):
    """RMS per column (over the rows where ``mask`` is true)."""
    mask = np.ones(err.shape, dtype=bool) if mask is None else mask
    return np.sqrt(np.sum(np.where(mask, err, 0.0) ** 2, axis=0)
                   / np.maximum(mask.sum(axis=0), 1))


def _rel(model, meas, mask=None):
    """
    RMS error relative to the RMS measurement, per column.

    NaN for a column whose ``mask`` is false everywhere (no sample), or
    whose measurement is zero there (no effort to compare).
    """
    rms = _rms(meas, mask)
    return np.where(rms > 0, _rms(model - meas, mask)
                    / np.where(rms > 0, rms, 1.0), np.nan)


def _write_replay_csv(path, names, ns, meas, mod):
    from .ident.urdf_out import atomic_open
    try:
        with atomic_open(path) as f:
            f.write('time,' + ','.join(f'{x}.measured,{x}.model'
                                       for x in names) + '\n')
            for a in range(0, len(ns), 10000):
                rows = []
                meas_l = meas[a:a + 10000].tolist()
                mod_l = mod[a:a + 10000].tolist()
                for r in range(a, min(a + 10000, len(ns))):
                    cells = ','.join(f'{mr!r},{mo!r}' for mr, mo in zip(
                        meas_l[r - a], mod_l[r - a]))
                    t = int(ns[r])
                    rows.append(f'{t // 1_000_000_000}.'
                                f'{t % 1_000_000_000:09d},{cells}\n')
                f.write(''.join(rows))
    except OSError as exc:
        _fail(f'{path}: cannot write: {exc.strerror or exc}')


def effort_units(model, drives):
    """
    Return each joint's effort axis label with its unit, model order.

    ``torque (N m)`` (``force (N)`` on a prismatic joint); where the URDF
    gives torque constants the efforts are compared in their own unit
    (a motor current: A on UR's driver), one of which is K N m.
    """
    from .safety import joint_units
    units = joint_units(model)
    if drives is None or drives.torque_constant is None:
        return [('force (N)' if unit == 'N' else 'torque (N m)')
                for unit in units]
    return [f'effort (unit = {k:.4g} {unit})'
            for k, unit in zip(drives.torque_constant, units)]


def replay_figure(t, names, meas, mod, low, labels):
    """
    Draw measured against model per joint; return the figure.

    ``t`` (s) since the first message; ``labels``: each joint's effort
    axis label with its unit (:func:`effort_units`).
    """
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    n = len(names)
    fig, axes = plt.subplots(n, 1, sharex=True, figsize=(10, 1.8 * n + 1),
                             squeeze=False)
    for j, ax in enumerate(axes[:, 0]):
        ax.plot(t, meas[:, j], color='0.7', lw=0.6, label='measured')
        ax.plot(t, low[:, j], color='k', lw=0.9, label='measured, low-pass')
        ax.plot(t, mod[:, j], color='tab:red', lw=0.9, label='model')
        ax.set_ylabel(f'{names[j]}\n{labels[j]}', fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0, 0].legend(loc='upper right', fontsize=7, ncol=3)
    axes[-1, 0].set_xlabel('time since the first message (s)')
    fig.tight_layout()
    return fig


def _plot(path, fig):
    import matplotlib.pyplot as plt
    from .ident.urdf_out import atomic_open
    try:
        with atomic_open(path, 'wb') as f:
            fig.savefig(f, format='png', dpi=90)
    except OSError as exc:
        _fail(f'{path}: cannot write: {exc.strerror or exc}')
    finally:
        plt.close(fig)
