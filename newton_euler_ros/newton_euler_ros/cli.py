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
``newton-euler``: inverse dynamics of a robot from the command line.

    newton-euler dynamics ROBOT --q ... [--qd ...] [--qdd ...]
                                [--wrench fx fy fz nx ny nz] [--link LINK]
                                [--wrench-frame base|end_effector] [--json]
    newton-euler dynamics ROBOT --states STATES.json
    newton-euler check ROBOT
    newton-euler urdf ROBOT [-o FILE]
    newton-euler feedforward ROBOT TRAJECTORY.json [--wrench ...] [--gains Q R]
                             [--drives]
    newton-euler robots
    newton-euler excite | identify | replay | payload | observe ...
    newton-euler send TRAJECTORY.json | record BAG   (on a live ROS graph)

ROBOT is a robot YAML file, the name of a bundled robot, or a URDF file
(``.urdf``, or XML under any name, with ``--base LINK --tip LINK`` to
choose the chain; without ``--tip`` the whole tree below the base: every
joint, mimic joints following their leaders, ``--link`` naming the link
of a wrench).  Every error is one line on stderr.  Exit status, the
same for every command (docs/cli.md): 0 done; 1 the inputs were usable
but the work failed (the ROS graph did not answer: no subscriber or
publisher in time, nothing recorded; an internal error); 2 an input is
wrong (the command line, or a file or value it names); 130 interrupted.
"""
import argparse
import json
import os
import sys

# Every command's linear algebra is on small matrices (at most a few
# hundred columns): BLAS threads only contend there, badly so on a busy
# machine (a 534 x 85 QR took 0.4 s with two threads on two loaded cores,
# 0.8 ms with one).  Set before numpy loads its BLAS.
os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')

import numpy as np  # noqa: E402 (after the BLAS thread count)

from .cli_export import register as register_export  # noqa: E402
from .cli_identify import register as register_identify  # noqa: E402
from .cli_loop import register as register_loop  # noqa: E402
from .cli_observe import register as register_observe  # noqa: E402
from .cli_options import (chain_options, json_option,  # noqa: E402
                          robot_argument)
from .cli_report import (format_table, mass_counted,  # noqa: E402
                         source, tree_lines, types_of)
from .cli_ros import (register as register_ros, RosCliError,  # noqa: E402
                      RosGraphError)
# only what every start needs: the dynamics, numba and the kernels load
# where a command first uses them, so --help and usage errors skip them
from .core.drives import describe_drives, model_drives  # noqa: E402
from .core.errors import NewtonEulerError, RobotFileError  # noqa: E402
from .core.inertia import Note  # noqa: E402
from .core.text import read_text  # noqa: E402

# the exit statuses of every command (docs/cli.md states the rule)
EXIT_DONE = 0
EXIT_FAILED = 1         # usable inputs, but the work failed
EXIT_BAD_INPUT = 2      # the command line, or a file or value it names
EXIT_USAGE = EXIT_BAD_INPUT
EXIT_INTERRUPTED = 130
MAX_JSON_BYTES = 64 * 1024 * 1024


class CliError(Exception):
    """A command-line error, printed as one line (exit status 2)."""


class InputError(NewtonEulerError):
    """An input file or value is unusable (exit status 2)."""


def _read_json(path):
    """Parse a JSON file; every failure is one line naming it."""
    text = read_text(path, MAX_JSON_BYTES, 'JSON file')
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f'{path}: not valid JSON: {exc}') from None
    except RecursionError:
        raise InputError(f'{path}: nested too deeply') from None


def _numbers(values, option):
    from .core.robot_file import to_number
    try:
        return [to_number(v, option) for v in values]
    except NewtonEulerError as exc:     # a malformed argument: usage
        raise CliError(str(exc)) from None


def _state_vector(values, n, option):
    if values is None:
        return np.zeros(n)
    x = _numbers(values, option)
    if len(x) != n:
        raise CliError(f'{option} needs {n} values (one per joint), '
                       f'got {len(x)}')
    return np.array(x)


def _at_link(model, wrench, wrench_frame, link):
    """
    Return (wrench, wrench_frame) the dynamics take, at ``link`` or not.

    With ``link`` the wrench acts there (``end_effector`` axes are the
    link's own); a tree with several tips has no end effector, so a
    wrench needs a link.
    """
    if link is None:
        if wrench is not None and model.tool_body is None:
            raise CliError(f'{model.name} has several tips and no end '
                           f'effector: give --link LINK for --wrench')
        return wrench, wrench_frame
    axes = 'base' if wrench_frame == 'base' else 'link'
    return (None if wrench is None else {link: wrench}), {link: axes}


def evaluate(model, q, qd, qdd, wrench, wrench_frame, link=None):
    """
    All terms at one state, as plain Python lists (JSON-ready).

    ``jacobian`` is the end effector's, or ``link``'s; None for a tree
    with several tips and no ``link``.
    """
    from .core.dynamics import (coriolis_matrix, gravity_torques,
                                inverse_dynamics, jacobian, mass_matrix)
    w, frame = _at_link(model, wrench, wrench_frame, link)
    if link is not None:
        J = jacobian(model, q, link, axes=frame[link])
    elif model.tool_body is not None:
        J = jacobian(model, q, wrench_frame)
    else:
        J = None
    tau = inverse_dynamics(model, q, qd, qdd, w,
                           frame if w is not None else 'base')
    return {
        'joint_names': list(model.joint_names),
        'tau': tau.tolist(),
        'mass_matrix': mass_matrix(model, q).tolist(),
        'coriolis_matrix': coriolis_matrix(model, q, qd).tolist(),
        'gravity': gravity_torques(model, q).tolist(),
        'jacobian': None if J is None else J.tolist(),
    }


def _load_states(path, n):
    states = _read_json(path)
    if not isinstance(states, list):
        raise InputError(f'{path}: must hold a JSON list of states')
    out = []
    for i, st in enumerate(states):
        if not isinstance(st, dict):
            raise InputError(f'{path}: state {i}: must be an object with '
                             f'"q", "qd", "qdd", "wrench"')
        unknown = set(st) - {'q', 'qd', 'qdd', 'wrench'}
        if unknown:
            raise InputError(f'{path}: state {i}: unknown key '
                             f'{sorted(unknown)[0][:200]!r}')
        vecs = {}
        for key, size in (('q', n), ('qd', n), ('qdd', n), ('wrench', 6)):
            value = st.get(key)
            if value is None:
                vecs[key] = np.zeros(size)
                continue
            if not isinstance(value, list) or len(value) != size:
                raise InputError(f'{path}: state {i}: {key}: must be a list '
                                 f'of {size} numbers')
            vecs[key] = np.array(_numbers(value, f'{path}: state {i}: {key}'))
        out.append(vecs)
    return out


def _warn(found):
    """Print warnings; notes about published data are for ``check``."""
    for message in found:
        if not isinstance(message, Note):
            print(f'warning: {message}', file=sys.stderr)


def _load(args):
    from .core.robot_file import inspect_robot
    try:
        return inspect_robot(args.robot, base=args.base, tip=args.tip)
    except RobotFileError as exc:
        # a mistyped --base/--tip is a usage error (the message names the
        # closest links)
        if 'link' in str(exc) and 'is not in the URDF' in str(exc):
            raise CliError(str(exc)) from None
        raise


def cmd_dynamics(args):
    model, found, _ = _load(args)
    _warn(found)
    n = model.n
    if args.states:
        if any(v is not None for v in (args.q, args.qd, args.qdd,
                                       args.wrench)):
            raise CliError('--states replaces --q/--qd/--qdd/--wrench; '
                           'give one or the other')
        results = []
        for st in _load_states(args.states, n):
            wrench = st['wrench'] if st['wrench'].any() else None
            results.append(evaluate(model, st['q'], st['qd'], st['qdd'],
                                    wrench, args.wrench_frame, args.link))
        print(json.dumps(results))
        return 0
    if args.q is None:
        raise CliError(f'--q is required ({n} values, one per joint: '
                       f'{" ".join(model.joint_names)})')
    q = _state_vector(args.q, n, '--q')
    qd = _state_vector(args.qd, n, '--qd')
    qdd = _state_vector(args.qdd, n, '--qdd')
    wrench = (np.array(_numbers(args.wrench, '--wrench'))
              if args.wrench is not None else None)
    result = evaluate(model, q, qd, qdd, wrench, args.wrench_frame,
                      args.link)
    if args.json:
        print(json.dumps(result))
    else:
        print(format_table(model, result, q, qd, qdd, wrench,
                           args.wrench_frame, args.link))
    return 0


def cmd_check(args):
    model, found, path = _load(args)
    # R revolute, C continuous, P prismatic
    types = ''.join(t[0].upper() for t in types_of(model))
    print(f'{path}: OK')
    print(f'  name: {model.name}')
    print(f'  joints: {model.n} ({types}), {source(model)}')
    print(f'  joint names: {", ".join(model.joint_names)}')
    report = model.info.get('urdf')
    if report and report.get('tree'):       # the whole tree below base
        for line in tree_lines(model, report):
            print(f'  {line}')
        print(f'  continuous joints: '
              f'{", ".join(report["continuous"]) or "none"}')
    elif report:
        chain = [report['base']]
        for jname, link in zip(report['chain'], report['chain_links']):
            chain.append(f'-[{jname}]-> {link}')
        print(f'  chain: {" ".join(chain)}')
        print(f'  merged fixed joints: '
              f'{", ".join(report["merged_fixed"]) or "none"}')
        print(f'  lumped off-chain subtrees (at zero position): '
              f'{", ".join(report["lumped"]) or "none"}')
        print(f'  locked off-chain moving joints: '
              f'{", ".join(report.get("locked", ())) or "none"}')
        print(f'  continuous joints: '
              f'{", ".join(report["continuous"]) or "none"}')
    print(f'  total mass: {model.total_mass:.6g} kg ({mass_counted(model)})')
    print(f'  gravity: {model.gravity.tolist()} m/s^2')
    for line in describe_drives(model_drives(model), model.joint_names):
        print(f'  {line}')
    notes = [m for m in found if isinstance(m, Note)]
    print(f'  warnings: {len(found) - len(notes)}')
    for message in found:
        print(f'  {"note" if message in notes else "warning"}: {message}')
    return 0


def cmd_simulate(args):
    from .sim.scene import load_scene
    from .sim.run import simulate
    scene = load_scene(args.scene)
    if args.engine is not None and args.engine != scene.engine:
        scene = _with_engine(scene, args.engine)
    _warn(scene.warnings)
    if args.duration is not None and not args.duration > 0.0:
        raise CliError(f'--duration must be > 0, got {args.duration}')
    result = simulate(scene, duration=args.duration,
                      feedforward=False if args.no_feedforward else None,
                      progress=not args.json and sys.stderr.isatty())
    summary = result.summary
    if args.json:
        print(json.dumps(summary))
        return 0
    names = scene.model.joint_names
    print(f'{scene.name}: {scene.model.name}, {summary["steps"]} '
          f'{summary["integrator"]} steps of {summary["step"]} s '
          f'({summary["duration"]:.3f} s simulated in '
          f'{summary["wall_time_s"]:.2f} s)')
    print(f'effects: {", ".join(summary["effects"]) or "none"}')
    ff = 'PD alone' if args.no_feedforward else (
        'PD + feedforward' if scene.feedforward else 'PD alone')
    print(f'tracking error ({ff}): RMS {summary["tracking_rms"]:.3e} rad, '
          f'max {summary["tracking_max"]:.3e} rad')
    if summary['energy_drift_max'] is None:
        print('energy drift: not booked (MuJoCo with friction, a wrench '
              'or contacts)')
    else:
        print(f'energy drift: {summary["energy_drift_max"]:.3e} J '
              f'({summary["energy_drift_relative"]:.1e} of the energy '
              f'scale)')
    print('final state:')
    w = max(12, *(len(x) for x in names))       # names are never cut
    for j, name in enumerate(names):
        print(f'  {name:<{w}} q {summary["final_q"][j]:>12.6f}   '
              f'qd {summary["final_qd"][j]:>12.6f}')
    return 0


def _with_engine(scene, engine):
    """Return the scene on another engine (contacts need MuJoCo)."""
    import dataclasses
    if engine != 'mujoco' and scene.contacts is not None:
        raise CliError(f'--engine {engine}: {scene.path} has contacts, '
                       f'which only the MuJoCo engine simulates')
    if engine == 'mujoco' and not scene.effects.velocity_products:
        raise CliError(f'--engine mujoco: {scene.path} leaves velocity '
                       f'products out, and MuJoCo always has them')
    return dataclasses.replace(scene, engine=engine)


def cmd_feedforward(args):
    from .core.trajectory import fill_efforts
    model, found, _ = _load(args)
    _warn(found)
    path = args.trajectory
    trajectory = _read_json(path)
    if not isinstance(trajectory, dict):
        raise InputError(f'{path}: must hold a JSON object with '
                         f'"joint_names" and "points"')
    wrench = (np.array(_numbers(args.wrench, '--wrench'))
              if args.wrench is not None else None)
    wrench, frame = _at_link(model, wrench, args.wrench_frame, args.link)
    drives = None
    if args.drives:
        drives = model_drives(model)
        if drives is None:
            raise InputError(
                f'--drives: {args.robot} has no drive terms (they come '
                f"from a URDF's <dynamics damping/friction> and "
                f'<ne:drive>, as identify writes them)')
    hold, left = None, []
    if (model.info.get('urdf') or {}).get('tree'):
        # a whole robot: the joints the trajectory leaves out stay at zero
        hold = np.zeros(model.n)
        names = trajectory.get('joint_names')
        left = [j for j in model.joint_names
                if isinstance(names, list) and j not in names]
    # an error is the one line: the note only once the efforts are filled
    filled = fill_efforts(model, trajectory, wrench, frame,
                          where=f'{path}: ', hold=hold, drives=drives)
    if left:
        print(f'note: joints not in the trajectory held at 0, at rest: '
              f'{", ".join(left)}', file=sys.stderr)
    if args.gains is not None:
        from .cli_gains import add_gains
        add_gains(model, filled, args.gains, wrench, frame, f'{path}: ',
                  hold, drives)
    print(json.dumps(filled))
    return 0


def cmd_urdf(args):
    from .core.urdf import model_to_urdf
    model, found, _ = _load(args)
    _warn(found)
    text = model_to_urdf(model)
    if args.output:
        try:
            with open(args.output, 'w', encoding='utf-8') as fh:
                fh.write(text)
        except OSError as exc:
            raise InputError(f'{args.output}: cannot write: '
                             f'{exc.strerror}') from None
    else:
        sys.stdout.write(text)
    return 0


def _chain_options(parser):
    chain_options(parser, 'URDF only: last link of the chain, the end '
                          'effector (default: none, the whole tree below '
                          'the base)')


def _wrench_options(parser, wrench_help, frame_help):
    """Add --wrench (``wrench_help``), --wrench-frame and --link."""
    parser.add_argument('--wrench', nargs=6,
                        metavar=('FX', 'FY', 'FZ', 'NX', 'NY', 'NZ'),
                        help=wrench_help)
    parser.add_argument('--wrench-frame', choices=('base', 'end_effector'),
                        default='base', help=frame_help)
    parser.add_argument('--link', metavar='LINK',
                        help='URDF only: the link the wrench acts at and '
                             'whose Jacobian is printed (default: the end '
                             'effector; a tree with several tips needs it '
                             'for --wrench)')


def cmd_robots(_args):
    from .core.robot_file import bundled_robots
    for name in bundled_robots():
        print(name)
    return 0


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise CliError(message)


def build_parser():
    parser = _Parser(prog='newton-euler', description=__doc__.strip().split('\n')[0])
    sub = parser.add_subparsers(dest='command', parser_class=_Parser)
    dyn = sub.add_parser('dynamics', help='tau, D, C, g and J at a state')
    robot_argument(dyn)
    _chain_options(dyn)
    dyn.add_argument('--q', nargs='+', metavar='Q',
                     help='joint positions (rad or m)')
    dyn.add_argument('--qd', nargs='+', metavar='QD',
                     help='joint velocities (default zeros)')
    dyn.add_argument('--qdd', nargs='+', metavar='QDD',
                     help='joint accelerations (default zeros)')
    _wrench_options(dyn, 'wrench the end effector exerts on its '
                         'environment (N, N m), moment about its origin',
                    'axes of --wrench and of the Jacobian (default base; '
                    "end_effector: the frame's own)")
    json_option(dyn, 'print one JSON object')
    dyn.add_argument('--states', metavar='FILE.json',
                     help='evaluate a JSON list of {"q","qd","qdd","wrench"}'
                          ' and print a JSON list')
    dyn.set_defaults(func=cmd_dynamics)
    chk = sub.add_parser('check', help='validate a robot file')
    robot_argument(chk)
    _chain_options(chk)
    chk.set_defaults(func=cmd_check)
    urdf = sub.add_parser('urdf', help='write a robot as URDF (inertials, '
                                       'limits, a fixed tool0 link)')
    robot_argument(urdf)
    urdf.add_argument('-o', '--output', metavar='FILE',
                      help='write to FILE instead of standard output')
    _chain_options(urdf)
    urdf.set_defaults(func=cmd_urdf)
    sim = sub.add_parser('simulate', help='simulate a scene offline')
    sim.add_argument('scene', metavar='SCENE',
                     help='scene YAML file or bundled scene name')
    sim.add_argument('--duration', type=float, metavar='T',
                     help="simulated seconds (default: the scene's)")
    json_option(sim, 'print the summary as one JSON object')
    sim.add_argument('--no-feedforward', action='store_true',
                     help='PD alone, without the inverse-dynamics '
                          'feedforward (for comparison)')
    sim.add_argument('--engine', choices=('newton_euler', 'mujoco'),
                     help="the plant: this library's dynamics or MuJoCo's "
                          "full physics (default: the scene's engine:)")
    sim.set_defaults(func=cmd_simulate)
    ff = sub.add_parser('feedforward', help='fill the effort of every point '
                                            'of a joint trajectory')
    robot_argument(ff)
    ff.add_argument('trajectory', metavar='TRAJECTORY.json',
                    help='JSON: {"joint_names": [...], "points": '
                         '[{"time_from_start": t, "positions": [...], '
                         '...}]}')
    _wrench_options(ff, 'wrench the end effector exerts along the whole '
                        'trajectory',
                    'axes of --wrench (default base; end_effector: the '
                    "frame's own)")
    _chain_options(ff)
    ff.add_argument('--gains', nargs=2, metavar=('Q', 'R'),
                    help='also write the time-varying LQR gains K of tau = '
                         'effort + K (x_ref - x), x = (q, qd), in each point'
                         ' ("gains", n x 2n): Q is P,V (position and '
                         'velocity weights) or 2n values, R one torque '
                         'weight or n values, comma-separated')
    ff.add_argument('--drives', action='store_true',
                    help="add the model's drive terms (viscous and Coulomb "
                         'friction, offset, rotor inertia) to the efforts, '
                         "as the node's drives.compensate does; with "
                         '--gains they join the linearised dynamics')
    ff.set_defaults(func=cmd_feedforward)
    rob = sub.add_parser('robots', help='list the bundled robots')
    rob.set_defaults(func=cmd_robots)
    register_identify(sub)
    register_export(sub)
    register_observe(sub)
    register_loop(sub)
    register_ros(sub)
    return parser


def main(argv=None):
    """Entry point of the ``newton-euler`` console script."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        if args.command is None:
            parser.print_help()
            return EXIT_USAGE
        return args.func(args)
    except RosGraphError as exc:
        print(f'newton-euler: error: {exc}', file=sys.stderr)
        return EXIT_FAILED
    except (CliError, RosCliError, NewtonEulerError) as exc:
        print(f'newton-euler: error: {exc}', file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED


if __name__ == '__main__':
    sys.exit(main())
