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
Keeping an arm clear of the surface it is mounted on (and other planes).

The arm moves as the bodies of its chain: body k is everything joint k
carries up to the next moving joint (the chain link, the links fixed to
it such as ``tool0`` or a hand, off-chain links at their zero position).
Its pose is frame k of :func:`core.dynamics.link_poses`.  A body is
bounded by the shapes of its links (``ident.geometry``: collision
geometry, else visual; STL hulls, boxes, spheres, cylinders) and, always,
by the origins of its links; a link without readable geometry counts by
its origin alone.

A constraint is a half-space of the base frame, ``n . p >= offset``
(``Plane``): the mounting surface is the base link's z = 0 plane, a wall
or a ceiling another plane, a workcell box six of them.  Each body's
clearance from a plane is the least ``n . p - offset`` over its shapes:
exact for hulls, boxes, spheres and cylinders.  A body must keep at least
``margin`` of clearance; a body already nearer than that at the start
(the casing around a shoulder joint of a table-mounted arm reaches down
to its mount) may not come nearer than it starts, less ``HELD_SLACK``
(a faceted mesh turning about its own axis).  A body below a plane at the
start is an error: the start, the plane or the mounting is wrong.

Self-collision is not checked.
"""
from dataclasses import dataclass
import math

import numpy as np

from .geometry import Cylinder, link_shapes, Points, Sphere
from ..core.dynamics import link_poses
from ..core.errors import DynamicsInputError
from ..core.workspace import Workspace

DEFAULT_MARGIN = 0.05        # m
HELD_SLACK = 0.002           # m (a faceted body turning about its axis)
SHRINK_STEPS = 10            # bisection steps: 1e-3 of the motion
HEADROOM = 1e-4              # m kept while shrinking (between grid points)


class ClearanceError(DynamicsInputError):
    """The start is inside a constraint (one line)."""


@dataclass
class Plane:
    """The half-space ``normal . p >= offset`` of the base frame."""

    normal: np.ndarray
    offset: float
    label: str

    @classmethod
    def make(cls, normal, offset, label):
        """Return a plane with a unit normal (ValueError if it is zero)."""
        n = np.asarray(normal, dtype=np.float64)
        norm = float(np.linalg.norm(n))
        if not (norm > 0 and math.isfinite(norm) and math.isfinite(offset)):
            raise ValueError(f'{label}: a plane needs a nonzero normal and '
                             f'a finite offset')
        return cls(n / norm, float(offset) / norm, label)


def floor(z=0.0):
    """Return the base frame's plane z = ``z`` (the arm keeps above it)."""
    return Plane.make((0.0, 0.0, 1.0), z, f'floor z = {z:g}')


def box(lo, hi):
    """Return the six planes of a box of the base frame (keep inside)."""
    planes = []
    for i, axis in enumerate('xyz'):
        if not lo[i] < hi[i]:
            raise ValueError(f'box: {axis} min {lo[i]:g} is not below '
                             f'{axis} max {hi[i]:g}')
        e = np.zeros(3)
        e[i] = 1.0
        planes.append(Plane.make(e, lo[i], f'box {axis} >= {lo[i]:g}'))
        planes.append(Plane.make(-e, -hi[i], f'box {axis} <= {hi[i]:g}'))
    return planes


@dataclass
class Body:
    """What moving joint k carries: its shapes in frame k."""

    frame: int
    name: str
    links: list
    points: np.ndarray               # (N, 3): hull vertices, corners, origins
    spheres: list
    cylinders: list


def _bodies_from_urdf(model, text, urdf_path):
    """Bodies of a URDF chain; and the links bounded by their origin."""
    from ..core.urdf import parse_urdf
    from ..core.urdf.tree import attached
    _, _, links, joints = parse_urdf(text, urdf_path or 'URDF')
    shapes = link_shapes(text, urdf_path)
    moving = list(model.info['urdf']['moving'])
    bodies, bare = [], []
    for k, jname in enumerate(moving):
        child = joints[jname].child
        stop = {moving[k + 1]} if k + 1 < len(moving) else set()
        pts, spheres, cylinders, names = [], [], [], []
        for lname, T, _ in attached(links, joints, child, stop):
            names.append(lname)
            pts.append(T[:3, 3][None, :])
            found = shapes.get(lname)
            if found is None or not found.shapes:
                if links[lname].mass > 0.0:
                    bare.append((lname, found.problem if found else ''))
                continue
            for shape in found.shapes:
                moved = shape.moved(T)
                if isinstance(moved, Points):
                    pts.append(moved.points)
                elif isinstance(moved, Sphere):
                    spheres.append(moved)
                elif isinstance(moved, Cylinder):
                    cylinders.append(moved)
        bodies.append(Body(k + 1, child, names, np.vstack(pts), spheres,
                           cylinders))
    return bodies, bare


