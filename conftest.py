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

import pytest

ALLOWED = ('ament_copyright',)


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
