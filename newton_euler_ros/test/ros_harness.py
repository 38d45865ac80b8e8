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
Helpers for tests that run real ROS 2 processes on loopback DDS.

Each test module takes its own ROS_DOMAIN_ID; discovery stays on
localhost.  The node under test runs as its own process through its
console script; the test talks to it from a separate rclpy context.
"""
import os
import signal
import subprocess
import sys
import time

PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PARAMS_DIR = os.path.join(PACKAGE_DIR, 'config', 'params')


def domain_id(offset):
    """Return a domain id unique to this test run and module (1..100)."""
    return 1 + (os.getpid() * 7 + offset) % 100


def ros_env(domain):
    """
    Return this process's environment with ROS traffic kept on loopback.

    LD_LIBRARY_PATH is inherited untouched (the ROS wheels' bootstrap set
    it; replacing it would break rclpy in the child).
    """
    env = dict(os.environ)
    env['ROS_DOMAIN_ID'] = str(domain)
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    env['PYTHONUNBUFFERED'] = '1'
    return env


def node_command(module, *ros_args):
    """Run a node module with this interpreter (same venv as the test)."""
    return [sys.executable, '-m', module, '--ros-args', *ros_args]


class NodeProcess:
    """A node started as a child process; stop() sends SIGINT."""

    def __init__(self, cmd, domain, log_path):
        self.log_path = log_path
        self._log = open(log_path, 'w')
        self.proc = subprocess.Popen(cmd, env=ros_env(domain),
                                     stdout=self._log,
                                     stderr=subprocess.STDOUT)

    def log(self):
        if not self._log.closed:
            self._log.flush()
        with open(self.log_path) as fh:
            return fh.read()

    def stop(self, timeout=15.0):
        """SIGINT, wait, return the exit code (kills after the timeout)."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self._log.close()
        return self.proc.returncode


class Probe:
    """A test-side rclpy node in its own context: publish, collect, call."""

    def __init__(self, domain, name='probe'):
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        self.rclpy = rclpy
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = rclpy.create_node(name, context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.inbox = {}

    def collect(self, msg_type, topic, depth=100):
        box = self.inbox.setdefault(topic, [])
        self.node.create_subscription(msg_type, topic, box.append, depth)
        return box

    def publisher(self, msg_type, topic, depth=100):
        return self.node.create_publisher(msg_type, topic, depth)

    def spin_until(self, predicate, timeout):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if predicate():
                return True
            self.executor.spin_once(timeout_sec=0.02)
        return predicate()

    def spin_for(self, seconds):
        self.spin_until(lambda: False, seconds)

    def call(self, srv_type, name, request, timeout=10.0):
        client = self.node.create_client(srv_type, name)
        if not client.wait_for_service(timeout_sec=timeout):
            raise TimeoutError(f'service {name} not available')
        future = client.call_async(request)
        self.spin_until(future.done, timeout)
        if not future.done():
            raise TimeoutError(f'service {name} did not answer')
        return future.result()

    def close(self):
        self.executor.shutdown()
        self.node.destroy_node()
        self.rclpy.try_shutdown(context=self.context)
