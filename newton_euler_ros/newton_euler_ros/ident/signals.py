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
From irregular JointState samples to (q, qd, qdd, effort) on a grid.

1. Resample every signal on a uniform grid over the header stamps (linear
   interpolation): stamps jitter and messages get lost.  A gap longer
   than ``MAX_GAP_PERIODS`` sample periods splits the recording into
   segments, each processed alone.
2. Low-pass with a zero-phase Butterworth filter (``scipy.signal.filtfilt``,
   order 4 forward and backward): no delay.
3. Differentiate the filtered position (or the filtered measured
   velocity, when there is one) by central differences: qd, then qdd.
4. Filter the effort with the *same* filter ("parallel filtering"): both
   sides of tau = Y pi see the same attenuation.
5. Drop ``edge`` samples at each end of a segment, where the filter's
   start-up transient lives.
"""
from dataclasses import dataclass

import numpy as np

ORDER = 4
MAX_GAP_PERIODS = 20
DEFAULT_CUTOFF = 10.0   # Hz, or a fifth of the sample rate if that is less


@dataclass
class Prepared:
    """Filtered samples on a uniform grid: t (m,), q, qd, qdd, effort."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    effort: np.ndarray
    rate: float
    cutoff: float

    def __len__(self):
        """Return the number of samples."""
        return len(self.t)


def sample_rate(stamps):
    """Return the median rate of the stamps (Hz)."""
    dt = np.diff(np.asarray(stamps, dtype=np.float64))
    dt = dt[dt > 0]
    if dt.size == 0:
        raise ValueError('the stamps do not advance')
    return 1.0 / float(np.median(dt))


def default_cutoff(rate):
    """Return the default low-pass cutoff (Hz) for a sample rate."""
    return min(DEFAULT_CUTOFF, 0.2 * rate)


def edge_samples(rate, cutoff):
    """Return the samples dropped at each end: three cutoff periods."""
    return int(np.ceil(3.0 * rate / cutoff))


def segments(stamps, rate, max_gap=MAX_GAP_PERIODS):
    """Yield (start, stop) index ranges with no gap above max_gap periods."""
    stamps = np.asarray(stamps, dtype=np.float64)
    cut = np.flatnonzero(np.diff(stamps) > max_gap / rate) + 1
    bounds = np.concatenate([[0], cut, [len(stamps)]])
    for a, b in zip(bounds[:-1], bounds[1:]):
        yield int(a), int(b)


def resample(stamps, X, rate):
    """Return (t, X on t): a uniform grid from the first stamp at ``rate``."""
    stamps = np.asarray(stamps, dtype=np.float64)
    count = int(np.floor((stamps[-1] - stamps[0]) * rate + 1e-9)) + 1
    t = stamps[0] + np.arange(count) / rate
    X = np.asarray(X, dtype=np.float64)
    out = np.empty((count, X.shape[1]))
    for j in range(X.shape[1]):
        out[:, j] = np.interp(t, stamps, X[:, j])
    return t, out


def lowpass(X, rate, cutoff):
    """Zero-phase Butterworth low-pass of each column."""
    from scipy.signal import butter, filtfilt
    b, a = butter(ORDER, cutoff / (0.5 * rate))
    return filtfilt(b, a, X, axis=0, padtype='odd',
                    padlen=min(3 * max(len(a), len(b)), X.shape[0] - 1))


def prepare(stamps, q, qd, effort, rate=None, cutoff=None, edge=None):
    """
    Return a :class:`Prepared` (None when nothing is left after the edges).

    ``stamps`` in seconds, ``q`` and ``effort`` (m, n), ``qd`` (m, n) or
    None.  ``rate`` defaults to the stamps' median rate, ``cutoff`` to
    :func:`default_cutoff`, ``edge`` to :func:`edge_samples`.  Segments
    split at gaps are processed alone and concatenated.
    """
    stamps = np.asarray(stamps, dtype=np.float64)
    rate = sample_rate(stamps) if rate is None else float(rate)
    cutoff = default_cutoff(rate) if cutoff is None else float(cutoff)
    if not 0 < cutoff < 0.5 * rate:
        raise ValueError(f'the cutoff {cutoff:g} Hz must be between 0 and '
                         f'half the sample rate ({0.5 * rate:g} Hz)')
    edge = edge_samples(rate, cutoff) if edge is None else int(edge)
    parts = []
    for a, b in segments(stamps, rate):
        if b - a < 2 * edge + 8:
            continue
        parts.append(_prepare_segment(
            stamps[a:b], q[a:b], None if qd is None else qd[a:b],
            effort[a:b], rate, cutoff, edge))
    parts = [p for p in parts if p is not None]
    if not parts:
        return None
    return Prepared(*(np.concatenate([getattr(p, k) for p in parts])
                      for k in ('t', 'q', 'qd', 'qdd', 'effort')),
                    rate=rate, cutoff=cutoff)


def _prepare_segment(stamps, q, qd, effort, rate, cutoff, edge):
    n = q.shape[1]
    cols = [q, effort] + ([] if qd is None else [qd])
    t, X = resample(stamps, np.hstack(cols), rate)
    if len(t) < 2 * edge + 8:
        return None
    X = lowpass(X, rate, cutoff)
    qf = X[:, :n]
    ef = X[:, n:2 * n]
    dt = 1.0 / rate
    vf = X[:, 2 * n:] if qd is not None else np.gradient(qf, dt, axis=0)
    af = np.gradient(vf, dt, axis=0)
    keep = slice(edge, len(t) - edge)
    return Prepared(t[keep], qf[keep], vf[keep], af[keep], ef[keep], rate,
                    cutoff)
