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

"""The closed-loop demo's report: torque terms, plots and summary.md."""
import os

import numpy as np

PLANT_NODES = {'mujoco': 'mujoco_sim_node', 'newton_euler': 'robot_sim_node'}


def torque_terms(scene, run):
    """Split the torques of a recorded run into the scene's terms."""
    from newton_euler_ros.core import (coriolis_matrix, gravity_torques,
                                       jacobian, mass_matrix)
    from newton_euler_ros.sim.simulate import SceneDynamics
    dyn = SceneDynamics(scene)
    model, eff = scene.model, scene.effects
    t, q, qd = run['t'], run['q'], run['qd']
    qdd = np.gradient(qd, t, axis=0) if len(t) > 2 else np.zeros_like(qd)
    names = ['D qdd', 'C qd', 'g', 'J^T F', 'friction', 'armature']
    terms = {k: np.zeros_like(q) for k in names}
    for k in range(len(t)):
        terms['D qdd'][k] = mass_matrix(model, q[k]) @ qdd[k]
        if eff.velocity_products:
            terms['C qd'][k] = coriolis_matrix(model, q[k], qd[k]) @ qd[k]
        if eff.gravity:
            terms['g'][k] = gravity_torques(model, q[k])
        if eff.wrench:
            w, frame = scene.wrench_at(t[k])
            terms['J^T F'][k] = jacobian(model, q[k], frame).T @ w
        if eff.friction:
            terms['friction'][k] = dyn.friction(qd[k])
        if eff.armature:
            terms['armature'][k] = scene.armature * qdd[k]
    return {k: v for k, v in terms.items()
            if k == 'D qdd' or np.abs(v).max() > 0.0}


