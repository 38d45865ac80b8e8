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
The chunked reduction (``ident.reduce.Reduced``) against one QR.

Whatever the chunks, the rows each joint keeps and the columns its rows
use, joint j's factor must give the residual of every x on joint j's
rows: ||R_j [x; -1]|| = ||A_j x - y_j||, and so R_j^T R_j = [A_j y_j]^T
[A_j y_j].  Each joint folds only the columns its rows have had nonzero;
R_j is built with every column when read.
"""
from newton_euler_ros.ident.reduce import Reduced
import numpy as np


def _chunks(rng, n, p, used, m):
    """Rows of n joints in p columns, joint j's only in ``used[j]``."""
    Y = np.zeros((m, n, p))
    for j in range(n):
        Y[:, j, used[j]] = rng.normal(size=(m, len(used[j])))
    return Y, rng.normal(size=(m, n))


def test_the_factors_give_each_joints_residuals():
    rng = np.random.default_rng(3)
    n, p = 3, 12
    # a joint that carries every column, one with a few, one whose
    # columns grow chunk by chunk (a finger still in the first chunk)
    used = [np.arange(p), np.array([2, 7, 9]), np.array([0, 5])]
    red = Reduced(n, p)
    rows = [[] for _ in range(n)]
    for k in range(4):
        if k == 2:
            used[2] = np.array([0, 5, 11, 3])
        Y, tau = _chunks(rng, n, p, used, 20 + 7 * k)
        keep = rng.random((Y.shape[0], n)) > 0.3
        red.add(Y, tau, keep)
        for j in range(n):
            rows[j].append(np.column_stack([Y[keep[:, j], j],
                                            tau[keep[:, j], j]]))
    for j in range(n):
        A = np.vstack(rows[j])
        R = red.R[j]
        assert R.shape[1] == p + 1 and R.shape[0] <= p + 1
        assert red.rows[j] == A.shape[0]
        np.testing.assert_allclose(R.T @ R, A.T @ A, rtol=0, atol=1e-11)
        x = np.append(rng.normal(size=p), -1.0)
        assert abs(np.linalg.norm(R @ x) - np.linalg.norm(A @ x)) < 1e-11
    # a joint's columns: only those it used, so its fold is small
    assert red.R[1].shape[0] == 4 and red.R[2].shape[0] == 5


def test_merged_is_the_reduction_of_both():
    rng = np.random.default_rng(4)
    n, p = 2, 9
    one, two, both = Reduced(n, p), Reduced(n, p), Reduced(n, p)
    Y, tau = _chunks(rng, n, p, [np.arange(4), np.array([1, 8])], 30)
    Z, sigma = _chunks(rng, n, p, [np.arange(p), np.array([3])], 25)
    one.add(Y, tau)
    two.add(Z, sigma)
    both.add(Y, tau)
    both.add(Z, sigma)
    merged = one.merged(two)
    assert (merged.rows == both.rows).all()
    for j in range(n):
        np.testing.assert_allclose(merged.R[j].T @ merged.R[j],
                                   both.R[j].T @ both.R[j], atol=1e-11)
    # joints no row reached: an empty factor of p + 1 columns
    empty = Reduced(n, p)
    assert empty.R[0].shape == (0, p + 1)
    assert (empty.merged(empty).R[1] == 0).all()
