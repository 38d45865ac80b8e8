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
inverse_dynamics_node: joint states (and a wrench) in, torques out.

A thin adapter: messages are converted to numpy, the library computes, the
result is published (the ROS-free layer: ``feedforward``, built by
``feedforward_build``; the reports: ``inverse_dynamics_reports``; the
linearisation: ``linearize_service``).
docs/node.md describes the whole interface.  With a URDF and no tip_link
it serves the whole robot below base_link (a tree, mimic joints): joint
states from several drivers merged, wrenches at the links their frames
name (``whole_robot``, ``wrenches``; docs/node.md, "Whole robots").

Subscribes
    joint_states (sensor_msgs/JointState), wrench (geometry_msgs/
    WrenchStamped), ~/reference (trajectory_msgs/JointTrajectory, only
    with acceleration_source = reference), robot_description
    (std_msgs/String, reliable + transient local, only when neither
    scene nor robot_file is set)
    ~/trajectory_in (trajectory_msgs/JointTrajectory): a planned
    trajectory whose points get their effort filled
Publishes
    ~/torque_command (std_msgs/Float64MultiArray), ~/torques
    (sensor_msgs/JointState), ~/trajectory_out (trajectory_msgs/
    JointTrajectory), /diagnostics (diagnostic_msgs/DiagnosticArray);
    with observer.enabled: ~/external_torque (sensor_msgs/JointState),
    ~/external_wrench (geometry_msgs/WrenchStamped), ~/contact
    (std_msgs/Bool)
Serves
    ~/compute_dynamics (newton_euler_interfaces/srv/ComputeDynamics),
    ~/linearize (newton_euler_interfaces/srv/Linearize): A, B of the
    dynamics at a state, and their discrete pair
