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
from .derivatives import (forward_dynamics_derivatives,
                          forward_dynamics_derivatives_batch,
                          inverse_dynamics_derivatives,
                          inverse_dynamics_derivatives_batch)
from .drives import Drives
from .dynamics import (coriolis_matrix, coriolis_matrix_batch,
                       end_effector_pose, forward_dynamics,
                       forward_dynamics_batch, frame_pose, gravity_torques,
                       gravity_torques_batch, inverse_dynamics,
                       inverse_dynamics_batch, jacobian, link_poses,
                       mass_matrix, mass_matrix_batch, mass_matrix_condition,
                       velocity_products, wrench_torques)
from .effects import EffectDynamics, Effects
from .errors import (DynamicsInputError, NewtonEulerError,
                     NotPositiveDefiniteError, RobotFileError)
from .float32 import Float32Dynamics
from .model import make_model, pose_matrix, RobotModel, rpy_matrix
from .observer import MomentumObserver, observe_recording
from .regressor import regressor, regressor_batch
from .robot_file import (bundled_robots, inspect_robot, load_robot,
                         robot_from_dict, RobotFileWarning)
from .urdf import load_urdf, model_to_urdf
from .workspace import Workspace

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
