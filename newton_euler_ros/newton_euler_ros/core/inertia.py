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
Rigid-body inertia: the one validity check and the one parallel-axis merge.

Every reader of inertial data (robot YAML files, URDF, scenes, the node's
payload parameters) checks it here, with one tolerance, and every merge of
rigidly joined bodies (URDF fixed joints, lumped subtrees, payloads) adds
them up here.

Tolerance.  A symmetric 3x3 inertia is accepted when its smallest
principal moment is at least ``-INERTIA_RTOL`` times its largest
(absolute) one, and a full 3x3 matrix as symmetric when its asymmetry is
at most ``INERTIA_RTOL`` times its largest entry: published inertias are
printed to 6-9 digits, so a round-off negative moment of 1e-10 relative
is data, a clearly negative one (or an asymmetric matrix) a typo.
"""
import numpy as np

INERTIA_RTOL = 1e-9


class Note(str):
    """
    A warning about published data that is accepted as published.

    ``newton-euler check`` and the node's start-up log show notes; the
    other commands do not repeat them on every use.
    """


def inertia_matrix(ixx, iyy, izz, ixy, iyz, ixz):
    """Symmetric 3x3 inertia from [Ixx, Iyy, Izz, Ixy, Iyz, Ixz]."""
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]],
                    dtype=np.float64)


def is_symmetric(inertia):
    """Return True when a 3x3 matrix is symmetric within INERTIA_RTOL."""
    inertia = np.asarray(inertia, dtype=np.float64)
    scale = max(float(np.abs(inertia).max()), 1e-300)
    return float(np.abs(inertia - inertia.T).max()) <= INERTIA_RTOL * scale


def principal_moments(inertia):
    """
    Return (moments ascending, valid) of a symmetric 3x3 inertia.

    ``valid`` is False when the smallest moment is negative beyond the
    tolerance (the matrix is not positive semidefinite).
    """
    eig = np.linalg.eigvalsh(np.asarray(inertia, dtype=np.float64))
    scale = max(float(np.abs(eig).max()), 1e-300)
    return eig, bool(eig[0] >= -INERTIA_RTOL * scale)


def format_moments(eig):
    """Return 'a, b, c': principal moments for a message."""
    return ', '.join(f'{e:.6g}' for e in eig)


def triangle_note(where, eig):
    """
    Return a Note when principal moments break the triangle inequality.

    ``eig``: the three principal moments, ascending.  No real body has
    such moments, but published models do (the Puma 560's link 1): they
    are accepted as published, with this note.
    """
    tol = INERTIA_RTOL * max(eig[2], 1e-300)
    if eig[0] + eig[1] < eig[2] - tol:
        return Note(f'{where}: principal moments {format_moments(eig)} '
                    f'break the triangle inequality (no real body has '
                    f'them); accepted as published')
    return None


def merge_bodies(bodies):
    """
    Mass, centre of mass and inertia of rigidly joined bodies.

    ``bodies``: (mass, com, inertia, R, p) per body, its centre of mass
    ``com`` and its inertia about it given in the body's own axes, and
    (R, p) the pose of those axes in the frame of the result.  Each body's
    inertia is rotated into that frame (R I R^T) and carried to the common
    centre of mass by the parallel-axis theorem,
    I += m (|d|^2 1 - d d^T) with d the body's offset from it.  Returns
    (mass, com, inertia about com) in the result's frame; a massless whole
    has its centre of mass at the origin.
    """
    mass = 0.0
    first = np.zeros(3)
    placed = []
    for m, com, inertia, R, p in bodies:
        R = np.asarray(R, dtype=np.float64)
        c = R @ np.asarray(com, dtype=np.float64) + np.asarray(p, np.float64)
        placed.append((m, c, R @ np.asarray(inertia, np.float64) @ R.T))
        mass += m
        first += m * c
    com = first / mass if mass > 0.0 else np.zeros(3)
    total = np.zeros((3, 3))
    for m, c, inertia in placed:
        d = c - com
        total += inertia + m * ((d @ d) * np.eye(3) - np.outer(d, d))
    return mass, com, 0.5 * (total + total.T)
