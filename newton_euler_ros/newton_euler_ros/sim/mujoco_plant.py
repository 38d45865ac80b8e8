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
The MuJoCo plant: a robot of :mod:`.mujoco_model` stepped in time.

Efforts are held between commands (zero-order hold) over physics steps
of the model's ``timestep``.  Until :meth:`MujocoPlant.release` the arm
holds its pose, as a real arm does with its brakes on before its
controller starts: time runs, nothing moves.  :meth:`contact_wrenches`
gives the wrench the environment applies to each link in contact, in the
world (base) axes, the moment about the link's origin: the sign and
point of the momentum observer's estimate
(:func:`~..core.observer.wrench.external_wrench`).  Nothing here imports
ROS.
"""
import numpy as np

from .mujoco_model import _mujoco


class MujocoPlant:
    """A :class:`~.mujoco_model.MujocoRobot` and its MuJoCo state."""

    def __init__(self, robot, q0=None):
        mujoco = _mujoco()
        self.mujoco = mujoco
        self.robot = robot
        self.model = robot.model
        self.data = mujoco.MjData(self.model)
        q0 = np.zeros(robot.n) if q0 is None else np.asarray(q0, float)
        if q0.shape != (robot.n,):
            raise ValueError(f'initial positions: {robot.n} values expected '
                             f'(joints {list(robot.joints)}), got '
                             f'{q0.size}')
        robot.set_state(self.data, q0)
        self.held = True        # brakes on until release()
        self._hold_q = self.data.qpos.copy()
        self._force = np.zeros(6)
        # callables hook(plant) run before every physics step (scene
        # objects that follow the robot or apply loads)
        self.hooks = []

    @property
    def time(self):
        """Return the simulated time, s."""
        return float(self.data.time)

    def release(self):
        """Let go of the brakes: from now on the efforts move the arm."""
        self.held = False

    def state(self):
        """Return (q, qd) of the commanded joints."""
        return self.robot.state(self.data)

    def applied(self):
        """Return the joint torque each motor applied in the last step."""
        return self.data.actuator_force[self.robot.actuator].copy()

    def advance(self, tau, duration):
        """Hold efforts ``tau`` for ``duration`` seconds of physics."""
        m, d = self.model, self.data
        steps = max(1, int(round(duration / m.opt.timestep)))
        if self.held:
            d.time += steps * m.opt.timestep
            return
        d.ctrl[self.robot.actuator] = tau
        step, hooks = self.mujoco.mj_step, self.hooks
        for _ in range(steps):
            for hook in hooks:
                hook(self)
            step(m, d)

    def hold(self):
        """Put the brakes on at the current pose."""
        self.held = True
        self.data.qvel[:] = 0.0
        self.mujoco.mj_forward(self.model, self.data)

    def contact_wrenches(self):
        """
        Return {link: (6,) wrench} of the links in contact now.

        ``[f; m]`` the environment applies to the link, world axes, the
        moment about the link's origin; contacts between two links of the
        robot are internal and left out.
        """
        mujoco, m, d = self.mujoco, self.model, self.data
        out = {}
        robot_body = self._robot_bodies()
        for i in range(d.ncon):
            con = d.contact[i]
            b1 = m.geom_bodyid[con.geom[0]]
            b2 = m.geom_bodyid[con.geom[1]]
            if robot_body[b1] and robot_body[b2]:
                continue
            mujoco.mj_contactForce(m, d, i, self._force)
            frame = con.frame.reshape(3, 3)     # rows: the contact axes
            f = frame.T @ self._force[:3]       # on body 2, from body 1
            t = frame.T @ self._force[3:]
            for body, sign in ((b2, 1.0), (b1, -1.0)):
                if not robot_body[body]:
                    continue
                origin = d.xpos[body]
                w = out.setdefault(m.body(body).name, np.zeros(6))
                w[:3] += sign * f
                w[3:] += sign * (t + np.cross(con.pos - origin, f))
        return out

    def _robot_bodies(self):
        cached = getattr(self, '_bodies', None)
        if cached is None:
            m, mujoco = self.model, self.mujoco
            mark = np.zeros(m.nbody, dtype=bool)
            names = list(self.robot.joints) + [
                f[0] for f in self.robot.followers]
            for name in names:
                j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
                mark[m.jnt_bodyid[j]] = True
            # a body welded below a moving one is part of the robot too;
            # bodies are stored parents first
            for b in range(1, m.nbody):
                mark[b] |= mark[m.body_parentid[b]]
            cached = self._bodies = mark
        return cached
