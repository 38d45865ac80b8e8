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
inverse_dynamics_node's momentum observer (``observer.*`` parameters).

The ROS side of ``core.observer``: after the torques of a JointState are
published, :meth:`NodeObserver.observe` runs one observer step on it (its
efforts converted to joint torques through the URDF's torque constants
when it has them: a current-sensing arm) and publishes
``~/external_torque`` (JointState, effort field), ``~/external_wrench``
(WrenchStamped, base frame; or one per link of ``observer.end_effectors``,
in its axes, frame_id the link) and, on every change, ``~/contact``
(Bool; also at ``observer.contact_period``).  On a whole robot the
efforts and velocities are the ones the node's merger holds (every joint
of the robot, possibly from several drivers).  Its state and counters go to
``/diagnostics`` (:meth:`NodeObserver.diagnostics`).  It never raises
into the node: a sample it cannot use is counted and skipped, and
JointStates without effort or velocity are reported once.
"""
import functools

from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
from geometry_msgs.msg import WrenchStamped
import numpy as np
from sensor_msgs.msg import JointState
from std_msgs.msg import Bool

from .common import ConfigurationError, qos_profile, QUIET, seconds
from ..core import NewtonEulerError
from ..core import observer as momentum
from ..core.effects import friction_torque
from ..core.effort_units import EffortMonitor
from ..core.text import clip
from ..joint_inputs import InputRejected
from ..safety import joint_units


class NodeObserver:
    """The observer of one node: publishers, running state, diagnostics."""

    def __init__(self, node, params, ff=None):
        """
        Create the publishers and the contact timer on ``node``.

        ``params`` are the node's checked parameters; with a computer
        ``ff`` already, a bad observer setting fails here (start-up).
        """
        self.node, self.params = node, params
        self.ff = self.obs = self.state = self.contact = None
        #: the efforts' unit checked against the model, window by window
        self.units = None
        self.said_units = None
        self.status = 'waiting for the first JointState'
        self.said = set()
        self.rejected = 0
        qos = qos_profile(params['qos.depth'], params['qos.reliability'])
        self.torque_pub = node.create_publisher(
            JointState, '~/external_torque', qos, event_callbacks=QUIET)
        self.wrench_pub = node.create_publisher(
            WrenchStamped, '~/external_wrench', qos, event_callbacks=QUIET)
        self.contact_pub = node.create_publisher(Bool, '~/contact', qos,
                                                 event_callbacks=QUIET)
        self._torque = JointState()
        self._wrench = WrenchStamped()
        self._wrench_out = np.zeros(6)
        #: (link, message, buffer) per end effector of
        #: observer.end_effectors (empty: the end effector, base axes)
        self._links = []
        node.create_timer(params['observer.contact_period'],
                          self.publish_contact)
        if ff is not None:
            try:
                self.observer_for(ff)
            except ValueError as exc:
                raise ConfigurationError(_parameter_named(str(exc))) \
                    from None

    def warm_kernels(self, ff):
        """
        Load (or compile) the observer's kernels for ``ff``'s model.

        Called where a model is built off the executor (a new
        robot_description), so that the first sample does not wait for
        them; the observer itself is built on that sample.
        """
        momentum.MomentumObserver(ff.model).warm_up()

    def observer_for(self, ff):
        """
        Return the observer of this computer's model (payload included).

        Built again when the model changes (a new description or
        payload): the residual and the contact carry over, and the
        integral restarts at the next sample.
        """
        if self.ff is ff:
            return self.obs
        p = self.params
        model = ff.model
        scene = ff.scene
        # the model's own drives (an identified URDF: friction, rotor
        # inertia, torque constants), or the scene's
        ratio = p['observer.static_friction']
        options = momentum.drive_options(model, ratio)
        if scene is not None and scene.effects.friction:
            options['drive_torque'] = functools.partial(_scene_friction,
                                                        scene)
            options['static_friction'] = ratio * scene.coulomb
        if scene is not None and scene.effects.armature:
            options['armature'] = scene.armature
        obs = momentum.MomentumObserver(
            model, p['observer.gain'], max_gap=p['observer.max_gap'],
            damping=p['observer.damping'],
            thresholds=_per_joint('observer.thresholds',
                                  p['observer.thresholds'], model),
            speed_thresholds=_per_joint('observer.speed_thresholds',
                                        p['observer.speed_thresholds'],
                                        model),
            acceleration_thresholds=_per_joint(
                'observer.acceleration_thresholds',
                p['observer.acceleration_thresholds'], model),
            rest_thresholds=_per_joint('observer.rest_thresholds',
                                       p['observer.rest_thresholds'], model),
            hysteresis=_at_most_one(p['observer.hysteresis']),
            rest_reference=p['observer.rest_reference'], **options)
        if obs.torque_constant is not None and 'constants' not in self.said:
            self.said.add('constants')
            self.node.get_logger().info(
                'observer: efforts converted to joint torques with the '
                "URDF's torque constants " + ', '.join(
                    f'{k:.4g}' for k in obs.torque_constant)
                + ' (N m per effort unit); thresholds in N m')
        obs.warm_up()
        old = self.state
        state = momentum.initial_state(obs)
        if old is not None and old.r.shape == state.r.shape:
            state.r[:] = old.r
            state.restarts = old.restarts
        if self.contact is None or self.contact.active.shape != (model.n,):
            self.contact = momentum.initial_contact(obs)
        else:                   # a new model: its residual settles anew
            self.contact.rest = momentum.RestState(model.n)
        urdf = model.info.get('urdf') if isinstance(model.info, dict) \
            else None
        base = (p['base_link'] or (urdf or {}).get('base')
                or (list(p['wrench.base_frames']) or ['base_link'])[0])
        self._wrench.header.frame_id = base
        self._torque.name = list(model.joint_names)
        self._links = self._end_effectors(model)
        self.ff, self.obs, self.state = ff, obs, state
        self._units_for(obs)
        return obs

    def _units_for(self, obs):
        """Check the efforts' unit against this observer's model."""
        mode = 'torque' if obs.torque_constant is None else 'given'
        old = self.units
        if old is not None and old.mode == mode and \
                old.names == list(obs.model.joint_names):
            return
        source = self.params['robot_file'] or 'the robot description'
        self.units = EffortMonitor(obs.model.joint_names, mode, 'observer',
                                   source)

    def _end_effectors(self, model):
        """Return (link, message, buffer) of each observer.end_effectors."""
        links = list(self.params['observer.end_effectors'])
        unknown = [x for x in links if x not in (model.link_frames or {})]
        if unknown:
            raise ValueError(f'observer.end_effectors: {unknown[0]!r} is not '
                             f'a link of {model.name}')
        if not links and model.tool_body is None and \
                'no wrench' not in self.said:
            self.said.add('no wrench')
            self.node.get_logger().info(
                'observer: the robot has several tips and no '
                'observer.end_effectors: external torques only, no wrench')
        out = []
        for link in links:
            msg = WrenchStamped()
            msg.header.frame_id = link
            out.append((link, msg, np.zeros(6)))
        #: two links or more: estimated jointly (core/observer/wrenches.py)
        self._joint = None
        own = momentum.own_joints(model, links) if len(links) > 1 else ()
        for link, joints in zip(links, own):
            if not joints and ('alone', link) not in self.said:
                self.said.add(('alone', link))
                self.node.get_logger().warning(
                    f'observer: {link!r} has no joint of its own (every '
                    f'joint that moves it moves another of '
                    f'observer.end_effectors too): its wrench stays zero')
        return out

    def _says(self, key, status, text):
        """Set the observer's status; log ``text`` once per kind."""
        self.status = status
        if key not in self.said:
            self.said.add(key)
            self.node.get_logger().warning(f'observer: {text}')

    def _step(self, ff, msg):
        """Return (residual, wrench, contact before, after) or None."""
        if ff.merger is not None:
            return self._merged_step(ff, msg)
        effort = ff.order.gather(msg.name, 'effort', msg.effort,
                                 required=False)
        if effort is None:
            self._says('effort', 'cannot run: JointStates have no effort',
                       'joint_states carry no effort: the observer cannot '
                       'run (torques go on)')
            return None
        if len(msg.velocity) == 0:
            self._says('velocity',
                       'cannot run: JointStates have no velocity',
                       'joint_states carry no velocity: the observer cannot '
                       'run (torques go on)')
            return None
        return self._run(ff, msg, effort)

    def _merged_step(self, ff, msg):
        """Do the same on a whole robot, from the merger's efforts."""
        effort, missing = ff.merger.efforts()
        if effort is None:
            self._says('effort', f'cannot run: no effort for '
                       f'{clip(", ".join(missing), 200)}',
                       f'no effort for joint(s) {clip(", ".join(missing), 300)}'
                       f' in their latest joint_states: the observer cannot '
                       f'run (torques go on)')
            return None
        unrated = ff.merger.unrated()
        if unrated:
            self._says('velocity', f'cannot run: no velocity for '
                       f'{clip(", ".join(unrated), 200)}',
                       f'no velocity for joint(s) '
                       f'{clip(", ".join(unrated), 300)} in their latest '
                       f'joint_states: the observer cannot run (torques go '
                       f'on)')
            return None
        return self._run(ff, msg, effort)

    def _run(self, ff, msg, effort):
        obs = self.observer_for(ff)
        stamp = seconds(msg.header.stamp) or \
            self.node.get_clock().now().nanoseconds * 1e-9
        r, what = momentum.observer_step(obs, self.state, stamp, ff.last_q,
                                         ff.last_qd, effort)
        if what == momentum.DUPLICATE:
            return None
        units = self.units
        if units.due(stamp, ff.last_qd):
            torque = effort if obs.torque_constant is None else \
                effort * obs.torque_constant
            # the model's torque: what the drives apply plus the residual
            if units.add(stamp, torque + r, torque, ff.last_qd):
                self._units_checked(units)
        before = self.contact.in_contact
        now = momentum.contact_step(obs, self.contact, r,
                                    self.state.allowance, stamp, ff.last_q,
                                    ff.last_qd)
        if len(self._links) > 1:
            self._joint_wrenches(obs, ff.last_q, r)
            F = None
        elif self._links:
            for link, _, F in self._links:
                momentum.external_wrench(obs, ff.last_q, r, out=F,
                                         frame=link, axes='link')
            F = None
        elif obs.model.tool_body is None:
            F = None
        else:
            F = momentum.external_wrench(obs, ff.last_q, r,
                                         out=self._wrench_out)
        self.status = 'running'
        return r, F, before, now

    def _joint_wrenches(self, obs, q, r):
        """
        Estimate the links' wrenches jointly into their buffers.

        A link whose own joints feel no contact (the contact test just
        run) reads zero; which components the joints cannot separate is
        said once, at the first pose, and kept for /diagnostics.
        """
        links = [link for link, _, _ in self._links]
        if 'separable' not in self.said:
            self.said.add('separable')
            self.node.get_logger().info(
                f'observer: wrenches of {", ".join(links)} estimated '
                f'jointly; not separable by the joints (at the first pose, '
                f'all pushed): '
                + momentum.separability(obs, q, links, axes='link').text())
        self._joint = momentum.external_wrenches(
            obs, q, r, links, axes='link', contact=self.contact)
        for (_, _, F), values in zip(self._links, self._joint.wrench):
            F[:] = values

    def _units_checked(self, units):
        """Say a window's verdict on the efforts' unit when it changes."""
        verdict = units.verdict
        if verdict == self.said_units:
            return
        self.said_units = verdict
        log = self.node.get_logger()
        if verdict is not None:
            log.warning(verdict)
        elif units.windows > 1:
            log.info('observer: the efforts now match the model (least-'
                     'squares ratio per joint)')

    def observe(self, ff, msg, reject):
        """
        Residual, wrench and contact for one JointState; publish them.

        ``ff`` has just computed the torques of ``msg`` (its ``last_q``,
        ``last_qd``); ``reject(source, exc)`` is the node's report of an
        unexpected failure.
        """
        try:
            step = self._step(ff, msg)
        except (InputRejected, NewtonEulerError, ValueError) as exc:
            self.rejected += 1
            why = clip(str(exc), 200)
            self._says('rejected', f'sample rejected: {why}',
                       f'sample rejected ({why}); rejections are counted in '
                       f'/diagnostics')
            return
        except Exception as exc:  # never let the observer kill the node
            reject('observer', exc)
            return
        if step is None:
            return
        r, F, before, now = step
        t = self._torque
        t.header.stamp = msg.header.stamp
        t.effort = r.tolist()
        self.torque_pub.publish(t)
        wrenches = ([(self._wrench, F)] if F is not None else
                    [(w, values) for _, w, values in self._links])
        for w, values in wrenches:
            w.header.stamp = msg.header.stamp
            f, m = w.wrench.force, w.wrench.torque
            f.x, f.y, f.z, m.x, m.y, m.z = values.tolist()
            self.wrench_pub.publish(w)
        if now != before:
            self.contact_pub.publish(Bool(data=now))
            if now:
                self.node.get_logger().info(
                    f'observer: contact (number {self.contact.count}): '
                    + contact_text(self.obs, self.contact, r,
                                   self.state.allowance))

    def publish_contact(self):
        """Publish ~/contact at the steady rate."""
        contact = self.contact
        self.contact_pub.publish(
            Bool(data=bool(contact is not None and contact.in_contact)))

    def diagnostics(self):
        """Return the observer's DiagnosticStatus."""
        contact, state = self.contact, self.state
        running = self.status == 'running'
        in_contact = bool(contact is not None and contact.in_contact)
        units = self.units
        verdict = None if units is None else units.verdict
        if verdict is not None:
            message = clip(verdict, 500)
        elif running:
            message = 'contact' if in_contact else 'no contact'
        else:
            message = self.status
        status = DiagnosticStatus(
            level=DiagnosticStatus.OK if running and verdict is None
            else DiagnosticStatus.WARN,
            name=self.node.get_fully_qualified_name() + ': observer',
            message=message)
        status.values = [
            KeyValue(key='state', value=self.status),
            KeyValue(key='in_contact', value=str(in_contact).lower()),
            KeyValue(key='contacts', value=str(
                contact.count if contact is not None else 0)),
            KeyValue(key='samples', value=str(
                state.samples if state is not None else 0)),
            KeyValue(key='restarts', value=str(
                state.restarts if state is not None else 0)),
            KeyValue(key='rejected', value=str(self.rejected)),
            KeyValue(key='gain', value=repr(self.params['observer.gain'])),
            KeyValue(key='thresholds', value=repr(
                list(self.params['observer.thresholds']))),
            KeyValue(key='static_friction', value=repr(
                self.params['observer.static_friction'])),
            KeyValue(key='rest_reference', value=_rest_text(
                self.params['observer.rest_reference'], contact)),
            KeyValue(key='effort_units', value=_units_text(units))]
        joint = getattr(self, '_joint', None)
        if joint is not None:       # the joint estimate's last say
            status.values.append(KeyValue(
                key='wrench_not_separable', value=joint.text()))
        return status


