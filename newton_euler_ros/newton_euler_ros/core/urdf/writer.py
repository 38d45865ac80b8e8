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

"""Writing any model as URDF (for robot_state_publisher and RViz)."""
import math

import numpy as np

from ..model import REVOLUTE


def matrix_rpy(R):
    """ROS roll, pitch, yaw of a rotation matrix (R = Rz Ry Rx)."""
    R = np.asarray(R, dtype=float)
    cp = math.hypot(R[0, 0], R[1, 0])
    pitch = math.atan2(-R[2, 0], cp)
    if cp > 1e-12:
        roll = math.atan2(R[2, 1], R[2, 2])
        yaw = math.atan2(R[1, 0], R[0, 0])
    else:   # gimbal lock: put the whole rotation about x into roll
        roll = math.atan2(-R[1, 2], R[1, 1])
        yaw = 0.0
    return roll, pitch, yaw


def _fmt(values):
    return ' '.join(repr(float(v)) for v in values)


def _origin_xml(T, indent):
    xyz = T[:3, 3]
    rpy = matrix_rpy(T[:3, :3])
    return f'{indent}<origin xyz="{_fmt(xyz)}" rpy="{_fmt(rpy)}"/>'


def model_to_urdf(model, base_link='base_link', tool_link='tool0'):
    """
    Return URDF text of a model: links with inertials, joints with limits.

    URDF link k is the frame joint k moves (link frame k-1 . Pre_k . M(q));
    the model's link frame k sits at Post_k in it, so the inertial origin
    is Post_k applied to the centre of mass, with Post_k's rotation; joint
    k's origin is Post_{k-1} Pre_k (the base pose for k = 1).  The end
    effector is a fixed link ``tool_link``.  Loading the text back gives
    the same dynamics (the tests check tau, D, C, g and J).  A tree is
    written as one: joint k's parent link is that of ``model.parents[k]``
    (Post of that joint, the base pose on the base), a mimic joint gets
    its ``<mimic>``, and a model without an end effector no tool link.
    """
    n = model.nb
    names = model.moving_joints
    link_names = [f'link{k + 1}' for k in range(n)]
    lines = ['<?xml version="1.0"?>',
             f'<!-- {model.name}: written by newton-euler urdf from a '
             f'{model.convention} model; gravity in {base_link} axes: '
             f'{_fmt(model.gravity)} m/s^2 -->',
             f'<robot name="{model.name}">',
             f'  <link name="{base_link}"/>']
    base = np.asarray(model.base, dtype=float)
    posts = [model.joint_post_matrix(k) for k in range(n)]
    for k in range(n):
        post = posts[k]
        p = model.parents[k]
        origin = (posts[p] if p >= 0 else base) @ model.joint_pre_matrix(k)
        lim = model.limits[k] if k < len(model.limits) else {}
        kind = model.joint_types[k]
        if kind == REVOLUTE and not ('lower' in lim and 'upper' in lim):
            kind = 'continuous'
        parent = base_link if p < 0 else link_names[p]
        inertia = np.asarray(model.inertia[k])
        com = post[:3, :3] @ model.com[k] + post[:3, 3]
        inertial_pose = np.eye(4)
        inertial_pose[:3, :3] = post[:3, :3]
        inertial_pose[:3, 3] = com
        lines += [
            f'  <link name="{link_names[k]}">',
            '    <inertial>',
            _origin_xml(inertial_pose, '      '),
            f'      <mass value="{_fmt([model.mass[k]])}"/>',
            '      <inertia ' + ' '.join(
                f'{key}="{_fmt([inertia[i, k]])}"' for key, i, k in (
                    ('ixx', 0, 0), ('ixy', 0, 1), ('ixz', 0, 2),
                    ('iyy', 1, 1), ('iyz', 1, 2), ('izz', 2, 2))) + '/>',
            '    </inertial>',
            '  </link>',
            f'  <joint name="{names[k]}" type="{kind}">',
            f'    <parent link="{parent}"/>',
            f'    <child link="{link_names[k]}"/>',
            _origin_xml(origin, '    '),
            f'    <axis xyz="{_fmt(model.joint_axis[k])}"/>']
        attrs = [f'{key}="{_fmt([lim[key]])}"' for key in ('lower', 'upper')
                 if key in lim and kind != 'continuous']
        attrs += [f'{key}="{_fmt([lim.get(key, 0.0)])}"'
                  for key in ('effort', 'velocity')]
        lines.append(f'    <limit {" ".join(attrs)}/>')
        if model.mimic[k] is not None:
            leader, mult, offset = model.mimic[k]
            lines.append(f'    <mimic joint="{names[leader]}" multiplier='
                         f'"{_fmt([mult])}" offset="{_fmt([offset])}"/>')
        lines.append('  </joint>')
    b = model.tool_body
    if b is not None:
        on = posts[b] if b >= 0 else base
        lines += [f'  <link name="{tool_link}"/>',
                  f'  <joint name="{tool_link}_joint" type="fixed">',
                  f'    <parent link="'
                  f'{link_names[b] if b >= 0 else base_link}"/>',
                  f'    <child link="{tool_link}"/>',
                  _origin_xml(on @ np.asarray(model.tool, dtype=float),
                              '    '),
                  '  </joint>']
    lines += ['</robot>', '']
    return '\n'.join(lines)
