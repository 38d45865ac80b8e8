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
Call inverse_dynamics_node's ~/compute_dynamics service once; print D, C, g, tau.

    .venv/bin/python examples/compute_dynamics_client.py \
        --joints joint1 joint2 joint3 joint4 joint5 joint6 \
        --q 0 0.5 -0.3 0.1 0.2 0.3 [--qd ...] [--qdd ...]

``--joints`` names your robot's joints (in any order, as in a
JointState) and ``--q``, ``--qd``, ``--qdd`` give one value per name;
a velocity or acceleration left out means zeros.  Without ``--joints``
and ``--q`` the node answers at the latest state it measured on
joint_states.  ``--service`` names another node's service.  A fresh
client's first call can go unanswered in a ROS 2 discovery race, so the
call is resent after 5 s (calls are idempotent); it gives up after
``--timeout`` seconds (60).
"""
import argparse
import sys
import time

import numpy as np
import rclpy
from rclpy.node import Node

from newton_euler_interfaces.srv import ComputeDynamics

SERVICE = '/inverse_dynamics_node/compute_dynamics'


def parse_args(argv=None):
    """Return the request's joints and state from the command line."""
    parser = argparse.ArgumentParser(
        description="Ask inverse_dynamics_node for D, C, g and tau at a "
                    "state of your robot's joints.")
    parser.add_argument('--joints', nargs='+', metavar='NAME', default=[],
                        help="the robot's joint names (any order)")
    for option, what in (('--q', 'positions (rad or m)'),
                         ('--qd', 'velocities (default zeros)'),
                         ('--qdd', 'accelerations (default zeros)')):
        parser.add_argument(option, nargs='+', type=float, default=[],
                            metavar=option[2:].upper(),
                            help=f'joint {what}, one per name')
    parser.add_argument('--service', default=SERVICE,
                        help=f'the service to call (default {SERVICE})')
    parser.add_argument('--timeout', type=float, default=60.0, metavar='S',
                        help='give up after S seconds (default 60)')
    args = parser.parse_args(argv)
    if bool(args.joints) != bool(args.q):
        parser.error('give --joints and --q together (or neither: the '
                     'latest measured state)')
    for option in ('q', 'qd', 'qdd'):
        values = getattr(args, option)
        if values and len(values) != len(args.joints):
            parser.error(f'--{option}: {len(values)} values for '
                         f'{len(args.joints)} joints')
    return args


def main(argv=None):
    """Call the service, print what it answers."""
    args = parse_args(argv)
    rclpy.init()
    node = Node('dynamics_client')
    client = node.create_client(ComputeDynamics, args.service)
    request = ComputeDynamics.Request(
        name=args.joints, position=args.q, velocity=args.qd,
        acceleration=args.qdd)
    deadline, res = time.monotonic() + args.timeout, None
    try:
        while res is None and time.monotonic() < deadline:
            if not client.wait_for_service(timeout_sec=1.0):
                continue
            future = client.call_async(request)
            rclpy.spin_until_future_complete(node, future, timeout_sec=5.0)
            res = future.result() if future.done() else None
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    if res is None:
        print(f'no answer from {args.service} within {args.timeout:g} s',
              file=sys.stderr)
        return 1
    if not res.success:
        print(f'{args.service}: {res.message}', file=sys.stderr)
        return 1
    n = len(res.name)
    np.set_printoptions(precision=4, suppress=True)
    print('joints', list(res.name))
    print('D =\n', np.reshape(res.mass_matrix, (n, n)))
    print('C =\n', np.reshape(res.coriolis_matrix, (n, n)))
    print('g =', np.array(res.gravity))
    print('tau =', np.array(res.torque))
    return 0


if __name__ == '__main__':
    sys.exit(main())
