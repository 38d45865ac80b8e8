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

"""The demo_identify report: figures per run, plots, summary files."""
import json
import os
import time

import numpy as np


def prepare_plots():
    """Import matplotlib (Agg), a second or two, ahead of :func:`plot`."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot  # noqa: F401


def _segment(segment, label):
    """Return a run's plan: ``segment``, or its entry when it is a dict."""
    return segment[label] if isinstance(segment, dict) else segment


def plot(runs, segment, truth, out):
    """
    Tracking error and feedforward torque error per run.

    ``segment``: the plan of every run, or a dict of each run's plan.
    """
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(9, 4))
    for label, r in runs.items():
        plan = plan_at(r['t'], _segment(segment, label))
        err = np.linalg.norm(r['q'] - plan, axis=1)
        ax.semilogy(r['t'], err + 1e-9, label=label, lw=0.9)
    ax.set_xlabel('simulated time (s)')
    ax.set_ylabel('|q - q_plan| (rad)')
    ax.set_title('Panda: tracking error along the plan')
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, 'tracking.png'), dpi=100)
    plt.close(fig)
    fig, axes = plt.subplots(7, 1, sharex=True, figsize=(9, 12))
    for j, ax in enumerate(axes):
        for label, r in runs.items():
            ax.plot(_segment(segment, label)[0],
                    r['ff'][:, j] - truth[label][:, j], lw=0.8, label=label)
        ax.set_ylabel(f'joint {j + 1}\nN m', fontsize=8)
    axes[0].set_title('feedforward effort minus the true torque')
    axes[0].legend(fontsize=7, ncol=2)
    axes[-1].set_xlabel('time along the plan (s)')
    fig.tight_layout()
    fig.savefig(os.path.join(out, 'torques.png'), dpi=90)
    plt.close(fig)


def plan_at(times, segment):
    """Return the planned positions at the given times."""
    ts, Q = segment[0], segment[1]
    return np.column_stack([np.interp(times, ts, Q[:, j])
                            for j in range(Q.shape[1])])


def figures(runs, truth, segment):
    """Return per run the feedforward and tracking errors, and table rows."""
    rows = []
    out = {}
    for label, r in runs.items():
        ff = r['ff'] - truth[label]
        ff_rms = float(np.sqrt(np.mean(ff ** 2)))
        ff_rel = ff_rms / float(np.sqrt(np.mean(truth[label] ** 2)))
        err = r['q'] - plan_at(r['t'], _segment(segment, label))
        tr_rms = float(np.sqrt(np.mean(err ** 2)))
        tr_max = float(np.abs(err).max())
        out[label] = {'ff_rms': ff_rms, 'ff_rel': ff_rel,
                      'tracking_rms': tr_rms, 'tracking_max': tr_max}
        rows.append(f'| {label} | {ff_rms:.3f} | {100 * ff_rel:.1f} % | '
                    f'{1000 * tr_rms:.2f} | {1000 * tr_max:.2f} |')
    return out, rows


def payload_line(estimate, payload):
    """Return the summary's line: the payload estimate against the truth."""
    m, c = estimate.get('payload.mass'), estimate.get('payload.com')
    return ('- payload estimate: '
            + (f'{m:.3f} kg' if m is not None else 'mass undetermined')
            + f' (true {payload["mass"]:g}), com '
            + (f'[{", ".join(f"{1000 * v:.1f}" for v in c)}] mm'
               if c is not None else 'undetermined') + ' (true '
            f'[{", ".join(f"{1000 * v:.1f}" for v in payload["com"])}])')


