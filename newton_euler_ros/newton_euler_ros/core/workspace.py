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


"""Preallocated scratch memory for the kernels of one model size."""
import numpy as np

from . import kernels as K


class Workspace:
    """
    Scratch memory for one model; reuse it across calls.

    Every dynamics function takes ``ws=``; without it they use the model's
    own ``model.default_workspace``, one per model, shared by every call
    that passes none.  Not thread-safe: give each thread its own
    ``Workspace(model)``.  The kernels check its sizes against the model
    they are called with, so a workspace of another size is refused.

    ``dtype`` is the number type of the kernels it serves (float64, or
    float32 for :class:`~newton_euler_ros.core.float32.Float32Dynamics`).
    ``helpers``: the workspaces of the threads a batch is shared among
    (``core.batch.run_split``), made on first use.
    """

    def __init__(self, model, dtype=np.float64):
        n = model.n
        nb = model.nb
        self.n = n              # coordinates (independent joints)
        self.nb = nb            # moving joints (bodies), mimic ones too
        self.square = (n, n)    # the shape of D and C
        self.dtype = np.dtype(dtype)
        self.ws = np.zeros((nb, K.W_WIDTH), dtype)
        self.scratch = np.zeros((3, n), dtype)
        self.frames = np.zeros((nb + 2, 12), dtype)
        self.chol = np.zeros((n, n), dtype)
        self.aw = np.zeros((nb + 1, K.A_WIDTH), dtype)
        self.cw = np.zeros((nb + 1, K.CW_WIDTH), dtype)
        self.dw = np.zeros((nb + 1, K.DW_WIDTH), dtype)
        self.fext = np.zeros((nb, 6), dtype)
        self.wext = np.zeros((nb, 15), dtype)
        self.fall = np.zeros((nb, 6), dtype)
        self.zeros = np.zeros(n, dtype)
        self.zero_wrench = np.zeros(6, dtype)
        self.status = np.zeros(1, np.int64)
        self.helpers = []       # the other threads' (``batch.run_split``)
        # inputs given as lists or tuples, copied in (calling.sequences_in)
        self.given = np.zeros(3 * n + 6, dtype)
        self.given_rows = (self.given[:n], self.given[n:2 * n],
                           self.given[2 * n:3 * n])
        self.given_wrench = self.given[3 * n:]
        # what calling.inputs returns for three lists, and for four
        self.given_three = (*self.given_rows, self.zero_wrench)
        self.given_four = (*self.given_rows, self.given_wrench)

    def __repr__(self):
        """Return e.g. ``Workspace(n=6, float64)``."""
        if self.nb != self.n:
            return f'Workspace(n={self.n}, nb={self.nb}, {self.dtype})'
        return f'Workspace(n={self.n}, {self.dtype})'