def contact_text(obs, contact, r, allowance):
    """
    Name the joints in contact, each with its residual and threshold.

    ``joint2 4.1 N m (threshold 2)``, the threshold in effect at that
    sample (grown with the joint's speed and acceleration when the
    observer has speed or acceleration thresholds); ``+ 0.5 static
    friction`` where
    the joint's static friction allowance raises the bound; a joint
    found by the rest reference alone by its change from its rest value,
    with the rest reference's threshold (at least its rest threshold).
    """
    units = joint_units(obs.model)
    # the threshold in effect: grown with speed and acceleration if set
    thresholds = (contact.threshold if obs.moving_thresholds and
                  contact.threshold is not None else obs.thresholds)
    rest_thresholds = np.maximum(thresholds, obs.rest_thresholds)
    rest = contact.rest
    by_rest = (rest.active if rest is not None and obs.rest_reference
               else np.zeros(obs.n, dtype=bool))
    parts = []
    for j, name in enumerate(obs.model.joint_names):
        thr, unit = thresholds[j], units[j]
        if contact.active[j]:
            extra = allowance[j] if allowance is not None else 0.0
            parts.append(f'{name} {r[j]:.3g} {unit} (threshold {thr:.3g}'
                         + (f' + {extra:.3g} static friction'
                            if extra > 0 else '') + ')')
        elif by_rest[j]:
            parts.append(f'{name} {r[j]:.3g} {unit}, '
                         f'{rest.deviation[j]:.3g} from its rest value '
                         f'(threshold {rest_thresholds[j]:.3g})')
    return ', '.join(parts)


