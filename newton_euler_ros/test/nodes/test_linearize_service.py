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
inverse_dynamics_node's ~/linearize over DDS, against the library.

One node process (the Puma, its output order shuffled, a wrench that
does not expire); this process publishes a joint state and a wrench and
calls the service: A, B, the discrete pair, tau0 and qdd0 against
``core.linearize.state_space`` in the node's order, the latest measured
state for an empty request, and the refusals (a joint missing, named; a
NaN; effort and acceleration both given; a negative time step).  Then
the handler without ROS: a robot that adds gravity itself (u without
g(q)), a scene's friction and rotor inertia, a scene without the
velocity products refused.
"""
import math
import warnings

import numpy as np
import pytest

pytest.importorskip('rclpy')

# After the skip: pytest must be imported first, hence E402 and I100.
from geometry_msgs.msg import WrenchStamped  # noqa: E402, I100
from newton_euler_interfaces.srv import Linearize  # noqa: E402
from newton_euler_ros.core import load_robot  # noqa: E402
from newton_euler_ros.core.linearize import state_space  # noqa: E402
from ros_harness import (domain_id, id_node_cmd, joint_state,  # noqa: E402
                         NodeProcess, Probe, wrench)
from sensor_msgs.msg import JointState  # noqa: E402

pytestmark = pytest.mark.ros

NODE = '/inverse_dynamics_node'
OUTPUT = ['joint3', 'joint1', 'joint2', 'joint6', 'joint4', 'joint5']
PERM = [2, 0, 1, 5, 3, 4]           # model index of each output joint
X = PERM + [6 + k for k in PERM]    # x = (q, qd) in the output order
WRENCH = [4.0, -3.0, 10.0, 0.5, -0.2, 0.1]   # base axes, on the tool
Q = np.array([0.1, 0.5, -0.3, 0.2, 0.4, -0.6])
QD = np.array([0.3, -0.2, 0.4, 0.1, -0.5, 0.2])


@pytest.fixture(scope='module')
def model():
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot('puma560')


@pytest.fixture(scope='module')
def probe(tmp_path_factory):
    domain = domain_id(23)
    node = NodeProcess(
        id_node_cmd('puma560.yaml', '-p', f'joints:=[{",".join(OUTPUT)}]',
                    '-p', 'wrench.timeout:=0.0'),
        domain, str(tmp_path_factory.mktemp('node') / 'node.log'))
    p = Probe(domain)
    try:
        # no joint state yet: an empty request is refused, and answered
        res = p.call(Linearize, f'{NODE}/linearize', Linearize.Request(),
                     timeout=90.0)
        assert not res.success and 'no joint state' in res.message, \
            res.message
        torques = p.collect(JointState, f'{NODE}/torques')
        js = p.publisher(JointState, 'joint_states')
        wr = p.publisher(WrenchStamped, 'wrench')
        assert p.spin_until(lambda: js.get_subscription_count() > 0 and
                            wr.get_subscription_count() > 0, 20.0)
        stamp = p.node.get_clock().now().to_msg()
        wr.publish(wrench('base_link', WRENCH, stamp))
        p.spin_for(0.3)
        js.publish(joint_state([f'joint{k}' for k in range(1, 7)], Q, QD,
                               stamp))
        assert p.spin_until(lambda: torques, 10.0), node.log()
        p.node_log = node.log
        yield p
    finally:
        p.close()
        node.stop()


def call(probe, **fields):
    return probe.call(Linearize, f'{NODE}/linearize',
                      Linearize.Request(**fields))


def in_output_order(lin):
    """Return A, B, Ad, Bd, tau0, qdd0 of the library in the node's order."""
    return (lin.A[np.ix_(X, X)], lin.B[np.ix_(X, PERM)],
            None if lin.Ad is None else lin.Ad[np.ix_(X, X)],
            None if lin.Bd is None else lin.Bd[np.ix_(X, PERM)],
            lin.tau0[PERM], lin.qdd0[PERM])


