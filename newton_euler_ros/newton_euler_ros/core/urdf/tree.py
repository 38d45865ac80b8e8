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
The URDF tree as a chain: its ends, the path between them, what is lumped.

:func:`chain_ends` resolves the base and tip links (naming the closest
links for a mistyped one), :func:`attached` collects the links rigidly
attached to a chain link (off-chain joints locked at zero, a mimic joint
at its offset) and :func:`combine` merges them by the parallel-axis
theorem (:func:`~newton_euler_ros.core.inertia.merge_bodies`).
"""
import difflib
import math

import numpy as np

from ..errors import RobotFileError
from ..inertia import merge_bodies
from ..model import PRISMATIC, REVOLUTE
from ..text import clip


#: the URDF joint types that are joints of a model, and their kind
MOVING = {'revolute': REVOLUTE, 'continuous': REVOLUTE,
          'prismatic': PRISMATIC}


def _short(text, limit=200):
    return clip(text, limit)


def axis_motion(kind, axis, q):
    """4x4 of a joint's own motion by q (a locked off-chain joint)."""
    T = np.eye(4)
    if q == 0.0:
        return T
    if kind in ('revolute', 'continuous'):
        k = np.asarray(axis)
        K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]],
                      [-k[1], k[0], 0.0]])
        T[:3, :3] = np.eye(3) + math.sin(q) * K + (1 - math.cos(q)) * K @ K
    elif kind == 'prismatic':
        T[:3, 3] = np.asarray(axis) * q
    return T


def _path(links, joints, base, tip):
    """Joint names from base down to tip, or None if base is no ancestor."""
    path = []
    lname = tip
    while lname != base:
        jname = links[lname].parent_joint
        if jname is None:
            return None
        path.append(jname)
        lname = joints[jname].parent
    return path[::-1]


def _leaves_below(links, joints, base):
    out = []
    stack = [base]
    while stack:
        lname = stack.pop()
        kids = links[lname].child_joints
        if not kids:
            out.append(lname)
        stack.extend(joints[j].child for j in kids)
    return sorted(out)


def attached(links, joints, start, stop_joints, pose=np.eye(4)):
    """
    Every link rigidly attached to ``start``, with its pose in start's frame.

    Follows every joint except those in ``stop_joints`` (the chain's next
    moving joint); off-chain moving joints are taken at zero (mimic joints
    at their offset).  Returns [(link name, 4x4 pose, via joint or None)].
    """
    out = [(start, pose, None)]
    stack = [(start, pose)]
    while stack:
        lname, T = stack.pop()
        for jname in links[lname].child_joints:
            if jname in stop_joints:
                continue
            joint = joints[jname]
            q = joint.mimic[2] if joint.mimic else 0.0
            Tc = T @ joint.origin @ axis_motion(joint.kind, joint.axis, q)
            out.append((joint.child, Tc, jname))
            stack.append((joint.child, Tc))
    return out


def fixed_above(links, joints, base):
    """Links above ``base`` joined to it by fixed joints: {name: pose}."""
    out = {}
    lname, T = base, np.eye(4)
    while links[lname].parent_joint is not None:
        joint = joints[links[lname].parent_joint]
        if joint.kind != 'fixed':
            break
        T = T @ np.linalg.inv(joint.origin)
        lname = joint.parent
        out[lname] = T
    return out


def combine(parts, links):
    """Mass, centre of mass and inertia (about it) of rigidly joined links."""
    return merge_bodies([(links[lname].mass, links[lname].com,
                          links[lname].inertia, T[:3, :3], T[:3, 3])
                         for lname, T, _ in parts])


def check_link(label, links, role, lname):
    """Raise naming the closest links when ``lname`` is not in the tree."""
    if lname is not None and lname not in links:
        close = difflib.get_close_matches(str(lname), list(links), n=3,
                                          cutoff=0.5)
        hint = (' (closest: ' + ', '.join(map(repr, close)) + ')'
                if close else
                f' (links: {_short(", ".join(links), 300)})')
        raise RobotFileError(f'{label}: {role} link {_short(lname)!r} is '
                             f'not in the URDF{hint}')


def mimic_cycle(joints):
    """Return the first cycle of mimic joints as a list of names, or None."""
    for start in joints:
        seen = [start]
        name = start
        while joints[name].mimic is not None:
            name = joints[name].mimic[0]
            if name in seen:
                return seen[seen.index(name):] + [name]
            seen.append(name)
    return None


def floating_root_base(label, links, joints, root):
    """
    Return (base, notes): where a model starts when no base is given.

    The root, unless the root's only child joint is ``floating`` or
    ``planar`` (a mobile robot's ``odom -> base_footprint``, a humanoid's
    ``world -> pelvis``): the model then starts at the first link below
    it, fixed there, with a warning saying so (the node logs it, a
    library call warns).
    """
    base, notes = root, []
    while len(links[base].child_joints) == 1:
        joint = joints[links[base].child_joints[0]]
        if joint.kind not in ('floating', 'planar'):
            break
        notes.append(
            f'{label}: {base!r} carries the rest through the {joint.kind} '
            f'joint {joint.name!r}: the model starts at {joint.child!r}, '
            f'fixed (give the base link to start elsewhere)')
        base = joint.child
    return base, notes


def chain_ends(label, links, joints, root, base, tip):
    """
    Return (base, tip, joint names from base to tip) of a URDF tree.

    ``base`` defaults to the root and ``tip`` to the single leaf below the
    base; a link that is not in the tree is named with the closest ones.
    """
    base = root if base is None else base
    for role, lname in (('base', base), ('tip', tip)):
        check_link(label, links, role, lname)
    if tip is None:
        leaves = _leaves_below(links, joints, base)
        if len(leaves) != 1:
            raise RobotFileError(
                f'{label}: the tree below {base!r} has {len(leaves)} leaves '
                f'({_short(", ".join(leaves), 400)}); choose the tip link')
        tip = leaves[0]
    chain = _path(links, joints, base, tip)
    if chain is None:
        raise RobotFileError(f'{label}: base link {base!r} is not an '
                             f'ancestor of tip link {tip!r}')
    return base, tip, chain
