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
The shapes of a URDF's links, for keeping them clear of a surface.

Each link is described by its ``<collision>`` elements, or by its
``<visual>`` ones when it has no collision geometry (or they cannot be
read), as a list of shapes in the link frame:

- ``Points``: box corners, or the convex-hull vertices of an STL mesh
  (binary or ASCII; ``scale`` applied).  The lowest point of a convex
  body over a plane is one of its hull vertices, so the hull is exact.
- ``Sphere``: a centre and a radius.
- ``Cylinder``: a centre, a unit axis, a radius and a half length.

Mesh files are found as ROS finds them: ``package://NAME/PATH`` under
``share/NAME`` of every prefix in ``AMENT_PREFIX_PATH``, under every
folder of ``ROS_PACKAGE_PATH``, or under a folder named NAME above the
URDF file (a description package's own layout); ``file://`` and plain
paths as they are (relative to the URDF file).  A link whose geometry
cannot be read (a missing file, a COLLADA or OBJ mesh) has no shapes,
and the reason is kept: the caller bounds it by its origin.

Reading meshes is for the command line on the user's own files: the
node never reads them (``core.urdf`` parses URDF from the network).
"""
from dataclasses import dataclass, field
import math
import os
import struct

import defusedxml.ElementTree as DET
import numpy as np

from ..core.model import pose_matrix

MAX_MESH_BYTES = 64 * 1024 * 1024


@dataclass
class Points:
    """Vertices (N, 3) of a convex body, in the link frame."""

    points: np.ndarray

    def moved(self, T):
        """Return the shape in the frame where ``T`` places its frame."""
        return Points(self.points @ T[:3, :3].T + T[:3, 3])


@dataclass
class Sphere:
    """A ball of ``radius`` about ``centre``."""

    centre: np.ndarray
    radius: float

    def moved(self, T):
        """Return the shape in the frame where ``T`` places its frame."""
        return Sphere(T[:3, :3] @ self.centre + T[:3, 3], self.radius)


@dataclass
class Cylinder:
    """A solid cylinder: centre, unit axis, radius, half length."""

    centre: np.ndarray
    axis: np.ndarray
    radius: float
    half_length: float

    def moved(self, T):
        """Return the shape in the frame where ``T`` places its frame."""
        return Cylinder(T[:3, :3] @ self.centre + T[:3, 3],
                        T[:3, :3] @ self.axis, self.radius,
                        self.half_length)


@dataclass
class LinkShapes:
    """A link's shapes, where they came from, or why there are none."""

    shapes: list = field(default_factory=list)
    source: str = ''          # 'collision', 'visual' or ''
    problem: str = ''         # why no geometry could be read


def read_stl(path):
    """Return the vertices (N, 3) of an STL file (binary or ASCII)."""
    size = os.path.getsize(path)
    if size > MAX_MESH_BYTES:
        raise ValueError(f'{size} bytes, more than {MAX_MESH_BYTES}')
    with open(path, 'rb') as fh:
        data = fh.read()
    if len(data) >= 84:
        (count,) = struct.unpack_from('<I', data, 80)
        if 84 + 50 * count == len(data):
            rec = np.dtype([('normal', '<f4', 3), ('v', '<f4', (3, 3)),
                            ('attr', '<u2')])
            tri = np.frombuffer(data, dtype=rec, count=count, offset=84)
            pts = tri['v'].reshape(-1, 3).astype(np.float64)
            return _checked(pts)
    text = data.decode('ascii', errors='replace')
    if not text.lstrip().startswith('solid'):
        raise ValueError('neither binary nor ASCII STL')
    pts = []
    for line in text.splitlines():
        words = line.split()
        if len(words) == 4 and words[0] == 'vertex':
            try:
                pts.append([float(w) for w in words[1:]])
            except ValueError:
                raise ValueError(f'bad vertex line {line.strip()[:60]!r}'
                                 ) from None
    return _checked(np.array(pts, dtype=np.float64).reshape(-1, 3))


def _checked(pts):
    if len(pts) == 0:
        raise ValueError('no vertices')
    if not np.isfinite(pts).all():
        raise ValueError('vertices that are not finite numbers')
    return pts


def hull_vertices(pts):
    """Return the convex-hull vertices of ``pts`` (all if it is flat)."""
    from scipy.spatial import ConvexHull, QhullError
    pts = np.unique(pts, axis=0)
    if len(pts) <= 8:
        return pts
    try:
        return pts[ConvexHull(pts).vertices]
    except (QhullError, ValueError):
        return pts


def package_roots(name, urdf_dir):
    """Folders where ``package://name/`` may be, in ROS's search order."""
    roots = []
    for prefix in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep):
        if prefix:
            roots.append(os.path.join(prefix, 'share', name))
    for folder in os.environ.get('ROS_PACKAGE_PATH', '').split(os.pathsep):
        if folder:
            roots += [os.path.join(folder, name), folder]
    here = os.path.abspath(urdf_dir or '.')
    while True:
        if os.path.basename(here) == name:
            roots.append(here)
        up = os.path.dirname(here)
        if up == here:
            break
        here = up
    return roots