"""
import collections
import sys
import threading
import time

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import WrenchStamped
from newton_euler_interfaces.srv import ComputeDynamics, Linearize
from rcl_interfaces.msg import SetParametersResult
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray, String
from trajectory_msgs.msg import JointTrajectory

from .common import (check_parameters, ConfigurationError,
                     declare_parameters, KernelTimer, qos_profile, QUIET,
                     release_memory, run_node, seconds, SharedGraphNode)
from .inverse_dynamics_reports import (answer, diagnostics, failed,
                                       mimic_line, model_line,
                                       no_model_text, UpdateTimes)
from .linearize_service import answer_linearize
from .node_observer import NodeObserver
from ..core import inspect_robot, NewtonEulerError
from ..core.robot_file import Note
from ..core.text import clip
from ..core.urdf import urdf_model
from ..feedforward_build import (build_computer, check_payload,
                                 is_whole_robot, PAYLOAD)
from ..joint_inputs import InputRejected, REJECTIONS
from ..parameters import load_specs
from ..safety import BOUND_SOURCES, over_text, OverLimitLog
from ..sim.scene import load_scene
from ..wrenches import wrench_input

# the rejections' counters come from their one list (joint_inputs)
COUNTERS = ('published',) + REJECTIONS + (
    'expired', 'service_calls', 'service_failures', 'internal_error',
    'no_model', 'descriptions_loaded', 'descriptions_rejected',
    'trajectories', 'payload_changes', 'over_limit', 'held')
# robot_state_publisher's QoS for robot_description: a late subscriber
# still gets the last description, but only with the same durability
DESCRIPTION_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)


class InverseDynamicsNode(SharedGraphNode):
    """Feedforward torques from joint states, by Newton-Euler."""

    def __init__(self, **kwargs):
        super().__init__('inverse_dynamics_node', **kwargs)
        self.specs = load_specs()
        p = self.params = declare_parameters(self, self.specs)
        self.counts = dict.fromkeys(COUNTERS, 0)
        self.log_throttle = p['log_throttle']
        self._last_log = {}
        # the joints over their torque bound, said once per change
        self._over_log = collections.defaultdict(OverLimitLog)
        self.ff = None          # swapped whole when a new model arrives
        self.kernels = KernelTimer(self.get_logger())
        self.update_times = UpdateTimes()
        self.model_source = ''
        #: why the last robot_description was rejected ('' when it loaded)
        self.description_rejected = ''
        scene = None
        if p['mode'] in ('gravity', 'gravity_coriolis') and \
                p['acceleration_source'] == 'reference':
            raise ConfigurationError(
                f'acceleration_source: reference needs mode full (or an '
                f'empty mode), not {p["mode"]}')
        self.mode = p['mode'] or ('full' if p['acceleration_source'] ==
                                  'reference' else 'gravity_coriolis')
        self.payload = tuple(p[k] for k in PAYLOAD)
        if (p['base_link'] or p['tip_link']) and p['scene']:
            raise ConfigurationError('base_link/tip_link: not with scene '
                                     '(the scene names its robot)')
        try:
            if p['scene']:
                scene = load_scene(p['scene'])
                model, found, path = (scene.model, scene.warnings,
                                      scene.robot_path)
            elif p['robot_file']:
                model, found, path = inspect_robot(
                    p['robot_file'], base=p['base_link'] or None,
                    tip=p['tip_link'] or None)
            else:
                model = None
        except NewtonEulerError as exc:
            key = 'scene' if p['scene'] else 'robot_file'
            raise ConfigurationError(f'{key}: {exc}') from None
        if model is not None:
            for message in found:
                # notes on published data: `newton-euler check` shows them
                log = (self.get_logger().debug if isinstance(message, Note)
                       else self.get_logger().warning)
                log(f'robot file: {message}')
            try:
                self.kernels.start()
                self.ff = self._make_computer(model, scene)
            except ValueError as exc:
                raise ConfigurationError(str(exc)) from None
            self.model_source = path
        else:
            # wait for robot_state_publisher's description; parse it off
            # the executor thread, swap the computer in when it is ready
            self._description_lock = threading.Lock()
            self._description_seq = 0
            self.create_subscription(String, 'robot_description',
                                     self._on_description, DESCRIPTION_QOS)
            self.get_logger().info(
                'no robot_file or scene: waiting for the robot_description '
                'topic; publishing nothing until it arrives')

        qos = qos_profile(p['qos.depth'], p['qos.reliability'])
        self.cmd_pub = self.create_publisher(Float64MultiArray,
                                             '~/torque_command', qos,
                                             event_callbacks=QUIET)
        self.torque_pub = self.create_publisher(JointState, '~/torques', qos,
                                                event_callbacks=QUIET)
        self.create_subscription(JointState, 'joint_states',
                                 self._on_joint_state, qos)
        self.create_subscription(WrenchStamped, 'wrench', self._on_wrench,
                                 qos)
        if self.mode == 'full':
            self.create_subscription(JointTrajectory, '~/reference',
                                     self._on_reference, 10)
        self.traj_pub = self.create_publisher(JointTrajectory,
                                              '~/trajectory_out', 10,
                                              event_callbacks=QUIET)
        self.create_subscription(JointTrajectory, '~/trajectory_in',
                                 self._on_trajectory, 10)
        # a deep request queue: a burst of callers must not be dropped by
        # DDS before the node sees them (the default depth is 10)
        service_qos = QoSProfile(depth=p['service.depth'],
                                 reliability=ReliabilityPolicy.RELIABLE)
        self.create_service(ComputeDynamics, '~/compute_dynamics',
                            self._on_compute_dynamics, qos_profile=service_qos)
        self.create_service(Linearize, '~/linearize', self._on_linearize,
                            qos_profile=service_qos)
        if p['diagnostics_period'] > 0.0:
            self.diag_pub = self.create_publisher(DiagnosticArray,
                                                  '/diagnostics', 10,
                                                  event_callbacks=QUIET)
            self.create_timer(p['diagnostics_period'], self._publish_counts)
        self.add_on_set_parameters_callback(self._on_set_parameters)
        # reused messages: the hot path allocates no message objects
        self._cmd = Float64MultiArray()
        self._torques = JointState()
        if self.ff is not None:
            self._log_model(self.ff, self.model_source)
        self._observer = None
        if self.params['observer.enabled']:
            self._observer = NodeObserver(self, self.params, self.ff)
        if self.ff is not None:
            self.kernels.done()

    def _make_computer(self, model, scene=None, previous=None,
                       payload=None):
        """Build the computer of a model (``build_computer``); ValueError."""
        return build_computer(self.params, self.mode, model,
                              payload or self.payload, scene, previous)

    def _whole(self, model):
        """Say whether a model is a whole robot (a URDF tree, no tip link)."""
        return is_whole_robot(model, self.params['tip_link'])

    def _log_model(self, ff, source):
        self.get_logger().info(model_line(ff, source, self.mode,
                                          self.payload, self.params))
        mimic = mimic_line(ff)
        if mimic is not None:
            self.get_logger().info(mimic)

    # ---- robot_description ----
    def _on_description(self, msg):
        with self._description_lock:
            self._description_seq += 1
            seq = self._description_seq
        threading.Thread(target=self._load_description,
                         args=(msg.data, seq), daemon=True).start()

    def _load_description(self, text, seq):
        p = self.params
        try:
            model, found, report = urdf_model(
                text, 'robot_description', base=p['base_link'] or None,
                tip=p['tip_link'] or None)
            self.kernels.start()
            ff = self._make_computer(model)
            if self._observer is not None:
                # off the executor: a first message must not wait for
                # the observer's kernels (joint states would queue up)
                self._observer.warm_kernels(ff)
        except Exception as exc:  # never let a description kill the node
            reason = clip(str(exc), 400)
            if not isinstance(exc, (NewtonEulerError, ValueError)):
                reason = f'internal error: {reason}'
            self.counts['descriptions_rejected'] += 1
            with self._description_lock:
                if seq == self._description_seq:    # the newest one
                    self.description_rejected = reason
            keep = ('the previous model keeps working' if self.ff is not None
                    else 'still no model: publishing nothing')
            self.get_logger().error(
                f'robot_description rejected: {reason}; {keep}')
            return
        with self._description_lock:
            if seq != self._description_seq:
                return          # a newer description is on its way
            self.description_rejected = ''
            for message in found:
                log = (self.get_logger().debug if isinstance(message, Note)
                       else self.get_logger().warning)
                log(clip(message, 400))
            self.ff = ff        # one reference swap: callbacks see either
            self.kernels.done()
            self.counts['descriptions_loaded'] += 1
            self.model_source = (
                f'robot_description, {report["base"]} -> {report["tip"]}'
                if report['tip'] and not self._whole(model) else
                f'robot_description, the tree below {report["base"]}')
        self._log_model(ff, self.model_source)

    # ---- parameters ----
    def _on_set_parameters(self, params):
        values, errors = check_parameters(params, self.specs)
        if errors:
            return SetParametersResult(successful=False, reason=errors)
        # (an empty default is declared without a value: self.params has
        # what the node runs with)
        current = {s.name: values.get(s.name, self.params[s.name])
                   for s in self.specs if s.name.startswith('wrench.')}
        payload = tuple(values.get(k, self.params[k]) for k in PAYLOAD)
        ff = self.ff
        new_ff = None
        if ff is not None:
            try:
                new_wrench = wrench_input(current, ff.model,
                                          ff.guard.bounds,
                                          ff.merger is not None)
                if payload != self.payload:
                    # a new model and workspace, built here, off the hot
                    # path; everything else carries over
                    new_ff = self._make_computer(
                        ff.bare_model, ff.bare_scene, previous=ff,
                        payload=payload)
            except ValueError as exc:
                return SetParametersResult(successful=False,
                                           reason=str(exc))
            if any(name.startswith('wrench.') for name in values):
                ff.wrench = new_wrench
        else:
            try:        # no model yet: check the payload values alone
                check_payload(*payload[:3])
            except ValueError as exc:
                return SetParametersResult(successful=False,
                                           reason=str(exc))
        if payload != self.payload:
            self.payload = payload
            self.counts['payload_changes'] += 1
            if new_ff is not None:
                self.ff = new_ff
            self.get_logger().info(
                f'payload now {payload[0]} kg at {list(payload[1])} m '
                f'({payload[3] or "end-effector"} frame)')
        self.params.update(values)
        if 'log_throttle' in values:
            self.log_throttle = values['log_throttle']
        return SetParametersResult(successful=True)

    # ---- inputs ----
    def _now(self):
        return self.get_clock().now().nanoseconds * 1e-9

    def _reject(self, source, exc):
        kind = exc.kind if isinstance(exc, InputRejected) else \
            'internal_error'
        self.counts[kind] += 1
        last = self._last_log.get(kind, -1e300)
        now = time.monotonic()
        if now - last >= self.log_throttle:
            self._last_log[kind] = now
            self.get_logger().warning(
                f'dropped {source}: {clip(exc)} ({kind}: '
                f'{self.counts[kind]} so far)')

    def _expired(self, ff):
        """Say a wrench expired: not dropped, no longer applied."""
        self.counts['expired'] += 1
        which = ('' if ff.merger is None else ' (' + clip(', '.join(
            ff.wrench.last_expired), 200) + ')')
        now = time.monotonic()
        if now - self._last_log.get('expired', -1e300) >= self.log_throttle:
            self._last_log['expired'] = now
            self.get_logger().warning(
                f'wrench expired: the last wrench{which} is older than '
                f'wrench.timeout ({ff.wrench.timeout} s); the torques are '
                f'computed without it until a new one arrives (expired: '
                f'{self.counts["expired"]} so far)')

    def _no_model(self, _source):
        # said once at start-up and in /diagnostics; counted, not logged
        self.counts['no_model'] += 1

    def _on_joint_state(self, msg):
        start = time.perf_counter()
        if self._answer_joint_state(msg):
            self.update_times.add(time.perf_counter() - start)

    def _answer_joint_state(self, msg):
        """Publish the torques of one joint state; True when published."""
        ff = self.ff
        if ff is None:
            self._no_model('joint state')
            return
        try:
            now = self._now()
            if ff.merger is not None:       # a whole robot: merge first
                state = ff.merger.merge(msg.name, msg.position, msg.velocity,
                                        msg.effort, now)
                if state is None:           # no commanded joint in it
                    self.counts['held'] += 1
                    return
                tau = ff.state_torques(*state, seconds(msg.header.stamp),
                                       now)
            else:
                tau = ff.torques(msg.name, msg.position, msg.velocity,
                                 seconds(msg.header.stamp), now)
            # the torques left the wrench out once it was too old: say so
            # once, with the first state answered without it
            if ff.wrench.expire(now):
                self._expired(ff)
        except InputRejected as exc:
            if exc.kind == 'other_joints':
                # another publisher on joint_states (a gripper driver's):
                # normal in a robot graph, counted and not logged
                self.counts['other_joints'] += 1
            else:
                self._reject('joint state', exc)
            return
        except Exception as exc:  # never let a message kill the node
            self._reject('joint state', exc)
            return
        asked = tau
        tau, exceeded = ff.guard.check(tau)
        if exceeded:
            self._over_limit(ff, 'torque command', ff.guard.over(asked))
            if tau is None:
                return
        values = tau.tolist()
        k = ff.order.command
        self._cmd.data = values if k == len(values) else values[:k]
        self.cmd_pub.publish(self._cmd)
        self._torques.header.stamp = msg.header.stamp
        self._torques.name = ff.output_names
        self._torques.effort = values
        self.torque_pub.publish(self._torques)
        self.counts['published'] += 1
        if self._observer is not None:
            self._observer.observe(ff, msg, self._reject)
        return True

    def _over_limit(self, ff, what, over):
        """Count a torque over its bound; say which once per change."""
        self.counts['over_limit'] += 1
        if not self._over_log[what].news(over):
            return
        action = {'clamp': 'clamped to it', 'drop': 'not published',
                  'publish': 'published anyway'}[ff.guard.action]
        sources = sorted({ff.bound_sources[ff.output_names.index(name)]
                          for name in over})
        self.get_logger().warning(
            f'{what} above the torque bound ({action}): {over_text(over)} '
            f'(bounds from {", ".join(BOUND_SOURCES[s] for s in sources)}; '
            f'{self.counts["over_limit"]} over so far; said again when '
            f'other joints go over)')

    def _take(self, source, use, msg):
        """
        Return ``use(ff, msg)`` with the current model.

        None where there is no model yet or ``use`` raises: the message is
        then dropped and counted as ``source``'s (InputRejected, or
        anything else, which must never kill the node).
        """
        ff = self.ff
        if ff is None:
            self._no_model(source)
            return None
        try:
            return use(ff, msg)
        except Exception as exc:
            self._reject(source, exc)
            return None

    def _on_wrench(self, msg):
        self._take('wrench', self._use_wrench, msg)

    def _use_wrench(self, ff, msg):
        w = msg.wrench
        ff.wrench.update(
            msg.header.frame_id,
            (w.force.x, w.force.y, w.force.z,
             w.torque.x, w.torque.y, w.torque.z),
            seconds(msg.header.stamp), self._now())

    def _on_reference(self, msg):
        self._take('reference', self._use_reference, msg)

    def _use_reference(self, ff, msg):
        points = [(seconds(pt.time_from_start), pt.accelerations)
                  for pt in msg.points]
        ff.reference.set(msg.joint_names, seconds(msg.header.stamp),
                         points, self._now())

    def _on_trajectory(self, msg):
        got = self._take('trajectory', self._trajectory_efforts, msg)
        if got is None:
            return
        ff, efforts, exceeded = got
        if exceeded:
            self._over_limit(ff, 'trajectory effort', exceeded)
        if efforts is None:
            return
        for pt, effort in zip(msg.points, efforts):
            pt.effort = effort.tolist()
        self.traj_pub.publish(msg)
        self.counts['trajectories'] += 1

    def _trajectory_efforts(self, ff, msg):
        """Return ``ff`` and its efforts along ``msg`` and those exceeded."""
        points = [{'time_from_start': seconds(pt.time_from_start),
                   'positions': pt.positions,
                   'velocities': pt.velocities,
                   'accelerations': pt.accelerations}
                  for pt in msg.points]
        efforts, exceeded = ff.trajectory(
            msg.joint_names, points, self._now(),
            self.params['trajectory.include_wrench'])
        return ff, efforts, exceeded

    def _on_compute_dynamics(self, request, response):
        return self._serve(answer, request, response)

    def _on_linearize(self, request, response):
        return self._serve(answer_linearize, request, response)

    def _serve(self, fill, request, response):
        """Answer every request: ``fill`` it, or say why it failed."""
        self.counts['service_calls'] += 1
        ff = self.ff
        if ff is None:
            self.counts['service_failures'] += 1
            return failed(response, self._no_model_text())
        try:
            return fill(response, ff, request, self._now())
        except (InputRejected, NewtonEulerError) as exc:
            message = str(exc)
        except Exception as exc:
            self._reject('service request', exc)
            message = f'internal error: {exc}'
        self.counts['service_failures'] += 1
        return failed(response, message)

    def _no_model_text(self):
        return no_model_text(self.description_rejected)

    def _publish_counts(self):
        release_memory()
        status = diagnostics(self.get_fully_qualified_name(), self.ff,
                             self.counts, self.mode, self.params,
                             self.payload, self.model_source,
                             self.description_rejected)
        status.append(self.update_times.status(
            self.get_fully_qualified_name()))
        if self._observer is not None:
            status.append(self._observer.diagnostics())
        msg = DiagnosticArray(status=status)
        msg.header.stamp = self.get_clock().now().to_msg()
        self.diag_pub.publish(msg)


def main(args=None):
    """Entry point of the ``inverse_dynamics_node`` console script."""
    return run_node(InverseDynamicsNode, 'inverse_dynamics_node', args)


if __name__ == '__main__':
    sys.exit(main())
