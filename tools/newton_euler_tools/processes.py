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
Child ROS 2 processes for the demo, the benchmarks and the tests.

Each child gets this process's environment plus its own ROS_DOMAIN_ID and
localhost-only discovery; :func:`first_domain` makes a tool start from
the user's ROS_DOMAIN_ID when it is set.  LD_LIBRARY_PATH is inherited untouched: the
ROS wheels' bootstrap set it, and a child with a replaced one cannot
import rclpy.
"""
import ctypes
import os
import signal
import subprocess


MAX_DOMAIN = 232        # the highest ROS 2 domain id


def first_domain(default, count=1):
    """
    Return the first of ``count`` consecutive ROS domain ids for a tool.

    ``ROS_DOMAIN_ID`` when it is set (the tool uses it and the next
    ``count - 1`` ids), else ``default``.  A value that is not an integer,
    or ids beyond :data:`MAX_DOMAIN`, raise ValueError (one line).
    """
    value = os.environ.get('ROS_DOMAIN_ID', '').strip()
    if not value:
        return default
    if not value.isdigit() or int(value) + count - 1 > MAX_DOMAIN:
        raise ValueError(
            f'ROS_DOMAIN_ID={value[:40]!r}: this tool uses {count} '
            f'consecutive domain ids from it, so it must be an integer in '
            f'0..{MAX_DOMAIN - count + 1}')
    return int(value)


def ros_env(domain):
    """Return this environment plus a domain id and localhost discovery."""
    env = dict(os.environ)
    env['ROS_DOMAIN_ID'] = str(domain)
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    env['PYTHONUNBUFFERED'] = '1'
    return env


_PR_SET_PDEATHSIG = 1
try:    # Linux prctl(2), or None elsewhere
    prctl = ctypes.CDLL(None, use_errno=True).prctl
    prctl.argtypes = [ctypes.c_int, ctypes.c_ulong, ctypes.c_ulong,
                      ctypes.c_ulong, ctypes.c_ulong]
except (OSError, AttributeError):
    prctl = None


def _die_with_parent():
    # runs in the child between fork and exec: SIGKILL when we die
    prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)


class ChildProcess:
    """
    A node started as a child process, its output in a log file.

    ``env`` adds variables to :func:`ros_env`'s; ``die_with_parent`` has
    the kernel kill the child if this process dies first (Linux).
    """

    def __init__(self, cmd, domain, log_path, label=None, env=None,
                 die_with_parent=False):
        self.cmd = cmd
        self.label = label or os.path.basename(log_path)
        self.log_path = log_path
        os.makedirs(os.path.dirname(os.path.abspath(log_path)), exist_ok=True)
        self._log = open(log_path, 'w')
        self.exit_code = None
        self.stop_how = None
        preexec = (_die_with_parent if die_with_parent and prctl is not None
                   else None)
        self.proc = subprocess.Popen(
            cmd, env={**ros_env(domain), **(env or {})},
            stdin=subprocess.DEVNULL, stdout=self._log,
            stderr=subprocess.STDOUT, preexec_fn=preexec)

    @property
    def pid(self):
        """Return the process id."""
        return self.proc.pid

    def alive(self):
        """Return True while the process runs."""
        return self.proc.poll() is None

    def tail(self, lines=15):
        """Return the last ``lines`` lines of the log ('' if unreadable)."""
        try:
            if not self._log.closed:
                self._log.flush()
            with open(self.log_path, errors='replace') as fh:
                return ''.join(fh.readlines()[-lines:])
        except OSError:
            return ''

    def log(self):
        """Return everything the process has written so far."""
        if not self._log.closed:
            self._log.flush()
        with open(self.log_path) as fh:
            return fh.read()

    def stop(self, timeout=15.0):
        """
        Send SIGINT and wait; return the exit status.

        A process still running after ``timeout`` seconds is killed, and
        the status is then the (negative) signal number.
        """
        if self.proc.poll() is None:
            self.stop_how = 'SIGINT'
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.stop_how = (f'SIGKILL (no exit {timeout:.0f} s after '
                                 f'SIGINT)')
                self.proc.kill()
                self.proc.wait()
        elif self.stop_how is None:
            self.stop_how = 'had already exited'
        if not self._log.closed:
            self._log.close()
        self.exit_code = self.proc.returncode
        return self.exit_code
