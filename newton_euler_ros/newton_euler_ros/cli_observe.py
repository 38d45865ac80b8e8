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
``newton-euler observe``: the momentum observer over a recorded bag.

    newton-euler observe MODEL.urdf BAG --base LINK --tip LINK
                         [--csv OUT.csv] [--plot OUT.png] [--json]
                         [--topic T] [--gain K] [--thresholds T [T ...]]
                         [--speed-thresholds B [B ...]]
                         [--acceleration-thresholds C [C ...]]
                         [--rest-thresholds T [T ...]]
                         [--static-friction R] [--no-rest-reference]
                         [--hysteresis H] [--damping L] [--max-gap S]
                         [--payload-mass M] [--payload-com X Y Z]

The same observer as inverse_dynamics_node's ``observer.*`` parameters
(:mod:`newton_euler_ros.core.observer`), run over the JointStates of a
rosbag2 recording (MCAP or sqlite3), so that gain and thresholds can be
tuned on one's own recording before turning it on.  Efforts are
converted to joint torques through the URDF's torque constants when it
has them (``<ne:drive torque_constant>``: a current-sensing arm).  With
``--csv``, writes one row per sample (time, external torque per joint,
external wrench, contact) and, with ``--plot``, a PNG; both are written
atomically.  Prints a summary with each joint's largest |external
torque| beyond the static friction allowance, and the thresholds it
suggests when the recording is free motion (docs/observer.md); with
``--json``, the same as one JSON object on stdout instead.
"""
import json
import math
import os
import sys
import tempfile

import numpy as np

from .cli_options import (chain_options, json_option, robot_argument,
                          topic_option)

WRENCH_COLUMNS = ('fx', 'fy', 'fz', 'mx', 'my', 'mz')


class _Usage(Exception):
    """A bad input: one line, exit status 2."""


def register(subparsers):
    """Add the ``observe`` command to the ``newton-euler`` parser."""
    obs = subparsers.add_parser(
        'observe', help='run the momentum observer (external torque, '
                        'wrench, contact) over a recorded bag')
    robot_argument(obs)
    obs.add_argument('bag', metavar='BAG',
                     help='rosbag2 directory (MCAP or sqlite3) with '
                          'sensor_msgs/JointState')
    chain_options(obs, 'URDF only: last link, the end effector (default: '
                       'the single leaf)')
    obs.add_argument('--csv', metavar='OUT.csv',
                     help='write one row per sample here')
    json_option(obs, 'print the summary as one JSON object (with '
                     'suggested_thresholds, one per joint in chain order) '
                     'instead of a table')
    obs.add_argument('--plot', metavar='OUT.png',
                     help='also plot external torques and wrench')
    topic_option(obs)
    obs.add_argument('--gain', type=float, default=50.0, metavar='K',
                     help='observer gain, 1/s (default 50)')
    obs.add_argument('--thresholds', type=float, nargs='+', default=[10.0],
                     metavar='T', help='contact threshold per joint in '
                     'chain order, or one for all (N m or N, also for a '
                     'current-sensing arm; default 10)')
    obs.add_argument('--speed-thresholds', type=float, nargs='+',
                     default=[0.0], metavar='B', help='per joint (or one '
                     'for all), the threshold grows by B per rad/s (m/s) '
                     "of the joint's speed (N m s/rad; default 0)")
    obs.add_argument('--acceleration-thresholds', type=float, nargs='+',
                     default=[0.0], metavar='C', help='per joint (or one '
                     'for all), the threshold grows by C per rad/s^2 of '
                     "the joint's acceleration (N m s^2/rad; default 0)")
    obs.add_argument('--rest-thresholds', type=float, nargs='+',
                     default=[0.0], metavar='T', help='per joint (or one '
                     "for all), the rest reference's own tolerance: its "
                     'tests use the larger of this and the threshold, '
                     "and test the joints' changes together too "
                     '(default 0: the threshold)')
    obs.add_argument('--static-friction', type=float, default=1.5,
                     metavar='R', help='at rest, allow for static friction '
                     "up to R x each joint's Coulomb friction (URDF "
                     '<dynamics friction>) above the thresholds; 0: none '
                     '(default 1.5)')
    obs.add_argument('--no-rest-reference', dest='rest_reference',
                     action='store_false',
                     help='do not feel pushes on the resting arm within the '
                          'friction band (the rest reference, '
                          'docs/observer.md)')
    obs.add_argument('--hysteresis', type=float, default=0.5,
                     help='release below this fraction of the threshold '
                          '(default 0.5)')
    obs.add_argument('--damping', type=float, default=0.01,
                     help='damping of the least-squares wrench (default '
                          '0.01)')
    obs.add_argument('--max-gap', type=float, default=0.1, metavar='S',
                     help='restart the integral after a gap longer than '
                          'this (s, default 0.1)')
    obs.add_argument('--payload-mass', type=float, default=0.0,
                     metavar='KG', help='payload on the end effector, kg')
    obs.add_argument('--payload-com', type=float, nargs=3,
                     default=[0.0, 0.0, 0.0], metavar=('X', 'Y', 'Z'),
                     help='payload centre of mass, end-effector frame, m')
    obs.set_defaults(func=cmd_observe)


def _atomic_write(path, write, mode='w'):
    """Write ``path`` through a temporary file in its folder, then rename."""
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise _Usage(f'{path}: folder {folder} does not exist')
    fd, tmp = tempfile.mkstemp(dir=folder, prefix='.' + os.path.basename(
        path), suffix='.tmp')
    try:
        with os.fdopen(fd, mode) as fh:
            write(fh)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def _finite(name, value, low=None, strict=True):
    if not math.isfinite(value) or (low is not None and (
            value <= low if strict else value < low)):
        bound = '' if low is None else f' {">" if strict else ">="} {low}'
        raise _Usage(f'{name}: must be finite{bound}, got {value}')


def _setup(args):
    """Model (payload included) and observer; _Usage on bad input."""
    from .core import inspect_robot, NewtonEulerError
    from .core.observer import drive_options, MomentumObserver
    from .core.robot_file import Note
    from .feedforward_build import payload_model

    for name in ('gain', 'max_gap'):
        _finite(f'--{name.replace("_", "-")}', getattr(args, name), 0.0)
    _finite('--damping', args.damping, 0.0, strict=False)
    _finite('--static-friction', args.static_friction, 0.0, strict=False)
    _finite('--hysteresis', args.hysteresis, 0.0)
    for opt, path in (('--csv', args.csv), ('--plot', args.plot)):
        if path and os.path.isdir(path):
            raise _Usage(f'{opt} {path}: is a directory')
    try:
        model, found, _ = inspect_robot(args.robot, base=args.base,
                                        tip=args.tip)
    except NewtonEulerError as exc:
        raise _Usage(str(exc)) from None
    for message in found:
        kind = 'note' if isinstance(message, Note) else 'warning'
        print(f'{kind}: {message}', file=sys.stderr)
    try:
        model = payload_model(model, args.payload_mass, args.payload_com,
                              [0.0] * 6)
        for name in ('thresholds', 'speed_thresholds',
                     'acceleration_thresholds', 'rest_thresholds'):
            given = getattr(args, name)
            if len(given) not in (1, model.n):
                raise ValueError(
                    f'--{name.replace("_", "-")}: give 1 or {model.n} '
                    f'values (chain order {list(model.joint_names)}), got '
                    f'{len(given)}')
        obs = MomentumObserver(model, args.gain, max_gap=args.max_gap,
                               damping=args.damping,
                               thresholds=args.thresholds,
                               speed_thresholds=args.speed_thresholds,
                               acceleration_thresholds=(
                                   args.acceleration_thresholds),
                               rest_thresholds=args.rest_thresholds,
                               hysteresis=args.hysteresis,
                               rest_reference=args.rest_reference,
                               **drive_options(model, args.static_friction))
    except ValueError as exc:
        text = str(exc).replace('payload.', '--payload-')
        for name in ('acceleration_thresholds', 'speed_thresholds',
                     'rest_thresholds'):
            text = text.replace(f'{name}:', f'--{name.replace("_", "-")}:')
        raise _Usage(text) from None
    return model, obs


def cmd_observe(args):
    """Run the observer over the bag; write the CSV (and the plot)."""
    try:
        return _observe(args)
    except _Usage as exc:
        print(f'newton-euler: error: {exc}', file=sys.stderr)
        return 2


def _observe(args):
    from .core.observer import observe_recording
    from .ident import effort as units
    from .ident.bag import BagError, read_joint_states

    model, obs = _setup(args)
    try:
        rec = read_joint_states(args.bag, model.joint_names, args.topic,
                                min_samples=2)
    except BagError as exc:
        raise _Usage(str(exc)) from None
    if rec.qd is None:
        raise _Usage(f'{args.bag}: the JointState messages on '
                     f'{args.topic!r} have no velocity (the observer needs '
                     f'joint velocities)')
    out = observe_recording(obs, rec.stamps, rec.q, rec.qd, rec.effort)
    unit = units.recording_mismatch(
        args.bag, model, rec.stamps, rec.q, rec.qd, rec.effort, args.robot,
        units.URDF_FIX + '; the external torques and contacts below are '
        'meaningless')
    unit = unit or _rest_units(args, model, rec)
    if unit:
        print(f'warning: {unit}', file=sys.stderr)
    names = list(model.joint_names)
    if args.csv:
        _atomic_write(args.csv, lambda fh: _write_csv(fh, rec, out, names))
    if args.plot:
        _plot(args.plot, rec.stamps, names, out, _thresholds(obs, out))
    summary = _summary(args, model, obs, rec, out)
    if args.json:
        print(json.dumps(summary))
        return 0
    print('\n'.join(_table(summary)))
    wrote = [x for x in (args.csv, args.plot) if x]
    if wrote:
        print('wrote ' + ' and '.join(wrote))
    return 0


def _rest_units(args, model, rec):
    """
    Check the units where the arm holds still: g(q) against the effort.

    The one line of ``core.effort_units.describe``, or None; for a
    recording of held poses, where the check on motion cannot tell.
    """
    from .core.batch import gravity_torques_batch
    from .core.drives import model_drives
    from .core.effort_units import describe, rest_ratios, URDF_FIX
    drives = model_drives(model)
    given = drives is not None and drives.torque_constant is not None
    meas = drives.effort_to_torque(rec.effort) if given else rec.effort
    K, counts = rest_ratios(rec.qd, gravity_torques_batch(model, rec.q),
                            meas)
    return describe(f'{args.bag} (where the arm holds still: gravity torque '
                    f'g(q) against the effort)', model.joint_names, K,
                    counts.astype(float), 'given' if given else 'torque',
                    args.robot, URDF_FIX + '; the external torques and '
                    'contacts below are meaningless')


def _motionless(args, rec):
    """Return the note on a recording where no joint moves, or []."""
    moving = float(np.mean(np.any(np.abs(rec.qd) > MOVING, axis=1)))
    if moving >= HELD:
        return []
    return [f'{args.bag}: no joint moves faster than {MOVING:g} rad/s in '
            f'{1 - moving:.1%} of the samples (held poses): the suggested '
            f"thresholds bound only the noise at rest, not the model's "
            f'error while moving; suggest them from a free recording with '
            f'motion (an excitation)']


MOVING = 0.05       # rad/s (m/s): a joint moves faster than this
HELD = 0.01         # a recording moving in fewer samples holds still


def _write_csv(fh, rec, out, names):
    fh.write(','.join(['time', 'stamp_ns'] + [f'tau_ext_{j}' for j in names]
                      + list(WRENCH_COLUMNS) + ['contact']) + '\n')
    for k in range(len(out.t)):
        row = [f'{out.t[k]:.9f}', str(int(rec.stamps_ns[k]))]
        row += [f'{x:.6g}' for x in out.residual[k]]
        row += [f'{x:.6g}' for x in out.wrench[k]]
        row.append('1' if out.contact[k] else '0')
        fh.write(','.join(row) + '\n')


def _intervals(t, flag):
    """[[start, end], ...] (s) of the runs where ``flag`` is true."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], flag.astype(int),
                                                   [0]))))
    return [[float(t[a]), float(t[min(b, len(t) - 1)])]
            for a, b in zip(edges[::2], edges[1::2])]


