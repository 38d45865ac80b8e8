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
Reduce a recording to a small least-squares problem, streaming.

Identification and payload estimation both fit linear models, per joint
j, y_j = A_j x, along a whole recording.  Their rows never need to be in
memory together: per joint, the R factor of the augmented matrix
[A_j | y_j], accumulated chunk by chunk (a QR of the previous R stacked
on the new rows), holds exactly what a fit needs, the residual
||A_j x - y_j||^2 of any x and the normal equations, in (c + 1)^2
numbers whatever the recording's length (:class:`Reduced`).

The steps, for one recording (:func:`reduce_recording`):

1. Stream the bag in chunks (``bag.iter_joint_states``) and prepare
   windows of it (``signals.prepare``: resample, zero-phase filter,
   differentiate, same filter on the effort, edges dropped; windows
   overlap by the filter's edge so nothing is lost between them).
2. Keep every k-th sample so that the fit rate is about
   ``FIT_RATE_FACTOR`` times the cutoff (the filtered signals carry
   nothing above the cutoff): :func:`decimation`.
3. Ask the caller's ``rows`` for the rows of those samples (a regressor
   and what it must explain) and add them to the reduction.  Time blocks
   of ``BLOCK_S`` seconds (shorter for a short recording) alternate
   between a training and a held-out reduction (one in
   ``HOLDOUT_EVERY``), so that hyperparameters can be chosen on data the
   fit did not see.
