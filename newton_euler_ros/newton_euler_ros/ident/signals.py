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
2. Low-pass with a zero-phase Butterworth filter (order 4, run forward
   and backward, as ``scipy.signal.filtfilt`` with odd padding; written
   here, compiled: importing ``scipy.signal`` costs a command 2 s): no
   delay.
3. Differentiate the filtered position (or the filtered measured
   velocity, when there is one) by central differences: qd, then qdd.
4. Filter the effort with the *same* filter ("parallel filtering"): both
   sides of tau = Y pi see the same attenuation.
5. Drop ``edge`` samples at each end of a segment, where the filter's
   start-up transient lives.
"""
from dataclasses import dataclass

from numba import njit
import numpy as np

from ..core.kernels._jit import ENTRY

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


def butterworth(order, wn):
    """
    Return (b, a): a digital Butterworth low-pass, ``wn`` of Nyquist.

    The analog prototype's poles on the left half circle, scaled to the
    pre-warped cutoff and mapped by the bilinear transform (sample rate 2,
    the normalised frequencies' unit); the zeros all at z = -1.
    """
    if not 0.0 < wn < 1.0:
        raise ValueError(f'the cutoff must be between 0 and the Nyquist '
                         f'frequency, got {wn:g} of it')
    poles = -np.exp(1j * np.pi * np.arange(-order + 1, order, 2)
                    / (2 * order))
    warped = 4.0 * np.tan(0.5 * np.pi * wn)
    poles = warped * poles
    gain = warped ** order / np.real(np.prod(4.0 - poles))
    b = gain * np.poly(-np.ones(order))
    a = np.real(np.poly((4.0 + poles) / (4.0 - poles)))
    return np.ascontiguousarray(b), np.ascontiguousarray(a)


def steady_state(b, a):
    """
    Return the filter's state for a unit step held forever (a[0] = 1).

    The state z of the transposed direct form that a constant input keeps
    constant: (1 - A) z = b[1:] - a[1:] b[0], A the companion matrix's
    transpose.
    """
    k = len(a) - 1
    M = np.eye(k)
    M[:, 0] += a[1:]
    M[np.arange(k - 1), np.arange(1, k)] -= 1.0
    return np.linalg.solve(M, b[1:] - a[1:] * b[0])


@njit(**ENTRY)
def _iir(b, a, x, z, y):
    # transposed direct form, down the rows of x, each column with its
    # own state z[:, column] (updated); y the output
    k = a.shape[0] - 1
    for c in range(x.shape[1]):
        for i in range(x.shape[0]):
            xi = x[i, c]
            yi = z[0, c] + b[0] * xi
            for j in range(k - 1):
                z[j, c] = z[j + 1, c] + b[j + 1] * xi - a[j + 1] * yi
            z[k - 1, c] = b[k] * xi - a[k] * yi
            y[i, c] = yi
    return 0


def lowpass(X, rate, cutoff):
    """
    Zero-phase Butterworth low-pass of each column of X (m, k).

    Forward, then backward over the result; each pass starts in the
    steady state of its first sample.  The ends are first extended by
    3 (order + 1) samples (fewer on a short X) reflected through the end
    value, so that the start-up transients fall outside.
    """
    X = np.asarray(X, dtype=np.float64)
    b, a = butterworth(ORDER, cutoff / (0.5 * rate))
    pad = min(3 * len(a), X.shape[0] - 1)
    ext = np.concatenate([2.0 * X[:1] - X[pad:0:-1], X,
                          2.0 * X[-1:] - X[-2:-pad - 2:-1]])
    zi = steady_state(b, a)[:, None]
    y = np.empty_like(ext)
    _iir(b, a, ext, np.ascontiguousarray(zi * ext[0]), y)
    back = np.ascontiguousarray(y[::-1])
    _iir(b, a, back, np.ascontiguousarray(zi * back[0]), y)
    return y[::-1][pad:len(y) - pad]


def precompile():
    """Compile (or load) this module's filter (``precompile.py``)."""
    lowpass(np.ones((40, 2)), 100.0, 10.0)


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
