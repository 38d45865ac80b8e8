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
A chain of a URDF tree as the model: from a base link to a tip link.

:func:`chain_model` builds what ``load_urdf(..., tip=LINK)`` returns:
the moving joints on the path from the base to the tip are the model's
joints; a fixed joint's origin merges into the next moving joint's
placement (those after the last moving joint make the tool transform);
every link rigidly attached to a chain link (fixed joints, and subtrees
off the chain, their moving joints locked at zero and a mimic joint at
its offset) merges into that link's body by the parallel-axis theorem.
The whole tree (no tip) is ``whole.tree_model``.
"""
import numpy as np

from .tree import attached, chain_ends, combine, fixed_above, MOVING
from ..errors import RobotFileError
from ..inertia import triangle_note
from ..model import make_chain
from ..text import clip


def _short(text, limit=200):
    return clip(text, limit)


def _moving_joints(label, joints, chain, base, tip):
    """Return the moving joints of the chain (a floating or planar: error)."""
    for jname in chain:
        kind = joints[jname].kind
        if kind in ('floating', 'planar'):
            raise RobotFileError(
                f'{label}: joint {jname!r} type: a {kind} joint is on the '
                f'chain from {base!r} to {tip!r}; only revolute, continuous,'
                f' prismatic and fixed joints can be: start below it (base '
                f'link {joints[jname].child!r})')
    moving = [j for j in chain if joints[j].kind in MOVING]
    if not moving:
        raise RobotFileError(f'{label}: no revolute, continuous or prismatic'
                             f' joint between {base!r} and {tip!r}')
    return moving


def _placements(joints, chain, moving):
    """
    Return (pre, merged, tool): each moving joint's placement ops.

    A fixed joint's origin is merged into the next moving joint's; those
    after the last moving joint make the tool transform.
    """
    pre, merged, pending = [], [], []
    for jname in chain:
        joint = joints[jname]
        if joint.kind == 'fixed':
            pending += joint.origin_ops
            merged.append(jname)
            continue
        pre.append(tuple(pending + joint.origin_ops))
        pending = []
    tool = np.eye(4)
    for jname in chain[chain.index(moving[-1]) + 1:]:
        tool = tool @ joints[jname].origin
    return pre, merged, tool


class _Bodies:
    """The rigid body each moving joint carries, and what went into it."""

    def __init__(self, links, joints, base, chain, moving):
        self.mass, self.com, self.inertia, self.carried = [], [], [], []
        self.lumped = []        # (joint, kind) of off-chain subtrees
        self.locked = []        # off-chain moving joints, at any depth
        self.massless = []      # links without <inertial>
        chain_links = {base} | {joints[j].child for j in chain}
        for k, jname in enumerate(moving):
            stop = {moving[k + 1]} if k + 1 < len(moving) else set()
            parts = attached(links, joints, joints[jname].child, stop)
            m, c, inertia_k = combine(parts, links)
            self.mass.append(m)
            self.com.append(c)
            self.inertia.append(inertia_k)
            self.carried.append(parts)
            for lname, _, via in parts:
                joint = joints[via] if via is not None else None
                # a massless link on a fixed joint is a frame (tool0,
                # ee_link, flange): nothing to warn about
                if not links[lname].has_inertial and not (
                        joint is not None and joint.kind == 'fixed'):
                    self.massless.append(lname)
                if joint is not None and via not in chain:
                    if joint.parent in chain_links:
                        self.lumped.append((via, joint.kind))
                    if joint.kind != 'fixed':
                        self.locked.append(via)


def _attached_frames(links, joints, base, moving, tip_parts, tool):
    """Return (tip_frames, base_frames): frames rigid with tip and base."""
    tool_inv = np.linalg.inv(tool)
    tip_frames = {lname: tool_inv @ T for lname, T, _ in tip_parts}
    base_frames = {}
    for lname, T, via in attached(links, joints, base, {moving[0]}):
        if via is None or joints[via].kind == 'fixed':
            base_frames[lname] = T
    base_frames.update(fixed_above(links, joints, base))
    return tip_frames, base_frames


def _locked_text(joint):
    if joint.mimic:
        other, mult, off = joint.mimic
        return (f'{joint.name} ({joint.kind}, mimic of {other}, at '
                f'{off:g})')
    return f'{joint.name} ({joint.kind})'


def _tree_warnings(label, links, joints, bodies):
    """Return what the user should know of the tree: locked, massless, odd."""
    found = []
    # fixed joints off the chain (a hand, a camera, ee_link) are merged as
    # those on it are: a correct model; moving ones are locked
    if bodies.locked:
        found.append(
            f'{label}: moving joints off the chain locked at zero (their '
            f'motion is not modelled; their links are lumped rigidly into '
            f'the chain): ' + _short(', '.join(
                _locked_text(joints[j]) for j in bodies.locked), 400))
    if bodies.massless:
        found.append(f'{label}: links without <inertial> are massless: '
                     f'{_short(", ".join(sorted(set(bodies.massless))), 400)}')
    for parts in bodies.carried:
        for lname, _, _ in parts:
            # a negative moment is refused; a prior's odd inertia is
            # listed in its note
            if links[lname].has_inertial and not links[lname].listed:
                note = triangle_note(f'{label}: link {lname!r} <inertia>',
                                     links[lname].eig)
                if note:
                    found.append(note)
    return found


def chain_model(name, label, links, joints, ends, gravity, limits, drives):
    """
    Build the chain model between the ends ``(root, base, tip)``.

    Returns (model, warnings, report); ``limits(names)`` and
    ``drives(names)`` give the joints' limits and drive terms (``urdf``).
    ``report`` describes what was made of the tree: the chain's links and
    joints, the merged fixed joints, the lumped subtrees, the locked
    joints and the frames rigidly attached to the base and to the tip
    (for wrenches).
    """
    base, tip, chain = chain_ends(label, links, joints, *ends)
    moving = _moving_joints(label, joints, chain, base, tip)
    pre, merged, tool = _placements(joints, chain, moving)
    bodies = _Bodies(links, joints, base, chain, moving)
    tip_frames, base_frames = _attached_frames(
        links, joints, base, moving, bodies.carried[-1], tool)
    report = {
        'base': base, 'tip': tip, 'chain': chain, 'moving': moving,
        'chain_links': [joints[j].child for j in chain],
        'links': [joints[j].child for j in moving],
        'merged_fixed': merged, 'lumped': [v for v, _ in bodies.lumped],
        'locked': list(bodies.locked),
        'tip_frames': tip_frames, 'base_frames': base_frames,
        'continuous': [j for j in moving if joints[j].kind == 'continuous'],
    }
    model = make_chain(
        name=name, joint_names=moving,
        joint_types=[MOVING[joints[j].kind] for j in moving],
        joint_pre=pre, joint_axis=[joints[j].axis for j in moving],
        mass=bodies.mass, com=bodies.com, inertia=bodies.inertia,
        gravity=gravity, tool=tool, limits=limits(moving),
        info={'source': label, 'urdf': report,
              # friction, offset, rotor inertia (or None)
              'drives': drives(moving)})
    return model, _tree_warnings(label, links, joints, bodies), report
