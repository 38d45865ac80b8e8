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
``newton-euler`` commands run inside the test process.

A new Python process pays about 2 s of CPU before a command starts
(numpy, numba, scipy and the kernels from numba's cache): at hundreds
of calls that was a large share of ``make test``.  The tests of what a
command prints and returns call :func:`newton_euler` instead, which runs
the console script's ``main`` here, with what a fresh process would
have: its own stdout and stderr, Python's default warning filters with
warnings printed to that stderr, a traceback and status 1 for an
uncaught exception, and the status ``sys.exit`` would give.

The commands as processes are still tested where the process is the
point: every command's exit status (``test_cli_exit_status``), the
console scripts and the pages' commands as pasted (``test_docs_commands``),
the commands that talk to a ROS graph, and the import path of a bare
start (``test_runtime_path``).
"""
import contextlib
import io
import os
import sys
import traceback
import warnings


def _status(code):
    """Return the exit status of ``sys.exit(code)``."""
    if code is None:
        return 0
    if isinstance(code, int):
        return code
    print(code, file=sys.stderr)
    return 1


@contextlib.contextmanager
def _default_warnings(stream):
    """Python's default warning filters, printing to ``stream``."""
    with warnings.catch_warnings():
        warnings.resetwarnings()
        warnings.simplefilter('default')
        for category in (DeprecationWarning, PendingDeprecationWarning,
                         ImportWarning, ResourceWarning):
            warnings.simplefilter('ignore', category)

        def show(message, category, filename, lineno, file=None, line=None):
            stream.write(warnings.formatwarning(message, category, filename,
                                                lineno, line))
        warnings.showwarning = show
        yield


def newton_euler(*args, cwd=None):
    """
    Run ``newton-euler ARGS`` in this process; (status, stdout, stderr).

    ``cwd``: the directory the command runs in (restored after).
    """
    from newton_euler_ros.cli import main
    out, err = io.StringIO(), io.StringIO()
    here = os.getcwd()
    try:
        if cwd is not None:
            os.chdir(cwd)
        with contextlib.redirect_stdout(out), \
                contextlib.redirect_stderr(err), _default_warnings(err):
            try:
                status = _status(main([str(a) for a in args]))
            except SystemExit as exc:
                status = _status(exc.code)
            except Exception:                    # noqa: B902 (as a process)
                traceback.print_exc()
                status = 1
    finally:
        os.chdir(here)
    return status, out.getvalue(), err.getvalue()
