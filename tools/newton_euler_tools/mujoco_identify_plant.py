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
The "real" Panda in MuJoCo, and a trajectory run on it and recorded.

The plant of :mod:`.mujoco_identify`: the published URDF with perturbed
inertials (``demo_identify.real_plant_urdf``), viscous and Coulomb
friction written as ``<dynamics damping friction>`` and rotor inertia as
``<ne:drive armature>`` (``ident.urdf_out``'s writer), compiled by
MuJoCo's own reader (``sim.mujoco_model``): MuJoCo's friction is its
``frictionloss`` constraint and its damping and armature its own, not
the library's drive terms.

:func:`run` stands in for joint_trajectory_controller with an effort
interface on the arm: the plan's efforts (the feedforward a model fills
in, ``core.trajectory.trajectory_efforts``, with the drive terms when
compensated) plus PD on the plan, sampled as the simulator node samples
it (``core.trajectory.TrajectoryFollower``), computed every physics tick
(1 kHz) and held over it.  The joint states are sampled at a driver's
rate with a sensor's noise; the effort is the torque the motors applied
(clamped to the effort limits).
"""
from dataclasses import dataclass
import math
import xml.etree.ElementTree as ET

import numpy as np

from .demo_identify import (ARMATURE, COULOMB, KD, KP, quiet_load,
                            real_plant_urdf, START, VISCOUS)

PHYSICS_STEP = 1e-3         # s: MuJoCo's step, the controller's tick
DRIVER_RATE = 500.0         # Hz: the joint states recorded
# the sensors: an encoder of 2^20 counts per turn read with 1e-5 rad of
# noise, a velocity estimate with 1e-3 rad/s, a torque reading with
# 0.05 N m (Gaussian, standard deviations)
QUANTUM = 2.0 * math.pi / 2 ** 20
NOISE = {'position': 1.0e-5, 'velocity': 1.0e-3, 'effort': 0.05}


def plant_urdf(published_text, links, seed):
    """
    Return the true robot's URDF text.

    Perturbed inertials ending at ``panda_link8`` (hand lumped), every
    joint's ``<dynamics damping friction>`` and ``<ne:drive armature>``
    the plant's (offset 0 and no Coulomb width: MuJoCo has neither), no
    ``<collision>`` (the arm moves in free space: no contact, and no mesh
    to resolve).
    """
    from newton_euler_ros.core.drives import (DEFAULT_COULOMB_WIDTH,
                                              DRIVES_NS, DRIVES_PREFIX,
                                              Drives)
    from newton_euler_ros.ident.urdf_out import _set_drive
    text = real_plant_urdf(published_text, links, seed)
    ET.register_namespace(DRIVES_PREFIX, DRIVES_NS)
    root = ET.fromstring(text)
    n = len(VISCOUS)
    drives = Drives(np.array(VISCOUS), np.array(COULOMB), np.zeros(n),
                    np.array(ARMATURE), np.full(n, DEFAULT_COULOMB_WIDTH))
    joints = {el.get('name'): el for el in root.findall('joint')}
    for j in range(n):
        el = joints[f'panda_joint{j + 1}']
        _set_drive(el, drives, j)
        # MuJoCo's friction is a constraint: no tanh, no width
        del el.find(f'{{{DRIVES_NS}}}drive').attrib['coulomb_width']
    for link in root.findall('link'):
        for el in link.findall('collision'):
            link.remove(el)
    return ET.tostring(root, encoding='unicode')


def load_plant(path, joints):
    """Compile the true robot's URDF file in MuJoCo at 1 kHz."""
    from newton_euler_ros.sim.mujoco_model import load_mujoco
    return load_mujoco(path, joints=joints, timestep=PHYSICS_STEP)


def feedforward_model(urdf_path, compensate):
    """
    Return (model, drives) of a URDF as the node would use them.

    ``compensate``: the URDF's drive terms (``core.drives.model_drives``,
    what ``drives.compensate`` adds), else None.
    """
    from newton_euler_ros.core.drives import model_drives
    model = quiet_load(urdf_path)
    return model, (model_drives(model) if compensate else None)


def plan_points(trajectory, model, drives):
    """Return the trajectory's points with the model's efforts filled."""
    from newton_euler_ros.core.trajectory import trajectory_efforts
    names, points = trajectory['joint_names'], trajectory['points']
    efforts = trajectory_efforts(model, names, points, drives=drives)
    return [dict(p, effort=e.tolist()) for p, e in zip(points, efforts)]


