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
localhost-only discovery.  LD_LIBRARY_PATH is inherited untouched: the
ROS wheels' bootstrap set it, and a child with a replaced one cannot
import rclpy.
"""
import os
import signal
import subprocess


def ros_env(domain):
    """Return this environment plus a domain id and localhost discovery."""
    env = dict(os.environ)
    env['ROS_DOMAIN_ID'] = str(domain)
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    env['PYTHONUNBUFFERED'] = '1'
    return env


class ChildProcess:
    """A node started as a child process, its output in a log file."""

    def __init__(self, cmd, domain, log_path, label=None):
        self.label = label or os.path.basename(log_path)
        self.log_path = log_path
        self._log = open(log_path, 'w')
        self.proc = subprocess.Popen(cmd, env=ros_env(domain),
                                     stdout=self._log,
                                     stderr=subprocess.STDOUT)

    def alive(self):
        """Return True while the process runs."""
        return self.proc.poll() is None

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
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        if not self._log.closed:
            self._log.close()
        return self.proc.returncode