def _summary(args, model, obs, rec, out):
    """Return what the command found, as a dict (the --json object)."""
    from .core.observer import beyond_friction, suggest_thresholds
    from .core.observer.thresholds import (rest_changes,
                                           suggest_rest_thresholds,
                                           suggest_state_thresholds)
    t = out.t
    resting = (np.abs(rec.qd) < obs.friction_width).all(axis=1)
    constant = obs.torque_constant
    state = suggest_state_thresholds(out)
    return {
        'robot': model.name, 'bag': args.bag, 'topic': args.topic,
        'joints': list(model.joint_names), 'samples': int(len(t)),
        'first_stamp_ns': int(rec.stamps_ns[0]),
        'duration': float(t[-1] - t[0]), 'gain': args.gain,
        'restarts': int(out.restarts), 'skipped': int(out.skipped),
        'torque_constant': None if constant is None else constant.tolist(),
        'static_friction': args.static_friction,
        'friction_allowance': obs.static_friction.tolist(),
        'thresholds': obs.thresholds.tolist(),
        'peak': np.abs(out.residual).max(axis=0).tolist(),
        'rms': np.sqrt((out.residual ** 2).mean(axis=0)).tolist(),
        'peak_beyond_friction': beyond_friction(out).max(axis=0).tolist(),
        'rest_reference': bool(obs.rest_reference),
        'peak_rest_change': rest_changes(out).tolist(),
        'suggested_thresholds': suggest_thresholds(out).tolist(),
        'speed_thresholds': obs.speed_thresholds.tolist(),
        'acceleration_thresholds': obs.acceleration_thresholds.tolist(),
        'rest_thresholds': obs.rest_thresholds.tolist(),
        'suggested_state_thresholds': dict(zip(
            ('thresholds', 'speed_thresholds', 'acceleration_thresholds',
             'rest_thresholds'),
            (x.tolist() for x in (*state, suggest_rest_thresholds(
                out, *state))))),
        'contacts': int(out.contacts),
        'contact_fraction': float(out.contact.mean()),
        'resting_fraction': float(resting.mean()),
        'contact_fraction_at_rest': (float(out.contact[resting].mean())
                                     if resting.any() else None),
        'contact_intervals': _intervals(t, out.contact),
        'csv': args.csv, 'plot': args.plot,
        'notes': list(getattr(rec, 'notes', [])) + _motionless(args, rec)}


