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
Console-script entry points of the nodes.

Importing a node pulls in rclpy, numpy and numba, which takes a second or
two; a SIGINT or SIGTERM in that time would end in a KeyboardInterrupt
traceback or a silent kill.  These entry points catch either signal from
the very start and stop with one line and exit status 0 (``--help``
prints the node's description, topics and parameters and exits 0
without starting ROS); from
``rclpy.init`` on, :func:`~newton_euler_ros.nodes.common.run_node` takes
over.
"""
import importlib
import os
import signal
import sys


def _run(name, module):
    def stop(signum, _frame):
        print(f'{name}: stopped during start-up '
              f'({signal.Signals(signum).name})', file=sys.stderr,
              flush=True)
        # nothing is running yet (no ROS context, no threads of ours);
        # SystemExit could be swallowed by an import that catches
        # BaseException, so leave at once
        os._exit(0)
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, stop)
    # --help: what the node does, its topics and parameters; no ROS
    from ..parameters import help_requested, print_help
    if help_requested(sys.argv[1:]):
        print_help(name)
        return 0
    return importlib.import_module(module).main()


def inverse_dynamics_node():
    """Run inverse_dynamics_node."""
    return _run('inverse_dynamics_node',
                'newton_euler_ros.nodes.inverse_dynamics_node')


def mujoco_sim_node():
    """Run mujoco_sim_node."""
    return _run('mujoco_sim_node', 'newton_euler_ros.nodes.mujoco_sim_node')


def robot_sim_node():
    """Run robot_sim_node."""
    return _run('robot_sim_node', 'newton_euler_ros.nodes.robot_sim_node')


def tracking_controller_node():
    """Run tracking_controller_node."""
    return _run('tracking_controller_node',
                'newton_euler_ros.nodes.tracking_controller_node')