def _bodies_from_frames(model):
    """Bodies of a model without geometry: the frame origins (and tool)."""
    bodies = []
    for k in range(model.n):
        pts = [np.zeros(3)]
        if k == model.n - 1:
            pts.append(np.asarray(model.tool)[:3, 3])
        bodies.append(Body(k + 1, model.joint_names[k], [], np.array(pts),
                           [], []))
    return bodies


class Clearance:
    """The bodies of a chain and the planes they must keep clear of."""

    def __init__(self, model, bodies, planes, margin=DEFAULT_MARGIN,
                 bare=()):
        self.model = model
        self.bodies = bodies
        self.planes = list(planes)
        self.margin = float(margin)
        self.bare = list(bare)
        self.required = None
        self.at_start = None
        self.ws = Workspace(model)

    @classmethod
    def of_urdf(cls, model, text, urdf_path, planes, margin=DEFAULT_MARGIN):
        """Bodies from the URDF's geometry (see the module docstring)."""
        bodies, bare = _bodies_from_urdf(model, text, urdf_path)
        return cls(model, bodies, planes, margin, bare)

    @classmethod
    def of_frames(cls, model, planes, margin=DEFAULT_MARGIN):
        """Bodies as the model's frame origins (no geometry)."""
        return cls(model, _bodies_from_frames(model), planes, margin)

    def poses(self, Q):
        """Rotations (m, F, 3, 3) and origins (m, F, 3) of every frame."""
        Q = np.atleast_2d(np.asarray(Q, dtype=np.float64))
        F = self.model.n + 2
        R = np.empty((len(Q), F, 3, 3))
        p = np.empty((len(Q), F, 3))
        for i, q in enumerate(Q):
            T = link_poses(self.model, q, ws=self.ws)
            R[i] = T[:, :3, :3]
            p[i] = T[:, :3, 3]
        return R, p

    def values(self, Q):
        """Clearance (m, bodies, planes) of each body from each plane."""
        R, p = self.poses(Q)
        out = np.empty((len(R), len(self.bodies), len(self.planes)))
        for b, body in enumerate(self.bodies):
            Rk, pk = R[:, body.frame], p[:, body.frame]
            for j, plane in enumerate(self.planes):
                nl = np.einsum('mij,i->mj', Rk, plane.normal)
                low = (nl @ body.points.T).min(axis=1)
                for s in body.spheres:
                    low = np.minimum(low, nl @ s.centre - s.radius)
                for c in body.cylinders:
                    a = nl @ c.axis
                    low = np.minimum(low, nl @ c.centre - c.half_length
                                     * np.abs(a) - c.radius
                                     * np.sqrt(np.maximum(0.0, 1 - a * a)))
                out[:, b, j] = pk @ plane.normal + low - plane.offset
        return out

    def set_start(self, start):
        """Fix what each body must keep; ClearanceError if one is inside."""
        v = self.values(start)[0]
        self.at_start = v
        b, j = np.unravel_index(np.argmin(v), v.shape)
        if v[b, j] < 0.0:
            raise ClearanceError(
                f'at the start, {self.bodies[b].name} is '
                f'{-v[b, j]:.3f} m beyond the {self.planes[j].label}: '
                f'the start, the plane or the mounting is wrong')
        self.required = np.where(v >= self.margin, self.margin,
                                 v - HELD_SLACK)

    def slack(self, Q):
        """Least (clearance - required) over samples, per (body, plane)."""
        return (self.values(Q) - self.required).min(axis=0)

    def ok(self, Q, headroom=0.0):
        """Return True when every sample keeps every body clear."""
        return bool(self.slack(Q).min() >= headroom)

    def shrink(self, start, dq):
        """
        Largest s in [0, 1] that keeps ``start + s dq`` clear (a grid).

        s = 0 (the start) is clear by construction; bisection keeps the
        last clear s, so the answer is always checked.
        """
        def gap(s):
            return float(self.slack(start + s * dq).min()) - HEADROOM

        g_hi = gap(1.0)
        if g_hi >= 0.0:
            return 1.0
        lo, hi, g_lo = 0.0, 1.0, gap(0.0)
        if g_lo < 0.0:
            return 0.0
        for _ in range(SHRINK_STEPS):
            mid = 0.5 * (lo + hi)
            g = gap(mid)
            if g >= 0.0:
                lo, g_lo = mid, g
            else:
                hi, g_hi = mid, g
        # one secant step in the last bracket: s then varies smoothly
        # with the motion (the optimiser differentiates it), and is kept
        # only if it is clear
        s = lo + (hi - lo) * g_lo / (g_lo - g_hi)
        return s if gap(s) >= -HEADROOM else lo

    def report(self, Q, t):
        """Rows (body, at start, least, at t, kept at least) per plane."""
        v = self.values(Q)
        rows = []
        for j, plane in enumerate(self.planes):
            for b, body in enumerate(self.bodies):
                i = int(np.argmin(v[:, b, j]))
                rows.append((plane.label, body.name, self.at_start[b, j],
                             v[i, b, j], t[i], self.required[b, j]))
        return rows
