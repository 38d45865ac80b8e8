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
Robots from URDF: the whole tree below a base link, or the chain to a tip.

Without ``tip``: the whole tree below ``base`` (default: the root link;
:mod:`~newton_euler_ros.core.urdf.whole`).  With ``tip``, the chain:

- The chain runs from ``base`` to ``tip``.  Its ``revolute``,
  ``continuous`` and ``prismatic`` joints are the model's joints, in
  chain order; a ``floating`` or ``planar`` joint on the chain is an
  error.
- ``fixed`` joints on the chain are merged: their origins are composed
  into the next moving joint's placement (or into the tool, after the
  last one), and the links they carry are combined with the moving link
  by the parallel-axis theorem (``inertia.merge_bodies``).
- Off-chain subtrees (gripper fingers, a second arm, a head) are lumped
  rigidly into the chain link they hang from, at their joints' zero
  position (a ``mimic`` joint at its offset).  A fixed joint off the chain
  (a hand, a camera, a flange frame) is merged like one on it, without a
  word; the moving joints so locked are named in one warning: their own
  motion is not modelled.
- ``<inertial>`` with its ``<origin xyz rpy>``: the inertia is rotated into
  the link frame (I_link = R I R^T, the centre of mass at xyz).  A link
  without ``<inertial>`` is massless (one warning lists them; not for
  frames on fixed joints such as ``tool0``).
- The end effector is the tip link's frame; gravity is [0, 0, -9.81] in
  the base link's axes unless given.

