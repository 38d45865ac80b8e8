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
A scene in MuJoCo (``engine: mujoco``): the world the figures are measured in.

The scene's robot file is compiled by :func:`.mujoco_model.load_mujoco`
and given the scene's effects: gravity (or none, or the scene's vector),
its friction (viscous as damping, Coulomb as frictionloss) and rotor
inertia (armature), a payload as a body fixed to its link, the wrench
(applied at the end effector, the reaction of what the robot exerts) and
the ``contacts`` block's objects (:mod:`.contacts`).  Velocity products
cannot be left out: MuJoCo has every rigid-body effect.  MuJoCo's
integrator is the scene's: ``rk4`` is MuJoCo's RK4,
``semi_implicit_euler`` its Euler (semi-implicit); the physics step is
the scene's step, and the controller runs at every step, its torque held
over it.  Nothing here imports ROS.
"""
import dataclasses
import time

import numpy as np

from .contacts import STANDOFF
from .mujoco_model import _mujoco, load_mujoco
from .mujoco_plant import MujocoPlant
from .simulate import SceneDynamics, SimulationResult, tracking_controller

PAD, TIP = 0.01, 0.02       # radii of the pad and of the pusher's ball, m
TIP_MASS = 0.1              # kg
TIP_DAMPING = 2.0           # N s/m on its rod: it meets the pad gently
RETRACT = 2.0               # N pulling the pusher back between pushes
# the pad and the ball touch each other only (contact bit 2), stiffly and
# without friction (condim 1): the ball follows the pad's position, not its
# velocity, so friction would drag on a moving link
PUSH_BIT = 2
PUSH_SOLREF = (0.005, 1.0)   # time constant >= 2 steps of 1 ms


def _tool_link(scene):
    """Return the end effector's link name in the robot file."""
    info = scene.model.info.get('urdf') or {}
    return info.get('tip') or 'tool0'


def _extend(scene):
    """Return extend(spec, mujoco) adding the scene's objects."""
    c = scene.contacts

    def extend(spec, mj):
        world = spec.worldbody
        if c is not None and c.floor is not None:
            g = world.add_geom()
            g.name = 'floor'
            g.type = mj.mjtGeom.mjGEOM_PLANE
            g.size = [0.0, 0.0, 1.0]
            g.pos = [0.0, 0.0, c.floor]
        if c is not None and c.table is not None:
            g = world.add_geom()
            g.name = 'table'
            g.type = mj.mjtGeom.mjGEOM_BOX
            g.size = c.table[0] / 2.0
            g.pos = c.table[1]
        if scene.payload is not None:
            mass, com, inertia, link = scene.payload
            body = spec.body(link or _tool_link(scene)).add_body()
            body.name = 'payload'
            body.mass = mass
            body.ipos = com
            body.fullinertia = [inertia[0, 0], inertia[1, 1], inertia[2, 2],
                                inertia[0, 1], inertia[0, 2], inertia[1, 2]]
            body.explicitinertial = True
        if c is not None and c.pusher is not None:
            _add_pusher(spec, mj, c.pusher)
    return extend


