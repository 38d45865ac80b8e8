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
Call inverse_dynamics_node's ~/compute_dynamics service once and print D, C, g.

    .venv/bin/python examples/compute_dynamics_client.py

The state is the Puma 560's (``config/params/puma560.yaml``); velocity
and acceleration are left empty, which means zeros.  A fresh client's
first call can go unanswered in a ROS 2 discovery race, so the call is
resent after 5 s (calls are idempotent); it gives up after 60 s.
"""
import sys
import time

import numpy as np
import rclpy
from rclpy.node import Node

from newton_euler_interfaces.srv import ComputeDynamics


def main():
    """Call the service, print what it answers."""
    rclpy.init()
    node = Node('dynamics_client')
    client = node.create_client(ComputeDynamics,
                                '/inverse_dynamics_node/compute_dynamics')
    request = ComputeDynamics.Request(
        name=[f'joint{i}' for i in range(1, 7)],
        position=[0.0, 0.5, -0.3, 0.1, 0.2, 0.3])
    deadline, res = time.monotonic() + 60.0, None
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
        print('no answer from /inverse_dynamics_node/compute_dynamics',
              file=sys.stderr)
        return 1
    n = len(res.name)
    np.set_printoptions(precision=4, suppress=True)
    print(res.success, res.message or 'ok', list(res.name))
    print('D =\n', np.reshape(res.mass_matrix, (n, n)))
    print('C =\n', np.reshape(res.coriolis_matrix, (n, n)))
    print('g =', np.array(res.gravity))
    return 0 if res.success else 1


if __name__ == '__main__':
    sys.exit(main())
