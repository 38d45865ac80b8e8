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
A robot as a MuJoCo model: the independent plant.

MuJoCo compiles the URDF with its own reader; this module only prepares
the text and adds what URDF cannot say (docs/mujoco.md has the table):

- inertials are taken as written: ``inertiafromgeom`` and
  ``balanceinertia`` are off, so a link MuJoCo cannot take (an inertia
  that breaks A + B >= C, a massless moving link) is refused in one line
  naming the link and MuJoCo's reason;
- fixed joints: the child is a body without joints, welded to its parent
  (MuJoCo's composite rigid body is then exactly the merged link); every
  link keeps its name, so contacts and pushers can name it;
- drive terms: ``viscous`` (``<dynamics damping>``) is the joint's
  ``damping``, ``coulomb`` (``<dynamics friction>``) its ``frictionloss``
  (a soft constraint in MuJoCo, not the library's tanh), ``armature``
  (``<ne:drive armature>``) its ``armature``; the offset, the Coulomb
  width and the torque constants have no MuJoCo counterpart and are left
  out, said in a note when present;
- limits: the joint range is MuJoCo's limit; the effort limit is the
  force range of the joint's motor actuator (one per independent joint,
  gear 1: ``ctrl`` is the joint torque);
- mimic joints: a joint equality constraint (follower = multiplier x
  leader + offset), added where MuJoCo's reader did not make one;
- meshes: a collision mesh is resolved from ``package://`` or a relative
  path where the file exists (STL, OBJ or MSH), and dropped with one note
  otherwise; visuals are discarded;
- a floating or planar root joint is welded (the plant's base is fixed),
  with a note.

An MJCF file (root ``<mujoco>``) is compiled as it is.  A robot YAML file
or bundled name is written as URDF first (``model_to_urdf``).  Nothing
here imports ROS.
"""
from dataclasses import dataclass
import os
import xml.etree.ElementTree as ET

import defusedxml.ElementTree as DET
import numpy as np

from ..core.drives import model_drives
from ..core.errors import RobotFileError
from ..core.robot_file import is_urdf, load_robot
from ..core.text import clip, read_text
from ..core.urdf import MAX_BYTES, read_urdf_text, urdf_model
from ..core.urdf.writer import model_to_urdf

MESH_FORMATS = ('.stl', '.obj', '.msh')
COMPILER = {'discardvisual': 'true', 'fusestatic': 'false',
            'inertiafromgeom': 'false', 'balanceinertia': 'false',
            'strippath': 'false', 'angle': 'radian'}
# URDF elements the plant reads; ros2_control, transmission, gazebo and
# extension blocks are left out before MuJoCo sees the text
KEEP = ('link', 'joint', 'material')


def _mujoco():
    try:
        import mujoco
    except ImportError as exc:      # pragma: no cover - make setup has it
        raise RobotFileError(f'the MuJoCo plant needs the mujoco package '
                             f'(make setup installs it): {exc}') from None
    return mujoco


@dataclass(frozen=True, eq=False)
class MujocoRobot:
    """
    A compiled MuJoCo model and how the robot's joints sit in it.

    ``joints`` are the commanded joints (independent, in the order asked
    for); ``qpos``, ``dof`` and ``actuator`` their addresses in
    ``data.qpos``, ``data.qvel`` and ``data.ctrl``; ``followers`` the mimic
    joints as (name, qpos address, dof address); ``notes`` what was
    dropped or changed on the way; ``label`` the source's name for
    messages; ``urdf`` the text MuJoCo compiled (None for MJCF).
    """

    model: object
    joints: tuple
    qpos: np.ndarray
    dof: np.ndarray
    actuator: np.ndarray
    followers: tuple
    notes: tuple
    label: str
    urdf: str = None

    @property
    def n(self):
        """Return the number of commanded joints."""
        return len(self.joints)

    def state(self, data):
        """Return (q, qd) of the commanded joints in ``data``."""
        return data.qpos[self.qpos].copy(), data.qvel[self.dof].copy()

    def set_state(self, data, q, qd=None):
        """Put (q, qd) on the commanded joints, followers on their leaders."""
        mujoco = _mujoco()
        data.qpos[self.qpos] = q
        data.qvel[self.dof] = 0.0 if qd is None else qd
        m = self.model
        for k in range(m.neq):
            if m.eq_type[k] != mujoco.mjtEq.mjEQ_JOINT:
                continue
            j1, j2 = m.eq_obj1id[k], m.eq_obj2id[k]
            c0, c1 = m.eq_data[k, 0], m.eq_data[k, 1]
            p2, v2 = m.jnt_qposadr[j2], m.jnt_dofadr[j2]
            data.qpos[m.jnt_qposadr[j1]] = c0 + c1 * data.qpos[p2]
            data.qvel[m.jnt_dofadr[j1]] = c1 * data.qvel[v2]
        mujoco.mj_forward(m, data)

    def body(self, link):
        """Return the body id of a link (RobotFileError naming it if none)."""
        mujoco = _mujoco()
        i = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, link)
        if i < 0:
            names = [self.model.body(b).name
                     for b in range(1, self.model.nbody)]
            raise RobotFileError(f'{self.label}: no link named {link!r} '
                                 f'(links: {clip(", ".join(names), 300)})')
        return i


def load_mujoco(source, joints=None, label=None, timestep=None,
                gravity=(0.0, 0.0, -9.81), extend=None):
    """
    Compile a robot for MuJoCo; return a :class:`MujocoRobot`.

    ``source``: URDF text or file, an MJCF file or text, a robot YAML file
    or bundled name, or a :class:`~..core.model.RobotModel`.  ``joints``:
    the commanded joints (default: every independent moving joint, in
    file order).  ``extend(spec, mujoco)`` may add scene objects to the
    ``MjSpec`` before it is compiled.  Every failure is one
    RobotFileError line naming the source.
    """
    mujoco = _mujoco()
    notes = []
    spec, urdf, order, label, own = _spec(source, label, notes, mujoco)
    if timestep is not None:
        spec.option.timestep = float(timestep)
    if urdf is not None:
        spec.option.gravity = np.asarray(
            gravity if own is None else own, dtype=float)
    if extend is not None:
        extend(spec, mujoco)
    model = _compile(spec, label, mujoco)
    mujoco_joints = [model.joint(j).name for j in range(model.njnt)]
    followers = _followers(model, mujoco)
    if order is None:
        order = [j for j in mujoco_joints
                 if j not in {f for f, _, _ in followers}
                 and model.jnt_type[mujoco_joints.index(j)] in (2, 3)]
    names = list(order) if joints is None or not len(joints) else \
        [str(j) for j in joints]
    ids = []
    for name in names:
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if j < 0 or model.jnt_type[j] not in (2, 3):
            raise RobotFileError(
                f'{label}: joints: no moving joint named {clip(name, 80)!r}'
                f' (joints: {clip(", ".join(order), 300)})')
        ids.append(j)
    if len(set(names)) != len(names):
        raise RobotFileError(f'{label}: joints: a joint is named twice')
    actuator = []
    for name, j in zip(names, ids):
        a = [k for k in range(model.nu) if model.actuator_trnid[k, 0] == j
             and model.actuator_trntype[k] == mujoco.mjtTrn.mjTRN_JOINT]
        if not a:
            raise RobotFileError(f'{label}: joint {name!r} has no motor '
                                 f'actuator (an MJCF model needs one per '
                                 f'commanded joint)')
        actuator.append(a[0])
    return MujocoRobot(
        model=model, joints=tuple(names),
        qpos=np.array([model.jnt_qposadr[j] for j in ids], dtype=np.intp),
        dof=np.array([model.jnt_dofadr[j] for j in ids], dtype=np.intp),
        actuator=np.array(actuator, dtype=np.intp),
        followers=tuple(followers), notes=tuple(notes), label=label,
        urdf=urdf)


def _spec(source, label, notes, mujoco):
    """
    Return (MjSpec, urdf or None, joint order or None, label, gravity).

    ``gravity`` is a robot file's own (None: the caller's).
    """
    if hasattr(source, 'moving_joints'):
        spec = _urdf_spec(model_to_urdf(source), label or source.name,
                          None, notes, mujoco)
        return spec + (source.gravity,)
    text = os.fspath(source) if not isinstance(source, str) else source
    if not text.lstrip('\ufeff \t\r\n').startswith('<'):
        path = text
        if not (is_urdf(path) or path.lower().endswith('.xml')):
            model = load_robot(path)        # a YAML file or bundled name
            spec = _urdf_spec(model_to_urdf(model),
                              label or os.path.basename(path), None, notes,
                              mujoco)
            return spec + (model.gravity,)
        text = read_text(path, MAX_BYTES, 'robot file')
        label = label or os.path.basename(path)
        folder = os.path.dirname(os.path.abspath(path))
    else:
        label = label or 'robot_description'
        folder = None
    text, label = read_urdf_text(text, label)
    root = _parse(text, label)
    if root.tag == 'mujoco':
        return _mjcf_spec(text, folder, label, mujoco), None, None, label, \
            None
    return _urdf_spec(text, label, folder, notes, mujoco) + (None,)


def _parse(text, label):
    try:
        return DET.fromstring(text, forbid_dtd=True, forbid_entities=True,
                              forbid_external=True)
    except Exception as exc:    # the URDF reader says it in its words
        if isinstance(exc, ET.ParseError) or 'Forbidden' in type(
                exc).__name__:
            urdf_model(text, label)     # raises its one-line error
        raise RobotFileError(f'{label}: {clip(exc, 200)}') from None


def _mjcf_spec(text, folder, label, mujoco):
    try:
        spec = mujoco.MjSpec.from_string(text)
    except Exception as exc:
        raise RobotFileError(f'{label}: MuJoCo refuses the MJCF: '
                             f'{_reason(exc)}') from None
    if folder is not None:
        spec.modelfiledir = folder
    return spec


def _urdf_spec(text, label, folder, notes, mujoco):
    # our own reader first: the file's errors are named as everywhere
    model, _, _ = urdf_model(text, label)
    drives = model_drives(model)
    root = _parse(text, label)
    out = ET.Element('robot', {'name': root.get('name') or 'robot'})
    order = []
    floating = []
    for el in root:
        if el.tag not in KEEP:
            continue
        el = _strip_namespaced(el)
        if el.tag == 'link':
            _link_meshes(el, folder, label, notes)
        if el.tag == 'joint':
            kind = el.get('type')
            if kind in ('floating', 'planar'):
                el.set('type', 'fixed')
                floating.append(el.get('name'))
            elif kind in ('revolute', 'continuous', 'prismatic') \
                    and el.find('mimic') is None:
                order.append(el.get('name'))
        out.append(el)
    if floating:
        notes.append(f'{label}: the {" and ".join(floating)} joint is '
                     f'floating or planar: the plant welds it (a fixed '
                     f'base)')
    block = ET.SubElement(out, 'mujoco')
    ET.SubElement(block, 'compiler', COMPILER)
    urdf = ET.tostring(out, encoding='unicode')
    try:
        spec = mujoco.MjSpec.from_string(urdf)
    except Exception as exc:
        raise RobotFileError(f'{label}: MuJoCo refuses the URDF: '
                             f'{_reason(exc)}') from None
    _drive_terms(spec, model, drives, label, notes)
    _mimic(spec, model, mujoco)
    _actuators(spec, model, order, mujoco)
    return spec, urdf, order, label


def _strip_namespaced(el):
    """Return a copy of el without elements of another namespace."""
    for parent in el.iter():
        for child in list(parent):
            if not isinstance(child.tag, str) or child.tag.startswith('{'):
                parent.remove(child)
    for node in el.iter():
        for key in [k for k in node.attrib if k.startswith('{')]:
            del node.attrib[key]
    return el


def _link_meshes(link, folder, label, notes):
    for kind in ('visual', 'collision'):
        for el in link.findall(kind):
            if kind == 'visual':
                link.remove(el)
                continue
            mesh = el.find('geometry/mesh')
            if mesh is None:
                continue
            name = mesh.get('filename') or ''
            path = resolve_mesh(name, folder)
            if path is None or not path.lower().endswith(MESH_FORMATS):
                link.remove(el)
                why = ('not found' if path is None else
                       'a format MuJoCo does not read')
                notes.append(f'{label}: link {link.get("name")!r} '
                             f'<collision> mesh {clip(name, 120)!r}: {why}; '
                             f'dropped (no contact there)')
            else:
                mesh.set('filename', path)


def resolve_mesh(name, folder=None):
    """
    Return the file a mesh's filename names, or None where none exists.

    ``package://pkg/rest`` is looked up as ``share/pkg/rest`` under each
    prefix of ``AMENT_PREFIX_PATH``, as ``pkg/rest`` under each folder of
    ``ROS_PACKAGE_PATH``, and in any folder named ``pkg`` above the URDF
    file; ``file://`` and plain paths as given (relative ones beside the
    URDF file).
    """
    if name.startswith('package://'):
        pkg, _, rest = name[len('package://'):].lstrip('/').partition('/')
        places = [os.path.join(p, 'share', pkg) for p in os.environ.get(
            'AMENT_PREFIX_PATH', '').split(os.pathsep) if p]
        places += [os.path.join(p, pkg) for p in os.environ.get(
            'ROS_PACKAGE_PATH', '').split(os.pathsep) if p]
        here = folder
        while here and os.path.dirname(here) != here:
            if os.path.basename(here) == pkg:
                places.append(here)
            here = os.path.dirname(here)
        for place in places:
            path = os.path.join(place, rest)
            if os.path.isfile(path):
                return os.path.abspath(path)
        return None
    name = name.removeprefix('file://')
    if not os.path.isabs(name):
        if folder is None:
            return None
        name = os.path.join(folder, name)
    return os.path.abspath(name) if os.path.isfile(name) else None


def _drive_terms(spec, model, drives, label, notes):
    if drives is None:
        return
    for k, name in enumerate(model.joint_names):
        joint = spec.joint(name)
        joint.damping[0] = float(drives.viscous[k])
        joint.frictionloss = float(drives.coulomb[k])
        joint.armature = float(drives.armature[k])
    left = [what for what, value in (
        ('offsets', np.any(drives.offset)),
        ('torque constants', drives.torque_constant is not None)) if value]
    if np.any(drives.coulomb):
        left.append("the Coulomb width (MuJoCo's friction is a "
                    'constraint, not a tanh)')
    if left:
        notes.append(f'{label}: not in the MuJoCo plant: '
                     f'{", ".join(left)}')


def _mimic(spec, model, mujoco):
    """Add the mimic joints' equality constraints MuJoCo did not make."""
    have = {e.name1 for e in spec.equalities
            if e.type == mujoco.mjtEq.mjEQ_JOINT}
    for j, m in enumerate(model.mimic or ()):
        if m is None:
            continue
        follower = model.moving_joints[j]
        if follower in have:
            continue
        leader, mult, offset = model.moving_joints[m[0]], m[1], m[2]
        eq = spec.add_equality()
        eq.type = mujoco.mjtEq.mjEQ_JOINT
        eq.objtype = mujoco.mjtObj.mjOBJ_JOINT
        eq.name1, eq.name2 = follower, leader
        eq.data[:5] = [offset, mult, 0.0, 0.0, 0.0]


