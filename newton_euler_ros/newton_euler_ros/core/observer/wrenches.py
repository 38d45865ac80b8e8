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
The wrenches of several end effectors of a tree, estimated jointly.

The residual ``r`` of :mod:`.momentum` is ``sum_i J_i^T F_i`` over the
frames pushed.  Estimating each frame's wrench alone
(:func:`.wrench.external_wrench` with ``frame=``) reads a push
on one hand at the other whenever a joint moves both (a torso): the
other hand's solve explains the torso's residual with a wrench of its
own.  :func:`external_wrenches` solves ``J_all^T F_all = r`` for all
frames at once, ``J_all`` (6k x n) the frames' Jacobians stacked, by
the same damped least squares (``F = V diag(s / (s^2 + lambda^2)) U^T
r`` from the SVD of ``J_all^T``), with two rules:

- *Own joints.*  A frame's own joints are those that move it and no
  other frame asked for (its branch below the last shared joint; a
  mimic joint counts as its leader).  A frame whose own joints show no
  contact (``|r_j|`` within the threshold plus the static friction
  allowance, the observer's contact test) gets a zero wrench and is left
  out of the solve: a push on one hand is never reported at the other.
  A frame with no joint of its own (a link above another frame asked
  for, or on the same link) is never reported (:func:`own_joints`).
- *What cannot be separated.*  Among the frames in the solve, a
  combination ``d`` (6k) of their wrenches with ``J_all^T d = 0`` gives
  the same joint torques as no wrench at all: its share is not
  estimated (the minimum-norm split, i.e. zero along ``d``).  Such a
  ``d`` is either a direction one frame cannot feel by itself (``J_i^T
  d_i = 0``, as for a single frame: ``unfelt``) or a trade between
  frames (``ambiguous``: each part felt by its frame, the sum of their
  torques zero), e.g. a vertical push on either shoulder of a robot
  whose only shared joint is a vertical torso lift.  Directions whose
  joint torques stay below the damping (``|J_all^T d| < lambda``, which
  the damped solve estimates at less than half) count as not separable.
  Two hands of seven-joint arms on a shared torso are separable away
  from singular poses: their own joints sense all six components.
"""
from dataclasses import dataclass, field
import functools

import numpy as np

from ..calling import vector
from ..errors import DynamicsInputError
from ..frames import AXES, frame_target, jacobian
from ..tree import coordinates, support

#: names of the six wrench components, for :meth:`Wrenches.text`
COMPONENTS = ('fx', 'fy', 'fz', 'mx', 'my', 'mz')
#: relative cutoff of the singular values (the damping's floor)
RTOL = 1e-9


def own_joints(model, frames):
    """
    Return, per frame, the coordinates (model order) only it moves.

    The joints between each frame and the base (a mimic joint as its
    leader's coordinate), minus those of every other frame of
    ``frames``: a tuple of sorted index tuples.  Cached per model.
    """
    frames = tuple(frames)
    cache = model.__dict__.setdefault('_own_joints', {})
    if frames in cache:
        return cache[frames]
    _, coord = coordinates(model.mimic)
    moved = [{coord[b] for b in support(model.parents,
                                        frame_target(model, name)[0])}
             for name in frames]
    out = []
    for i, joints in enumerate(moved):
        others = set().union(*(m for k, m in enumerate(moved) if k != i))
        out.append(tuple(sorted(joints - others)))
    cache[frames] = tuple(out)
    return cache[frames]


@dataclass
class Wrenches:
    """
    The joint estimate of :func:`external_wrenches`.

    ``wrench`` (k, 6): per frame ``[fx, fy, fz, mx, my, mz]``, the wrench
    the environment applies to it (moment about its origin, in the axes
    asked for); zero for a frame not ``active`` (its own joints felt
    nothing).  ``ambiguous`` (6k, m): an orthonormal basis of the
    combinations of the active frames' wrenches that the joints cannot
    tell from one another (rows ``6 i .. 6 i + 5`` are frame i's; zero
    rows for inactive frames); ``unfelt``: per frame a (6, u) basis of
    the directions its own Jacobian cannot feel at all ((6, 0) for an
    inactive frame).  Both are in the wrench's axes, computed on first
    use (some SVDs: the estimate itself does not need them).
    """

    frames: tuple
    wrench: np.ndarray
    active: np.ndarray
    J: np.ndarray = field(default=None, repr=False)  # the active frames'
    damping: float = 0.0

    @functools.cached_property
    def _analysis(self):
        k = len(self.frames)
        idx = np.flatnonzero(self.active)
        ambiguous, unfelt = np.zeros((6 * k, 0)), [np.zeros((6, 0))] * k
        if self.J is None or not idx.size:
            return ambiguous, tuple(unfelt)
        amb, unf = _not_separable(self.J, self.damping)
        rows = (6 * idx[:, None] + np.arange(6)).ravel()
        ambiguous = np.zeros((6 * k, amb.shape[1]))
        ambiguous[rows] = amb
        for a, i in enumerate(idx):
            unfelt[i] = unf[a]
        return ambiguous, tuple(unfelt)

    @property
    def ambiguous(self):
        """(6k, m) orthonormal basis of the non-separable combinations."""
        return self._analysis[0]

    @property
    def unfelt(self):
        """Per frame, a (6, u) basis of what its Jacobian cannot feel."""
        return self._analysis[1]

    def ambiguous_at(self, i):
        """
        Return a (6, c) basis of frame i's part of the ambiguous set.

        ``c`` is how many directions of frame ``i``'s wrench the joints
        cannot separate from the other frames' (0: all of it is its own).
        """
        block = self.ambiguous[6 * i:6 * i + 6]
        if not block.size:
            return np.zeros((6, 0))
        U, s, _ = np.linalg.svd(block, full_matrices=False)
        return U[:, s > 1e-6]

    @property
    def ambiguous_counts(self):
        """Per frame, how many of its directions are not separable."""
        return tuple(self.ambiguous_at(i).shape[1]
                     for i in range(len(self.frames)))

    def text(self, limit=400):
        """
        Say which components are not separable, one line.

        ``none`` or ``2 combinations: 0.71 l_link.fz - 0.71 r_link.fz;
        ...``: each combination's components of at least a tenth of its
        largest, the frames' names and the axes of the wrench.
        """
        m = self.ambiguous.shape[1]
        if m == 0:
            return 'none'
        parts = []
        for c in range(m):
            d = self.ambiguous[:, c]
            d = d * np.sign(d[np.argmax(np.abs(d))])
            big = np.flatnonzero(np.abs(d) >= 0.1 * np.abs(d).max())
            terms = [f'{d[x]:+.2f} {self.frames[x // 6]}.'
                     f'{COMPONENTS[x % 6]}' for x in big]
            parts.append(' '.join(terms).lstrip('+'))
        out = (f'{m} combination{"s" if m != 1 else ""} (same joint '
               f'torques): ' + '; '.join(parts))
        return out if len(out) <= limit else out[:limit - 3] + '...'


def external_wrenches(obs, q, r, frames, *, axes='base', allowance=None,
                      contact=None, felt=None):
    """
    Return the :class:`Wrenches` of ``frames`` estimated jointly at q.

    ``frames``: links of the model (or ``'end_effector'``), each
    reported with the moment about its origin in base axes or its own
    (``axes='link'``).  Which joints felt a contact: ``felt`` (n bools,
    model order) if given; else ``contact``, a :class:`ContactState`
    just updated by :func:`~.contact.contact_step` (its band
    flags, and the rest reference's when the observer has it on); else
    ``|r_j| > threshold_j + allowance_j`` with the observer's thresholds
    and ``allowance`` (the state's static friction allowance; None:
    none).  The damped least-squares solve uses the observer's damping;
    its result is zeros, never NaN, if the SVD fails.
    """
    if axes not in AXES:
        raise DynamicsInputError(f"axes must be 'base' or 'link', got "
                                 f'{axes!r}')
    frames = tuple(frames)
    n = obs.n
    r = vector('r', r, n)
    q = vector('q', q, n)
    own = own_joints(obs.model, frames)
    felt = _felt(obs, r, allowance, contact, felt)
    k = len(frames)
    active = np.array([any(felt[j] for j in joints) for joints in own],
                      dtype=np.bool_)
    F = np.zeros((k, 6))
    idx = np.flatnonzero(active)
    J = None
    if idx.size:
        J = np.concatenate([jacobian(obs.model, q, frames[i], axes=axes,
                                     ws=obs.ws) for i in idx])
        sol = _solve(J, r, obs.damping)
        if sol is None:
            J = None
        else:
            F[idx] = sol.reshape(-1, 6)
    return Wrenches(frames, F, active, J, obs.damping)


def separability(obs, q, frames, *, axes='base'):
    """
    Return the :class:`Wrenches` layout of ``frames`` all pushed at q.

    What :func:`external_wrenches` reports when every frame is active
    (``wrench`` zero): which combinations of their wrenches the joints
    cannot separate at this pose, whatever the residual.  For a log line
    at start-up (``Wrenches.text``).
    """
    return external_wrenches(obs, q, np.zeros(obs.n), frames, axes=axes,
                             felt=np.ones(obs.n, dtype=np.bool_))


def _felt(obs, r, allowance, contact, felt):
    """Return the per-joint contact flags (n bools) the rules use."""
    n = obs.n
    if felt is not None:
        felt = np.asarray(felt, dtype=np.bool_).reshape(-1)
        if felt.shape != (n,):
            raise DynamicsInputError(f'felt: must have {n} values (one per '
                                     f'joint), got {felt.size}')
        return felt
    if contact is not None:
        out = np.array(contact.active, dtype=np.bool_)
        rest = getattr(contact, 'rest', None)
        if obs.rest_reference and rest is not None:
            out |= rest.active
        return out
    extra = 0.0 if allowance is None else np.asarray(allowance, dtype=float)
    return np.abs(r) - extra > obs.thresholds


def _solve(J, r, damping):
    """F = V diag(s / (s^2 + damping^2)) U^T r of J^T = U S V^T; or None."""
    try:
        U, s, Vt = np.linalg.svd(J.T, full_matrices=False)
    except np.linalg.LinAlgError:
        return None
    if not s.size or not s[0] > 0.0:
        return np.zeros(J.shape[0])
    keep = s > RTOL * s[0]
    s = s[keep]
    F = Vt[keep].T @ (s / (s * s + damping * damping) * (U[:, keep].T @ r))
    return F if np.isfinite(F).all() else None


def _not_separable(J, damping):
    """
    Return (ambiguous (6k, m), unfelt per frame) of the stacked J (6k, n).

    Cutoff on singular values: the damping, and at least ``RTOL`` times
    the largest.  Frame i feels the range U_i of its J_i; a trade between
    frames is a null vector c of M = [J_1^T U_1 ... J_k^T U_k], the
    combination ``d = diag(U_i) c`` (orthonormal, as the U_i are).
    """
    k = J.shape[0] // 6
    try:
        s_all = np.linalg.svd(J, compute_uv=False)
        cut = max(damping, RTOL * (s_all[0] if s_all.size else 0.0))
        felt, unfelt = [], []
        for i in range(k):
            U, s, _ = np.linalg.svd(J[6 * i:6 * i + 6], full_matrices=True)
            rank = int(np.count_nonzero(s > cut))
            felt.append(U[:, :rank])
            unfelt.append(U[:, rank:])
        M = np.concatenate([J[6 * i:6 * i + 6].T @ felt[i]
                            for i in range(k)], axis=1)
        if not M.shape[1]:
            return np.zeros((6 * k, 0)), unfelt
        _, s, Vt = np.linalg.svd(M, full_matrices=True)
        rank = int(np.count_nonzero(s > cut))
        C = Vt[rank:].T                 # (sum of ranks, m)
    except np.linalg.LinAlgError:
        return np.zeros((6 * k, 0)), [np.zeros((6, 0))] * k
    out = np.zeros((6 * k, C.shape[1]))
    start = 0
    for i in range(k):
        rank = felt[i].shape[1]
        out[6 * i:6 * i + 6] = felt[i] @ C[start:start + rank]
        start += rank
    return out, unfelt
