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
Write an identified model's inertials where a robot's description reads them.

The model is a URDF (``newton-euler identify``'s output); each link's
``<inertial>`` is read with the package's URDF parser, so the mass, the
centre of mass and the inertia tensor about it are in the link's own
frame whatever ``<origin rpy>`` the file used.

Formats:

- ``ur``: ur_description's ``config/<type>/physical_parameters.yaml``
  (ROS 2, branch ``rolling``, which Jazzy is released from).  Its xacro
  (``urdf/ur_macro.xacro``) writes, for each of ``shoulder``,
  ``upper_arm``, ``forearm``, ``wrist_1``, ``wrist_2``, ``wrist_3``, the
  link ``<name>_link``'s inertial as ``<mass value=<name>_mass>``,
  ``<origin xyz=center_of_mass.<name>_cog rpy=rotation.<name>>`` and
  ``<inertia tensor.<name>>``: the tensor is about the centre of mass in
  axes rotated by ``rotation`` (URDF's rpy, R = Rz Ry Rx) from the link's.
  We keep each link's ``rotation`` of the template (the published files
  align the cylinder-shaped upper arm and forearm with it) and write the
  tensor in those axes, Rᵀ I R; without a template the rotation is zero.
  The template's other fields (``offsets``, ``base_mass``, the radii,
  ``links``) are not identified and are kept as they are.
- ``franka``: franka_description's ``robots/<arm>/inertials.yaml``: per
  link ``link0`` ... ``link7`` an ``origin`` (``xyz``, ``rpy`` as strings
  of three numbers), a ``mass`` and an ``inertia`` (``xx xy xz yy yz
  zz``), read by ``franka-inertials`` in ``robots/common/utils.xacro`` as
  the URDF ``<inertial>`` of ``<prefix>link<i>``.  We write ``rpy: 0 0 0``
  and the tensor in the link's axes; ``link0`` (the fixed base, not
  identified) as the model has it.