def check(res, lin, dt):
    assert res.success, res.message
    assert list(res.name) == OUTPUT
    A, B, Ad, Bd, tau0, qdd0 = in_output_order(lin)
    np.testing.assert_allclose(np.reshape(res.state_matrix, (12, 12)), A,
                               rtol=1e-12, atol=1e-12 * np.abs(A).max())
    np.testing.assert_allclose(np.reshape(res.input_matrix, (12, 6)), B,
                               rtol=1e-12, atol=1e-12 * np.abs(B).max())
    if dt:
        np.testing.assert_allclose(
            np.reshape(res.discrete_state_matrix, (12, 12)), Ad,
            rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(
            np.reshape(res.discrete_input_matrix, (12, 6)), Bd,
            rtol=1e-12, atol=1e-12 * np.abs(Bd).max())
    else:
        assert not res.discrete_state_matrix
        assert not res.discrete_input_matrix
    np.testing.assert_allclose(res.effort, tau0, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(res.acceleration, qdd0, rtol=1e-12,
                               atol=1e-12)


def test_a_b_and_the_discrete_pair_are_the_librarys(probe, model):
    names = list(reversed(model.joint_names))
    q, qd = np.array([0.4, -0.2, 0.7, 0.0, 0.3, 0.5]), np.full(6, 0.2)
    tau = np.array([1.0, 20.0, -5.0, 0.1, -0.2, 0.05])
    res = call(probe, name=names, position=q[::-1].tolist(),
               velocity=qd[::-1].tolist(), effort=tau[::-1].tolist(),
               time_step=0.002)
    check(res, state_space(model, q, qd, tau=tau, dt=0.002,
                           wrench=np.array(WRENCH)), 0.002)
    qdd = np.linspace(-1.0, 1.0, 6)
    res = call(probe, name=names, position=q[::-1].tolist(),
               acceleration=qdd[::-1].tolist())
    check(res, state_space(model, q, np.zeros(6), qdd=qdd,
                           wrench=np.array(WRENCH)), 0.0)


def test_an_empty_request_is_the_latest_measured_state(probe, model):
    res = call(probe, time_step=0.01)
    check(res, state_space(model, Q, QD, dt=0.01, wrench=np.array(WRENCH)),
          0.01)
    np.testing.assert_allclose(res.acceleration, 0.0, atol=1e-12)


def test_bad_requests_are_refused_with_the_reason(probe, model):
    names = list(model.joint_names)
    zeros = [0.0] * 6
    for fields, reason in (
            ({'name': names[:5], 'position': zeros[:5]},
             "missing joints ['joint6']"),
            ({'name': names, 'position': zeros[:5] + [math.nan]},
             "position of 'joint6' is nan"),
            ({'name': names, 'position': zeros, 'effort': zeros,
              'acceleration': zeros}, 'effort and acceleration both given'),
            ({'name': names, 'position': zeros, 'effort': zeros[:4]},
             'effort has 4 entries for 6 names'),
            ({'time_step': -0.01}, 'time_step must be finite and >= 0'),
            ({'time_step': math.inf}, 'time_step must be finite')):
        res = call(probe, **fields)
        assert not res.success and reason in res.message, (fields,
                                                           res.message)
        assert not res.state_matrix and not res.effort
    # and good requests work afterwards; nothing was an internal error
    assert call(probe).success
    assert 'internal error' not in probe.node_log()


# ---- the handler without ROS: what the node's settings change ----

def computer(model=None, scene=None, **kwargs):
    from newton_euler_ros.feedforward import FeedforwardComputer
    from newton_euler_ros.joint_inputs import JointOrder
    from newton_euler_ros.wrenches import WrenchInput
    names = (scene.model if model is None else model).joint_names
    return FeedforwardComputer(model, JointOrder(names), WrenchInput([], []),
                               None, scene, **kwargs)


def test_a_robot_that_adds_gravity_is_linearised_without_it(model):
    """robot_compensates_gravity: u is the torque sent, without g(q)."""
    from newton_euler_ros.nodes.linearize_service import linearize
    ff = computer(model, robot_compensates_gravity=True)
    names = list(model.joint_names)
    lin = linearize(ff, names, Q, QD, [], [], 0.0, 0.0)
    want = state_space(model, Q, QD, gravity=False)
    np.testing.assert_allclose(lin.A, want.A, rtol=1e-12, atol=1e-12)
    # the torque the node would send for qdd = 0: g(q) left out
    D, C, g, tau = ff.terms(names, Q, QD, [], 0.0)
    np.testing.assert_allclose(lin.tau0, tau, rtol=1e-12, atol=1e-12)


def test_a_scenes_friction_and_rotor_inertia_join_the_dynamics():
    from newton_euler_ros.nodes.linearize_service import linearize
    from newton_euler_ros.sim.scene import load_scene
    press = load_scene('puma_payload_press')     # friction, rotor inertia
    ff = computer(scene=press)
    names = list(press.model.joint_names)
    qdd = np.linspace(-1.0, 1.0, 6)
    qd = np.array([0.3, -0.3, 0.4, 0.25, -0.5, 0.3])
    lin = linearize(ff, names, Q, qd, [], qdd, 0.0, 0.0)
    # the node's own torque at the point: its Coulomb friction is
    # F_c sign(qd), here F_c tanh(qd / 0.02), equal 12 widths from rest
    D, C, g, tau = ff.terms(names, Q, qd, qdd, 0.0)
    np.testing.assert_allclose(lin.tau0, tau, rtol=1e-9, atol=1e-9)
    # dqdd/dtau = (D + I_a)^-1 and dqdd/dqd has the viscous term
    np.testing.assert_allclose(lin.B[6:] @ D, np.eye(6), atol=1e-9)
    bare = state_space(ff.model, Q, qd, qdd=qdd)
    assert np.abs(lin.A[6:, 6:] - bare.A[6:, 6:]).max() > 0.1
    slow = load_scene('panda_slow_earth')        # no velocity products
    ff = computer(scene=slow)
    with pytest.raises(Exception, match='leaves out the velocity products'):
        linearize(ff, [], [], [], [], [], 0.0, 0.0)