def _rest_text(enabled, contact):
    """Return the diagnostics' word on the rest reference."""
    if not enabled:
        return 'off'
    rest = None if contact is None else contact.rest
    return 'armed (the arm rests)' if rest is not None and rest.armed \
        else 'waiting for the arm to rest'


def _units_text(units):
    """Return the diagnostics' word on the efforts' unit."""
    if units is None or units.windows == 0:
        return 'not checked yet (10 s of motion needed)'
    if units.verdict is not None:
        return 'not what the URDF says'
    unit = 'N m per torque_constant' if units.mode == 'given' else 'N m'
    plural = 's' if units.windows != 1 else ''
    return f'{unit} (checked on {units.windows} window{plural} of motion)'


#: the observer's settings that are node parameters of the same name
_OBSERVER_PARAMETERS = ('gain', 'max_gap', 'damping', 'thresholds',
                        'speed_thresholds', 'acceleration_thresholds',
                        'rest_thresholds', 'hysteresis')


def _parameter_named(text):
    """Name the node parameter (observer.X) in the library's error on X."""
    name = text.split(':', 1)[0]
    return f'observer.{text}' if name in _OBSERVER_PARAMETERS else text


def _per_joint(name, values, model):
    """One value per joint (chain order) from a list of 1 or n values."""
    values = list(values)
    if len(values) not in (1, model.n):
        raise ValueError(f'{name}: must have 1 or {model.n} values (one '
                         f'per joint, chain order '
                         f'{list(model.joint_names)}), got {len(values)}')
    return values


def _scene_friction(scene, qd, _qdd=None):
    return friction_torque(scene, qd)


def _at_most_one(value):
    if not value <= 1.0:
        raise ValueError(f'observer.hysteresis: must be <= 1, got {value!r}')
    return value
