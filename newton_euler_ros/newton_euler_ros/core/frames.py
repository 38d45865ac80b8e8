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
Named frames: poses and Jacobians of any link, and wrenches at links.

A model's links are named in ``model.link_frames`` (every link of a URDF
tree, the ones merged by fixed joints too: ``tool0``, a force-torque
sensor's frame), each fixed to a moving joint's link (or to the base) at a
constant pose; ``'end_effector'`` names the end-effector frame.

- :func:`jacobian`: J(q) of a frame's origin, rows [v; w], in base axes
  or the frame's own; only the joints between it and the base move it.
- :func:`link_poses`, :func:`end_effector_pose`, :func:`frame_pose`.
- Wrenches at links: ``inverse_dynamics(..., wrench={LINK: F, ...},
  wrench_frame={LINK: 'base' or 'link'})`` (:func:`link_wrench_rows`
  turns them into the kernels' per-body rows, in link axes) and
  :func:`wrench_torques`, sum J_link^T F, the same torques by virtual
  work.
"""
import difflib

import numpy as np

from . import kernels as K
from .calling import (BOOL, INT, MAT, out_array, PACKED, status_error,
                      strict_entry, TARGET, VEC, vector, workspace)
from .errors import DynamicsInputError
from .text import clip

END_EFFECTOR = 'end_effector'
AXES = ('base', 'link')         # of a named frame's Jacobian and wrench
OLD_AXES = {'base': False, END_EFFECTOR: True}   # frame= of the end effector

_jac = strict_entry(K.run_jacobian, PACKED, VEC, INT, TARGET, BOOL, MAT, MAT,
                    MAT, home=globals())
_poses = strict_entry(K.run_link_poses, PACKED, VEC, MAT, MAT, home=globals())


def _readonly(x):
    x = np.ascontiguousarray(x, dtype=np.float64)
    x.setflags(write=False)
    return x


def frame_target(model, name):
    """
    Return (joint, 12-vector) of a named frame, for the Jacobian kernel.

    The joint whose link carries the frame (-1: the base) and the frame's
    pose (R row-major, p) in that joint's kernel frame; cached per model.
    """
    cache = model.__dict__.setdefault('_frame_targets', {})
    if name in cache:
        return cache[name]
    if name == END_EFFECTOR:
        if model.tool_body is None:
            raise DynamicsInputError(
                f'{model.name} has no end effector (a tree with several '
                f'tips): name a link ({_some_links(model)})')
        out = (model.tool_body, _readonly(model.frames_array[K.F_TOOL]))
    else:
        body, T = _named(model, name)
        if body >= 0:
            B = np.eye(4)
            B[:3, :3] = model.links_array[body, K.L_BODY:K.L_BODY + 9] \
                .reshape(3, 3)
            B[:3, 3] = model.links_array[body, K.L_BODY + 9:K.L_BODY + 12]
            T = B @ T
        out = (body, _readonly(np.concatenate([T[:3, :3].ravel(),
                                               T[:3, 3]])))
    cache[name] = out
    return out


def _some_links(model):
    names = list(model.link_frames)
    return 'links: ' + clip(', '.join(names), 300) if names else \
        'this model names no links'


def _named(model, name):
    """Return (joint, 4x4 pose) of a link of ``model.link_frames``."""
    try:
        return model.link_frames[name]
    except (KeyError, TypeError):
        close = difflib.get_close_matches(str(name), list(model.link_frames),
                                          n=3, cutoff=0.5)
        hint = ('closest: ' + ', '.join(map(repr, close)) if close
                else _some_links(model))
        raise DynamicsInputError(
            f"frame must be 'base', 'end_effector' or a link of "
            f'{model.name}: {clip(repr(name), 200)} is not one ({hint})'
        ) from None


def frame_body(model, name):
    """Return (joint, 4x4 pose in its link frame) of a named frame."""
    if name == END_EFFECTOR:
        frame_target(model, name)           # raises without one
        return model.tool_body, np.asarray(model.tool)
    return _named(model, name)


def jacobian(model, q, frame='base', *, axes=None, ws=None, out=None):
    """
    Geometric Jacobian J(q), (6, n), of a frame's origin.

    Rows are [linear velocity; angular velocity] such that
    ``[v; w] = J(q) qd``.  ``frame`` names the frame: a link of the model
    (``model.link_frames``: every URDF link) or ``'end_effector'``;
    ``axes`` is ``'base'`` (the default) or ``'link'`` (the frame's own
    axes; for the end effector its axes).  Only the joints between the
    frame and the base move it: the other columns are zero (a mimic
    joint's column adds to its leader's, times its multiplier).  Cost:
    O(nb).

    Without ``axes``, ``frame='base'`` and ``frame='end_effector'`` keep
    their meaning of before trees: the end effector's Jacobian in base
    or end-effector axes (``jacobian(model, q)``, ``jacobian(model, q,
    'end_effector')``); a link named ``base`` is then reached with
    ``axes='base'``.
    """
    if axes is None and frame in OLD_AXES:
        local = OLD_AXES[frame]
        frame = END_EFFECTOR
    elif axes is None or axes in AXES:
        local = axes == 'link'
    else:
        raise DynamicsInputError(
            f"axes must be 'base' or 'link', got {clip(repr(axes), 100)}")
    body, target = frame_target(model, frame)
    ws = workspace(model, ws)
    n = ws.n
    q = vector('q', q, n)
    J = out_array(out, (6, n))
    code = _jac(model.packed, q, body, target, local, ws.ws, ws.frames, J)
    if code >= 0:
        raise status_error(code, (q,))
    return J


def _poses_array(model, q, ws):
    ws = workspace(model, ws)
    q = vector('q', q, ws.n)
    code = _poses(model.packed, q, ws.ws, ws.frames)
    if code >= 0:
        raise status_error(code, (q,))
    return ws.frames


def _matrix(row):
    T = np.eye(4)
    T[:3, :3] = row[:9].reshape(3, 3)
    T[:3, 3] = row[9:]
    return T


def end_effector_pose(model, q, *, ws=None):
    """4x4 pose of the end-effector frame in the base frame."""
    return _matrix(_poses_array(model, q, ws)[-1])


def link_poses(model, q, *, ws=None):
    """
    Poses of frame 0, the nb moving joints' link frames and the end effector.

    In the base frame: an (nb + 2, 4, 4) array of homogeneous transforms,
    row j + 1 the link frame of ``model.moving_joints[j]``.
    """
    frames = _poses_array(model, q, ws)
    T = np.zeros((frames.shape[0], 4, 4))
    T[:, :3, :3] = frames[:, :9].reshape(-1, 3, 3)
    T[:, :3, 3] = frames[:, 9:]
    T[:, 3, 3] = 1.0
    return T


def frame_pose(model, q, frame, *, ws=None):
    """4x4 pose in the base frame of a named frame (a link, the end effector)."""
    body, T = frame_body(model, frame)
    return _matrix(_poses_array(model, q, ws)[body + 1]) @ T


def _axes_of(wrench_frame, name):
    frame = (wrench_frame.get(name, 'base') if isinstance(wrench_frame, dict)
             else wrench_frame)
    if frame not in AXES:
        raise DynamicsInputError(
            f"wrench_frame of {clip(repr(name), 100)} must be 'base' or "
            f"'link', got {clip(repr(frame), 100)}")
    return frame


def _wrenches(model, wrenches, wrench_frame):
    """Yield (name, joint, 4x4 pose, F (6,), axes) of a wrench mapping."""
    if isinstance(wrench_frame, dict):
        unknown = set(wrench_frame) - set(wrenches)
        if unknown:
            raise DynamicsInputError(
                f'wrench_frame names {clip(", ".join(map(repr, unknown)), 200)}'
                f' without a wrench')
    for name, F in wrenches.items():
        body, T = frame_body(model, name)
        F = vector(f'wrench[{clip(repr(name), 100)}]', F, 6)
        i = K.first_nonfinite(F)
        if i >= 0:
            raise DynamicsInputError(
                f'wrench[{clip(repr(name), 100)}][{i}] is {float(F[i])!r}; '
                f'every entry must be finite')
        yield name, body, T, F, _axes_of(wrench_frame, name)


def link_wrench_rows(model, q, wrenches, wrench_frame, ws):
    """
    Return ``ws.fall``: the wrenches of a mapping as per-joint rows.

    ``wrenches`` maps frame names to [f; n] (N, N m) exerted by that frame
    on its environment, the moment about the frame's origin, in base axes
    or the frame's own (``wrench_frame``: one of :data:`AXES` for all, or
    a mapping per name, default ``'base'``).  Row j of the result is the
    sum of those on joint j's link, in its link axes about its origin:
    with (R, p) the frame's pose in that link frame, f_l = R f and
    n_l = R n + p x f_l (link axes), or f_l = R_j^T f and
    n_l = R_j^T n + p x f_l (base axes, R_j the link's rotation in the
    base frame, from one pose pass).  A frame fixed to the base takes its
    wrench on the base: no joint torque.
    """
    return derivative_wrench_rows(model, q, wrenches, wrench_frame, ws)[0]


def derivative_wrench_rows(model, q, wrenches, wrench_frame, ws):
    """
    Return (fall, fext, wext): wrenches at links for the derivatives.

    ``fall`` (``ws.fall``) holds them all as :func:`link_wrench_rows`
    does, in link axes at the current pose (their value).  For their
    derivatives, those in the frame's own axes turn with the link: into
    ``fext`` (``ws.fext``), as the recursion's rows.  Those in base axes
    keep their direction while the link moves their point: row j of
    ``wext`` (``ws.wext``) sums, over those on joint j's link, in
    frame-0 axes with P the frame's origin, the moment about frame 0's
    origin n + P x f, the force f, and M = P f^T - (P . f) 1 (the
    kernels' ``DW_W``).
    """
    fall, fext, wext = ws.fall, ws.fext, ws.wext
    fall[:] = 0.0
    fext[:] = 0.0
    wext[:] = 0.0
    poses = None
    for _, body, T, F, frame in _wrenches(model, wrenches, wrench_frame):
        if body < 0:
            continue
        R, p = T[:3, :3], T[:3, 3]
        if frame == 'link':
            f = R @ F[:3]
            row = np.concatenate([f, R @ F[3:] + np.cross(p, f)])
            fext[body] += row
            fall[body] += row
            continue
        if poses is None:
            poses = _poses_array(model, q, ws).copy()
        R0, t0 = poses[0, :9].reshape(3, 3), poses[0, 9:]
        Rj, pj = poses[body + 1, :9].reshape(3, 3), poses[body + 1, 9:]
        f = Rj.T @ F[:3]
        fall[body, :3] += f
        fall[body, 3:] += Rj.T @ F[3:] + np.cross(p, f)
        P = R0.T @ (pj + Rj @ p - t0)
        f, n = R0.T @ F[:3], R0.T @ F[3:]
        wext[body, :3] += n + np.cross(P, f)
        wext[body, 3:6] += f
        wext[body, 6:] += (np.outer(P, f) - (P @ f) * np.eye(3)).ravel()
    return fall, fext, wext


def wrench_torques(model, q, wrench, wrench_frame='base', *, ws=None):
    """
    J(q)^T F_e: the joint forces that balance wrenches by virtual work.

    ``wrench`` is the end effector's [f; n] (``wrench_frame`` ``'base'`` or
    ``'end_effector'``), or a mapping {frame name: [f; n]} with
    ``wrench_frame`` as in :func:`link_wrench_rows`: then the sum of
    J_frame^T F over the frames.  Computed from the Jacobians;
    :func:`~newton_euler_ros.core.dynamics.inverse_dynamics` applies the
    same wrenches in its backward pass, and the two agree to round-off.
    """
    if isinstance(wrench, dict):
        total = np.zeros(workspace(model, ws).n)
        for name, _, _, F, frame in _wrenches(model, wrench, wrench_frame):
            total += jacobian(model, q, name, axes=frame, ws=ws).T @ F
        return total
    F = vector('wrench', wrench, 6)
    i = K.first_nonfinite(F)
    if i >= 0:
        raise status_error(3 * K.NONFINITE + i, (None, None, None, F))
    if wrench_frame not in OLD_AXES:
        raise DynamicsInputError(
            f"wrench_frame must be 'base' or 'end_effector', got "
            f'{clip(repr(wrench_frame), 100)}')
    J = jacobian(model, q, wrench_frame, ws=ws)
    return J.T @ F