def summary_lines(loop, payload, wall, rows):
    """Return the lines of summary.md."""
    args, out, estimate = loop.args, loop.out, loop.estimate
    periods, period, harmonics = loop.periods, loop.period, loop.harmonics
    steps = loop.steps
    with open(os.path.join(out, 'excite.txt'), encoding='utf-8') as f:
        excite_lines = [x for x in f.read().splitlines()
                        if 'condition number' in x]
    with open(os.path.join(out, 'identify.txt'), encoding='utf-8') as f:
        ident_lines = [x for x in f.read().splitlines()
                       if x.startswith(('rank', 'identified in'))]
    lines = [
        '# The identification loop, end to end',
        '',
        f'`make demo-identify` ({"quick, " if args.quick else ""}'
        f'{wall:.0f} s wall). The plant (robot_sim_node) is a Panda whose '
        f'links differ from the published URDF (masses +-15 %, centres of '
        f'mass +-15 mm, inertias +-25 %) with joint friction and rotor '
        f'inertia; inverse_dynamics_node starts with the published URDF. '
        f'An excitation trajectory ({periods} x {period:g} s, {harmonics} '
        f'harmonics) runs through the node (`~/trajectory_in` -> '
        f'`~/trajectory_out`) into the simulator (PD + the efforts, as '
        f'joint_trajectory_controller); `/joint_states` is recorded to a '
        f'rosbag2; `newton-euler identify` corrects the URDF; the same '
        f'trajectory runs with the identified URDF (on `robot_description`)'
        f' and `drives.compensate:=true`, and at the same time, in another '
        f'ROS domain, with the plant holding {payload["mass"]:g} kg the node '
        f'is not told of; `newton-euler payload` estimates the payload from '
        "that recording, and a last run has the estimate in the node's "
        f'`payload.*` (one `set_parameters_atomically` call).',
        '',
        '| run | feedforward torque error, RMS (N m) | relative to the true '
        'torque | tracking error, RMS (mrad) | max (mrad) |',
        '|---|---|---|---|---|',
        *rows,
        '',
        'Feedforward torque error: the efforts the node filled in, against '
        'the true torque of the plant along the plan (its real inertials, '
        'friction and rotor inertia, the payload when held). Tracking error: '
        'the joint positions against the plan.',
        '',
        f'- excite: {excite_lines[0].strip() if excite_lines else ""}',
        *[f'- identify: {x}' for x in ident_lines],
        payload_line(estimate, payload),
        '- wall time per step (s; the nodes of a run start while an earlier '
        'step works): ' + ', '.join(f'{k} {v:.1f}'
                                    for k, v in steps.times.items()),
        '',
        'Files: `excitation.json`, `recording/` and `payload_recording/` '
        '(rosbag2), `panda_identified.urdf`, the output of the commands '
        '(`excite.txt`, `identify.txt`, `payload.json`), the logs of the '
        'nodes in `logs/`.',
        '',
        '![tracking error](tracking.png)',
        '',
        '![feedforward torque error](torques.png)', '']
    return lines


def write_report(loop, payload, started):
    """
    Write the plots, summary.md and summary.json; print the table.

    A loop with a ``held_out`` error (the MuJoCo plant's) writes its own
    summary (``loop.summary_lines``) and adds its figures
    (``loop.figures``) to summary.json.
    """
    out = loop.out
    segment = getattr(loop, 'segments', None) or loop.segment
    plot(loop.runs, segment, loop.truth, out)
    table, rows = figures(loop.runs, loop.truth, segment)
    wall = time.monotonic() - started
    mujoco = hasattr(loop, 'held_out')
    if mujoco:
        lines, headline = loop.summary_lines(payload, wall, rows, table)
    else:
        lines = summary_lines(loop, payload, wall, rows)
        headline = []
    with open(os.path.join(out, 'summary.md'), 'w', encoding='utf-8') as f:
        f.write('\n'.join(lines))
    result = {'plant': 'mujoco' if mujoco else 'builtin', 'runs': table,
              'payload_estimate': loop.estimate, 'payload_true': payload,
              'wall_s': wall, 'steps_s': loop.steps.times,
              'runs_timing_s': {r.label: r.timing(started)
                                for r in loop.all_runs()}}
    if mujoco:
        result.update(loop.figures(table))
    with open(os.path.join(out, 'summary.json'), 'w', encoding='utf-8') as f:
        json.dump(result, f, indent=1)
    print('\n'.join(lines[4:6 + len(rows)] + headline))
    print(f'wrote {out} ({wall:.0f} s)', flush=True)
