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

"""The best-of-R wall time and the command line the small benchmarks share."""
import argparse
import time


def min_time(fn, number=1, repeat=5):
    """
    Return the best time per call of ``fn``, in seconds.

    ``fn`` is called once first (JIT loading, caches), then ``repeat``
    times ``number`` calls are timed; the fastest repetition counts (the
    least disturbed by the rest of the machine).
    """
    fn()
    best = float('inf')
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(number):
            fn()
        best = min(best, (time.perf_counter() - start) / number)
    return best


def min_times(fns, number=1, repeat=5):
    """
    Return {name: best time per call} of ``fns`` ({name: callable}).

    Timed side by side: each of the ``repeat`` rounds times ``number``
    calls of every callable in turn, so a slow spell of the machine
    (seconds long on a shared one) falls on all of them, not on one.
    """
    for fn in fns.values():
        fn()
    best = dict.fromkeys(fns, float('inf'))
    for _ in range(repeat):
        for name, fn in fns.items():
            start = time.perf_counter()
            for _ in range(number):
                fn()
            best[name] = min(best[name],
                             (time.perf_counter() - start) / number)
    return best


def tool_parser(module, description, quick=None):
    """
    Return the parser of ``python -m newton_euler_tools.MODULE``.

    With ``quick`` (its help: what it cuts), its first option is
    ``--quick``.
    """
    parser = argparse.ArgumentParser(
        prog=f'python -m newton_euler_tools.{module}',
        description=description)
    if quick:
        parser.add_argument('--quick', action='store_true', help=quick)
    return parser


def quick_option(doc, what, argv=None):
    """
    Return whether ``--quick`` is given: a small benchmark's only option.

    The command line's description is the first line of ``doc`` (the
    module's docstring); ``what`` is ``--quick``'s help: what it cuts.
    """
    parser = argparse.ArgumentParser(description=doc.strip().split('\n')[0])
    parser.add_argument('--quick', action='store_true', help=what)
    return parser.parse_args(argv).quick
