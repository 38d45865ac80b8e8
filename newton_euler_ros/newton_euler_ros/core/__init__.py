"""Pure numpy/numba core: robot model, kinematics and dynamics (no ROS).

See :mod:`newton_euler_ros.core.dynamics` for the functions, one per term
of ``D(q) qdd + C(q, qd) qd + g(q) + J(q)^T F_e = tau``.
"""
from .dynamics import (Workspace, coriolis_matrix, end_effector_pose,
                       forward_dynamics, gravity_torques, inverse_dynamics,
                       inverse_dynamics_batch, jacobian, link_poses,
                       mass_matrix, velocity_products, wrench_torques)
from .errors import (DynamicsInputError, NewtonEulerError,
                     NotPositiveDefiniteError, RobotFileError)
from .model import RobotModel, make_model, pose_matrix, rpy_matrix
from .robot_file import (RobotFileWarning, bundled_robots, inspect_robot,
                         load_robot, robot_from_dict)

__all__ = [
    'DynamicsInputError', 'NewtonEulerError', 'NotPositiveDefiniteError',
    'RobotFileError', 'RobotFileWarning', 'RobotModel', 'Workspace',
    'bundled_robots', 'coriolis_matrix', 'end_effector_pose',
    'forward_dynamics', 'gravity_torques', 'inspect_robot',
    'inverse_dynamics', 'inverse_dynamics_batch', 'jacobian', 'link_poses',
    'load_robot', 'make_model', 'mass_matrix', 'pose_matrix',
    'robot_from_dict', 'rpy_matrix', 'velocity_products', 'wrench_torques',
]
