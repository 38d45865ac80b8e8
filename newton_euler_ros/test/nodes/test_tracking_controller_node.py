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
tracking_controller_node's names: relative or private, wired by remaps.

Started in a namespace without remaps, every topic of the node lies in
that namespace (nothing hard-coded absolute); with the closed loop's
remaps (:data:`newton_euler_ros.graph.CONTROLLER_REMAPS`, which the
launch file and the demo use) its endpoints are the simulator's and the
inverse-dynamics node's topics.
"""
import ast
import os
import sys

from newton_euler_ros import graph
from newton_euler_ros.graph import CONTROLLER_REMAPS, ros_args
import pytest

pytest.importorskip('rclpy')

from ros_harness import domain_id, NodeProcess, PACKAGE_DIR, Probe  # noqa: E402, I100

pytestmark = pytest.mark.ros

NODE = 'tracking_controller_node'


def node_cmd(*args):
    script = os.path.join(os.path.dirname(sys.executable), NODE)
    base = [script] if os.path.exists(script) else [
        sys.executable, '-m', f'newton_euler_ros.nodes.{NODE}']
    return base + ['--ros-args', '-p', 'scene:=puma_payload_press', *args]


def endpoints(probe, namespace):
    """Return ({published topic}, {subscribed topic}) of the node."""
    node = probe.node
    try:
        pubs = node.get_publisher_names_and_types_by_node(NODE, namespace)
        subs = node.get_subscriber_names_and_types_by_node(NODE, namespace)
    except Exception:       # not discovered yet
        return set(), set()
    return {name for name, _ in pubs}, {name for name, _ in subs}


def own(topics):
    """Drop the topics every node has."""
    return {t for t in topics
            if not t.endswith(('/rosout', '/parameter_events'))}


@pytest.mark.parametrize('namespace, remap, published, subscribed', [
    ('/arm', False,
     {'/arm/tracking_controller_node/commands',
      '/arm/tracking_controller_node/reference'},
     {'/arm/tracking_controller_node/start',
      '/arm/tracking_controller_node/feedforward'}),
    ('/', True,
     {'/robot_sim_node/commands', '/inverse_dynamics_node/reference'},
     {'/robot_sim_node/start', '/inverse_dynamics_node/torques'}),
], ids=['namespace', 'remapped'])
def test_names_are_relative_or_private(tmp_path, namespace, remap,
                                       published, subscribed):
    args = (['-r', f'__ns:={namespace}'] if namespace != '/' else []) + (
        ros_args(CONTROLLER_REMAPS) if remap else [])
    domain = domain_id(87)
    node = NodeProcess(node_cmd(*args), domain, str(tmp_path / 'node.log'))
    probe = Probe(domain)
    try:
        assert probe.spin_until(
            lambda: published <= own(endpoints(probe, namespace)[0])
            and subscribed <= own(endpoints(probe, namespace)[1]), 60.0), \
            (endpoints(probe, namespace), node.log())
        pubs, subs = (own(e) for e in endpoints(probe, namespace))
        assert pubs == published, node.log()
        assert subs - subscribed <= {f'{namespace.rstrip("/")}/'
                                     'joint_states'}, node.log()
    finally:
        probe.close()
        status = node.stop()
    assert status == 0, node.log()


@pytest.mark.parametrize('launch_file, names', [
    ('closed_loop.launch.py', ('CONTROLLER_REMAPS',)),
    ('inverse_dynamics.launch.py', ('INVERSE_DYNAMICS_TOPICS',)),
    ('inverse_dynamics_urdf.launch.py', ('URDF_TOPICS',)),
    ('whole_robot.launch.py', ('URDF_TOPICS',)),
])
def test_launch_files_take_their_wiring_from_graph(launch_file, names):
    """The launch files' remaps come from graph.py, written once there."""
    path = os.path.join(PACKAGE_DIR, 'launch', launch_file)
    tree = ast.parse(open(path).read())
    imported = {alias.name for n in ast.walk(tree)
                if isinstance(n, ast.ImportFrom)
                and n.module == 'newton_euler_ros.graph'
                for alias in n.names}
    assert set(names) <= imported
    remappings = [kw.value for n in ast.walk(tree) if isinstance(n, ast.Call)
                  for kw in n.keywords if kw.arg == 'remappings']
    assert len(remappings) == 1
    assert all(name in ast.dump(remappings[0]) for name in names)
    # no topic is named in the file itself
    for name, _, default, _ in graph.URDF_TOPICS:
        assert repr(name) not in ast.unparse(tree), name


def test_graph_topics_are_the_nodes_defaults():
    """Every remappable topic's default is the node's own name for it."""
    for name, _, default, _ in graph.URDF_TOPICS:
        assert default == name.replace('~', 'inverse_dynamics_node')


@pytest.mark.parametrize('feedforward, sim_time', [
    (False, False), (True, False), (True, True)],
    ids=['pd', 'feedforward', 'feedforward-sim-time'])
def test_subscribes_to_joint_states_once_its_peers_are_matched(
        tmp_path, feedforward, sim_time):
    """
    The handshake that lets a simulator start its clock in time.

    robot_sim_node waits for its joint_states subscribers; the controller
    is one only once ~/commands has ``wait_for_subscribers`` matched
    subscribers (and, with feedforward, ~/feedforward and ~/reference are
    matched too), so the simulator never starts before it can be heard.
    With ``use_sim_time`` (the MuJoCo plant's graph) ROS time stands
    still until the plant's first /clock, which itself waits for this
    subscription: the handshake must not wait on ROS time.
    """
    from sensor_msgs.msg import JointState
    from std_msgs.msg import Float64MultiArray
    from trajectory_msgs.msg import JointTrajectory
    domain = domain_id(91)
    node = NodeProcess(node_cmd('-p', f'feedforward:={str(feedforward)}',
                                '-p', 'wait_for_subscribers:=2',
                                '-p', f'use_sim_time:={str(sim_time)}',
                                *ros_args(CONTROLLER_REMAPS)),
                       domain, str(tmp_path / 'node.log'))
    probe = Probe(domain)
    other = Probe(domain, name='probe2')
    try:
        def subscribed():
            return '/joint_states' in endpoints(probe, '/')[1]

        assert probe.spin_until(
            lambda: '/robot_sim_node/commands' in endpoints(probe, '/')[0],
            60.0), node.log()
        probe.collect(Float64MultiArray, '/robot_sim_node/commands')
        probe.spin_for(1.0)
        assert not subscribed(), 'one of two command subscribers'
        other.collect(Float64MultiArray, '/robot_sim_node/commands')
        if feedforward:
            probe.spin_for(1.0)
            assert not subscribed(), 'no inverse-dynamics node yet'
            probe.publisher(JointState, '/inverse_dynamics_node/torques')
            probe.collect(JointTrajectory, '/inverse_dynamics_node/reference')
        assert probe.spin_until(subscribed, 10.0), node.log()
        # the log line follows the subscription (CI read the log between
        # the two once)
        assert probe.spin_until(lambda: 'peers matched' in node.log(),
                                10.0), node.log()
    finally:
        other.close()
        probe.close()
        status = node.stop()
    assert status == 0, node.log()
