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
Input and result checks inside the kernels, returned as status codes.

The first non-finite input, an overflowing result (codes in ``layout``).
"""
import math

from ._jit import njit
from .layout import OVERFLOW


@njit(cache=True, inline='always')
def first_nonfinite(x):
    """Index of the first non-finite entry of x, or -1."""
    for i in range(x.shape[0]):
        if not math.isfinite(x[i]):
            return i
    return -1


@njit(cache=True, inline='always')
def first_nonfinite_entry(X):
    """Flat (row-major) index of the first non-finite entry of 2-D X, or -1."""
    for i in range(X.shape[0]):
        for k in range(X.shape[1]):
            if not math.isfinite(X[i, k]):
                return i * X.shape[1] + k
    return -1


@njit(cache=True, inline='always')
def check_finite(q, qd, qdd, wrench):
    """-1 when all entries are finite, else 1000 * argument + index."""
    i = first_nonfinite(q)
    if i >= 0:
        return i
    i = first_nonfinite(qd)
    if i >= 0:
        return 1000 + i
    i = first_nonfinite(qdd)
    if i >= 0:
        return 2000 + i
    i = first_nonfinite(wrench)
    if i >= 0:
        return 3000 + i
    return -1


@njit(cache=True, inline='always')
def block_status(X, lo, hi):
    """Return -1 when X[lo:hi, lo:hi] is finite, else OVERFLOW."""
    for i in range(lo, hi):
        for k in range(lo, hi):
            if not math.isfinite(X[i, k]):
                return OVERFLOW
    return -1


@njit(cache=True)
def matrix_status(X):
    """Return -1 when every entry is finite, else OVERFLOW."""
    for i in range(X.shape[0]):
        if first_nonfinite(X[i]) >= 0:
            return OVERFLOW
    return -1


@njit(cache=True)
def round_into(x, out):
    """
    Copy x into out, converting to out's dtype.

    float64 -> float32 rounds to nearest and gives +-inf past the float32
    range, without the warning numpy's cast would print.
    """
    for i in range(x.shape[0]):
        out[i] = x[i]
