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
Random kinematic trees written as URDF text (test data).

Seeded: each link hangs from a random earlier one (so trees branch, also
at the root), by a revolute, continuous, prismatic or fixed joint with a
random origin and axis; links carry random valid inertias (some none: a
massless frame on a fixed joint); some revolute and prismatic joints mimic an earlier
joint of the same type (multiplier and offset random).  Both our loader
and Pinocchio's read the same text.
"""
import numpy as np

INERTIAL = ('<inertial><origin xyz="{xyz}" rpy="{rpy}"/><mass value="{m}"/>'
            '<inertia ixx="{ixx}" ixy="{ixy}" ixz="{ixz}" iyy="{iyy}" '
            'iyz="{iyz}" izz="{izz}"/></inertial>')


def _vec(x):
    return ' '.join(f'{v:.17g}' for v in x)


def _inertial(rng):
    m = rng.uniform(0.2, 3.0)
    second = m * rng.uniform(0.002, 0.05, 3)
    principal = np.array([second[1] + second[2], second[0] + second[2],
                          second[0] + second[1]])
    # a random symmetric positive definite tensor: Q diag Q^T
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    Ic = Q @ np.diag(principal) @ Q.T
    return INERTIAL.format(
        xyz=_vec(rng.uniform(-0.15, 0.15, 3)),
        rpy=_vec(rng.uniform(-3, 3, 3)), m=f'{m:.17g}',
        ixx=f'{Ic[0, 0]:.17g}', ixy=f'{Ic[0, 1]:.17g}',
        ixz=f'{Ic[0, 2]:.17g}', iyy=f'{Ic[1, 1]:.17g}',
        iyz=f'{Ic[1, 2]:.17g}', izz=f'{Ic[2, 2]:.17g}')


def random_tree_urdf(seed, links=9, mimic=2, kinds=('revolute', 'continuous',
                                                    'prismatic', 'fixed')):
    """
    Return (URDF text, joint names) of a random tree of ``links`` links.

    Link 0 is the root ``base``, link k ``l<k>`` (two digits) on joint
    ``j<k>``; ``mimic`` joints (at most) follow a moving joint of their
    type that comes before them depth first (children in document order,
    which is also name order here: Pinocchio's).
    """
    rng = np.random.default_rng(seed)
    parts = ['<?xml version="1.0"?>', f'<robot name="tree{seed}">',
             '<link name="base"/>']
    joints = []
    kinds_of = {}
    parent_of = {}
    for k in range(1, links):
        parent = 0 if k == 1 else int(rng.integers(0, k))
        parent_of[k] = parent
        kind = str(rng.choice(kinds))
        if k == 1 and kind == 'fixed':
            kind = 'revolute'
        # a frame without inertial only on a fixed joint (a moving link
        # carrying nothing would leave D singular)
        inertial = ('' if kind == 'fixed' and rng.random() < 0.3
                    else _inertial(rng))
        parts.append(f'<link name="l{k:02d}">{inertial}</link>')
        axis = rng.normal(size=3)
        if rng.random() < 0.3:          # an axis along a frame axis
            axis = np.eye(3)[rng.integers(0, 3)] * rng.choice([-1, 1])
        body = (f'<joint name="j{k:02d}" type="{kind}">'
                f'<parent link="{"base" if parent == 0 else f"l{parent:02d}"}"'
                f'/><child link="l{k:02d}"/><origin xyz="'
                f'{_vec(rng.uniform(-0.4, 0.4, 3))}" rpy="'
                f'{_vec(rng.uniform(-3, 3, 3))}"/>')
        if kind != 'fixed':
            body += f'<axis xyz="{_vec(axis)}"/>'
        if kind in ('revolute', 'prismatic'):
            body += ('<limit lower="-3" upper="3" effort="100" '
                     'velocity="2"/>')
        if kind == 'continuous':
            body += '<limit effort="100" velocity="2"/>'
        joints.append((f'j{k:02d}', kind, body))
        kinds_of[f'j{k:02d}'] = kind
    order = _depth_first(parent_of)
    followers = {}
    candidates = [f'j{k:02d}' for k in order
                  if kinds_of[f'j{k:02d}'] in ('revolute', 'prismatic')]
    for i in range(len(candidates) - 1, -1, -1):
        name = candidates[i]
        if len(followers) >= mimic:
            break
        leaders = [c for c in candidates[:i] if c not in followers
                   and kinds_of[c] == kinds_of[name]]
        if leaders:
            followers[name] = (str(rng.choice(leaders)),
                               rng.choice([-1, 1]) * rng.uniform(0.3, 1.5),
                               rng.uniform(-0.5, 0.5))
    for name, kind, body in joints:
        if name in followers and followers[name][0] not in followers:
            leader, mult, off = followers[name]
            body += (f'<mimic joint="{leader}" multiplier="{mult:.17g}" '
                     f'offset="{off:.17g}"/>')
        parts.append(body + '</joint>')
    parts.append('</robot>')
    return '\n'.join(parts), [name for name, _, _ in joints]


def _depth_first(parent_of):
    """Link numbers depth first from the root, children in number order."""
    kids = {}
    for k, p in sorted(parent_of.items()):
        kids.setdefault(p, []).append(k)
    out, stack = [], list(reversed(kids.get(0, [])))
    while stack:
        k = stack.pop()
        out.append(k)
        stack.extend(reversed(kids.get(k, [])))
    return out
