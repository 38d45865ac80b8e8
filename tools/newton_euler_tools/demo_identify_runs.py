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
The runs of ``make demo-identify``: a node and a plant over DDS.

``LoopRun`` starts one run's processes in a ROS domain of its own,
gives the node its model and the plan, records ``/joint_states``
(``LoopRecorder``, optionally into a rosbag2) and stops them;
``wait_until`` and ``drive`` step several runs at once.
``demo_identify`` composes them into the loop.  The plant is MuJoCo
(``mujoco``: mujoco_sim_node, efforts in, fed by
:mod:`.trajectory_controller`, which takes the node's filled plan) or
the library's own simulator (``builtin``: robot_sim_node, which takes
the plan itself).
"""
import os
import shutil
import threading
import time

from newton_euler_ros.graph import EFFORT_COMMANDS, ID, SIM
import numpy as np

from .demo import (check_exits, Child, DemoError, poll, Recorder,
                   STARTUP_TIMEOUT)
from .demo_pick import trajectory_message
from .ident_example import BASE, TIP

JOINTS = [f'panda_joint{k}' for k in range(1, 8)]
CONTROLLER = '/trajectory_controller'
PLAN_RESEND = 2.0     # s without the controller's start: send the plan again
# per plant: the topic the node's filled plan goes to, the topic of t = 0
# of the plan, the plant's command topic
TOPICS = {
    'builtin': (f'{SIM}/joint_trajectory', f'{SIM}/start',
                f'{SIM}/commands'),
    'mujoco': (f'{CONTROLLER}/joint_trajectory', f'{CONTROLLER}/start',
               EFFORT_COMMANDS),
}


class LoopRecorder(Recorder):
    """
    The recorder of one run, spinning in a thread of its own.

    Besides joint states and the start time it sees the trajectory the
    node filled, publishes the plan on the node's ``~/trajectory_in`` and
    a URDF on ``robot_description``, watches the node's diagnostics (is
    its model loaded?) and sets its ``payload.*`` parameters.
    ``/joint_states`` is subscribed only on :meth:`open`: the simulator
    starts its clock once it has its two subscribers (the node and this
    recorder), so a run's processes can start well before it goes.
    """

    def __init__(self, domain, name, plant='builtin'):
        self.opened = False
        filled, start, commands = TOPICS[plant]
        super().__init__(domain, name=name, start=start, commands=commands)
        from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
        from rclpy.qos import (DurabilityPolicy, QoSProfile,
                               ReliabilityPolicy)
        from std_msgs.msg import String
        from trajectory_msgs.msg import JointTrajectory
        self.filled = []
        self.stamps_ns = []
        self.names = None
        self.model_loaded = False
        self._diagnostic_ok = DiagnosticStatus.OK
        # (wall-clock arrival, message) of what the node passed on
        self.node.create_subscription(
            JointTrajectory, filled,
            lambda msg: self.filled.append((time.time(), msg)), 10)
        self.plan = self.node.create_publisher(JointTrajectory,
                                               f'{ID}/trajectory_in', 10)
        latched = QoSProfile(depth=1,
                             reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self._string = String
        self.description = self.node.create_publisher(
            String, 'robot_description', latched)
        self.node.create_subscription(DiagnosticArray, '/diagnostics',
                                      self._on_diagnostics, 10)
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()

    def _spin(self):
        while not self._done.is_set():
            try:
                self.executor.spin_once(timeout_sec=0.05)
            except Exception:       # the context shut down under us
                if not self._done.is_set():
                    raise

    def _subscribe_states(self):
        if self.opened and self.state_sub is None:
            self.state_sub = self.node.create_subscription(
                self._state_type, '/joint_states', self._on_state, 1000)

    def open_states(self):
        """Subscribe to /joint_states: the simulator may start."""
        self.opened = True
        self._subscribe_states()

    def _on_state(self, msg):
        super()._on_state(msg)
        self.stamps_ns.append(msg.header.stamp.sec * 1_000_000_000
                              + msg.header.stamp.nanosec)
        if self.names is None:
            self.names = list(msg.name)

    def _on_diagnostics(self, msg):
        ok = self._diagnostic_ok
        for status in msg.status:
            # the node's first status is OK once it has a model
            if status.name == ID and status.level == ok:
                self.model_loaded = True

    def describe(self, text):
        """Publish ``text`` on robot_description (latched)."""
        self.description.publish(self._string(data=text))

    def set_payload(self, estimate):
        """Set the node's payload.* in one set_parameters_atomically call."""
        from rcl_interfaces.srv import SetParametersAtomically
        from rclpy.parameter import Parameter
        client = self.node.create_client(
            SetParametersAtomically, f'{ID}/set_parameters_atomically')
        request = SetParametersAtomically.Request(parameters=[
            Parameter(k, value=v).to_parameter_msg()
            for k, v in estimate.items()])
        end = time.monotonic() + 30.0
        future = None
        while time.monotonic() < end:
            if not client.service_is_ready():
                time.sleep(0.02)
                continue
            # a fresh client's first response can be lost in discovery
            # (ros2/rmw_fastrtps#418); setting the same values is idempotent
            future = client.call_async(request)
            resend = min(end, time.monotonic() + 2.0)
            while not future.done() and time.monotonic() < resend:
                time.sleep(0.01)
            if future.done():
                break
            client.remove_pending_request(future)
        if future is None or not future.done() \
                or not future.result().result.successful:
            raise DemoError(f'{ID}: setting the payload failed')

    def pause(self):
        """Stop spinning: nothing is recorded any more."""
        self._done.set()
        self._thread.join()

    def close(self):
        self.pause()
        super().close()


