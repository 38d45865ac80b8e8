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
Every test runs in ``make test``: a skip there is a failure.

``make test`` sets up every dependency (ROS 2 wheels, Pinocchio,
example-robot-data, rosbags, ...), so a test that skips itself there has
lost something (a broken install, a renamed module) and says so as a
failure, with its skip reason.  The Makefile sets
``NEWTON_EULER_NO_SKIPS=1``; a plain ``pytest`` elsewhere (a colcon
workspace without the peers) may still skip.  The one skip allowed is
``ament_copyright``, which exists only in an apt ROS 2 install.
"""
import os
import signal
import time

import pytest

ALLOWED = ('ament_copyright',)


def pytest_configure(config):
    """
    Give the commands the tests start a Ctrl-C that works.

    A shell without job control starts a background command (``make test
    &`` in a script) with SIGINT and SIGQUIT ignored, and every process
    it starts inherits that: the tests that interrupt a command
    (``test_cli_exit_status.py``) would then wait on a command that
    cannot hear them.  pytest restores Python's own handler here, which
    its children do not inherit: they start with the default.
    """
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def _strict():
    return os.environ.get('NEWTON_EULER_NO_SKIPS') == '1'


def _reason(report):
    longrepr = report.longrepr
    if isinstance(longrepr, tuple) and len(longrepr) == 3:
        return str(longrepr[2])
    return str(longrepr)


def _fail_skip(report):
    reason = _reason(report)
    if any(name in reason for name in ALLOWED):
        return
    report.outcome = 'failed'
    report.longrepr = ('skipped under make test, where every dependency is '
                       f'installed: {reason}')


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """Turn a test's skip into a failure under make test."""
    outcome = yield
    report = outcome.get_result()
    if _strict() and report.skipped and not hasattr(report, 'wasxfail'):
        _fail_skip(report)


@pytest.hookimpl(hookwrapper=True)
def pytest_make_collect_report(collector):
    """Turn a module's skip (importorskip at import) into a failure."""
    outcome = yield
    report = outcome.get_result()
    if _strict() and report.skipped:
        _fail_skip(report)


# The test files that take longest under ``make test`` (measured with
# --durations on this 2-core machine; the bounds-checked and entry-point
# kernels compile, minutes, when the kernel sources changed), longest
# first.  ``make test`` hands whole files to its two workers in
# collection order (``--dist loadfile --no-loadscope-reorder``; xdist's
# default order, by number of tests, ran the one-test bounds check last,
# alone for 7 minutes): these start first and the short files fill in.
LONGEST_FIRST = (
    'tools/test/test_docs_commands.py',
    'newton_euler_ros/test/core/test_bounds_checked.py',
    'tools/test/test_demo_identify.py',
    'tools/test/test_demo.py',
    'newton_euler_ros/test/core/test_precision_crba.py',
    'newton_euler_ros/test/core/test_entry_points.py',
    'newton_euler_ros/test/ident/test_identify_dual_arm.py',
    'newton_euler_ros/test/nodes/test_cli_exit_status.py',
    'tools/test/test_accuracy_report.py',
    'newton_euler_ros/test/nodes/test_send_record.py',
    'newton_euler_ros/test/linters/test_flake8.py',
    'tools/test/test_mujoco_observer.py',
    'newton_euler_ros/test/nodes/test_mujoco_sim_node.py',
    'newton_euler_ros/test/nodes/test_inverse_dynamics_node.py',
)


def pytest_collection_modifyitems(session, config, items):
    """Put the files of LONGEST_FIRST first, in its order (stable)."""
    root = str(config.rootpath)
    missing = [p for p in LONGEST_FIRST
               if not os.path.exists(os.path.join(root, p))]
    if missing:
        raise pytest.UsageError(
            f'conftest.py: LONGEST_FIRST names no such file: {missing}')
    rank = {p: k for k, p in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(
        os.path.relpath(str(item.path), root), len(rank)))


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    """
    Append each test's wall and CPU seconds to build/test_seconds.txt.

    CPU is the worker's own and its finished children's (``os.times``),
    set-up and teardown included, so a node a fixture started is counted
    where it is stopped.  A record for finding where the suite's time
    goes (``docs/tests.md``), not a check: a write that fails is ignored.
    """
    wall, before = time.monotonic(), os.times()
    yield
    after = os.times()
    cpu = sum(after[k] - before[k] for k in range(4))
    path = os.path.join(str(item.config.rootpath), 'build',
                        'test_seconds.txt')
    try:
        with open(path, 'a', encoding='utf-8') as fh:
            fh.write(f'{time.monotonic() - wall:8.2f} {cpu:8.2f}  '
                     f'{item.nodeid}\n')
    except OSError:
        pass
