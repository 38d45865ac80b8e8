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
Rigid transforms in any number type: the joints' constant placements.

A model keeps each joint's constant transforms as lists of elementary
operations (``('rz', theta)``, ``('xyz', x, y, z)``, ``('rpy', r, p, y)``,
...; :data:`OPS`) so that they can be evaluated in any number type:
float64 for the kernels (:class:`Float64Math`), mpmath for the 50-digit
reference.  :func:`evaluate_ops` composes them into (R, p) as nested
lists; :func:`rpy_matrix` and :func:`pose_matrix` are the float64 ROS
conventions.
"""
import math

import numpy as np


def rpy_matrix(roll, pitch, yaw):
    """Rotation of ROS roll-pitch-yaw angles: Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr]])


def pose_matrix(xyz=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0)):
    """4x4 homogeneous transform from a translation and ROS rpy angles."""
    T = np.eye(4)
    T[:3, :3] = rpy_matrix(*rpy)
    T[:3, 3] = xyz
    return T


class Float64Math:
    """The number type of the kernels: float64 with ``math``."""

    cos = staticmethod(math.cos)
    sin = staticmethod(math.sin)
    sqrt = staticmethod(math.sqrt)
    num = staticmethod(float)


OPS = {'tx': 1, 'ty': 1, 'tz': 1, 'rx': 1, 'ry': 1, 'rz': 1, 'xyz': 3,
       'rpy': 3, 'matrix': 12}


def _identity(m):
    z, o = m.num(0.0), m.num(1.0)
    return [[o, z, z], [z, o, z], [z, z, o]], [z, z, z]


def _mul(A, B):
    return [[A[i][0] * B[0][k] + A[i][1] * B[1][k] + A[i][2] * B[2][k]
             for k in range(3)] for i in range(3)]


def _apply(A, x):
    return [A[i][0] * x[0] + A[i][1] * x[1] + A[i][2] * x[2]
            for i in range(3)]


def _compose(X, Y):
    """(R1, p1) . (R2, p2) = (R1 R2, p1 + R1 p2)."""
    (R1, p1), (R2, p2) = X, Y
    t = _apply(R1, p2)
    return _mul(R1, R2), [p1[i] + t[i] for i in range(3)]


def _transpose(A):
    return [[A[k][i] for k in range(3)] for i in range(3)]


def _elementary(op, args, m):
    """(R, p) of one operation, in the number type of ``m``."""
    R, p = _identity(m)
    if op in ('tx', 'ty', 'tz'):
        p['xyz'.index(op[1])] = m.num(args[0])
    elif op in ('rx', 'ry', 'rz'):
        c, s = m.cos(m.num(args[0])), m.sin(m.num(args[0]))
        i = 'xyz'.index(op[1])
        a, b = (i + 1) % 3, (i + 2) % 3
        R[a][a], R[a][b], R[b][a], R[b][b] = c, -s, s, c
    elif op == 'xyz':
        p = [m.num(x) for x in args]
    elif op == 'rpy':
        for angle, axis in zip(args[::-1], 'zyx'):
            R = _mul(R, _elementary('r' + axis, (angle,), m)[0])
    elif op == 'matrix':
        R = [[m.num(args[3 * i + k]) for k in range(3)] for i in range(3)]
        p = [m.num(x) for x in args[9:]]
    else:
        raise ValueError(f'unknown transform operation {op!r}')
    return R, p


def evaluate_ops(ops, m=Float64Math):
    """Compose a list of elementary operations into (R, p)."""
    X = _identity(m)
    for op in ops:
        X = _compose(X, _elementary(op[0], op[1:], m))
    return X


def matrix_op(T):
    """Return the operation ``('matrix', ...)`` of a 4x4 transform."""
    T = np.asarray(T, dtype=np.float64)
    return ('matrix',) + tuple(float(x) for x in T[:3, :3].ravel()) + tuple(
        float(x) for x in T[:3, 3])


def ops_matrix(ops):
    """4x4 float64 transform of a list of operations."""
    R, p = evaluate_ops(ops)
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


def axis_frame(axis, m=Float64Math):
    """
    Return a rotation A with A z = axis (a unit vector).

    Exact for +-x, +-y and +-z.

    For axis_z >= 0 it is the rotation about z x axis (Rodrigues, written
    with k = 1 / (1 + z)); for axis_z < 0, A(-axis) Rx(pi), which keeps
    1 + z away from zero.
    """
    x, y, z = (m.num(v) for v in axis)
    o = m.num(1.0)
    if z >= 0:
        k = o / (o + z)
        return [[o - x * x * k, -(x * y * k), x],
                [-(x * y * k), o - y * y * k, y],
                [-x, -y, z]]
    k = o / (o - z)
    return [[o - x * x * k, x * y * k, x],
            [-(x * y * k), -(o - y * y * k), y],
            [x, -y, z]]