def _add_pusher(spec, mj, pusher):
    pad = spec.body(pusher.link).add_geom()
    pad.name = 'pusher_pad'
    pad.type = mj.mjtGeom.mjGEOM_SPHERE
    pad.size = [PAD, 0.0, 0.0]
    pad.pos = pusher.point
    pad.mass = 0.0
    pad.contype = pad.conaffinity = PUSH_BIT
    pad.solref = PUSH_SOLREF
    pad.condim = 1
    # the carriage: moved with the pad (position and velocity set before
    # each step, so the ball meets the pad at their relative speed)
    carriage = spec.worldbody.add_body()
    carriage.name = 'pusher'
    carriage.mass = 100.0
    carriage.inertia = [1e-3, 1e-3, 1e-3]
    carriage.explicitinertial = True
    carriage.gravcomp = 1.0
    for k, axis in enumerate(np.eye(3)):
        j = carriage.add_joint()
        j.name = f'pusher_{"xyz"[k]}'
        j.type = mj.mjtJoint.mjJNT_SLIDE
        j.axis = axis
    tip = carriage.add_body()
    tip.name = 'pusher_tip'
    tip.mass = TIP_MASS
    tip.inertia = [1e-6, 1e-6, 1e-6]
    tip.explicitinertial = True
    tip.gravcomp = 1.0
    slide = tip.add_joint()
    slide.name = 'pusher_slide'
    slide.type = mj.mjtJoint.mjJNT_SLIDE
    slide.axis = pusher.direction
    slide.range = [0.0, STANDOFF + PAD]
    slide.limited = mj.mjtLimited.mjLIMITED_TRUE
    slide.damping[0] = TIP_DAMPING
    ball = tip.add_geom()
    ball.name = 'pusher_ball'
    ball.type = mj.mjtGeom.mjGEOM_SPHERE
    ball.size = [TIP, 0.0, 0.0]
    ball.contype = ball.conaffinity = PUSH_BIT
    ball.solref = PUSH_SOLREF
    ball.condim = 1
    act = spec.add_actuator()
    act.name = 'pusher'
    act.target = 'pusher_slide'
    act.trntype = mj.mjtTrn.mjTRN_JOINT
    act.gear[0] = 1.0


def _pusher_hook(plant, pusher):
    """Return a hook: the carriage moves with the pad; the ball presses."""
    mj, m = plant.mujoco, plant.model
    body = plant.robot.body(pusher.link)
    axes = [mj.mj_name2id(m, mj.mjtObj.mjOBJ_JOINT, f'pusher_{a}')
            for a in 'xyz']
    qpos = np.array([m.jnt_qposadr[j] for j in axes])
    dof = np.array([m.jnt_dofadr[j] for j in axes])
    act = mj.mj_name2id(m, mj.mjtObj.mjOBJ_ACTUATOR, 'pusher')
    back = (PAD + TIP + STANDOFF) * pusher.direction
    vel = np.zeros(6)

    def hook(plant):
        d = plant.data
        R = d.xmat[body].reshape(3, 3)
        arm = R @ pusher.point
        mj.mj_objectVelocity(m, d, mj.mjtObj.mjOBJ_BODY, body, vel, 0)
        d.qpos[qpos] = d.xpos[body] + arm - back
        d.qvel[dof] = vel[3:] + np.cross(vel[:3], arm)
        force = pusher.force(d.time)
        d.ctrl[act] = force if force > 0.0 else -RETRACT
    return hook


def _wrench_hook(scene, body):
    """Return a hook applying the reaction of the scene's wrench."""

    def hook(plant):
        mj, m, d = plant.mujoco, plant.model, plant.data
        wrench, frame = scene.wrench_at(d.time)
        d.qfrc_applied[:] = 0.0
        if wrench is None:
            return
        R = d.xmat[body].reshape(3, 3)
        f, t = np.asarray(wrench[:3], float), np.asarray(wrench[3:], float)
        if frame == 'end_effector':
            f, t = R @ f, R @ t
        # F_e is what the robot exerts: the world pushes back with -F_e
        mj.mj_applyFT(m, d, -f, -t, d.xpos[body].copy(), body,
                      d.qfrc_applied)
    return hook


def scene_plant(scene, step=None, integrator=None):
    """Return the :class:`MujocoPlant` of a scene at its initial state."""
    robot = load_mujoco(scene.robot_path, joints=None,
                        timestep=step or scene.step, extend=_extend(scene))
    m = robot.model
    mj = _mujoco()
    method = integrator or scene.integrator
    m.opt.integrator = (mj.mjtIntegrator.mjINT_RK4 if method == 'rk4'
                        else mj.mjtIntegrator.mjINT_EULER)
    m.opt.gravity = scene.model.gravity if scene.effects.gravity else 0.0
    idx = [robot.joints.index(j) for j in scene.model.joint_names]
    dof = robot.dof[idx]
    for key, on, values in (('dof_damping', scene.effects.friction,
                             scene.viscous),
                            ('dof_frictionloss', scene.effects.friction,
                             scene.coulomb),
                            ('dof_armature', scene.effects.armature,
                             scene.armature)):
        getattr(m, key)[dof] = values if on else 0.0
    # the scene's joint order is the library's: the plant takes it
    robot = dataclasses.replace(robot, joints=tuple(scene.model.joint_names),
                                qpos=robot.qpos[idx], dof=dof,
                                actuator=robot.actuator[idx])
    plant = MujocoPlant(robot, scene.q0)
    plant.data.qvel[dof] = scene.qd0
    mj.mj_forward(m, plant.data)
    c = scene.contacts
    if c is not None and c.pusher is not None:
        plant.hooks.append(_pusher_hook(plant, c.pusher))
    if scene.effects.wrench:
        plant.hooks.append(_wrench_hook(scene,
                                        robot.body(_tool_link(scene))))
    plant.release()
    return plant