Parsing.  URDF text arrives from the network (``robot_description``),
so ``defusedxml`` parses it: no DTDs, entity declarations or external
entities; text capped at :data:`MAX_BYTES`, documents at
:data:`MAX_ELEMENTS` links plus joints; meshes never read.  Every error is
a :class:`~newton_euler_ros.core.errors.RobotFileError` naming the source
(the file, or ``robot_description``), the element and the attribute.
Writing: :mod:`~newton_euler_ros.core.urdf.writer`.
"""
import math
import os
import warnings
import xml.etree.ElementTree as ET  # noqa: N817 (only for ParseError)

import defusedxml
import defusedxml.ElementTree as DET
import numpy as np

from .chain import chain_model
from .tree import check_link, floating_root_base, mimic_cycle
from .whole import tree_model
from ..drives import read_drives
from ..errors import RobotFileError, RobotFileWarning
from ..inertia import format_moments, Note, principal_moments, triangle_note
from ..model import pose_matrix, rpy_matrix
from ..text import clip, read_text

MAX_BYTES = 16 * 1024 * 1024
#: links plus joints: robots have hundreds (a dual-arm TIAGo 350); a
#: chain of thousands would cost check's O(n^3) singularity test minutes
MAX_ELEMENTS = 4000
MAX_NAME = 200
JOINT_TYPES = ('revolute', 'continuous', 'prismatic', 'fixed', 'floating',
               'planar')


def _short(text, limit=MAX_NAME):
    return clip(text, limit)


class _Source:
    """
    The origin of a URDF (for messages) and how strictly it is read.

    ``prior``: the file is the prior of an identification, which makes
    every link physical anyway: physically impossible values (a negative
    mass or principal moment, negative friction) are accepted, each
    listed in ``notes`` ("where: what").
    """

    def __init__(self, label, prior=False, notes=None):
        self.label = label
        self.prior = prior
        self.notes = [] if notes is None else notes

    def accept(self, where, message):
        """List an impossible value of a prior; raise for anything else."""
        if not self.prior:
            raise self.error(where, message)
        self.notes.append(f'{where}: {message}')

    def error(self, where, message):
        return RobotFileError(f'{self.label}: {where}: {message}')


def read_urdf_text(text_or_path, label=None):
    """
    Return (text, label) for URDF given as XML text or as a file path.

    Text is recognised by its first non-blank character, ``<``.
    """
    if isinstance(text_or_path, bytes):
        text_or_path = _decode(text_or_path, label or 'robot_description')
    text = str(text_or_path)
    text = text.removeprefix('\ufeff')     # a byte order mark
    if text.lstrip().startswith('<'):
        label = label or 'robot_description'
        if len(text) > MAX_BYTES:
            raise RobotFileError(
                f'{label}: {len(text)} characters, more than the '
                f'{MAX_BYTES} accepted')
        return text, label
    body = read_text(text, MAX_BYTES, 'URDF file')
    return body.removeprefix('\ufeff'), label or os.path.basename(text)


def _decode(data, label):
    try:
        return data.decode('utf-8')
    except UnicodeDecodeError as exc:
        raise RobotFileError(f'{label}: not UTF-8 text (byte {exc.start}); '
                             f'is it a URDF file?') from None


def _parse(text, src):
    if not text.strip():
        raise RobotFileError(f'{src.label}: the URDF is empty')
    try:
        root = DET.fromstring(text, forbid_dtd=True, forbid_entities=True,
                              forbid_external=True)
    except defusedxml.DefusedXmlException as exc:
        what = {'DTDForbidden': 'a <!DOCTYPE> declaration',
                'EntitiesForbidden': f'an entity declaration '
                                     f'({getattr(exc, "name", "")!r})',
                'ExternalReferenceForbidden': 'an external reference'}.get(
                    type(exc).__name__, type(exc).__name__)
        raise RobotFileError(f'{src.label}: refused: {what} (DTDs and '
                             f'entities are not accepted in URDF)') from None
    except ET.ParseError as exc:
        line, col = getattr(exc, 'position', (0, 0))
        raise RobotFileError(f'{src.label}: not well-formed XML (line '
                             f'{line}, column {col + 1})') from None
    sign = _xacro_sign(root)
    if sign:
        raise RobotFileError(f'{src.label}: xacro, not URDF ({sign}): '
                             f'expand it with xacro first')
    if root.tag != 'robot':
        raise RobotFileError(f'{src.label}: the root element is '
                             f'<{_short(root.tag)}>, not <robot>')
    return root


def _xacro_sign(root):
    """
    Return what shows a document is xacro, or '' for plain XML.

    An element in the xacro namespace (``<xacro:macro>``), or an
    attribute holding a xacro expression (``${...}``) or substitution
    (``$(find ...)``).  The ``xmlns:xacro`` declaration alone is not a
    sign: xacro leaves it in the URDF it writes.
    """
    for el in root.iter():
        tag = el.tag if isinstance(el.tag, str) else ''
        if tag.startswith('{') and 'xacro' in tag.partition('}')[0]:
            return f'<xacro:{_short(tag.partition("}")[2], 60)}>'
        for attr, value in el.attrib.items():
            if '${' in value or '$(' in value:
                return (f'<{_short(tag, 60)} {_short(attr, 60)}='
                        f'"{_short(value, 60)}">')
    return ''


def _numbers(el, attr, count, where, src, default=None):
    """Parse ``count`` space-separated finite numbers of an attribute."""
    raw = el.get(attr) if el is not None else None
    if raw is None:
        if default is None:
            raise src.error(where, f'missing attribute {attr!r}')
        return list(default)
    parts = raw.split()
    if len(parts) != count:
        raise src.error(f'{where} {attr}', f'must be {count} number'
                        f'{"s" if count > 1 else ""}, got {_short(raw)!r}')
    out = []
    for part in parts:
        try:
            x = float(part)
        except ValueError:
            raise src.error(f'{where} {attr}', f'not a number: '
                            f'{_short(part)!r}') from None
        if not math.isfinite(x):
            raise src.error(f'{where} {attr}', f'must be finite, got {part}')
        out.append(x)
    return out


def _origin(el, where, src):
    """(xyz, rpy) of an optional <origin> child."""
    o = el.find('origin')
    w = f'{where}<origin>'
    xyz = _numbers(o, 'xyz', 3, w, src, (0.0, 0.0, 0.0))
    rpy = _numbers(o, 'rpy', 3, w, src, (0.0, 0.0, 0.0))
    return xyz, rpy


class _Link:
    def __init__(self, name):
        self.name = name
        self.mass = 0.0
        self.com = np.zeros(3)
        self.inertia = np.zeros((3, 3))
        self.has_inertial = False
        self.listed = False     # its inertia is in a prior's note
        self.parent_joint = None
        self.child_joints = []


class _Joint:
    def __init__(self, name, kind, parent, child):
        self.name = name
        self.kind = kind
        self.parent = parent
        self.child = child
        self.xyz = (0.0, 0.0, 0.0)
        self.rpy = (0.0, 0.0, 0.0)
        self.axis = np.array([1.0, 0.0, 0.0])
        self.limits = {}
        self.mimic = None

    @property
    def origin(self):
        return pose_matrix(self.xyz, self.rpy)

    @property
    def origin_ops(self):
        """Return the ``<origin>`` as the model's transform operations."""
        ops = []
        if any(self.xyz):
            ops.append(('xyz',) + tuple(self.xyz))
        if any(self.rpy):
            ops.append(('rpy',) + tuple(self.rpy))
        return ops