def _actuators(spec, model, order, mujoco):
    limits = dict(zip(model.moving_joints, model.limits))
    for name in order:
        act = spec.add_actuator()
        act.name = name
        act.target = name
        act.trntype = mujoco.mjtTrn.mjTRN_JOINT
        act.gear[0] = 1.0
        effort = limits.get(name, {}).get('effort')
        if effort:
            act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
            act.forcerange = [-effort, effort]


def _followers(model, mujoco):
    out = []
    for k in range(model.neq):
        if model.eq_type[k] == mujoco.mjtEq.mjEQ_JOINT:
            j = model.eq_obj1id[k]
            out.append((model.joint(j).name, int(model.jnt_qposadr[j]),
                        int(model.jnt_dofadr[j])))
    return out


def _reason(exc):
    """Return MuJoCo's error text as one line, without 'Error: '."""
    lines = [s.strip() for s in str(exc).splitlines() if s.strip()]
    return clip('; '.join(lines).removeprefix('Error: '), 400)


def _compile(spec, label, mujoco):
    try:
        return spec.compile()
    except Exception as exc:
        lines = [s.strip() for s in str(exc).splitlines() if s.strip()]
        reason = (lines[0] if lines else str(exc)).removeprefix('Error: ')
        where = next((s for s in lines if s.startswith('Element name')),
                     '')
        name = where.split("'")[1] if where.count("'") >= 2 else None
        what = f'link {name!r}' if name else 'the model'
        raise RobotFileError(f'{label}: MuJoCo refuses {what}: '
                             f'{clip(reason, 300)}') from None