def _table(s):
    """Return the summary as the lines the command prints."""
    at_rest = s['contact_fraction_at_rest']
    lines = [
        f'{s["robot"]}: {s["samples"]} samples over {s["duration"]:.3f} s '
        f'from {s["bag"]} ({s["topic"]}); gain {s["gain"]:g} 1/s, '
        f'{s["restarts"]} restart(s), {s["skipped"]} sample(s) skipped',
        f'contacts: {s["contacts"]} (in contact {s["contact_fraction"]:.1%} '
        f'of samples' + ('' if at_rest is None else
                         f', {at_rest:.1%} of those at rest') + ')']
    if s['torque_constant'] is not None:
        lines.append("efforts converted to joint torques with the URDF's "
                     'torque constants ' + ', '.join(
                         f'{k:.4g}' for k in s['torque_constant'])
                     + ' (N m per effort unit)')
    lines.append(f'{"joint":<24}{"threshold":>10}{"friction":>10}'
                 f'{"max |tau_ext|":>14}{"beyond":>9}{"at rest":>9}'
                 f'{"rms":>9}{"suggested":>10}')
    for j, name in enumerate(s['joints']):
        lines.append(
            f'{name:<24}{s["thresholds"][j]:>10.3g}'
            f'{s["friction_allowance"][j]:>10.3g}{s["peak"][j]:>14.3g}'
            f'{s["peak_beyond_friction"][j]:>9.3g}'
            f'{s["peak_rest_change"][j]:>9.3g}{s["rms"][j]:>9.3g}'
            f'{s["suggested_thresholds"][j]:>10.3g}')
    lines.append('friction = static friction allowed for at rest (N m or '
                 'N); beyond = max |tau_ext| beyond it; at rest = max '
                 "change from the settled arm's rest value (the rest "
                 'reference); suggested = 2 x the larger (valid when the '
                 'recording is free motion, no contact)')
    state = s['suggested_state_thresholds']
    lines.append('or thresholds growing with speed and acceleration '
                 '(suggested: --thresholds ' + ' '.join(
                     f'{x:.3g}' for x in state['thresholds'])
                 + ' --speed-thresholds ' + ' '.join(
                     f'{x:.3g}' for x in state['speed_thresholds'])
                 + ' --acceleration-thresholds ' + ' '.join(
                     f'{x:.3g}' for x in state['acceleration_thresholds'])
                 + ' --rest-thresholds ' + ' '.join(
                     f'{x:.3g}' for x in state['rest_thresholds'])
                 + ')')
    for note in s['notes']:
        lines.append(f'note: {note}')
    return lines


