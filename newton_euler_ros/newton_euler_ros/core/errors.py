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

"""Exception types of the core library."""


class NewtonEulerError(Exception):
    """Base class of every error this package raises on purpose."""


class RobotFileError(NewtonEulerError, ValueError):
    """
    A robot (or scene) description is invalid.

    The message names the file, the link and the field, e.g.
    ``puma560.yaml: links[2] (joint3): mass: must be >= 0, got -1.0``.
    """


class DynamicsInputError(NewtonEulerError, ValueError):
    """
    A state or wrench passed to a dynamics function is unusable.

    Raised for a wrong size or a non-finite entry; the message names the
    argument and the index, e.g. ``qd[3] is nan; every entry must be
    finite``.
    """


class NotPositiveDefiniteError(NewtonEulerError, ArithmeticError):
    """
    The mass matrix is not positive definite, so it cannot be inverted.

    ``joint`` is the index of the first joint whose Cholesky pivot is not
    positive: that joint, given the joints before it, moves no mass or
    inertia (for example a massless tail of the chain).
    """

    def __init__(self, message, joint):
        super().__init__(message)
        self.joint = joint


class RobotFileWarning(UserWarning):
    """A robot file is accepted but something in it is suspicious."""


class SlowInputWarning(UserWarning):
    """An input is converted on every call: right, but about 0.1 ms more."""
