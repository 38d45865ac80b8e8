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
mujoco_sim_node: a robot simulated by MuJoCo, driven by effort commands.

The independent plant (docs/node.md, "mujoco_sim_node"): the robot of
``robot_file`` (a URDF, an MJCF file, a robot YAML file or a bundled
name), or of the latched ``robot_description`` when it is empty, is
compiled by MuJoCo's own reader (:mod:`..sim.mujoco_model`: damping,
Coulomb friction and armature from the URDF, effort limits as the motors'
force ranges, mimic joints as equality constraints).  Every tick advances
it by 1 / ``rate`` of simulated time in physics steps of ``timestep``,
holding the last command (zero-order hold), then publishes the state
stamped in simulated time, and ``/clock``, so the graph can run on
``use_sim_time``.  The ticks are paced by the wall clock at
``real_time_factor`` (0: as fast as the machine can).

With ``scene`` (a scene file or bundled scene, docs/mujoco.md), the
scene makes the plant (:func:`..sim.mujoco_scene.scene_plant`): its
robot, initial state, physics step and integrator, its effects (gravity,
payload, friction, rotor inertia, the wrench's reaction) and its
``contacts`` (floor, table, pusher).  With ``wait_for_subscribers`` N,
simulated time stays at 0 (no tick) until joint_states has N matched
subscribers; the latched ``~/start`` then carries the stamp of t = 0 (a
controller's reference starts there).

Until the first valid command the arm holds its initial pose, brakes on,
as a real arm does before its controller starts (time runs, nothing
moves); the log says when the brakes are released.  A command of the
wrong length or with NaN or inf is ignored and counted.  When no new
command has come for ``command_timeout`` seconds of simulated time the
efforts are zero, said once in the log (and again once when commands
resume).

Contact wrenches: for each link in contact, one
``geometry_msgs/WrenchStamped`` per tick on
``~/contact_wrenches/<link>`` (one publisher per link of the robot,
created at start; a link name's characters that a topic cannot hold
become ``_``): the wrench the environment applies to the link, force
and moment in world axes, the moment about the link's origin (the sign,
axes and point of the momentum observer's estimate);
``header.frame_id`` is the robot's root link, whose axes are the world's
(a URDF's base is fixed at the world origin), or ``world`` when an MJCF
model's root body is turned.  The tick a link leaves contact it gets one
zero wrench, so that a reader's last value is right.

Sensor noise: ``noise.position``, ``noise.velocity`` and
``noise.effort`` are the standard deviations of Gaussian noise added to
what joint_states carries for the commanded joints, drawn every tick
from a generator seeded with ``noise.seed``, as a driver's encoders,
velocity estimate and torque readings have it; the plant itself is
not touched.  All zero (the default): MuJoCo's state exactly.

With ``lockstep``, once the brakes are released a tick advances only
when a valid command came after the last joint state (a controller
answering each state at the driver's rate, its deadline always met);
while the brakes hold, the ticks come at most 20 a second of wall clock
(``HELD_PACE``), so that a graph answering each state keeps up with them;
after ``command_timeout`` seconds of wall clock without one the ticks go
on without waiting until the next command.  With ``real_time_factor``
0 as well, each command ticks at once: the loop runs as fast as the
plant and its controller can answer each other.

Subscribes
    effort_controller/commands (std_msgs/Float64MultiArray: one effort
    per joint of ``joints``, N m or N; what ros2_control's effort forward
    controller takes), robot_description (std_msgs/String, transient
    local, only when robot_file is empty)
Publishes
    joint_states (sensor_msgs/JointState: position, velocity and effort =
    the torque the motors applied; mimic followers after the commanded
    joints, effort 0), /clock (rosgraph_msgs/Clock: simulated time, every
    tick), ~/start (std_msgs/Header, transient local: the stamp of
    t = 0), wrench (geometry_msgs/WrenchStamped: a scene's wrench,
    every tick, as robot_sim_node publishes it),
    ~/contact_wrenches/<link> (geometry_msgs/WrenchStamped, see above),
    /diagnostics (diagnostic_msgs/DiagnosticArray, every second: commands
    received, bad commands ignored, stale periods, the real-time
    factor achieved, whether the brakes hold)
"""
import math
import re
import sys
import time

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import WrenchStamped
import numpy as np
from rclpy.clock import Clock, ClockType
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock as ClockMsg
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray, Header, String

from .common import (ConfigurationError, declare_parameters, qos_profile,
                     QUIET, release_memory, run_node, SharedGraphNode)
from .robot_sim_node import FRAME_IDS, publish_wrench
from ..core import NewtonEulerError
from ..core.text import clip
from ..parameters import load_specs

NAME = 'mujoco_sim_node'
DIAGNOSTICS_PERIOD = 1.0    # wall-clock seconds between /diagnostics
WARN_PERIOD = 2.0           # wall-clock seconds between bad-command logs
#: lockstep, brakes on: wall-clock seconds at least between two ticks.
#: Nothing paces those ticks (no command comes until the controller
#: answers), and a graph that answers each state (a controller waiting
#: for each state's feedforward) can fall behind them for good.
HELD_PACE = 0.05
# robot_state_publisher's QoS for robot_description: a late subscriber
# still gets the last description, but only with the same durability
DESCRIPTION_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)


def stamp(t):
    """Return a builtin_interfaces/Time of ``t`` seconds."""
    ns = int(round(t * 1e9))
    return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def topic_token(name):
    """Return a link name as one token of a ROS topic name."""
    token = re.sub(r'_+', '_', re.sub(r'[^A-Za-z0-9_]', '_', name))
    token = token.strip('_') or 'link'
    return f'_{token}' if token[0].isdigit() else token


def load_plant(source, params, label=None):
    """
    Compile ``source`` and put it at its initial pose: a MujocoPlant.

    Raises ConfigurationError naming the parameter at fault.
    """
    from ..sim.mujoco_model import load_mujoco
    from ..sim.mujoco_plant import MujocoPlant
    try:
        robot = load_mujoco(source, joints=params['joints'] or None,
                            label=label, timestep=params['timestep'])
    except (NewtonEulerError, ValueError, OSError) as exc:
        key = 'robot_file' if label is None else 'robot_description'
        raise ConfigurationError(f'{key}: {clip(str(exc), 400)}') from None
    q0 = params['initial_positions']
    if q0 and len(q0) != robot.n:
        raise ConfigurationError(
            f'initial_positions: {robot.n} values expected, one per joint '
            f'of {", ".join(robot.joints)}; got {len(q0)}')
    try:
        return MujocoPlant(robot, q0 or None)
    except ValueError as exc:
        raise ConfigurationError(f'initial_positions: {exc}') from None


def scene_plant_of(params):
    """Return (MujocoPlant, scene) of the ``scene`` parameter."""
    from ..sim.mujoco_scene import scene_plant
    from ..sim.scene import load_scene
    for key, default in (('robot_file', ''), ('joints', []),
                         ('initial_positions', []), ('timestep', 0.001)):
        if params[key] not in (default, [], ()):
            raise ConfigurationError(
                f'{key}: the scene gives it; leave it unset with scene')
    try:
        scene = load_scene(params['scene'])
        plant = scene_plant(scene)
    except (NewtonEulerError, ValueError, OSError) as exc:
        raise ConfigurationError(f'scene: {clip(str(exc), 400)}') from None
    plant.hold()
    return plant, scene


class MujocoSimNode(SharedGraphNode):
    """MuJoCo plant: efforts in, joint states, /clock and contacts out."""

    def __init__(self, **kwargs):
        super().__init__(NAME, **kwargs)
        self.specs = load_specs(NAME)
        p = self.params = declare_parameters(self, self.specs)
        self.plant = None
        self.subscribers = p['wait_for_subscribers']
        self.started = False
        self.rtf = p['real_time_factor']
        self.timeout = p['command_timeout']
        self.wall = Clock(clock_type=ClockType.STEADY_TIME)
        # counters, in /diagnostics and in the last log line
        self.received = 0       # valid commands
        self.bad = 0            # wrong length, NaN or inf: ignored
        self.early = 0          # before a robot_description has loaded
        self.stale_periods = 0
        self.stale = False
        self.tau = None
        self.commanded = False  # a valid command has come: brakes off
        self.last_command = 0.0     # its simulated time
        self._last_warn = -math.inf
        self._window = None     # (wall, simulated) time of the last report
        self.achieved = float('nan')
        self.in_contact = set()
        self.contact_pubs = {}
        # the sensors' noise: standard deviations, None when all zero
        sigma = [p[f'noise.{k}'] for k in ('position', 'velocity', 'effort')]
        self.noise = sigma if any(sigma) else None
        self._rng = np.random.default_rng(p['noise.seed'])
        self.lockstep = p['lockstep']
        self.fresh = False      # a valid command since the last state
        self._waiting = None    # wall time a lockstep wait began
        self._held_tick = -math.inf     # wall time of the last held tick

        qos = qos_profile(100, 'reliable')
        self.state_pub = self.create_publisher(JointState, 'joint_states',
                                               qos, event_callbacks=QUIET)
        self.clock_pub = self.create_publisher(ClockMsg, '/clock',
                                               qos_profile(10, 'reliable'),
                                               event_callbacks=QUIET)
        self.diag_pub = self.create_publisher(DiagnosticArray,
                                              '/diagnostics', 10,
                                              event_callbacks=QUIET)
        self.create_subscription(Float64MultiArray,
                                 'effort_controller/commands',
                                 self._on_command, qos)
        self.create_timer(DIAGNOSTICS_PERIOD, self._on_diagnostics,
                          clock=self.wall)
        self.start_pub = self.create_publisher(Header, '~/start',
                                               DESCRIPTION_QOS)
        self.scene = self.wrench_pub = None
        if p['scene']:
            plant, self.scene = scene_plant_of(p)
            wrench = self.scene.wrench
            if self.scene.effects.wrench and wrench.kind != 'topic':
                # the scene's wrench, as a force/torque sensor reads it:
                # the inverse-dynamics node takes it from this topic
                self.wrench_pub = self.create_publisher(
                    WrenchStamped, 'wrench', qos, event_callbacks=QUIET)
                self._scene_wrench = WrenchStamped()
                self._scene_wrench.header.frame_id = FRAME_IDS[wrench.frame]
            self._start(plant)
        elif p['robot_file']:
            self._start(load_plant(p['robot_file'], p))
        else:
            self.create_subscription(String, 'robot_description',
                                     self._on_description, DESCRIPTION_QOS)
            self.get_logger().info(
                'no robot_file: waiting for the robot_description topic; '
                'publishing nothing until it arrives')

    # ---- start-up ----
    def _start(self, plant):
        """Publish and tick from now on: the plant is ready."""
        robot = self.plant_robot = plant.robot
        m = plant.model
        self.names = list(robot.joints) + [f[0] for f in robot.followers]
        self._follow_q = np.array([f[1] for f in robot.followers],
                                  dtype=np.intp)
        self._follow_v = np.array([f[2] for f in robot.followers],
                                  dtype=np.intp)
        self._zero = np.zeros(robot.n)
        self._zero_followers = [0.0] * len(robot.followers)
        self.tau = self._zero.copy()
        rate = self.scene.rate if self.scene else self.params['rate']
        steps = max(1, int(round(1.0 / rate / m.opt.timestep)))
        self.period = steps * m.opt.timestep
        # the frame of the contact wrenches' axes: the world's, named by
        # the robot's root link when that has the world's axes (a URDF's
        # always has: its base is fixed at the world origin)
        self.base = 'world'
        if m.nbody > 1 and m.body_parentid[1] == 0 and np.allclose(
                plant.data.xquat[1], [1.0, 0.0, 0.0, 0.0], atol=1e-12):
            self.base = m.body(1).name
        self._state = JointState()
        self._state.name = self.names
        self._clock_msg = ClockMsg()
        self._wrench = WrenchStamped()
        self._wrench.header.frame_id = self.base
        self._contact_topics(plant)
        log = self.get_logger().info
        log(f'robot: {robot.label}, {robot.n} commanded joints'
            + (f', {len(robot.followers)} mimic followers'
               if robot.followers else ''))
        log(f'joints: {", ".join(self.names)}')
        log(f'timestep: {m.opt.timestep:g} s physics, {steps} step(s) per '
            f'tick')
        log(f'rate: {1.0 / self.period:g} Hz of simulated time, real-time '
            f'factor {self.rtf:g}'
            + (' (as fast as it can)' if self.rtf == 0.0 else ''))
        if self.noise is not None:
            log('sensor noise (standard deviations): position '
                f'{self.noise[0]:g}, velocity {self.noise[1]:g}, effort '
                f'{self.noise[2]:g}; seed {self.params["noise.seed"]}')
        for note in robot.notes:
            log(f'note: {note}')
        log('holding the initial pose (brakes on) until the first command '
            'on effort_controller/commands')
        self.plant = plant
        self._window = (time.monotonic(), plant.time)
        wall_period = 0.0 if self.rtf == 0.0 else self.period / self.rtf
        # lockstep as fast as it can: the commands drive the ticks, the
        # timer only the brakes' time and the end of a wait
        self._driven = self.lockstep and self.rtf == 0.0
        if self._driven:
            wall_period = self.period
        self.create_tick_timer(wall_period, self._tick, clock=self.wall)

    def _contact_topics(self, plant):
        """Create one contact-wrench publisher per link of the robot."""
        m = plant.model
        robot_bodies = plant._robot_bodies()
        for b in range(1, m.nbody):
            if robot_bodies[b]:
                self._contact_pub(m.body(b).name)

    def _contact_pub(self, link):
        pub = self.contact_pubs.get(link)
        if pub is None and link not in self.contact_pubs:
            topic = f'~/contact_wrenches/{topic_token(link)}'
            try:
                pub = self.create_publisher(WrenchStamped, topic, 10,
                                            event_callbacks=QUIET)
            except Exception as exc:    # an odd name: say it, go on
                self.get_logger().warning(
                    f'link {link!r}: no contact-wrench topic: '
                    f'{clip(str(exc), 200)}')
            self.contact_pubs[link] = pub
        return pub

    def _on_description(self, msg):
        if self.plant is not None:
            self.get_logger().warning(
                'robot_description: a new description is ignored while the '
                'plant runs (restart the node to simulate another robot)')
            return
        try:
            plant = load_plant(msg.data, self.params, 'robot_description')
        except ConfigurationError as exc:
            self.get_logger().error(f'{exc}; still waiting for a '
                                    f'robot_description')
            return
        except Exception as exc:    # never let a message kill the node
            self.get_logger().error(
                f'robot_description rejected: internal error: '
                f'{clip(str(exc), 300)}; still waiting')
            return
        self._start(plant)

    # ---- commands ----
    def _on_command(self, msg):
        if self.plant is None:
            self.early += 1
            return
        data = np.asarray(msg.data, dtype=float)
        if data.shape != self.tau.shape or not np.isfinite(data).all():
            self.bad += 1
            now = time.monotonic()
            if now - self._last_warn >= WARN_PERIOD:
                self._last_warn = now
                what = ('not finite' if data.shape == self.tau.shape
                        else f'{data.size} values')
                self.get_logger().warning(
                    f'command ignored: {self.tau.size} finite efforts '
                    f'expected ({", ".join(self.plant_robot.joints)}), got '
                    f'{what} ({self.bad} ignored so far)')
            return
        self.received += 1
        self.tau = data
        self.fresh = True
        if self._waiting is False:
            self.get_logger().info('lockstep resumed')
        self._waiting = None
        if self._driven and self.started and not self.plant.held:
            self._tick()
        self.last_command = self.plant.time
        if self.stale:
            self.stale = False
            self.get_logger().info(
                f'commands resumed at t = {self.plant.time:.3f} s')
        if not self.commanded:
            self.commanded = True

    # ---- the tick ----
    def _tick(self):
        plant = self.plant
        if not self.started:
            if self.state_pub.get_subscription_count() < self.subscribers:
                return      # t = 0 held until the graph is there
            self.started = True
            self.start_pub.publish(Header(stamp=stamp(plant.time),
                                          frame_id='sim_start'))
            self.get_logger().info(
                f'simulation starts (t = {plant.time:g} s; joint_states '
                f'has {self.state_pub.get_subscription_count()} '
                f'subscribers)')
        if plant.held and self.commanded:
            plant.release()
            self.get_logger().info(
                f'first command at t = {plant.time:.3f} s: brakes released')
        if self.lockstep:
            if plant.held:
                now = time.monotonic()
                if now - self._held_tick < HELD_PACE:
                    return
                self._held_tick = now
            elif not self._lockstep_ready():
                return
        self.fresh = False
        tau = self.tau
        if not plant.held and not self.stale and \
                plant.time - self.last_command >= self.timeout - 1e-9:
            self.stale = True
            self.stale_periods += 1
            self.get_logger().warning(
                f'no command for {self.timeout:g} s of simulated time '
                f'(t = {plant.time:.3f} s): zero effort until the next '
                f'one')
        if self.stale:
            tau = self._zero
        plant.advance(tau, self.period)
        self._publish(plant)

    def _lockstep_ready(self):
        """Return True when this tick may advance (fresh command, no wait)."""
        if self.fresh or self._waiting is False:
            return True
        now = time.monotonic()
        if self._waiting is None:
            self._waiting = now
        elif now - self._waiting >= self.timeout:
            self._waiting = False
            self.get_logger().warning(
                f'lockstep: no command for {self.timeout:g} s of wall '
                f'clock (t = {self.plant.time:.3f} s): ticking without '
                'waiting until the next one')
            return True
        return False

    def _publish(self, plant):
        now = stamp(plant.time)
        self._clock_msg.clock = now
        self.clock_pub.publish(self._clock_msg)
        if self.wrench_pub is not None:     # first: the torques need it
            publish_wrench(self.wrench_pub, self._scene_wrench, now,
                           self.scene.wrench.at(plant.time))
        q, qd = plant.state()
        effort = self._zero if plant.held else plant.applied()
        if self.noise is not None:
            q, qd, effort = self._sensed(q, qd, effort)
        msg = self._state
        msg.header.stamp = now
        if self._follow_q.size:
            d = plant.data
            msg.position = q.tolist() + d.qpos[self._follow_q].tolist()
            msg.velocity = qd.tolist() + d.qvel[self._follow_v].tolist()
            msg.effort = effort.tolist() + self._zero_followers
        else:
            msg.position = q.tolist()
            msg.velocity = qd.tolist()
            msg.effort = effort.tolist()
        self.state_pub.publish(msg)
        if plant.data.ncon or self.in_contact:
            self._publish_contacts(plant, now)

    def _sensed(self, q, qd, effort):
        """Return (q, qd, effort) with the sensors' Gaussian noise."""
        normal, n = self._rng.normal, q.size
        sp, sv, se = self.noise
        return (q + normal(0.0, sp, n), qd + normal(0.0, sv, n),
                effort + normal(0.0, se, n))

    def _publish_contacts(self, plant, now):
        wrenches = plant.contact_wrenches()
        zero = np.zeros(6)
        gone = self.in_contact - set(wrenches)
        self.in_contact = set(wrenches)
        for link, w in [*wrenches.items(), *((g, zero) for g in gone)]:
            pub = self._contact_pub(link)
            if pub is not None:
                publish_wrench(pub, self._wrench, now, w)

    # ---- diagnostics ----
    def _on_diagnostics(self):
        release_memory()
        status = DiagnosticStatus(name=f'{self.get_name()}: plant',
                                  hardware_id='mujoco')
        plant = self.plant
        if plant is None:
            status.level = DiagnosticStatus.WARN
            status.message = 'waiting for robot_description'
            values = {'commands before the robot': self.early}
        else:
            now, t = time.monotonic(), plant.time
            then, t0 = self._window
            if now > then:
                self.achieved = (t - t0) / (now - then)
            self._window = (now, t)
            status.hardware_id = plant.robot.label
            if plant.held:
                status.message = ('holding the initial pose (brakes on) '
                                  'until the first command')
            elif self.stale:
                status.level = DiagnosticStatus.WARN
                status.message = (f'no command for {self.timeout:g} s: '
                                  'zero effort')
            else:
                status.message = 'simulating'
            values = {'commands received': self.received,
                      'bad commands ignored': self.bad,
                      'stale periods': self.stale_periods,
                      'stale': self.stale,
                      'held': plant.held,
                      'simulated time': f'{t:.6f}',
                      'real-time factor': f'{self.achieved:.3f}',
                      'real-time factor asked': f'{self.rtf:g}',
                      'links in contact': ', '.join(sorted(self.in_contact))}
        status.values = [KeyValue(key=k, value=str(v).lower()
                                  if isinstance(v, bool) else str(v))
                         for k, v in values.items()]
        msg = DiagnosticArray(status=[status])
        msg.header.stamp = self.get_clock().now().to_msg()
        self.diag_pub.publish(msg)

    def destroy_node(self):
        """Log what the plant received, then destroy."""
        self.get_logger().info(
            f'commands received: {self.received} ({self.bad} bad commands '
            f'ignored, {self.stale_periods} stale periods)')
        return super().destroy_node()


def main(args=None):
    """Entry point of the ``mujoco_sim_node`` console script."""
    return run_node(MujocoSimNode, NAME, args)


if __name__ == '__main__':
    sys.exit(main())
