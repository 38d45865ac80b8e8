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
Write an identified model as the input URDF with its numbers replaced.

Everything else of the input is kept (visuals, collisions, joints,
limits, comments, other links): only

- each body's moving link's ``<inertial>`` (the chain's links, or every
  moving joint's child link of a tree, a mimic follower's too; the parts
  rigidly attached to it by fixed joints keep their published inertials,
  and the identified total of the body is their sum);
- each coordinate's joint's ``<dynamics damping=... friction=...>``
  (viscous and Coulomb friction; other attributes of an existing
  ``<dynamics>`` stay);
- each coordinate's joint's ``<ne:drive armature=... offset=...
  coulomb_width=...>`` in the namespace ``core.drives.DRIVES_NS``
  (declared on ``<robot>``), which URDF parsers that do not know it
  ignore.

A mimic follower's joint is left as it is: it is no coordinate, its
friction and rotor inertia act through its leader's drive (identified as
the leader's), and ``core.drives`` reads drive terms of coordinates only.

Files are written atomically (:func:`atomic_write`): a temporary file in
the same directory, flushed to disk, then renamed over the target.
"""
import os
import tempfile
import xml.etree.ElementTree as ET

import numpy as np

from ..core.drives import DRIVES_NS, DRIVES_PREFIX
from ..core.regressor import link_inertials, N_INERTIAL


def atomic_write(path, data, mode='w'):
    """Write ``data`` (str or bytes) to ``path`` atomically."""
    path = os.path.abspath(path)
    folder = os.path.dirname(path)
    fd, tmp = tempfile.mkstemp(prefix='.' + os.path.basename(path) + '.',
                               suffix='.tmp', dir=folder)
    try:
        with os.fdopen(fd, 'wb' if 'b' in mode or isinstance(data, bytes)
                       else 'w', **({} if isinstance(data, bytes)
                                    else {'encoding': 'utf-8'})) as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


class atomic_open:  # noqa: N801 (used like open)
    """``with atomic_open(path) as f:`` write f; renamed over path at exit."""

    def __init__(self, path, mode='w'):
        self.path = os.path.abspath(path)
        self.mode = mode

    def __enter__(self):
        fd, self.tmp = tempfile.mkstemp(
            prefix='.' + os.path.basename(self.path) + '.', suffix='.tmp',
            dir=os.path.dirname(self.path))
        kw = {} if 'b' in self.mode else {'encoding': 'utf-8',
                                          'newline': ''}
        self.f = os.fdopen(fd, self.mode, **kw)
        return self.f

    def __exit__(self, exc_type, exc, tb):
        try:
            if exc_type is None:
                self.f.flush()
                os.fsync(self.f.fileno())
            self.f.close()
            if exc_type is None:
                os.replace(self.tmp, self.path)
        finally:
            if os.path.exists(self.tmp):
                os.unlink(self.tmp)
        return False


def _fmt(values):
    return ' '.join(repr(float(v)) for v in values)


def _parse_keep_comments(text):
    parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
    parser.feed(text)
    return parser.close()


def _set_inertial(link_el, pi_own):
    m, c, Ic = link_inertials(pi_own)
    if m <= 0.0:
        m, c, Ic = 0.0, np.zeros(3), np.zeros((3, 3))
    Ic = 0.5 * (Ic + Ic.T)
    old = link_el.find('inertial')
    index = list(link_el).index(old) if old is not None else 0
    if old is not None:
        link_el.remove(old)
    # indented like the element it replaces
    inner = (old.text if old is not None and old.text else '\n      ')
    last = (old[-1].tail if old is not None and len(old) and old[-1].tail
            else '\n    ')
    el = ET.Element('inertial')
    el.text = inner
    el.tail = old.tail if old is not None else '\n    '
    o = ET.SubElement(el, 'origin', xyz=_fmt(c), rpy='0 0 0')
    o.tail = inner
    ms = ET.SubElement(el, 'mass', value=repr(float(m)))
    ms.tail = inner
    i = ET.SubElement(el, 'inertia', ixx=repr(float(Ic[0, 0])),
                      ixy=repr(float(Ic[0, 1])), ixz=repr(float(Ic[0, 2])),
                      iyy=repr(float(Ic[1, 1])), iyz=repr(float(Ic[1, 2])),
                      izz=repr(float(Ic[2, 2])))
    i.tail = last
    link_el.insert(index, el)


def _append(parent, tag):
    """Append a child element, indented like its siblings."""
    kids = list(parent)
    el = ET.SubElement(parent, tag)
    if kids:
        el.tail = kids[-1].tail
        kids[-1].tail = (kids[-2].tail if len(kids) > 1
                         else parent.text or '\n')
    else:
        parent.text = '\n'
        el.tail = '\n'
    return el


def _set_drive(joint_el, drives, j):
    dyn = joint_el.find('dynamics')
    if dyn is None:
        dyn = _append(joint_el, 'dynamics')
    dyn.set('damping', repr(float(drives.viscous[j])))
    dyn.set('friction', repr(float(drives.coulomb[j])))
    tag = f'{{{DRIVES_NS}}}drive'
    ext = joint_el.find(tag)
    if ext is None:
        ext = _append(joint_el, tag)
    ext.set('armature', repr(float(drives.armature[j])))
    ext.set('offset', repr(float(drives.offset[j])))
    ext.set('coulomb_width', repr(float(drives.coulomb_width[j])))
    if drives.torque_constant is not None:
        ext.set('torque_constant', repr(float(drives.torque_constant[j])))


def identified_urdf(text, model, theta, fixed, drives):
    """
    Return the URDF text of ``text`` with the identified parameters.

    ``model`` is the nominal chain or tree loaded from ``text`` (its
    ``info['urdf']`` names the bodies' links); ``theta`` the identified
    10nb inertial parameters (then optionally the drives); ``fixed``
    (nb, 10) the parameters of the parts rigidly attached to each body
    (``fit.fixed_parts``); ``drives`` a ``core.drives.Drives`` of the n
    coordinates.
    """
    ET.register_namespace(DRIVES_PREFIX, DRIVES_NS)
    root = _parse_keep_comments(text)
    report = model.info['urdf']
    links = {el.get('name'): el for el in root.findall('link')}
    joints = {el.get('name'): el for el in root.findall('joint')}
    for k in range(model.nb):
        pi = np.asarray(theta[N_INERTIAL * k:N_INERTIAL * (k + 1)])
        _set_inertial(links[report['links'][k]], pi - fixed[k])
    for j, name in enumerate(model.joint_names):
        _set_drive(joints[name], drives, j)
    body = ET.tostring(root, encoding='unicode')
    return '<?xml version="1.0" encoding="utf-8"?>\n' + body + '\n'