def simulate_mujoco(scene, duration=None, controller=None, feedforward=None,
                    step=None, feedforward_at='desired', plant=None):
    """
    Simulate a scene in MuJoCo; return a SimulationResult.

    As :func:`.simulate.simulate_builtin`: ``controller(t, q, qd) -> (tau,
    tau_ff)`` (default the scene's PD plus the library's feedforward) at
    every step, held over it.  The energy columns are the library's
    energy of MuJoCo's motion and the torques' work on it (friction,
    contacts and the wrench are not booked: ``summary`` reports the
    balance only when the scene has none of them).
    """
    dyn = SceneDynamics(scene)
    control = controller or tracking_controller(dyn, feedforward,
                                                feedforward_at)
    plant = plant or scene_plant(scene, step)
    dt = plant.model.opt.timestep
    T = scene.duration if duration is None else duration
    if not T > 0.0:
        raise ValueError(f'duration must be > 0 s, got {T}')
    steps = max(1, int(round(T / dt)))
    n = scene.model.n
    shape = (steps + 1, n)
    out_q, out_qd, out_tau, out_ff, out_ref = (np.zeros(shape)
                                               for _ in range(5))
    out_e = np.zeros(steps + 1)
    out_w = np.zeros((steps + 1, 3))
    work = 0.0
    start = time.perf_counter()
    for k in range(steps + 1):
        t = k * dt
        q, qd = plant.state()
        out_q[k], out_qd[k] = q, qd
        out_ref[k] = scene.reference.at(t)[0]
        out_e[k] = dyn.energy(q, qd)
        if k:
            work += out_tau[k - 1] @ (q - out_q[k - 1])
        out_w[k, 0] = work
        if k == steps:
            break
        tau, ff = control(t, q, qd)
        out_tau[k], out_ff[k] = tau, ff
        plant.advance(tau, dt)
        if not np.isfinite(plant.data.qvel).all():
            raise ValueError(
                f'MuJoCo diverged at t = {t:.4f} s (step {dt} s, kp '
                f'{scene.kp.tolist()}, kd {scene.kd.tolist()}): take a '
                f'smaller step or lower gains')
    out_tau[-1], out_ff[-1] = out_tau[-2], out_ff[-2]
    wall = time.perf_counter() - start
    result = SimulationResult(
        np.arange(steps + 1) * dt, out_q, out_qd, out_tau, out_ff, out_ref,
        out_e, out_w, wall, scene.effects.names(),
        f'mujoco {scene.integrator}', dt)
    err = out_q - out_ref
    balanced = not (scene.effects.friction or scene.effects.wrench
                    or scene.contacts is not None)
    scale = max(1.0, float(np.abs(out_e).max()))
    drift = float(np.abs(result.drift).max()) if balanced else None
    result.summary = {
        'scene': scene.name, 'robot': scene.model.name, 'engine': 'mujoco',
        'effects': scene.effects.names(), 'integrator': result.integrator,
        'step': dt, 'steps': steps, 'duration': steps * dt,
        'final_q': out_q[-1].tolist(), 'final_qd': out_qd[-1].tolist(),
        'tracking_rms': float(np.sqrt(np.mean(err ** 2))),
        'tracking_rms_per_joint': np.sqrt(np.mean(err ** 2,
                                                  axis=0)).tolist(),
        'tracking_max': float(np.abs(err).max()),
        'energy_drift_max': drift,
        'energy_drift_relative': None if drift is None else drift / scale,
        'wall_time_s': wall,
    }
    return result
