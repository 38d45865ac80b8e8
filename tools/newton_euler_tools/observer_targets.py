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
The observer's targets on the current-sensing example, seed by seed.

    python -m newton_euler_tools.observer_targets [--seeds 0-8] [--out DIR]

For each seed, ``current_arm_example``'s UR5-like arm (motor currents at
100 Hz, static friction held anywhere in its band at rest and drifting,
stops, lost messages, gaps) is observed with the URDF an identification
gives (``current_arm_model``), as docs/observer.md tells a user:
thresholds suggested from one free-motion minute with stops, then

- contacts in 9 other free-motion recordings (30 s each, with stops);
- the share of the un-pushed rest reported in contact;
- 10 pushes of 20-100 N on the tool (half-sines of 0.4-1.2 s, the arm
  resting or moving): how many are reported within 0.2 s of their onset
  (and, after the table, when the others were and what the arm was
  doing as they began);

once with the rest reference (the default) and once without
(``rest_reference=False``: the threshold and the static friction
allowance alone).  ``newton_euler_ros/test/nodes/test_observer_targets.py``
checks seed 0 with these functions.
"""
import argparse
import os
import sys
import tempfile
import warnings

import numpy as np


def recordings(seed, out_dir):
    """Write the arm's identified URDF and its 11 recordings; return them."""
    from . import current_arm_example as example
    from .current_arm_model import write_identified
    from .current_arm_motions import (held_then_moving, point_to_point,
                                      random_pushes)
    arm = example.real_arm(seed)
    urdf = write_identified(os.path.join(out_dir, 'arm.urdf'), arm, seed)
    runs = {}
    for k in range(1, 11):          # the first, a minute, for thresholds
        motion = point_to_point(seed + 100 * k, 60.0 if k == 1 else 30.0,
                                dwell=(0.3, 2.5), few=0.3, reverse=0.7)
        path = os.path.join(out_dir, f'free_{k}')
        runs[f'free_{k}'] = (path, example.record(arm, path, motion,
                                                  seed=seed * 1000 + k))
    motion = held_then_moving(seed + 7)
    pushes = random_pushes(seed, motion.seconds, 10)
    path = os.path.join(out_dir, 'pushed')
    runs['pushed'] = (path, example.record(arm, path, motion, pushes=pushes,
                                           seed=seed * 1000 + 99))
    return {'urdf': urdf, 'arm': arm, 'runs': runs, 'pushes': pushes}


def observed(urdf, path, thresholds, rest_reference=True, speed=0.0,
             acceleration=0.0, rest=0.0):
    """
    Run the observer over a bag as ``observe`` does (in process).

    ``speed``, ``acceleration``, ``rest``: its speed, acceleration and
    rest thresholds.
    """
    from newton_euler_ros.core import load_robot
    from newton_euler_ros.core.observer import (drive_options,
                                                MomentumObserver,
                                                observe_recording)
    from newton_euler_ros.ident.bag import read_joint_states
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        model = load_robot(urdf, base='base_link', tip='tool0')
    rec = read_joint_states(path, model.joint_names, '/joint_states')
    obs = MomentumObserver(model, 50.0, thresholds=thresholds,
                           rest_reference=rest_reference,
                           speed_thresholds=speed,
                           acceleration_thresholds=acceleration,
                           rest_thresholds=rest, **drive_options(model))
    return rec, observe_recording(obs, rec.stamps, rec.q, rec.qd,
                                  rec.effort)


def truth_at(truth, rec):
    """Return seconds from the start and the true sample of each message."""
    t = (rec.stamps_ns - rec.stamps_ns[0]) * 1e-9
    return t, np.clip(np.searchsorted(truth['t'], t - 1e-6), 0,
                      len(truth['t']) - 1)


def pushes_felt(data, rec, out):
    """
    Per push: (N, 'rest' or 'move', s from onset to the report or None).

    And the share of the un-pushed rest in contact (the arm resting, no
    push within 0.3 s).
    """
    _, truth = data['runs']['pushed']
    t, i = truth_at(truth, rec)
    resting = (truth['qd'][i] == 0.0).all(axis=1)
    pushed = np.zeros(t.size, dtype=bool)
    rows = []
    for p in data['pushes']:
        pushed |= (t >= p['start']) & (t <= p['start'] + p['duration']
                                       + 0.3)
        on = (t >= p['start']) & (t <= p['start'] + p['duration'])
        hits = np.flatnonzero(on & out.contact)
        rows.append((round(float(np.linalg.norm(p['force']))),
                     'rest' if resting[on].all() else 'move',
                     round(float(t[hits[0]] - p['start']), 3)
                     if hits.size else None))
    return rows, float(out.contact[resting & ~pushed].mean())


