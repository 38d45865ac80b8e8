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
Deterministic simulation of a scene, paying only for its effects.

The scene's effects select the terms (:mod:`..core.effects`): without
gravity the recursion skips gravity entirely, without velocity products
it skips every velocity term, without a wrench no Jacobian is formed, and
friction and rotor inertia are added only when present.  Forward
dynamics solve ``(D + diag(armature)) qdd = tau - bias`` by Cholesky.

Energy bookkeeping integrates, alongside the state, the work of the
applied torques, of friction and of the end-effector wrench, so that
``drift = E(t) - E(0) - W_tau - W_friction - W_wrench`` shows the
integrator's error alone.
"""
from dataclasses import dataclass, field
import time

import numpy as np

from .scene import INTEGRATORS
from ..core.dynamics import jacobian, link_poses
from ..core.effects import EffectDynamics
from ..core.errors import DynamicsInputError


def pd_torque(scene, q_d, qd_d, q, qd):
    """Return the scene's PD law, kp (q_d - q) + kd (qd_d - qd)."""
    return scene.kp * (q_d - q) + scene.kd * (qd_d - qd)


class SceneDynamics(EffectDynamics):
    """
    A scene's :class:`EffectDynamics`, with its energy and power.

    Its effects, friction and rotor inertia are the scene's; the wrench is
    an argument of every method, as for the base class (the scene's own
    is :meth:`Scene.wrench_at`).
    """

    def __init__(self, scene):
        super().__init__(scene.model, scene.effects, scene.viscous,
                         scene.coulomb, scene.armature)
        self.scene = scene

    def energy(self, q, qd):
        """Kinetic (with rotor inertia) plus gravitational potential."""
        T = 0.5 * qd @ self.mass_matrix(q, out=self._D) @ qd
        U = 0.0
        if self.effects.gravity:
            poses = link_poses(self.model, q, ws=self.ws)
            g = self.model.gravity
            for j in range(self.model.nb):      # every body of a tree
                c = poses[j + 1, :3, :3] @ self.model.com[j] + \
                    poses[j + 1, :3, 3]
                U -= self.model.mass[j] * (g @ c)
        return T + U

    def power(self, q, qd, tau, wrench=None, frame='base'):
        """(P_tau, P_friction, P_wrench): power into the robot."""
        p_tau = qd @ tau
        p_f = -(qd @ self.friction(qd)) if self.effects.friction else 0.0
        p_w = 0.0
        if self.effects.wrench and wrench is not None:
            p_w = -(jacobian(self.model, q, frame, ws=self.ws) @ qd) @ wrench
        return p_tau, p_f, p_w


def advance(method, accel, q, qd, t, h, power=None):
    """
    Return (q, qd, work) one step of ``h`` later: the one integrator step.

    ``accel(t, q, qd)`` gives the accelerations (the torques are held over
    the step by the caller).  ``method`` is 'rk4' (four calls) or
    'semi_implicit_euler' (one: qd first, then q with the new qd).  With
    ``power(t, q, qd)``, ``work`` is its integral over the step by the same
    rule (RK4's weights; the end state for semi-implicit Euler), else 0.
    """
    if method == 'rk4':
        a1 = accel(t, q, qd)
        q2, v2 = q + 0.5 * h * qd, qd + 0.5 * h * a1
        a2 = accel(t + 0.5 * h, q2, v2)
        q3, v3 = q + 0.5 * h * v2, qd + 0.5 * h * a2
        a3 = accel(t + 0.5 * h, q3, v3)
        q4, v4 = q + h * v3, qd + h * a3
        a4 = accel(t + h, q4, v4)
        work = 0.0
        if power is not None:
            work = h / 6.0 * (power(t, q, qd) + 2 * power(t + 0.5 * h, q2, v2)
                              + 2 * power(t + 0.5 * h, q3, v3)
                              + power(t + h, q4, v4))
        return (q + h / 6.0 * (qd + 2 * v2 + 2 * v3 + v4),
                qd + h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4), work)
    if method == 'semi_implicit_euler':
        qd = qd + h * accel(t, q, qd)
        q = q + h * qd
        work = 0.0 if power is None else h * power(t + h, q, qd)
        return q, qd, work
    raise ValueError(f'integrator must be one of {", ".join(INTEGRATORS)}, '
                     f'got {method!r}')