def _thresholds(obs, out):
    """Return (m, n): each sample's thresholds (speed and acceleration)."""
    return (obs.thresholds + obs.speed_thresholds * out.speed
            + obs.acceleration_thresholds * out.acceleration)


def _plot(path, t, names, out, thresholds):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(10, 8))
    ax = axes[0]
    for j, name in enumerate(names):
        line, = ax.plot(t, out.residual[:, j], lw=0.8, label=name)
        # the contact test's bound: threshold + static friction allowance
        bound = thresholds[:, j] + out.allowance[:, j]
        ax.plot(t, bound, color=line.get_color(), lw=0.5, ls=':')
        ax.plot(t, -bound, color=line.get_color(), lw=0.5, ls=':')
    ax.set_ylabel('external torque\n(N m or N)')
    ax.legend(fontsize=7, ncol=4, loc='upper right')
    for ax, cols, unit in ((axes[1], slice(0, 3), 'force (N)'),
                           (axes[2], slice(3, 6), 'moment (N m)')):
        for c, label in zip(range(cols.start, cols.stop),
                            WRENCH_COLUMNS[cols]):
            ax.plot(t, out.wrench[:, c], lw=0.8, label=label)
        ax.set_ylabel(f'external {unit}\n(base axes)')
        ax.legend(fontsize=7, ncol=3, loc='upper right')
    for ax in axes:
        ax.fill_between(t, 0, 1, where=out.contact, color='tab:red',
                        alpha=0.12, transform=ax.get_xaxis_transform(),
                        label=None)
    axes[-1].set_xlabel('time since the first sample (s); red: contact')
    fig.suptitle('momentum observer: what the environment applies')
    fig.tight_layout()
    _atomic_write(path, lambda fh: fig.savefig(fh, format='png', dpi=110),
                  'wb')
    plt.close(fig)