def onset(data, rec, push):
    """
    Say what the arm was doing when ``push`` began, in a few words.

    Resting (seconds since it stopped, until it moves), moving, and the
    gap in the messages at the onset if one was longer than 0.1 s.
    """
    _, truth = data['runs']['pushed']
    t, i = truth_at(truth, rec)
    resting = (truth['qd'][i] == 0.0).all(axis=1)
    k = int(np.searchsorted(t, push['start']))
    words = []
    if k < t.size and k > 0 and t[k] - t[k - 1] > 0.1:
        words.append(f'in a {t[k] - t[k - 1]:.2f} s gap of the messages, '
                     f'{t[k] - push["start"]:.2f} s of it after the onset')
    k = min(k, t.size - 1)
    if resting[k]:
        a = b = k
        while a > 0 and resting[a - 1]:
            a -= 1
        while b < t.size - 1 and resting[b + 1]:
            b += 1
        words.append(f'resting, {push["start"] - t[a]:.2f} s after its '
                     f'stop and {t[b] - push["start"]:.2f} s before it moves')
    else:
        words.append('moving')
    return ', '.join(words)


def evaluate(data, rest_reference=True):
    """Return the targets of one seed's recordings, a dict of figures."""
    from newton_euler_ros.core.observer.thresholds import suggest_thresholds
    path, _ = data['runs']['free_1']
    _, out = observed(data['urdf'], path, 10.0, rest_reference)
    thresholds = suggest_thresholds(out)
    free = sum(observed(data['urdf'], data['runs'][f'free_{k}'][0],
                        thresholds, rest_reference)[1].contacts > 0
               for k in range(2, 11))
    rec, out = observed(data['urdf'], data['runs']['pushed'][0], thresholds,
                        rest_reference)
    rows, at_rest = pushes_felt(data, rec, out)
    late = [(n, after, onset(data, rec, p))
            for (n, _, after), p in zip(rows, data['pushes'])
            if after is None or after > 0.2]
    return {'thresholds': thresholds.tolist(), 'free_with_contact': free,
            'rows': rows, 'at_rest': at_rest, 'late': late,
            'soon': sum(r[2] is not None and r[2] <= 0.2 for r in rows)}


UNMODELLED = 1.0    # the arm of --moving: current_arm_example.real_arm's


def moving_recordings(seed, out_dir, unmodelled=UNMODELLED):
    """
    Write the recordings of the moving-arm targets; return them.

    An arm whose identified model misses friction in speed squared and
    some rotor inertia (``real_arm(seed, unmodelled)``): one free minute
    with stops to fit the thresholds on (as :func:`recordings`'
    ``free_1``), a held-out 40 s of point-to-point moves at full speed
    with short stops and reversals (``validation``), five held poses
    (``rest``), and the 10 pushes of ``pushed``.
    """
    from . import current_arm_example as example
    from .current_arm_model import write_identified
    from .current_arm_motions import (held_then_moving, holding,
                                      point_to_point, random_pushes)
    arm = example.real_arm(seed, unmodelled)
    urdf = write_identified(os.path.join(out_dir, 'arm.urdf'), arm, seed)
    motion = held_then_moving(seed + 7)
    pushes = random_pushes(seed, motion.seconds, 10)
    plan = {'free_1': (point_to_point(seed + 100, 60.0, dwell=(0.3, 2.5),
                                      few=0.3, reverse=0.7), ()),
            'validation': (point_to_point(seed + 50, 40.0), ()),
            'rest': (holding(seed), ()), 'pushed': (motion, pushes)}
    runs = {}
    for k, (name, (motion, push)) in enumerate(plan.items()):
        path = os.path.join(out_dir, name)
        runs[name] = (path, example.record(arm, path, motion, pushes=push,
                                           seed=seed * 1000 + 500 + k))
    return {'urdf': urdf, 'arm': arm, 'runs': runs, 'pushes': pushes}


def moving_evaluate(data, state=True):
    """
    Return the moving-arm targets of one seed, a dict of figures.

    Thresholds fitted on ``free_1``: ``suggest_state_thresholds``
    (``state``) or ``suggest_thresholds`` (one number per joint); then
    contact episodes on the held-out ``validation`` and on the held
    poses, and the pushes reported (resting / moving) and within 0.2 s
    of their onset.
    """
    from newton_euler_ros.core.observer.thresholds import (
        suggest_rest_thresholds, suggest_state_thresholds, suggest_thresholds)
    _, out = observed(data['urdf'], data['runs']['free_1'][0], 10.0)
    if state:
        a, b, c = suggest_state_thresholds(out)
        rest = suggest_rest_thresholds(out, a, b, c)
    else:
        a, b, c, rest = suggest_thresholds(out), 0.0, 0.0, 0.0
    got = {'thresholds': [np.asarray(x).tolist() for x in (a, b, c, rest)]}
    for name in ('validation', 'rest'):
        _, o = observed(data['urdf'], data['runs'][name][0], a, True, b, c,
                        rest)
        got[name] = int(o.contacts)
        got[name + '_share'] = float(o.contact.mean())
    rec, o = observed(data['urdf'], data['runs']['pushed'][0], a, True, b, c,
                      rest)
    rows, at_rest = pushes_felt(data, rec, o)
    got.update(rows=rows, at_rest=at_rest,
               felt={w: (sum(r[2] is not None for r in rows if r[1] == w),
                         sum(r[1] == w for r in rows))
                     for w in ('rest', 'move')},
               soon=sum(r[2] is not None and r[2] <= 0.2 for r in rows))
    return got