def integrator_step(dyn, method, q, qd, tau, t, h, wrench_at=None):
    """
    Return (q, qd) one step of ``h`` later, holding the torques ``tau``.

    The stepping of the simulator node and of the integrator
    measurements: :func:`advance` on the scene's forward dynamics.
    ``wrench_at(t) -> (wrench or None, frame)`` gives the wrench at each
    stage (default: the scene's own, :meth:`Scene.wrench_at`).
    """
    wrench_at = wrench_at or dyn.scene.wrench_at
    q, qd, _ = advance(
        method,
        lambda t, q, qd: dyn.accelerations(q, qd, tau, *wrench_at(t)),
        q, qd, t, h)
    return q, qd


FEEDFORWARD_AT = ('desired', 'measured')


def check_feedforward_at(value):
    """Return ``value`` if it is 'desired' or 'measured'; else raise."""
    if not isinstance(value, str) or value not in FEEDFORWARD_AT:
        raise ValueError(f"feedforward_at must be 'desired' or 'measured', "
                         f'got {value!r}')
    return value


def tracking_controller(dyn, feedforward=None, feedforward_at='desired'):
    """
    PD on the scene's reference, plus feedforward torques.

    ``feedforward`` defaults to the scene's setting.  The feedforward is
    the scene's inverse dynamics at the desired state (q_d, qd_d, qdd_d)
    with ``feedforward_at='desired'``, or at the measured state
    (q, qd, qdd_d) with ``'measured'``: the reference acceleration with
    the measured positions and velocities.
    """
    scene = dyn.scene
    use_ff = scene.feedforward if feedforward is None else feedforward
    measured = check_feedforward_at(feedforward_at) == 'measured'

    def control(t, q, qd):
        q_d, qd_d, qdd_d = scene.reference.at(t)
        tau = pd_torque(scene, q_d, qd_d, q, qd)
        if not use_ff:
            ff = np.zeros_like(q)
        elif measured:
            ff = dyn.torques(q, qd, qdd_d, *scene.wrench_at(t))
        else:
            ff = dyn.torques(q_d, qd_d, qdd_d, *scene.wrench_at(t))
        return tau + ff, ff
    return control