@dataclass
class Run:
    """A run on the plant: the truth and what the driver reported."""

    t: np.ndarray           # (m,) s, from the release
    q: np.ndarray           # (m, n) true positions
    q_ref: np.ndarray       # (m, n) the plan sampled there
    applied: np.ndarray     # (m, n) torque the motors applied, N m
    measured: tuple         # (q, qd, effort) with the sensors' noise
    motion: tuple           # (start, end) of the plan, s
    seconds: float          # wall time of the physics and control

    def tracking(self):
        """Return (RMS, max, per-joint RMS) of q_ref - q while moving."""
        inside = (self.t >= self.motion[0]) & (self.t <= self.motion[1])
        err = (self.q_ref - self.q)[inside]
        return (float(np.sqrt(np.mean(err ** 2))), float(np.abs(err).max()),
                np.sqrt(np.mean(err ** 2, axis=0)).tolist())

    def write_bag(self, path, names):
        """Write the driver's joint states as a rosbag2 (MCAP)."""
        from newton_euler_ros.ident.bag_write import write_joint_states
        stamps = np.round(self.t * 1e9).astype(np.int64) + 1_000_000_000
        write_joint_states(path, stamps, names, *self.measured)


def run(robot, names, model, points, rest, rng):
    """
    Track ``points`` (efforts filled) on a fresh plant; return a Run.

    The arm starts at rest at the plan's first point, released at t = 0;
    it stands there for ``rest[0]`` s under the controller, follows the
    plan, and stands at its end for ``rest[1]`` s.
    """
    import time
    from newton_euler_ros.core.trajectory import TrajectoryFollower
    from newton_euler_ros.sim.mujoco_plant import MujocoPlant
    follower = TrajectoryFollower(model)
    follower.set(names, rest[0], points)
    order = [list(names).index(j) for j in robot.joints]
    kp, kd = np.asarray(KP)[order], np.asarray(KD)[order]
    cols = [list(model.joint_names).index(j) for j in robot.joints]
    q0 = np.asarray(points[0]['positions'])[order]
    plan_end = rest[0] + points[-1]['time_from_start']
    ticks = int(round((plan_end + rest[1]) / PHYSICS_STEP))
    every = int(round(1.0 / (DRIVER_RATE * PHYSICS_STEP)))
    plant = MujocoPlant(robot, q0)
    plant.release()
    rows = []
    began = time.perf_counter()
    first = follower.sample(rest[0])
    for k in range(ticks):
        t = k * PHYSICS_STEP
        q, qd = plant.state()
        q_d, qd_d, eff = first if t < rest[0] else follower.sample(t)
        q_d, qd_d, eff = q_d[cols], qd_d[cols], eff[cols]
        plant.advance(kp * (q_d - q) + kd * (qd_d - qd) + eff,
                      PHYSICS_STEP)
        if (k + 1) % every == 0:
            t1 = (k + 1) * PHYSICS_STEP
            q1, qd1 = plant.state()
            ref = first[0] if t1 < rest[0] else follower.sample(t1)[0]
            rows.append((t1, q1, qd1, ref[cols], plant.applied()))
    seconds = time.perf_counter() - began
    t = np.array([r[0] for r in rows])
    q, qd, q_ref, applied = (np.array([r[i] for r in rows])
                             for i in (1, 2, 3, 4))
    return Run(t, q, q_ref, applied, sense(q, qd, applied, rng),
               (rest[0], plan_end), seconds)


def sense(q, qd, effort, rng):
    """Return (q, qd, effort) as the driver reports them (noise, counts)."""
    q = np.round((q + rng.normal(0.0, NOISE['position'], q.shape))
                 / QUANTUM) * QUANTUM
    qd = qd + rng.normal(0.0, NOISE['velocity'], qd.shape)
    effort = effort + rng.normal(0.0, NOISE['effort'], effort.shape)
    return q, qd, effort


__all__ = ['DRIVER_RATE', 'feedforward_model', 'load_plant', 'NOISE',
           'PHYSICS_STEP', 'plan_points', 'plant_urdf', 'QUANTUM', 'run',
           'Run', 'START']