def moving_main(seeds, out):
    """Print the moving-arm targets per seed, one line per threshold kind."""
    print('seed  thresholds         contact episodes:        pushes '
          'reported: resting moving  within 0.2 s')
    print('                         point-to-point  held')
    total = {}
    with tempfile.TemporaryDirectory() as tmp:
        for seed in seeds:
            folder = os.path.join(out or tmp, f'moving_{seed}')
            os.makedirs(folder, exist_ok=True)
            data = moving_recordings(seed, folder)
            for state in (False, True):
                e = moving_evaluate(data, state)
                kind = 'a + b|qd| + c|qdd|' if state else 'one per joint'
                t = total.setdefault(kind, [0] * 7)
                for i, x in enumerate((e['validation'], e['rest'],
                                       *e['felt']['rest'], *e['felt']['move'],
                                       e['soon'])):
                    t[i] += x
                print(f'{seed:>4}  {kind:<19}{e["validation"]:>8}'
                      f'{e["rest"]:>12}{"":16}{e["felt"]["rest"][0]:>2} of '
                      f'{e["felt"]["rest"][1]:<3}{e["felt"]["move"][0]:>3} '
                      f'of {e["felt"]["move"][1]:<3}{e["soon"]:>6} of 10')
                if state:
                    print('      (a, b, c; rest) = ' + '; '.join(
                        ' '.join(f'{v:.2g}' for v in x)
                        for x in e['thresholds']))
    for kind, t in total.items():
        print(f'all   {kind:<19}{t[0]:>8}{t[1]:>12}{"":16}{t[2]:>2} of '
              f'{t[3]:<3}{t[4]:>3} of {t[5]:<3}{t[6]:>6} of '
              f'{10 * len(seeds)}')
    return 0


def _seeds(text):
    if '-' in text:
        a, b = text.split('-')
        return list(range(int(a), int(b) + 1))
    return [int(x) for x in text.split(',')]


def main(argv=None):
    """Print the targets per seed, with and without the rest reference."""
    parser = argparse.ArgumentParser(
        prog='python -m newton_euler_tools.observer_targets',
        description=__doc__.split('\n\n')[0])
    parser.add_argument('--seeds', type=_seeds, default=_seeds('0-8'),
                        help="seeds, 'A-B' or 'A,B,...' (default 0-8)")
    parser.add_argument('--out', default=None, help='folder for the '
                        'recordings (default: a temporary one)')
    parser.add_argument('--moving', action='store_true',
                        help='the moving-arm targets instead: an arm whose '
                        'model errs in proportion to speed and '
                        'acceleration, thresholds one per joint against '
                        'a + b|qd| + c|qdd| (default seeds 0-2)')
    args = parser.parse_args(argv)
    if args.moving:
        return moving_main(args.seeds if '--seeds' in ' '.join(
            argv or sys.argv) else [0, 1, 2], args.out)
    total = {True: [0, 0, []], False: [0, 0, []]}
    late = []
    print('seed  pushes within 0.2 s of onset   free recordings with '
          'contact   un-pushed rest in contact')
    print('      rest ref. / without          rest ref. / without       '
          '      rest ref. / without')
    with tempfile.TemporaryDirectory() as tmp:
        for seed in args.seeds:
            folder = os.path.join(args.out or tmp, f'seed_{seed}')
            os.makedirs(folder, exist_ok=True)
            data = recordings(seed, folder)
            got = {on: evaluate(data, on) for on in (True, False)}
            late += [(seed, *x) for x in got[True]['late']]
            for on, e in got.items():
                total[on][0] += e['soon']
                total[on][1] += e['free_with_contact']
                total[on][2].append(e['at_rest'])
            print(f'{seed:>4}  {got[True]["soon"]:>4} / {got[False]["soon"]:<4}'
                  f'{"":21}{got[True]["free_with_contact"]:>2} / '
                  f'{got[False]["free_with_contact"]:<2}{"":21}'
                  f'{got[True]["at_rest"]:6.1%} / {got[False]["at_rest"]:.1%}')
    n = len(args.seeds)
    print(f'all   {total[True][0]:>4} / {total[False][0]:<4} of {10 * n}'
          f'{"":13}{total[True][1]:>2} / {total[False][1]:<2} of {9 * n}'
          f'{"":15}at most {max(total[True][2]):.1%} / '
          f'{max(total[False][2]):.1%}')
    print('\npushes not reported within 0.2 s of onset (rest reference on):')
    for seed, newtons, after, words in late:
        said = 'not reported' if after is None else f'{after:.3f} s'
        print(f'  seed {seed}: {newtons} N, {said} (onset: {words})')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