def _name(el, what, src, index):
    name = el.get('name')
    if name is None or not name.strip():
        raise src.error(f'<{what}> #{index + 1}', "missing attribute 'name'")
    if len(name) > MAX_NAME or any(ord(c) < 32 for c in name):
        raise src.error(f'<{what}> #{index + 1} name', 'must be at most '
                        f'{MAX_NAME} printable characters, got '
                        f'{_short(name)!r}')
    return name


def _read_inertial(link, el, src):
    where = f'link {link.name!r} <inertial>'
    inertial = el.find('inertial')
    if inertial is None:
        return
    link.has_inertial = True
    xyz, rpy = _origin(inertial, where, src)
    mass_el = inertial.find('mass')
    if mass_el is None:
        raise src.error(where, 'missing <mass>')
    mass = _numbers(mass_el, 'value', 1, f'{where}<mass>', src)[0]
    if mass < 0.0:
        src.accept(f'{where}<mass> value', f'must be >= 0, got {mass}')
    in_el = inertial.find('inertia')
    if in_el is None:
        raise src.error(where, 'missing <inertia>')
    vals = {}
    for key in ('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz'):
        vals[key] = _numbers(in_el, key, 1, f'{where}<inertia>', src)[0]
    inertia = np.array([[vals['ixx'], vals['ixy'], vals['ixz']],
                        [vals['ixy'], vals['iyy'], vals['iyz']],
                        [vals['ixz'], vals['iyz'], vals['izz']]])
    eig, valid = principal_moments(inertia)
    if not valid:
        src.accept(f'{where}<inertia>', 'not positive semi-definite '
                   f'(principal moments {format_moments(eig)})')
        link.listed = True          # a prior's (anything else raised)
    elif src.prior and triangle_note(where, eig):
        # the fit replaces it: listed with the prior's others, not
        # "accepted as published"
        src.notes.append(f'{where}<inertia>: principal moments '
                         f'{format_moments(eig)} break the triangle '
                         f'inequality')
        link.listed = True
    R = rpy_matrix(*rpy)
    link.mass = mass
    link.com = np.array(xyz)
    link.inertia = R @ inertia @ R.T
    link.eig = eig