Both descriptions put every arm joint's axis along its child link's z
axis; a model whose exported links do not turn about their z axes has
other link frames (UR's ROS 1 description, for instance) and is refused:
its inertials would land in the wrong axes.

Links may carry a prefix (ur_description's ``tf_prefix``, Franka's
``<arm_id>_``: ``fr3_link1``, example-robot-data's ``panda_link1``);
without ``prefix`` the one prefix that names every needed link is used.
"""
import math
import os

import numpy as np
import yaml

from .urdf_out import atomic_write
from ..core.errors import NewtonEulerError
from ..core.robot_file import read_yaml, to_number
from ..core.text import clip
from ..core.transforms import rpy_matrix
from ..core.urdf import parse_urdf, read_urdf_text

FORMATS = ('ur', 'franka')
UR_PARTS = ('shoulder', 'upper_arm', 'forearm', 'wrist_1', 'wrist_2',
            'wrist_3')
FRANKA_LINKS = tuple(f'link{i}' for i in range(1, 8))
FRANKA_BASE = 'link0'
WHAT = {'ur': "ur_description's physical_parameters.yaml",
        'franka': "franka_description's inertials.yaml"}
#: |axis - z| accepted as "along z" (URDF axes are written to ~1e-6)
AXIS_TOLERANCE = 1e-6


class ExportError(NewtonEulerError, ValueError):
    """An unusable model, template or output (exit status 2)."""


def needed_links(fmt):
    """Return the link names (without prefix) a format needs."""
    if fmt == 'ur':
        return tuple(f'{p}_link' for p in UR_PARTS)
    if fmt == 'franka':
        return FRANKA_LINKS
    raise ExportError(f'--format: must be one of {", ".join(FORMATS)}, '
                      f'got {clip(fmt, 40)!r}')


def read_model(path):
    """Return (label, links, joints) of a URDF file (``core.urdf``)."""
    text, label = read_urdf_text(path)
    _, _, links, joints = parse_urdf(text, label)
    return label, links, joints


def find_prefix(label, links, fmt, prefix=None):
    """Return the prefix naming every link ``fmt`` needs in ``links``."""
    names = needed_links(fmt)
    if prefix is not None:
        for name in names:
            if prefix + name not in links:
                raise ExportError(
                    f'{label}: no link {prefix + name!r} ({WHAT[fmt]} '
                    f'needs {", ".join(prefix + n for n in names)})')
        return prefix
    last = names[-1]
    found = sorted({lname[:-len(last)] for lname in links
                    if lname.endswith(last)})
    full = [p for p in found if all(p + n in links for n in names)]
    if len(full) == 1:
        return full[0]
    if len(full) > 1:
        raise ExportError(f'{label}: the links of {WHAT[fmt]} are there '
                          f'with several prefixes ({", ".join(map(repr, full))}'
                          f'); choose one with --prefix')
    p = found[0] if found else ''
    missing = next(n for n in names if p + n not in links)
    raise ExportError(f'{label}: no link {p + missing!r} ({WHAT[fmt]} needs '
                      f'{", ".join(p + n for n in names)}; another prefix: '
                      f'--prefix)')


def link_inertial(label, links, joints, lname):
    """Return (mass, com, inertia) of a moving link, checked."""
    link = links[lname]
    where = f'{label}: link {lname!r}'
    if not link.has_inertial:
        raise ExportError(f'{where}: has no <inertial>')
    mass = float(link.mass)
    if not (math.isfinite(mass) and mass > 0.0):
        raise ExportError(f'{where} <mass>: must be positive, got {mass}')
    com = np.asarray(link.com, dtype=float)
    inertia = np.asarray(link.inertia, dtype=float)
    if not (np.all(np.isfinite(com)) and np.all(np.isfinite(inertia))):
        raise ExportError(f'{where} <inertial>: must be finite')
    joint = joints.get(link.parent_joint) if link.parent_joint else None
    if joint is None or joint.kind not in ('revolute', 'continuous'):
        raise ExportError(f'{where}: its parent joint must be revolute '
                          f'(the description moves it), got '
                          f'{joint.kind if joint else "none"}')
    if np.max(np.abs(np.asarray(joint.axis) - (0.0, 0.0, 1.0))) > \
            AXIS_TOLERANCE:
        axis = ' '.join(f'{v:g}' for v in joint.axis)
        raise ExportError(
            f'{where}: joint {joint.name!r} turns about {axis}, not its '
            f"child link's z axis as in the description: the model's link "
            f"frames are not the description's (a ROS 1 URDF?); export "
            f"from a URDF made from the description's xacro")
    return mass, com, 0.5 * (inertia + inertia.T)


def _mapping(value, where):
    if not isinstance(value, dict):
        raise ExportError(f'{where}: must be a mapping, got '
                          f'{clip(repr(value), 60)}')
    return value


def _template(path):
    """Return the template's data, with the fields export reads checked."""
    try:
        data = read_yaml(path)
    except NewtonEulerError as exc:
        raise ExportError(f'--template {exc}') from None
    name = clip(os.fspath(path), 200)
    data = _mapping(data, f'--template {name}')
    for key in ('offsets', 'inertia_parameters'):
        if key not in data:
            raise ExportError(f'--template {name}: no {key!r} (not a '
                              f'ur_description physical_parameters.yaml?)')
    ip = _mapping(data['inertia_parameters'],
                  f'--template {name}: inertia_parameters')
    rot = _mapping(ip.get('rotation'),
                   f'--template {name}: inertia_parameters.rotation')
    angles = {}
    for part in UR_PARTS:
        where = f'--template {name}: inertia_parameters.rotation.{part}'
        entry = _mapping(rot.get(part), where)
        try:
            angles[part] = [to_number(entry.get(k), f'{where}.{k}')
                            for k in ('roll', 'pitch', 'yaw')]
        except NewtonEulerError as exc:
            raise ExportError(str(exc)) from None
    return data, angles


def ur_parameters(model_path, template=None, prefix=None):
    """
    Return (data, note) of ur_description's physical_parameters.yaml.

    ``data`` is the template's mapping with ``inertia_parameters``'
    masses, centres of mass and tensors of the six arm links replaced,
    or, without a template, only an ``inertia_parameters`` with those
    and zero rotations; ``note`` says what was kept or left out.
    """
    label, links, joints = read_model(model_path)
    prefix = find_prefix(label, links, 'ur', prefix)
    if template is not None:
        data, angles = _template(template)
        ip = data['inertia_parameters']
        note = (f'offsets, base_mass, radii and links kept from '
                f'{os.path.basename(os.fspath(template))}')
    else:
        angles = {p: [0.0, 0.0, 0.0] for p in UR_PARTS}
        ip = {}
        data = {'inertia_parameters': ip}
        note = ('without --template: wrote inertia_parameters (masses, '
                'center_of_mass, rotation, tensor) only; merge it into your '
                'physical_parameters.yaml, which has offsets, base_mass, '
                'the radii and links')
    cogs = ip.setdefault('center_of_mass', {})
    rot = ip.setdefault('rotation', {})
    tensors = ip.setdefault('tensor', {})
    if not isinstance(cogs, dict) or not isinstance(tensors, dict):
        raise ExportError(f'--template {template}: inertia_parameters.'
                          f'center_of_mass and .tensor must be mappings')
    for part in UR_PARTS:
        m, c, inertia = link_inertial(label, links, joints,
                                      f'{prefix}{part}_link')
        R = rpy_matrix(*angles[part])
        t = R.T @ inertia @ R
        ip[f'{part}_mass'] = float(m)
        cogs[f'{part}_cog'] = {'x': float(c[0]), 'y': float(c[1]),
                               'z': float(c[2])}
        if template is None:
            rot[part] = {'roll': 0.0, 'pitch': 0.0, 'yaw': 0.0}
        tensors[part] = {'ixx': float(t[0, 0]), 'ixy': float(t[0, 1]),
                         'ixz': float(t[0, 2]), 'iyy': float(t[1, 1]),
                         'iyz': float(t[1, 2]), 'izz': float(t[2, 2])}
    return data, note


def _three(v):
    return ' '.join(repr(float(x)) for x in v)


def franka_inertials(model_path, prefix=None):
    """Return (data, note) of franka_description's inertials.yaml."""
    label, links, joints = read_model(model_path)
    prefix = find_prefix(label, links, 'franka', prefix)
    data = {}
    base = links.get(prefix + FRANKA_BASE)
    names = list(FRANKA_LINKS)
    if base is not None and base.has_inertial and base.mass > 0.0:
        names.insert(0, FRANKA_BASE)
        note = f'{prefix}{FRANKA_BASE} (the fixed base) as the model has it'
    else:
        note = (f'no {prefix}{FRANKA_BASE} inertial in the model: keep '
                f"{FRANKA_BASE} of the description's file")
    for name in names:
        lname = prefix + name
        if name == FRANKA_BASE:
            m, c, inertia = base.mass, base.com, base.inertia
        else:
            m, c, inertia = link_inertial(label, links, joints, lname)
        data[name] = {
            'origin': {'xyz': _three(c), 'rpy': '0.0 0.0 0.0'},
            'mass': float(m),
            'inertia': {'xx': float(inertia[0, 0]),
                        'xy': float(inertia[0, 1]),
                        'xz': float(inertia[0, 2]),
                        'yy': float(inertia[1, 1]),
                        'yz': float(inertia[1, 2]),
                        'zz': float(inertia[2, 2])}}
    return data, note


def export_text(model_path, fmt, template=None, prefix=None):
    """Return (YAML text, note) of ``model_path`` in format ``fmt``."""
    needed_links(fmt)
    name = os.path.basename(os.fspath(model_path))
    if fmt == 'ur':
        data, note = ur_parameters(model_path, template, prefix)
    else:
        if template is not None:
            raise ExportError('--template: only --format ur keeps fields of '
                              'a template (inertials.yaml holds inertials '
                              'only)')
        data, note = franka_inertials(model_path, prefix)
    head = (f'# {WHAT[fmt]}: inertials identified in {name} '
            f'(newton-euler export)\n# {note}\n')
    body = yaml.safe_dump(data, sort_keys=False, default_flow_style=False,
                          width=1000, allow_unicode=True)
    return head + body, note


def export(model_path, fmt, output, template=None, prefix=None,
           overwrite=False):
    """Write ``model_path``'s inertials as ``fmt`` to ``output``; return note."""
    out = os.fspath(output)
    if os.path.isdir(out):
        raise ExportError(f'-o {clip(out, 200)}: is a directory')
    if os.path.lexists(out) and not overwrite:
        raise ExportError(f'-o {clip(out, 200)}: exists; refusing to '
                          f'overwrite it (add --overwrite)')
    folder = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(folder):
        raise ExportError(f'-o {clip(out, 200)}: no such directory '
                          f'{clip(folder, 200)}')
    text, note = export_text(model_path, fmt, template, prefix)
    try:
        atomic_write(out, text)
    except OSError as exc:
        raise ExportError(f'-o {clip(out, 200)}: cannot write: '
                          f'{exc.strerror or exc}') from None
    return note