@dataclass
class SimulationResult:
    """Sampled trajectory and summary of one simulation run."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    tau: np.ndarray
    tau_ff: np.ndarray
    q_ref: np.ndarray
    energy: np.ndarray
    work: np.ndarray          # (steps + 1, 3): tau, friction, wrench
    wall_time: float
    effects: list
    integrator: str
    step: float
    summary: dict = field(default_factory=dict)

    @property
    def drift(self):
        """E(t) - E(0) minus the work done on the robot."""
        return self.energy - self.energy[0] - self.work.sum(axis=1)


class IntegrationDiverged(DynamicsInputError):
    """The state grew without bound: the step is too long for the gains."""


def diverged(scene, method, dt, t):
    """
    Return the error of an integration that diverged at time ``t``.

    It names the time step and the largest gains, with their joints.
    """
    names = scene.model.joint_names
    i, j = int(np.argmax(scene.kp)), int(np.argmax(scene.kd))
    return IntegrationDiverged(
        f'{scene.name}: the integration diverged at t = {t:.4g} s '
        f'({method}, time step {dt:g} s, gains kp up to '
        f'{scene.kp[i]:g} ({names[i]}) and kd up to {scene.kd[j]:g} '
        f'({names[j]})): use a smaller integrator step or lower '
        f'controller gains')


def _close(bar):
    if bar is not None:
        bar.close()


def simulate_builtin(scene, duration=None, controller=None,
                     feedforward=None, integrator=None, step=None,
                     progress=False, feedforward_at='desired'):
    """
    Simulate a scene deterministically in this engine; a SimulationResult.

    ``controller(t, q, qd) -> (tau, tau_ff)`` defaults to
    :func:`tracking_controller` (with ``feedforward`` and
    ``feedforward_at``, 'desired' or 'measured'); torques are held
    constant over each step (as a digital controller would).
    ``progress`` shows a progress bar.  Whatever the scene's ``engine``:
    :func:`.run.simulate` chooses the engine a scene asks for.
    """
    check_feedforward_at(feedforward_at)
    dyn = SceneDynamics(scene)
    control = controller or tracking_controller(dyn, feedforward,
                                                feedforward_at)
    method = integrator or scene.integrator
    dt = step or scene.step
    T = scene.duration if duration is None else duration
    if not T > 0.0:
        raise ValueError(f'duration must be > 0 s, got {T}')
    # at least one step: a duration under half a step is one step, not none
    steps = max(1, int(round(T / dt)))
    n = scene.model.n
    q, qd = scene.q0.astype(float).copy(), scene.qd0.astype(float).copy()
    out_t = np.arange(steps + 1) * dt
    out_q = np.empty((steps + 1, n))
    out_qd = np.empty((steps + 1, n))
    out_tau = np.zeros((steps + 1, n))
    out_ff = np.zeros((steps + 1, n))
    out_ref = np.empty((steps + 1, n))
    out_e = np.empty(steps + 1)
    out_w = np.zeros((steps + 1, 3))
    work = np.zeros(3)
    bar = None
    if progress:
        try:
            from tqdm import tqdm
            bar = tqdm(total=steps, unit='step', desc=scene.name,
                       mininterval=0.5)
        except ImportError:
            bar = None

    if method not in INTEGRATORS:
        raise ValueError(f'integrator must be one of '
                         f'{", ".join(INTEGRATORS)}, got {method!r}')
    start = time.perf_counter()
    # a diverging integration overflows: said once, as such (below)
    with np.errstate(over='ignore', invalid='ignore'):
        for k in range(steps + 1):
            t = k * dt
            out_q[k], out_qd[k] = q, qd
            out_ref[k] = scene.reference.at(t)[0]
            try:
                out_e[k] = dyn.energy(q, qd)
                out_w[k] = work
                if k == steps:
                    break
                tau, ff = control(t, q, qd)
                out_tau[k], out_ff[k] = tau, ff
                q, qd, w = advance(
                    method,
                    lambda t, q, qd: dyn.accelerations(
                        q, qd, tau, *scene.wrench_at(t)),
                    q, qd, t, dt,
                    lambda t, q, qd: np.array(dyn.power(
                        q, qd, tau, *scene.wrench_at(t))))
            except DynamicsInputError:
                if k == 0:          # the scene's own start: its inputs
                    raise
                _close(bar)
                raise diverged(scene, method, dt, t) from None
            if not (np.isfinite(q).all() and np.isfinite(qd).all()):
                _close(bar)
                raise diverged(scene, method, dt, t + dt)
            work = work + w
            if bar is not None:
                bar.update(1)
    _close(bar)
    out_tau[-1], out_ff[-1] = out_tau[-2], out_ff[-2]
    wall = time.perf_counter() - start
    result = SimulationResult(out_t, out_q, out_qd, out_tau, out_ff, out_ref,
                              out_e, out_w, wall, scene.effects.names(),
                              method, dt)
    err = out_q - out_ref
    scale = max(1.0, float(np.abs(out_e).max()))
    result.summary = {
        'scene': scene.name,
        'robot': scene.model.name,
        'effects': scene.effects.names(),
        'integrator': method,
        'step': dt,
        'steps': steps,
        'duration': steps * dt,
        'final_q': out_q[-1].tolist(),
        'final_qd': out_qd[-1].tolist(),
        'tracking_rms': float(np.sqrt(np.mean(err ** 2))),
        'tracking_rms_per_joint': np.sqrt(np.mean(err ** 2,
                                                  axis=0)).tolist(),
        'tracking_max': float(np.abs(err).max()),
        'energy_drift_max': float(np.abs(result.drift).max()),
        'energy_drift_relative': float(np.abs(result.drift).max() / scale),
        'wall_time_s': wall,
    }
    return result