def _read_joint(el, index, src, links):
    name = _name(el, 'joint', src, index)
    where = f'joint {name!r}'
    kind = el.get('type')
    if kind not in JOINT_TYPES:
        raise src.error(f'{where} type', f'must be one of '
                        f'{", ".join(JOINT_TYPES)}, got {_short(kind)!r}')
    ends = []
    for tag in ('parent', 'child'):
        e = el.find(tag)
        link = e.get('link') if e is not None else None
        if link is None:
            raise src.error(where, f'missing <{tag} link=...>')
        if link not in links:
            raise src.error(f'{where} <{tag}> link', f'no link named '
                            f'{_short(link)!r}')
        ends.append(link)
    if ends[0] == ends[1]:
        raise src.error(where, f'parent and child are the same link '
                        f'{ends[0]!r}')
    joint = _Joint(name, kind, ends[0], ends[1])
    joint.xyz, joint.rpy = _origin(el, f'{where} ', src)
    if kind in ('revolute', 'continuous', 'prismatic', 'planar'):
        axis = np.array(_numbers(el.find('axis'), 'xyz', 3,
                                 f'{where} <axis>', src, (1.0, 0.0, 0.0)))
        norm = float(np.sqrt(axis @ axis))
        if not norm > 0.0:
            raise src.error(f'{where} <axis> xyz', 'must be a nonzero '
                            'vector, got 0 0 0')
        joint.axis = axis / norm
    lim = el.find('limit')
    if lim is not None and kind in ('revolute', 'continuous', 'prismatic'):
        w = f'{where} <limit>'
        out = {}
        keys = ('effort', 'velocity') if kind == 'continuous' else (
            'lower', 'upper', 'effort', 'velocity')
        for key in keys:
            if lim.get(key) is not None:
                out[key] = _numbers(lim, key, 1, w, src)[0]
        if 'lower' in out and 'upper' in out and out['lower'] > out['upper']:
            raise src.error(f'{w} lower', f'{out["lower"]} is above upper '
                            f'{out["upper"]}')
        joint.limits = out
    mimic = el.find('mimic')
    if mimic is not None:
        w = f'{where} <mimic>'
        other = mimic.get('joint')
        if other is None:
            raise src.error(w, "missing attribute 'joint'")
        mult = _numbers(mimic, 'multiplier', 1, w, src, (1.0,))[0]
        off = _numbers(mimic, 'offset', 1, w, src, (0.0,))[0]
        joint.mimic = (other, mult, off)
    return joint


def parse_urdf(text, label='robot_description', prior=False, notes=None):
    """
    Parse and check URDF text; return (name, root, links, joints).

    ``prior=True`` reads the prior of an identification: physically
    impossible inertials are accepted, each listed in ``notes``.
    """
    src = _Source(label, prior, notes)
    root = _parse(text, src)
    name = root.get('name') or 'robot'
    link_els = root.findall('link')
    joint_els = root.findall('joint')
    if len(link_els) + len(joint_els) > MAX_ELEMENTS:
        raise RobotFileError(f'{label}: {len(link_els)} links and '
                             f'{len(joint_els)} joints, more than the '
                             f'{MAX_ELEMENTS} accepted')
    if not link_els:
        raise RobotFileError(f'{label}: <robot> has no <link>')
    links = {}
    for i, el in enumerate(link_els):
        lname = _name(el, 'link', src, i)
        if lname in links:
            raise src.error(f'link {lname!r}', 'the name is used twice')
        link = links[lname] = _Link(lname)
        _read_inertial(link, el, src)
    joints = {}
    for i, el in enumerate(joint_els):
        joint = _read_joint(el, i, src, links)
        if joint.name in joints:
            raise src.error(f'joint {joint.name!r}', 'the name is used twice')
        child = links[joint.child]
        if child.parent_joint is not None:
            raise src.error(f'joint {joint.name!r} <child> link',
                            f'{joint.child!r} already has the parent joint '
                            f'{child.parent_joint!r}')
        child.parent_joint = joint.name
        links[joint.parent].child_joints.append(joint.name)
        joints[joint.name] = joint
    for joint in joints.values():
        if joint.mimic and joint.mimic[0] not in joints:
            raise src.error(f'joint {joint.name!r} <mimic> joint',
                            f'no joint named {_short(joint.mimic[0])!r}')
    cycle = mimic_cycle(joints)
    if cycle:
        raise src.error(f'joint {cycle[0]!r} <mimic> joint',
                        'mimic joints form a cycle: '
                        + _short(' -> '.join(cycle), 300))
    roots = [n for n, lk in links.items() if lk.parent_joint is None]
    if not roots:
        raise RobotFileError(f'{label}: the links form a cycle (every link '
                             f'has a parent joint)')
    if len(roots) > 1:
        raise RobotFileError(f'{label}: more than one root link (links '
                             f'without a parent joint): '
                             f'{_short(", ".join(sorted(roots)), 400)}')
    # every link must hang from the root: the others sit on a cycle
    seen = set()
    stack = [roots[0]]
    while stack:
        lname = stack.pop()
        seen.add(lname)
        stack.extend(joints[j].child for j in links[lname].child_joints)
    if len(seen) != len(links):
        cyc = sorted(set(links) - seen)
        raise RobotFileError(f'{label}: links on a cycle: '
                             f'{_short(", ".join(cyc), 400)}')
    return name, roots[0], links, joints


