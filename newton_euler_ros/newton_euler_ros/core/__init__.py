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
Pure numpy/numba core: robot model, kinematics and dynamics (no ROS).

See :mod:`newton_euler_ros.core.dynamics` for the functions, one per term
of ``D(q) qdd + C(q, qd) qd + g(q) + J(q)^T F_e = tau``,
:mod:`newton_euler_ros.core.float32` for the same in single precision,
:mod:`newton_euler_ros.core.regressor` for the torque regressor
(``tau = Y pi``), :mod:`newton_euler_ros.core.drives` for joint friction
and rotor inertia, and :mod:`newton_euler_ros.core.observer` for the
momentum observer.
"""
import importlib

# where each name of the package's API lives: imported on first use
# (PEP 562), so that a program reading only, say, ``core.errors`` or
# ``core.text`` (the CLI's --help and its usage errors) does not load
# numba and the kernels
_WHERE = {
    'forward_dynamics_derivatives': 'derivatives',
    'forward_dynamics_derivatives_batch': 'derivatives',
    'inverse_dynamics_derivatives': 'derivatives',
    'inverse_dynamics_derivatives_batch': 'derivatives',
    'Drives': 'drives',
    'EffectDynamics': 'effects', 'Effects': 'effects',
    'DynamicsInputError': 'errors', 'NewtonEulerError': 'errors',
    'NotPositiveDefiniteError': 'errors', 'RobotFileError': 'errors',
    'Float32Dynamics': 'float32',
    'make_model': 'model', 'pose_matrix': 'model', 'RobotModel': 'model',
    'rpy_matrix': 'model',
    'MomentumObserver': 'observer', 'observe_recording': 'observer',
    'regressor': 'regressor', 'regressor_batch': 'regressor',
    'bundled_robots': 'robot_file', 'inspect_robot': 'robot_file',
    'load_robot': 'robot_file', 'robot_from_dict': 'robot_file',
    'RobotFileWarning': 'errors',
    'load_urdf': 'urdf', 'model_to_urdf': 'urdf',
    'Workspace': 'workspace',
}
_WHERE.update(dict.fromkeys((
    'coriolis_matrix', 'coriolis_matrix_batch', 'end_effector_pose',
    'forward_dynamics', 'forward_dynamics_batch', 'frame_pose',
    'gravity_torques', 'gravity_torques_batch', 'inverse_dynamics',
    'inverse_dynamics_batch', 'jacobian', 'link_poses', 'mass_matrix',
    'mass_matrix_batch', 'mass_matrix_condition', 'velocity_products',
    'wrench_torques'), 'dynamics'))


def __getattr__(name):
    """Import the module of one of the package's names on its first use."""
    where = _WHERE.get(name)
    if where is None:
        raise AttributeError(
            f'module {__name__!r} has no attribute {name!r}')
    value = getattr(importlib.import_module(f'.{where}', __name__), name)
    globals()[name] = value     # the next use is a plain lookup
    return value


def __dir__():
    return sorted(set(globals()) | set(_WHERE))


__all__ = [
    'Drives', 'DynamicsInputError', 'EffectDynamics', 'Effects',
    'Float32Dynamics', 'forward_dynamics_derivatives',
    'forward_dynamics_derivatives_batch', 'inverse_dynamics_derivatives',
    'inverse_dynamics_derivatives_batch', 'MomentumObserver', 'load_urdf', 'model_to_urdf',
    'observe_recording', 'regressor', 'regressor_batch',
    'NewtonEulerError', 'NotPositiveDefiniteError', 'RobotFileError', 'RobotFileWarning',
    'RobotModel', 'Workspace', 'bundled_robots', 'coriolis_matrix',
    'coriolis_matrix_batch', 'end_effector_pose', 'forward_dynamics',
    'forward_dynamics_batch', 'frame_pose', 'gravity_torques',
    'gravity_torques_batch',
    'inspect_robot', 'inverse_dynamics', 'inverse_dynamics_batch',
    'jacobian', 'link_poses', 'load_robot', 'make_model', 'mass_matrix',
    'mass_matrix_batch', 'mass_matrix_condition', 'pose_matrix',
    'robot_from_dict', 'rpy_matrix', 'velocity_products', 'wrench_torques',
]
