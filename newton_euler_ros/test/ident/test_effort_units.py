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
The efforts' unit checked window by window, as the node's observer does.

``EffortMonitor`` on the observer's own estimate of the model's torque
(the applied torque plus the residual), over recordings of
``current_arm_example``'s UR5 (motor currents in A at 100 Hz with stops,
stiction, lost messages and gaps; and one of torques): every window of
currents against the published URDF (no torque constants) is flagged,
with the torque constants as ratios; no window against the identified
URDF (constants within 3 %), nor of torques against the published URDF.
And the window's rules: one sample per 10 ms at most, none at rest.
"""
import warnings

from newton_euler_ros.core import load_robot
from newton_euler_ros.core.effort_units import EffortMonitor
from newton_euler_ros.core.observer import (drive_options, MomentumObserver,
                                            observe_recording)
from newton_euler_ros.ident.bag import read_joint_states
import numpy as np
import pytest

SEED = 0


@pytest.fixture(scope='module')
def runs(tmp_path_factory):
    from newton_euler_tools import current_arm_example as example
    from newton_euler_tools.current_arm_model import write_identified
    from newton_euler_tools.current_arm_motions import point_to_point
    tmp = tmp_path_factory.mktemp('effort_units')
    arm = example.real_arm(SEED)
    identified = write_identified(tmp / 'identified.urdf', arm, SEED)
    bags = {}
    for k, (seconds, effort) in enumerate(((60.0, 'current'),
                                           (45.0, 'current'),
                                           (60.0, 'torque'))):
        path = str(tmp / f'{effort}_{k}')
        example.record(arm, path, point_to_point(
            SEED + 10 * k, seconds, dwell=(0.3, 1.5), few=0.3, reverse=0.7),
            effort=effort, seed=SEED * 100 + k)
        bags[path] = effort
    return {'published': example.ur5_path(), 'identified': identified,
            'bags': bags, 'constants': arm.constants}


def verdicts(urdf, bag):
    """Run the observer and the monitor over a bag as the node does."""
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot(urdf, base='base_link', tip='tool0')
    rec = read_joint_states(bag, model.joint_names, '/joint_states')
    obs = MomentumObserver(model, 50.0, **drive_options(model))
    out = observe_recording(obs, rec.stamps, rec.q, rec.qd, rec.effort)
    given = obs.torque_constant is not None
    monitor = EffortMonitor(model.joint_names, 'given' if given else
                            'torque', 'observer', urdf)
    found = []
    for k in range(len(out.t)):
        torque = rec.effort[k] * (obs.torque_constant if given else 1.0)
        if monitor.add(out.t[k], torque + out.residual[k], torque,
                       rec.qd[k]):
            found.append(monitor.verdict)
    return model, found


def test_currents_flagged_only_against_a_urdf_without_constants(runs):
    counts = {'flagged': 0, 'clean': 0}
    ratios = []
    for bag, effort in runs['bags'].items():
        model, published = verdicts(runs['published'], bag)
        assert published, bag                   # 10 s of motion at least
        if effort == 'torque':
            assert published == [None] * len(published), published
            counts['clean'] += len(published)
            continue
        _, identified = verdicts(runs['identified'], bag)
        assert identified == [None] * len(identified), identified
        counts['clean'] += len(identified)
        for line in published:
            assert line.startswith('observer: the efforts are not joint '
                                   'torques in N m'), line
            assert 'needs their torque_constant' in line, line
            # the ratios named are about the loaded joints' torque
            # constants (as far as the published inertials go)
            for j in (1, 2):
                name = model.joint_names[j]
                ratio = float(line.split(name + ' ')[1].split()[0].strip(
                    ','))
                ratios.append(ratio / runs['constants'][j])
        counts['flagged'] += len(published)
    print(f'\nwindows flagged: {counts["flagged"]} of currents against the '
          f'published URDF; not flagged: {counts["clean"]} (currents '
          f'against the identified URDF, torques against the published); '
          f'ratio / torque constant on shoulder_lift and elbow: '
          f'{min(ratios):.2f} to {max(ratios):.2f}')
    assert 0.6 < min(ratios) and max(ratios) < 1.6, ratios
    assert counts['flagged'] >= 3 and counts['clean'] >= 5, counts


def test_one_sample_per_spacing_and_none_at_rest():
    names = ['a', 'b']
    monitor = EffortMonitor(names, 'torque', 'test', window=100)
    t = np.arange(0.0, 2.0, 0.001)                  # 1 kHz
    rng = np.random.default_rng(1)
    moving = np.array([0.3, 0.0])
    taken = 0
    for k, tk in enumerate(t):
        qd = moving if tk < 1.5 else np.zeros(2)    # rests after 1.5 s
        tau = rng.normal(size=2)
        taken += monitor.due(tk, qd)
        if monitor.add(tk, tau, 13.0 * tau, qd):
            assert taken == 100, taken          # a window of 100 samples
    # 1.5 s of motion at 1 kHz: one sample per 10 ms at most
    assert monitor.windows == 1 and 130 <= taken <= 151, taken
    # efforts 13 x the torque on a joint that counts: a ratio of 1/13
    assert monitor.verdict is not None and 'a 0.0769' in monitor.verdict
    # a stamp going backwards (a bag replayed) is taken again
    assert monitor.due(0.0, moving)
    assert not monitor.due(0.0, np.zeros(2))


def test_torques_against_constants_and_opposite_signs_are_named():
    rng = np.random.default_rng(2)
    tau = rng.normal(size=(400, 3)) * [10.0, 20.0, 5.0]
    qd = np.full((400, 3), 0.5) * np.sign(rng.normal(size=(400, 3)))
    for effort, mode, words in (
            (tau * 12.0, 'given', 'do not match the torque constants of '
             'arm.urdf'),
            (-tau, 'torque', 'opposite sign'),
            (tau / 12.0, 'torque', 'not joint torques in N m')):
        monitor = EffortMonitor(['a', 'b', 'c'], mode, 'test', 'arm.urdf',
                                window=400)
        for k in range(400):
            monitor.add(0.02 * k, tau[k], effort[k], qd[k])
        assert monitor.windows == 1 and words in monitor.verdict, \
            monitor.verdict
    monitor = EffortMonitor(['a', 'b', 'c'], 'torque', 'test', window=400)
    for k in range(400):
        monitor.add(0.02 * k, tau[k], tau[k] * 1.1, qd[k])
    assert monitor.windows == 1 and monitor.verdict is None