def _chain_limits(joints, moving):
    """Each moving joint's limits; a velocity or effort of 0 is not given."""
    return [{key: value for key, value in joints[j].limits.items()
             if key not in ('velocity', 'effort') or value > 0.0}
            for j in moving]


def urdf_model(text, label='robot_description', base=None, tip=None,
               gravity=(0.0, 0.0, -9.81), prior=False):
    """
    Build the model of URDF text; return (model, warnings, report).

    Without ``tip``: the whole tree below ``base`` (``whole``).
    With it, the chain; ``report`` describes what was made of the tree:
    the chain's links and joints, the merged fixed joints, the lumped
    subtrees and the frames rigidly attached to the base and to the tip
    (for wrenches).  ``prior=True``: the file is the prior of an
    identification, read leniently (:func:`parse_urdf`; negative friction
    too): one Note among the warnings lists the impossible values.
    Nothing else reads that way.
    """
    notes = []
    name, root, links, joints = parse_urdf(text, label, prior, notes)
    floating = []
    if base is None:    # below a floating or planar root, with a note
        base, floating = floating_root_base(label, links, joints, root)
        if tip is not None and tip == base:     # nothing left to move
            base, floating = None, []
    if tip is None:
        check_link(label, links, 'base', base)
        model, found, report = tree_model(
            name, label, links, joints, base, gravity,
            lambda names: _chain_limits(joints, names),
            lambda names: read_drives(_parse(text, _Source(label)), names,
                                      label, prior, notes))
        return model, floating + _prior_note(label, notes) + found, report
    model, found, report = chain_model(
        name, label, links, joints, (root, base, tip), gravity,
        lambda names: _chain_limits(joints, names),
        lambda names: read_drives(_parse(text, _Source(label)), names,
                                  label, prior, notes))
    return model, floating + _prior_note(label, notes) + found, report


def _prior_note(label, notes):
    if not notes:
        return []
    return [Note(f'{label}: physically impossible values accepted as the '
                 f'prior of an identification (the fit makes every link '
                 f'physical and its friction >= 0; nothing else reads such '
                 f'a file): ' + _short('; '.join(notes), 1500))]


def inspect_urdf(text_or_path, base=None, tip=None, label=None,
                 gravity=(0.0, 0.0, -9.81), prior=False):
    """Load a URDF (text or path); return (model, warnings, report)."""
    text, label = read_urdf_text(text_or_path, label)
    return urdf_model(text, label, base=base, tip=tip, gravity=gravity,
                      prior=prior)


def load_urdf(text_or_path, base=None, tip=None, gravity=(0.0, 0.0, -9.81)):
    """
    Load a URDF, given as XML text or a file path, as a model.

    Without ``tip``: the whole tree below ``base`` (default: the root
    link); with it, the chain from ``base`` to ``tip``.

    ``gravity`` is in the base link's axes (URDF does not carry it).

    Warnings are issued as
    :class:`~newton_euler_ros.core.robot_file.RobotFileWarning` (notes on
    data accepted as published are left to :func:`inspect_urdf` and
    ``newton-euler check``); errors raise
    :class:`~newton_euler_ros.core.errors.RobotFileError`.
    """
    model, found, _ = inspect_urdf(text_or_path, base=base, tip=tip,
                                   gravity=gravity)
    for message in found:
        if not isinstance(message, Note):
            warnings.warn(message, RobotFileWarning, stacklevel=2)
    return model