"""
from dataclasses import dataclass

import numpy as np

from .bag import BagError, DEFAULT_TOPIC, iter_joint_states, recording_seconds
from .signals import default_cutoff, edge_samples, prepare, sample_rate

BLOCK_S = 4.0
HOLDOUT_EVERY = 5
FIT_RATE_FACTOR = 10.0
STATE_CHUNK = 4096
READ_CHUNK = 32768


class IdentificationError(BagError):
    """The recording cannot give a model (one line naming the bag)."""


class Reduced:
    """
    Per joint, the R factor of [A_j | y_j] accumulated over chunks.

    ``R[j]`` has p + 1 columns and at most p + 1 rows; the residual of any
    x on joint j's rows is ||R[j] [x; -1]||, and the squared norm of y_j
    is ||R[j][:, p]||^2.  Inside, each joint keeps only the columns its
    rows have ever had nonzero (on a tree, the bodies its joint carries
    and its own drive terms; of PR2's 384, 131 at a shoulder, 11 at the
    laser's tilt): the QR of every chunk costs the square of those, and
    R[j] is built from them when read.
    """

    def __init__(self, n, p):
        self.n = n
        self.p = p
        self._cols = [np.array([p]) for _ in range(n)]
        self._R = [np.zeros((0, 1)) for _ in range(n)]
        self._full = None
        self.rows = np.zeros(n, dtype=np.int64)

    @property
    def R(self):
        """Per joint the (rows, p + 1) factor, zero outside its columns."""
        if self._full is None:
            self._full = []
            for cols, C in zip(self._cols, self._R):
                full = np.zeros((C.shape[0], self.p + 1))
                full[:, cols] = C
                self._full.append(full)
        return self._full

    def _fold(self, j, rows, cols):
        """QR of joint j's factor with (k, len(cols)) rows in ``cols``."""
        union = np.union1d(self._cols[j], cols)
        A = np.zeros((rows.shape[0] + self._R[j].shape[0], union.size))
        A[:rows.shape[0], np.searchsorted(union, cols)] = rows
        A[rows.shape[0]:, np.searchsorted(union, self._cols[j])] = \
            self._R[j]
        self._cols[j] = union
        self._R[j] = np.linalg.qr(A, mode='r')
        self._full = None

    def add(self, Y, tau, keep=None):
        """
        Add (m, n, p) regressor rows and (m, n) right-hand sides.

        ``keep`` (m, n) bool: joint j takes only the rows keep[:, j].
        """
        if Y.shape[0] == 0:
            return
        for j in range(self.n):
            sel = slice(None) if keep is None else keep[:, j]
            Yj, tj = Y[sel, j, :], tau[sel, j]
            m = Yj.shape[0]
            if m == 0:
                continue
            cols = np.append(np.flatnonzero(np.any(Yj != 0.0, axis=0)),
                             self.p)
            self._fold(j, np.column_stack([Yj[:, cols[:-1]], tj]), cols)
            self.rows[j] += m

    def merged(self, other):
        """Return the reduction of both sets of rows."""
        out = Reduced(self.n, self.p)
        for j in range(self.n):
            out._cols[j], out._R[j] = self._cols[j], self._R[j]
            out._fold(j, other._R[j], other._cols[j])
        out.rows = self.rows + other.rows
        return out

    def sq_residuals(self, theta):
        """(n,) squared residual norms of theta, per joint."""
        x = np.append(theta, -1.0)
        return np.array([float(np.sum((Rj @ x) ** 2)) for Rj in self.R])

    def sq_effort(self):
        """(n,) squared norms of the right-hand sides, per joint."""
        return np.array([float(np.sum(Rj[:, self.p] ** 2))
                         for Rj in self.R])

    def stats(self, theta):
        """Return (rms, relative rms) per joint of the residual of theta."""
        rows = np.maximum(self.rows, 1)
        rms = np.sqrt(self.sq_residuals(theta) / rows)
        ref = np.sqrt(self.sq_effort() / rows)
        return rms, rms / np.maximum(ref, 1e-300)

    def stacked(self, weights):
        """Weighted [A | y] rows of all joints (reduced), (<= n(p+1), p+1)."""
        return np.vstack([Rj * w for Rj, w in zip(self.R, weights)])


def prepared_windows(path, joint_names, topic=DEFAULT_TOPIC, cutoff=None,
                     window=READ_CHUNK):
    """
    Yield ``signals.Prepared`` windows of the recording, in order.

    Windows overlap by twice the filter's edge in raw samples, and the
    samples of a window at or before the last one yielded are dropped, so
    the windows tile the recording once.
    """
    tail = None
    rate = None
    last_t = -np.inf
    for chunk in iter_joint_states(path, joint_names, topic, chunk=window):
        parts = [chunk] if tail is None else [tail, chunk]
        stamps = np.concatenate([p.stamps for p in parts])
        q = np.concatenate([p.q for p in parts])
        qd = None if any(p.qd is None for p in parts) else np.concatenate(
            [p.qd for p in parts])
        e = np.concatenate([p.effort for p in parts])
        if rate is None:
            rate = sample_rate(stamps)
            cutoff = default_cutoff(rate) if cutoff is None else cutoff
            edge = edge_samples(rate, cutoff)
        piece = prepare(stamps, q, qd, e, rate=rate, cutoff=cutoff,
                        edge=edge)
        keep = 2 * edge + 4
        tail = _Tail(stamps[-keep:], q[-keep:],
                     None if qd is None else qd[-keep:], e[-keep:])
        if piece is None:
            continue
        new = piece.t > last_t + 0.5 / rate
        if not new.any():
            continue
        last_t = piece.t[new][-1]
        for key in ('t', 'q', 'qd', 'qdd', 'effort'):
            setattr(piece, key, getattr(piece, key)[new])
        yield piece


@dataclass
class _Tail:
    stamps: np.ndarray
    q: np.ndarray
    qd: object
    effort: np.ndarray


def decimation(rate, cutoff):
    """Return k: every k-th filtered sample is fitted (about 10 x cutoff)."""
    return max(1, int(rate / (FIT_RATE_FACTOR * cutoff)))


def reduce_recording(path, joint_names, rows, columns, topic=DEFAULT_TOPIC,
                     cutoff=None, split=True, outputs=None):
    """
    Reduce a recording: return (train, held_out or None, info dict).

    ``rows(q, qd, qdd, effort)`` returns the rows of (m,) filtered
    samples: A (m, n, ``columns``) and y (m, n), and optionally a third
    (m, n) bool array: the rows each joint's fit keeps.  The rows left
    out are reduced apart, into ``info['rest']`` = (train, held): a
    caller can report on every sample and fit on the kept ones.  With
    ``split=False`` every block goes to ``train``.  Blocks are
    ``BLOCK_S`` long, shorter for a recording under ten blocks (down to
    half a second), so that even a short one has a held-out part.
    ``info``: 'rate', 'cutoff', 'step' (the decimation), 'duration' (s)
    and 'samples' (filtered).  ``outputs``: how many rows per sample
    ``rows`` gives (default one per joint read; fewer when only some
    joints matter, e.g. those carrying a payload).
    """
    n = len(joint_names) if outputs is None else int(outputs)
    block_s = BLOCK_S
    if split:
        block_s = min(BLOCK_S, max(0.5, recording_seconds(path) / 10.0))
    train = Reduced(n, columns)
    held = Reduced(n, columns) if split else None
    rest = None
    samples = 0
    info = {'rate': None, 'cutoff': None, 'duration': 0.0}
    t_first = None
    for piece in prepared_windows(path, joint_names, topic, cutoff):
        if info['rate'] is None:
            info['rate'], info['cutoff'] = piece.rate, piece.cutoff
            step = decimation(piece.rate, piece.cutoff)
            info['step'] = step
        if t_first is None:
            t_first = piece.t[0]
        info['duration'] = piece.t[-1] - t_first
        idx = np.arange(0, len(piece), step)
        samples += len(piece)
        for a in range(0, len(idx), STATE_CHUNK):
            sel = idx[a:a + STATE_CHUNK]
            Y, tau, *keep = rows(piece.q[sel], piece.qd[sel],
                                 piece.qdd[sel], piece.effort[sel])
            keep = keep[0] if keep else None
            if keep is not None and rest is None:
                rest = (Reduced(n, columns),
                        Reduced(n, columns) if split else None)
            out = np.zeros(len(sel), dtype=bool)
            if held is not None:
                block = np.floor((piece.t[sel] - t_first) / block_s)
                out = (block % HOLDOUT_EVERY) == HOLDOUT_EVERY - 1
            for part, rows_in, spare in ((train, ~out, 0), (held, out, 1)):
                if part is None:
                    continue
                k = None if keep is None else keep[rows_in]
                part.add(Y[rows_in], tau[rows_in], k)
                if keep is not None:
                    rest[spare].add(Y[rows_in], tau[rows_in], ~k)
    info['samples'] = samples
    info['rest'] = rest
    if samples == 0:
        raise IdentificationError(
            f'{path}: too short: nothing is left after filtering (needs '
            f'more than a few tenths of a second of samples without gaps)')
    return train, held, info
