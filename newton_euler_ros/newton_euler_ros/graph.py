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
The closed loop's wiring, without ROS: one place for its remaps.

The nodes use relative (``joint_states``, ``wrench``) or private
(``~/commands``) names; a graph connects them by remapping.  The closed
loop of the demo is robot_sim_node -> inverse_dynamics_node ->
tracking_controller_node -> robot_sim_node, with the nodes' default
names; ``launch/closed_loop.launch.py`` and ``newton_euler_tools.demo``
both take its remaps from here, and the inverse-dynamics launch files
their remappable topics.
"""
SIM = '/robot_sim_node'
ID = '/inverse_dynamics_node'


def controller_remaps(sim, commands):
    """
    (from, to) remaps of tracking_controller_node closing a loop.

    ``sim`` is the plant node's name (its ``start`` service), ``commands``
    the topic that takes the controller's torques.
    """
    return (
        ('~/start', f'{sim}/start'),
        ('~/feedforward', f'{ID}/torques'),
        ('~/reference', f'{ID}/reference'),
        ('~/commands', commands),
    )


#: (from, to) remaps of tracking_controller_node in the closed loop
CONTROLLER_REMAPS = controller_remaps(SIM, f'{SIM}/commands')

# the same loop with MuJoCo as the plant (mujoco_sim_node), which takes
# efforts where ros2_control's effort forward controller does
MUJOCO_SIM = '/mujoco_sim_node'
EFFORT_COMMANDS = '/effort_controller/commands'
MUJOCO_CONTROLLER_REMAPS = controller_remaps(MUJOCO_SIM, EFFORT_COMMANDS)


#: (name in the node, launch argument, default, description) of the topics
#: inverse_dynamics_node's launch files let a graph remap
INVERSE_DYNAMICS_TOPICS = (
    ('joint_states', 'joint_states', 'joint_states',
     'sensor_msgs/JointState input'),
    ('wrench', 'wrench', 'wrench', 'geometry_msgs/WrenchStamped input'),
    ('~/torque_command', 'torque_command',
     'inverse_dynamics_node/torque_command',
     'topic of the Float64MultiArray command, e.g. '
     '/effort_controller/commands'),
)
#: the same, for a node that reads its robot from the URDF
URDF_TOPICS = (('robot_description', 'robot_description',
                'robot_description',
                'std_msgs/String URDF (reliable, transient local)'),
               ) + INVERSE_DYNAMICS_TOPICS


def ros_args(remaps):
    """Return ``remaps`` as command-line arguments: ['-r', 'a:=b', ...]."""
    return [arg for name, target in remaps
            for arg in ('-r', f'{name}:={target}')]