def _array(values):
    return '[' + ','.join(repr(float(v)) for v in values) + ']'


class LoopRun:
    """
    One run: a plant and inverse_dynamics_node, a ROS domain each.

    The processes start at once, on construction; the node gets the
    URDF as ``robot_file`` or, when ``urdf`` is None, later on
    ``robot_description`` (:meth:`describe`).  :meth:`go` lets the
    simulator start.  On the builtin plant the plan is sent, stamped at
    its t = 0, as soon as the simulator announces it (half a second
    ahead; the simulator then holds t = 0 for up to a second until the
    plan comes).  On MuJoCo (``plant='mujoco'``: mujoco_sim_node with
    ``noise``, its ``noise.*``, and trajectory_controller with the
    ``gains`` (kp, kd)) the plan is sent stamped 0 once the plant ticks:
    the controller starts it at the next joint state and says when on
    its ``~/start``, t = 0 of the run; the brakes hold the arm until
    then.  :meth:`finish` returns the recorded arrays and stops the
    processes in a thread; :meth:`close` waits for them.
    """

    def __init__(self, label, scene, domain, log_dir, urdf=None,
                 compensate=False, plant_payload=None, plant='builtin',
                 noise=None, gains=None):
        self.label = label
        self.plant = plant
        self.children = []
        self.status = {}
        self.segment = None
        self.sent = False
        self.resent = 0             # plans sent again (MuJoCo: see begun)
        self._stopper = None
        self.closed = False
        self.times = {'start': time.monotonic()}    # wall clock, per phase
        self.rec = LoopRecorder(domain, f'demo_recorder_{label}', plant)
        self.filled_topic = TOPICS[plant][0]
        if plant == 'mujoco':
            self._mujoco_children(label, scene, domain, log_dir, urdf,
                                  compensate, noise or {}, gains)
            return
        sim_args = ['-p', f'scene:={scene}', '-p', 'wait_for_subscribers:=2']
        if plant_payload:
            sim_args += [
                '-p', f'payload.mass:={plant_payload["mass"]}',
                '-p', f'payload.com:={_array(plant_payload["com"])}',
                '-p', f'payload.inertia:={_array(plant_payload["inertia"])}']
        self._start_nodes(
            label, 'robot_sim_node', sim_args, urdf, compensate,
            ['-r', f'~/trajectory_out:={SIM}/joint_trajectory'], domain,
            log_dir)

    def _start_nodes(self, label, plant, sim_args, urdf, compensate, remaps,
                     domain, log_dir):
        """
        Start the plant node ``plant`` and inverse_dynamics_node.

        The node gives the plan's gravity (and, with ``compensate``, the
        drives') efforts, its robot from ``urdf`` or else from
        robot_description, with the remaps ``remaps``.
        """
        id_args = ['-p', f'base_link:={BASE}', '-p', f'tip_link:={TIP}',
                   '-p', 'mode:=gravity', '-p', 'drives.compensate:='
                   f'{"true" if compensate else "false"}',
                   '-p', 'diagnostics_period:=0.2', *remaps]
        if urdf:
            id_args = ['-p', f'robot_file:={urdf}', *id_args]
        self.children.append(Child(f'{label}_{plant}',
                                   f'newton_euler_ros.nodes.{plant}',
                                   sim_args, domain, log_dir))
        self.children.append(Child(
            f'{label}_inverse_dynamics_node',
            'newton_euler_ros.nodes.inverse_dynamics_node', id_args, domain,
            log_dir))

    def _mujoco_children(self, label, scene, domain, log_dir, urdf,
                         compensate, noise, gains):
        """
        mujoco_sim_node, inverse_dynamics_node, trajectory_controller.

        The plant (its payload, if any, in the scene) starts its clock
        once the controller and the recorder subscribe to joint_states;
        the node only fills the plan (its joint_states are remapped
        away: nothing else of it is used here).
        """
        sim_args = ['-p', f'scene:={scene}', '-p', 'wait_for_subscribers:=2',
                    '-p', 'lockstep:=true', '-p', 'real_time_factor:=0.0']
        for key, value in noise.items():
            sim_args += ['-p', f'noise.{key}:={value!r}']
        self._start_nodes(
            label, 'mujoco_sim_node', sim_args, urdf, compensate,
            ['-r', f'~/trajectory_out:={self.filled_topic}',
             '-r', f'joint_states:={CONTROLLER}/unused_joint_states'],
            domain, log_dir)
        kp, kd = gains
        controller_args = ['-p', f'joints:={JOINTS!r}'.replace("'", '"'),
                           '-p', f'kp:={_array(kp)}', '-p', f'kd:={_array(kd)}']
        self.children.append(Child(
            f'{label}_trajectory_controller',
            'newton_euler_tools.trajectory_controller', controller_args,
            domain, log_dir))

    def describe(self, text):
        """Give the node its URDF on robot_description."""
        self.rec.describe(text)

    def check(self):
        """Raise DemoError when a process exited before its time."""
        if self._stopper is None:
            for child in self.children:
                child.check_alive()

    def ready(self):
        """Both nodes up and matched, the node's model loaded."""
        self.check()
        rec = self.rec
        ready = (rec.publishers('/joint_states') >= 1
                 and rec.plan.get_subscription_count() >= 1
                 and rec.publishers(self.filled_topic) >= 1
                 and rec.model_loaded)
        if self.plant == 'mujoco':     # the controller hears and is heard
            ready = ready and (rec.subscribers(self.filled_topic) >= 2
                               and rec.publishers(EFFORT_COMMANDS) >= 1
                               and rec.subscribers(EFFORT_COMMANDS) >= 2)
        return ready

    def go(self, segment):
        """Let the simulator start; the plan follows its start time."""
        self.segment = segment
        self.times['go'] = time.monotonic()
        self.rec.open_states()

    def begun(self):
        """Send the plan once t = 0 is known; True once it is sent."""
        self.check()
        rec = self.rec
        if self.plant == 'mujoco':
            # stamped 0: the controller starts it at the next state and
            # says so on its latched ~/start.  No start PLAN_RESEND s
            # after sending: the plan was lost on its way (the node's
            # publisher may match the controller after the recorder saw
            # both; a message before that is gone), so it is sent again.
            now = time.monotonic()
            if rec.t0 is None and rec.states and (
                    not self.sent
                    or now - self.times['plan sent'] > PLAN_RESEND):
                if self.sent:
                    self.resent += 1
                    print(f'[{self.label}] no start {PLAN_RESEND:g} s after '
                          'the plan was sent: sending it again', flush=True)
                rec.plan.publish(trajectory_message(JOINTS, 0.0,
                                                    self.segment))
                self.sent = True
                self.times['plan sent'] = now
            return self.sent and rec.t0 is not None
        if not self.sent and rec.t0 is not None:
            rec.plan.publish(trajectory_message(JOINTS, rec.t0,
                                                self.segment))
            self.sent = True
            self.times['plan sent'] = time.monotonic()
        return self.sent

    def done(self, duration):
        """Return True once the simulation reached ``duration``."""
        t = self.rec.last_time()
        if self.begun() and t is not None and t >= duration - 1e-9:
            self.times.setdefault('end reached', time.monotonic())
            return True
        return False

    def finish(self, duration, bag=None):
        """Stop the processes (in a thread); return the recorded arrays."""
        rec = self.rec
        self.stop()
        rec.pause()
        self.times['finish'] = time.monotonic()
        if not rec.filled:
            raise DemoError(f'[{self.label}] the simulator did not get the '
                            f'trajectory with efforts')
        arrival, plan = rec.filled[0]
        if self.plant == 'builtin':
            # > 0: the simulator held t = 0 that long for the plan
            self.times['plan late'] = arrival - rec.t0
        states = list(rec.states)
        ns = np.array(rec.stamps_ns, dtype=np.int64)
        t = np.array([s[0] for s in states]) - rec.t0
        keep = (t >= -1e-9) & (t <= duration + 1e-9)
        order = np.argsort(t[keep], kind='stable')
        idx = np.flatnonzero(keep)[order]
        q = np.array([states[i][1] for i in idx])
        qd = np.array([states[i][2] for i in idx])
        effort = np.array([states[i][3] for i in idx])
        if bag is not None:
            from newton_euler_ros.ident.bag_write import write_joint_states
            if os.path.exists(bag):
                shutil.rmtree(bag)
            write_joint_states(bag, ns[idx], rec.names, q, qd, effort)
        self.times['recorded'] = time.monotonic()
        return {'t': t[idx], 'q': q, 'qd': qd, 'effort': effort,
                'ff': np.array([p.effort for p in plan.points])}

    def timing(self, started):
        """Return the wall time (s since ``started``) of each phase."""
        return {k: round(v - (0.0 if k == 'plan late' else started), 2)
                for k, v in self.times.items()}

    def stop(self):
        """Stop the processes, last started first, in a thread."""
        if self._stopper is None:
            def stop_all():
                for child in reversed(self.children):
                    self.status[child.label] = child.stop()
            self._stopper = threading.Thread(target=stop_all, daemon=True)
            self._stopper.start()

    def close(self):
        """Wait for the processes to exit; DemoError unless all exit 0."""
        self.abort()
        check_exits(self.label, self.status)

    def abort(self):
        """Stop the processes and the recorder, whatever state they are in."""
        self.stop()
        self._stopper.join()
        if not self.closed:
            self.closed = True
            self.rec.close()


def wait_until(runs, predicate, what, timeout=STARTUP_TIMEOUT):
    """Poll ``predicate()``; fail if a process exits or on timeout."""
    def check():
        for r in runs:
            r.check()
    poll(predicate, what, check, lambda: time.sleep(0.02), timeout)


def drive(runs, duration):
    """Run ``runs`` (gone already) until each reached ``duration``."""
    def all_done():
        done = [r.done(duration) for r in runs]     # each sends its plan
        return all(done)
    # a lockstep plant slows with the machine's load (a tenth of real
    # time at a load average of 15 on two cores)
    slow = 30.0 if any(r.plant == 'mujoco' for r in runs) else 5.0
    wait_until(runs, all_done,
               ', '.join(r.label for r in runs) + f' to reach t = '
               f'{duration:g} s', 60.0 + slow * duration)
