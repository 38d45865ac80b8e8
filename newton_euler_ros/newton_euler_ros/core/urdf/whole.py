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
The whole URDF tree below a base link as one model (no tip given).

- Joint order: depth first from the base link, each link's child joints
  in URDF document order (Pinocchio's order for the same file); a joint's
  parent is the nearest moving joint above it (-1: the base).
- Every ``revolute``, ``continuous`` and ``prismatic`` joint below the base
  is a joint of the model; ``fixed`` joints merge as on a chain: their
  origins compose into the next moving joint's placement and the links
  they carry into the moving link's body (``inertia.merge_bodies``).  A
  ``floating`` or ``planar`` joint below the base is an error.
- ``<mimic joint= multiplier= offset=>``: the joint follows its leader,
  q = multiplier q_leader + offset, chains of mimic joints resolved to
  the root leader (q = m1 (m2 q_root + o2) + o1); it is not a coordinate
  (``model.joint_names`` lists the others), as Pinocchio's
  ``buildModelFromUrdf(path, mimic=True)``.
- The end effector is the leaf link when the tree below the base has
  one; with several tips there is none (``model.tool_body`` None: name a
  link for a Jacobian or a wrench).
- Every link below the base (and those fixed above it) is a named frame
  of the model (``model.link_frames``).
"""
import numpy as np

from .tree import combine, fixed_above, MOVING
from ..errors import RobotFileError
from ..inertia import triangle_note
from ..model import make_chain
from ..text import clip


class _Walk:
    """The depth-first walk: bodies, placements, parts and named frames."""

    def __init__(self, label, links, joints, base):
        self.label = label
        self.links, self.joints = links, joints
        self.moving = []        # joint names, one per body
        self.parents = []
        self.pre = []           # placement ops in the parent's link frame
        self.parts = []         # per body: [(link, pose, via joint)]
        self.base_parts = [(base, np.eye(4), None)]
        self.fixed = []         # merged fixed joints
        self.order = []         # every joint below the base, walked
        self.frames = {base: (-1, np.eye(4))}
        # depth first, children in document order: a joint is numbered
        # when it is taken off the stack, its child link's joints pushed
        # last-first so that the first one comes next
        stack = [(j, -1, (), np.eye(4))
                 for j in reversed(links[base].child_joints)]
        while stack:
            child, body, ops, T = self._child(*stack.pop())
            stack.extend((j, body, ops, T)
                         for j in reversed(links[child].child_joints))

    def _child(self, jname, body, ops, T):
        """Visit joint ``jname`` below a link of ``body``; return its child."""
        joint = self.joints[jname]
        self.order.append(jname)
        if joint.kind in ('floating', 'planar'):
            raise RobotFileError(
                f'{self.label}: joint {jname!r} type: a {joint.kind} joint '
                f'is in the tree below the base; only revolute, continuous,'
                f' prismatic and fixed joints can be: start below it (base '
                f'link {joint.child!r}), or give a tip link whose chain '
                f'avoids it')
        if joint.kind == 'fixed':
            self.fixed.append(jname)
            Tc = T @ joint.origin
            part = (joint.child, Tc, jname)
            (self.base_parts if body < 0 else self.parts[body]).append(part)
            self.frames[joint.child] = (body, Tc)
            return joint.child, body, tuple(ops) + tuple(joint.origin_ops), Tc
        k = len(self.moving)
        self.moving.append(jname)
        self.parents.append(body)
        self.pre.append(tuple(ops) + tuple(joint.origin_ops))
        self.parts.append([(joint.child, np.eye(4), jname)])
        self.frames[joint.child] = (k, np.eye(4))
        return joint.child, k, (), np.eye(4)


def _mimic(label, joints, walk):
    """Each body's mimic (leader body, multiplier, offset), resolved."""
    index = {name: k for k, name in enumerate(walk.moving)}
    out = []
    for name in walk.moving:
        mult, offset, seen = 1.0, 0.0, [name]
        leader = name
        while joints[leader].mimic is not None:
            other, m, o = joints[leader].mimic
            if other in seen:       # parse_urdf refuses cycles already
                raise RobotFileError(f'{label}: joint {name!r} <mimic> '
                                     f'joint: a cycle ({" -> ".join(seen)})')
            seen.append(other)
            offset, mult = offset + mult * o, mult * m
            leader = other
        if leader == name:
            out.append(None)
            continue
        if leader not in index:
            kind = joints[leader].kind
            raise RobotFileError(
                f'{label}: joint {name!r} <mimic> joint: its leader '
                f'{leader!r} is ' + (f'a {kind} joint' if kind not in MOVING
                                     else 'not below the base link'))
        out.append((index[leader], mult, offset))
    return out


def _tool(links, joints, walk, base):
    """Return (tool body or None, tool pose, tip link or None)."""
    leaves = [name for name in walk.frames if not links[name].child_joints]
    if len(leaves) != 1 or not walk.moving:
        return None, np.eye(4), None
    body, T = walk.frames[leaves[0]]
    return body, T, leaves[0]


def _notes(label, links, joints, walk):
    found = []
    massless = []
    for parts in walk.parts:
        for lname, _, via in parts:
            link = links[lname]
            if not link.has_inertial and joints[via].kind != 'fixed':
                massless.append(lname)
            if link.has_inertial and not link.listed:
                note = triangle_note(f'{label}: link {lname!r} <inertia>',
                                     link.eig)
                if note:
                    found.append(note)
    if massless:
        found.append(f'{label}: links without <inertial> are massless: '
                     f'{clip(", ".join(sorted(set(massless))), 400)}')
    return found


def tree_model(name, label, links, joints, base, gravity, limits, drives):
    """
    Build the model of the whole tree below ``base``.

    Returns (model, warnings, report); ``limits(names)`` and
    ``drives(names)`` give the joints' limits and drives (``urdf``).
    """
    walk = _Walk(label, links, joints, base)
    if not walk.moving:
        raise RobotFileError(f'{label}: no revolute, continuous or prismatic '
                             f'joint below {base!r}')
    mimic = _mimic(label, joints, walk)
    bodies = [combine(parts, links) for parts in walk.parts]
    tool_body, tool, tip = _tool(links, joints, walk, base)
    frames = dict(walk.frames)
    for lname, T in fixed_above(links, joints, base).items():
        frames[lname] = (-1, T)
    independent = [n for n, m in zip(walk.moving, mimic) if m is None]
    tip_frames = {}
    if tool_body is not None:
        inv = np.linalg.inv(tool)
        tip_frames = {lname: inv @ T for lname, T, _ in walk.parts[tool_body]}
    report = {
        'base': base, 'tip': tip, 'tree': True, 'chain': walk.order,
        'chain_links': [joints[j].child for j in walk.order],
        'parent_links': {j: joints[j].parent for j in walk.order},
        'moving': list(walk.moving),
        'links': [joints[j].child for j in walk.moving],
        'parents': list(walk.parents), 'merged_fixed': walk.fixed,
        'lumped': [],
        'mimic': {walk.moving[k]: (walk.moving[m[0]], m[1], m[2])
                  for k, m in enumerate(mimic) if m is not None},
        'tip_frames': tip_frames,
        'base_frames': {lname: T for lname, (b, T) in frames.items()
                        if b < 0},
        'continuous': [j for j in walk.moving
                       if joints[j].kind == 'continuous'],
    }
    model = make_chain(
        name=name, joint_names=walk.moving,
        joint_types=[MOVING[joints[j].kind] for j in walk.moving],
        joint_pre=walk.pre, joint_axis=[joints[j].axis for j in walk.moving],
        mass=[b[0] for b in bodies], com=[b[1] for b in bodies],
        inertia=[b[2] for b in bodies], gravity=gravity, tool=tool,
        limits=limits(walk.moving), parents=walk.parents, mimic=mimic,
        tool_body=tool_body, link_frames=frames,
        info={'source': label, 'urdf': report,
              'drives': drives(independent)})
    return model, _notes(label, links, joints, walk), report