def plots(scene, runs, terms, out):
    """Write the PNG plots; return their file names."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    joints = scene.model.joint_names
    n = len(joints)
    cols = 3
    rows = (n + cols - 1) // cols
    files = []

    fig, axes = plt.subplots(rows, cols, figsize=(13, 3.2 * rows),
                             squeeze=False)
    ff, pd = runs['feedforward'], runs['pd']
    for j in range(n):
        ax = axes[j // cols][j % cols]
        ax.plot(ff['t'], ff['q_ref'][:, j], 'k--', lw=1.2, label='reference')
        ax.plot(ff['t'], ff['q'][:, j], lw=1.2, label='PD + feedforward')
        ax.plot(pd['t'], pd['q'][:, j], lw=1.2, label='PD alone')
        ax.set_title(joints[j])
        ax.set_xlabel('t [s]')
        ax.set_ylabel('q [rad]')
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=8)
    fig.suptitle(f'{scene.name}: joint tracking over ROS 2')
    fig.tight_layout()
    files.append('joint_tracking.png')
    fig.savefig(os.path.join(out, files[-1]), dpi=100)
    plt.close(fig)

    fig, axes = plt.subplots(rows, cols, figsize=(13, 3.2 * rows),
                             squeeze=False)
    for j in range(n):
        ax = axes[j // cols][j % cols]
        for label, values in terms.items():
            ax.plot(ff['t'], values[:, j], lw=1.0, label=label)
        ax.plot(ff['t'], ff['tau'][:, j], 'k', lw=0.8, alpha=0.6,
                label='commanded (PD + feedforward)')
        ax.set_title(joints[j])
        ax.set_xlabel('t [s]')
        ax.set_ylabel('torque [N m]')
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7)
    fig.suptitle(f'{scene.name}: the terms of tau at the recorded states; '
                 f"black: the torque the plant applied (the controller's "
                 f'command, PD + feedforward)')
    fig.tight_layout()
    files.append('torque_terms.png')
    fig.savefig(os.path.join(out, files[-1]), dpi=100)
    plt.close(fig)

    fig, axes = plt.subplots(1, 2, figsize=(13, 4))
    for key, label in (('feedforward', 'PD + feedforward'),
                       ('pd', 'PD alone')):
        run = runs[key]
        axes[0].semilogy(run['t'], np.maximum(
            np.linalg.norm(run['err'], axis=1), 1e-12), label=label)
    axes[0].set_xlabel('t [s]')
    axes[0].set_ylabel('|q - q_ref| [rad]')
    axes[0].grid(alpha=0.3, which='both')
    axes[0].legend()
    width = 0.4
    x = np.arange(n)
    for off, key, label in ((-width / 2, 'feedforward', 'PD + feedforward'),
                            (width / 2, 'pd', 'PD alone')):
        rms = np.sqrt(np.mean(runs[key]['err'] ** 2, axis=0))
        axes[1].bar(x + off, rms, width, label=label)
    axes[1].set_yscale('log')
    axes[1].set_xticks(x)
    axes[1].set_xticklabels(joints)
    axes[1].set_ylabel('RMS error [rad]')
    axes[1].legend()
    fig.suptitle(f'{scene.name}: tracking error with and without '
                 f'feedforward')
    fig.tight_layout()
    files.append('tracking_error.png')
    fig.savefig(os.path.join(out, files[-1]), dpi=100)
    plt.close(fig)
    return files


def summary(scene, runs, rms, files, duration, wall, plant='mujoco',
            costs=None):
    """Return summary.md's text."""
    node = PLANT_NODES[plant]
    ratio = rms['pd'] / rms['feedforward'] if rms['feedforward'] > 0 \
        else float('inf')
    lines = [
        f'# Closed-loop demo: {scene.name}',
        '',
        f'{scene.description}',
        '',
        f'Robot {scene.model.name} ({scene.model.n} joints), '
        f'{duration:g} s simulated at {scene.rate:g} Hz control over ROS 2 '
        f'({node} -> inverse_dynamics_node -> '
        f'tracking_controller_node), integrator {scene.integrator} step '
        f'{scene.step:g} s; wall time {wall:.1f} s.',
        '',
        ('The plant is MuJoCo (mujoco_sim_node): the same robot compiled '
         "by MuJoCo's own reader and integrated by its own physics, with "
         "every effect of the scene; the controller's feedforward is the "
         "library's." if plant == 'mujoco' else
         "The plant is the library's own simulator (robot_sim_node): it "
         "shares the feedforward's dynamics, so it cannot show an error "
         'the two share; `--plant mujoco` (the default) measures on '
         'MuJoCo.'),
        '',
        '## Tracking',
        '',
        '| controller | RMS error [rad] | max error [rad] | joint states '
        '| commands sent | received by the plant | recorded |',
        '|---|---|---|---|---|---|---|',
    ]
    for key, label in (('feedforward', 'PD + feedforward'),
                       ('pd', 'PD alone')):
        run = runs[key]
        lines.append(f'| {label} | {rms[key]:.3e} | '
                     f'{np.abs(run["err"]).max():.3e} | {len(run["t"])} | '
                     f'{run["sent"]} | {run["received"]} | '
                     f'{run["commands"]} |')
    lines += [
        '',
        'Commands: sent by tracking_controller_node (its count on exit), '
        f'received by {node} (its count on exit) and recorded by '
        "this demo's probe, over the whole run: the controller answers "
        'joint states from the start until it is stopped, first of the '
        'nodes, so they may exceed the joint states recorded in '
        '[0, duration].',
        '',
        f'RMS with feedforward: {rms["feedforward"]:.6e} rad',
        f'RMS without feedforward: {rms["pd"]:.6e} rad',
        f'Ratio (without / with): {ratio:.1f}',
        '',
        '## Effects',
        '',
        f'{", ".join(scene.effects.names()) or "none"}',
        '',
        '## What accuracy costs',
        '',
    ]
    if costs:
        lines += [
            'Offline, after the runs (`python -m newton_euler_tools.'
            'mujoco_costs`): the feedforward computed with every effect, '
            'with each left out, with none, and PD alone, each timed per '
            'call (best of several rounds, side by side) and tracked on '
            "MuJoCo's full physics.",
            '',
            '| feedforward computed with | us per call | tracking RMS '
            '[rad] | max [rad] |',
            '|---|---|---|---|']
        lines += [f'| {label} | {us:.2f} | {rms_:.3e} | {top:.3e} |'
                  if us else f'| {label} | - | {rms_:.3e} | {top:.3e} |'
                  for label, us, rms_, top in costs]
    else:
        lines.append(
            'Measured on the MuJoCo plant only (`--plant mujoco`); `make '
            'bench` (`python -m newton_euler_tools.bench_effects`) times '
            'each effect side by side.')
    lines += ['', '## Plots', ''] + [f'![{f}]({f})' for f in files] + ['']
    return '\n'.join(lines)
