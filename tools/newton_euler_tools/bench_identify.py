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
Identification: time for a 40 s recording; time and memory against length.

    python -m newton_euler_tools.bench_identify [--quick] [--rate HZ]

1. The 40 s, 500 Hz, 7-joint Panda recording of ``ident_example``
   (Pinocchio efforts): the time ``identify`` takes, as the command prints
   it (target <= 10 s on a 2-core machine, warm caches).
2. Synthetic Panda recordings of 1 and 30 minutes (``--quick``: 1 and 3)
   at ``--rate`` (default 1000 Hz, what real arms publish), efforts from
   the nominal model plus drive terms and noise: each identified in its
   own process, which reports its time and peak resident memory
   (VmHWM).  The fit accumulates a (14n + 1)^2 R factor per joint,
   so memory must not grow with the recording's length; the time does
   (reading and deserialising the bag dominates).
"""
import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np

from .ident_example import (BASE, fourier_trajectory, make_example,
                            panda_path, random_drives, TIP)

MODULE = 'newton_euler_tools.bench_identify'


def _panda():
    from newton_euler_ros.core import load_robot
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot(panda_path(), base=BASE, tip=TIP)


def synthetic_bag(path, seconds, rate, seed=0):
    """Write a long synthetic recording; efforts from our nominal model."""
    from newton_euler_ros.core import inverse_dynamics_batch
    from newton_euler_ros.ident.bag_write import write_joint_states
    model = _panda()
    rng = np.random.default_rng(seed)
    traj = fourier_trajectory(model, rng)
    drives = random_drives(rng, model.n)
    count = int(seconds * rate)
    t = np.arange(count) / rate
    q, qd, qdd = traj(t)
    tau = inverse_dynamics_batch(model, q, qd, qdd)
    tau += (drives['viscous'] * qd + drives['coulomb']
            * np.tanh(qd / drives['coulomb_width']) + drives['offset']
            + drives['armature'] * qdd)
    tau += rng.normal(0, 0.05, tau.shape)
    stamps = 10**9 + np.round(t * 1e9).astype(np.int64)
    write_joint_states(path, stamps, model.joint_names, q, qd, tau)


def peak_rss_mb():
    """
    Peak resident memory of this process, MB.

    VmHWM of /proc/self/status: ``ru_maxrss`` would not do, Linux carries
    it over fork and exec from the parent (the bench's parent holds the
    long recording it has just written).
    """
    try:
        with open('/proc/self/status', encoding='ascii') as f:
            for line in f:
                if line.startswith('VmHWM:'):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def identify_once(bag):
    """Identify the Panda from ``bag``; return seconds and peak RSS (MB)."""
    from newton_euler_ros.ident.fit import identify
    model = _panda()
    with open(panda_path(), encoding='utf-8') as f:
        text = f.read()
    start = time.perf_counter()
    result = identify(model, bag, urdf_text=text)
    seconds = time.perf_counter() - start
    peak = peak_rss_mb()
    rel = result.fit_stats['identified'][1]
    return {'seconds': seconds, 'peak_mb': peak,
            'samples': int(result.info['samples']),
            'mean_rel': float(np.mean(rel))}


def _child(bag):
    # one BLAS thread, as the newton-euler command sets it (cli.py)
    env = dict(os.environ, OPENBLAS_NUM_THREADS='1')
    out = subprocess.run([sys.executable, '-m', MODULE, '--identify',
                          bag], capture_output=True, text=True, check=True,
                         env=env)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None):
    """Print the table."""
    parser = argparse.ArgumentParser(description=__doc__.strip().split(
        '\n')[0])
    parser.add_argument('--quick', action='store_true',
                        help='1 and 3 minutes instead of 1 and 30')
    parser.add_argument('--rate', type=float, default=1000.0)
    parser.add_argument('--identify', metavar='BAG', help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.identify:
        print(json.dumps(identify_once(args.identify)))
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        paths = make_example(os.path.join(tmp, 'ex'), seconds=40.0,
                             rate=500.0, seed=0, validation=False)
        r = _child(paths['recording'])
        print(f'40 s, 500 Hz, 7-joint Panda recording: identified in '
              f'{r["seconds"]:.2f} s (target <= 10 s), peak memory '
              f'{r["peak_mb"]:.0f} MB, residual {100 * r["mean_rel"]:.2f} % '
              f'mean relative RMS')
        minutes = (1, 3) if args.quick else (1, 30)
        print(f'synthetic recordings at {args.rate:g} Hz, each identified in '
              f'its own process:')
        print(f'{"length":>8}{"messages":>11}{"time (s)":>10}'
              f'{"peak RSS (MB)":>15}')
        for m in minutes:
            bag = os.path.join(tmp, f'synthetic_{m}min')
            synthetic_bag(bag, 60.0 * m, args.rate)
            r = _child(bag)
            print(f'{m:>6} min{int(60 * m * args.rate):>11}'
                  f'{r["seconds"]:>10.1f}{r["peak_mb"]:>15.0f}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