def resolve_mesh(filename, urdf_dir):
    """Return the path of a mesh file name, or raise ValueError."""
    if filename.startswith('package://'):
        rest = filename[len('package://'):]
        name, _, rel = rest.partition('/')
        for root in package_roots(name, urdf_dir):
            path = os.path.join(root, rel)
            if os.path.isfile(path):
                return path
        raise ValueError(f'package://{name} not found')
    path = filename[len('file://'):] if filename.startswith('file://') \
        else filename
    path = os.path.join(urdf_dir or '.', path)
    if not os.path.isfile(path):
        raise ValueError('no such file')
    return path


def _numbers(el, attr, count, default):
    raw = el.get(attr) if el is not None else None
    if raw is None:
        if default is None:
            raise ValueError(f'missing attribute {attr!r}')
        return list(default)
    try:
        vals = [float(x) for x in raw.split()]
    except ValueError:
        raise ValueError(f'{attr}={raw[:40]!r}: not numbers') from None
    if len(vals) == 1 and count == 3:       # scale="0.001"
        vals *= 3
    if len(vals) != count or not all(math.isfinite(v) for v in vals):
        raise ValueError(f'{attr}={raw!r}: {count} finite numbers needed')
    return vals


def _shape(element, urdf_dir, cache):
    """Return the shape of one <collision> or <visual>, in the link frame."""
    o = element.find('origin')
    T = pose_matrix(_numbers(o, 'xyz', 3, (0, 0, 0)),
                    _numbers(o, 'rpy', 3, (0, 0, 0)))
    geo = element.find('geometry')
    kinds = [] if geo is None else [g for g in geo if isinstance(g.tag, str)]
    if len(kinds) != 1:
        raise ValueError('<geometry> must hold one shape')
    g = kinds[0]
    if g.tag == 'box':
        h = 0.5 * np.abs(_numbers(g, 'size', 3, None))
        corners = np.array([[sx, sy, sz] for sx in (-1, 1)
                            for sy in (-1, 1) for sz in (-1, 1)]) * h
        return Points(corners).moved(T)
    if g.tag == 'sphere':
        return Sphere(np.zeros(3),
                      abs(_numbers(g, 'radius', 1, None)[0])).moved(T)
    if g.tag == 'cylinder':
        r = abs(_numbers(g, 'radius', 1, None)[0])
        length = abs(_numbers(g, 'length', 1, None)[0])
        return Cylinder(np.zeros(3), np.array([0.0, 0.0, 1.0]), r,
                        0.5 * length).moved(T)
    if g.tag == 'mesh':
        filename = g.get('filename') or ''
        if not filename.lower().endswith('.stl'):
            raise ValueError(f'mesh {os.path.basename(filename)!r} is not '
                             f'STL')
        path = resolve_mesh(filename, urdf_dir)
        if path not in cache:
            cache[path] = hull_vertices(read_stl(path))
        scale = np.array(_numbers(g, 'scale', 3, (1, 1, 1)))
        return Points(cache[path] * scale).moved(T)
    raise ValueError(f'unknown geometry <{g.tag}>')


def link_shapes(text, urdf_path=None):
    """
    Return {link name: :class:`LinkShapes`} of a URDF's text.

    ``urdf_path`` (the file the text came from) locates relative and
    package meshes.  The text is trusted to be a URDF that
    ``core.urdf`` has already accepted.
    """
    root = DET.fromstring(text, forbid_dtd=True, forbid_entities=True,
                          forbid_external=True)
    urdf_dir = os.path.dirname(os.path.abspath(urdf_path)) \
        if urdf_path else None
    cache = {}
    out = {}
    for link in root.findall('link'):
        found = LinkShapes()
        problems = []
        for source in ('collision', 'visual'):
            elements = link.findall(source)
            if not elements:
                continue
            try:
                shapes = [_shape(el, urdf_dir, cache) for el in elements]
            except (ValueError, OSError) as exc:
                problems.append(f'{source}: {exc}')
                continue
            found = LinkShapes(shapes, source)
            break
        if not found.shapes:
            found.problem = '; '.join(problems) or 'no geometry'
        out[link.get('name')] = found
    return out
