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
The strict entries' hold on numba (``core.calling.strict_entry``).

A strict entry is compiled for one signature and answers any other
argument type by raising ``Refused`` at once; it does so through two of
numba's private dispatcher callbacks (numba is pinned for that reason).
A numba that renamed them would silently go back to its slow search for
conversions (about 100 us a call, measured in docs/performance.md) or
compile a new signature per argument type: these tests fail first.
"""
from newton_euler_ros.core import (calling, gravity_torques, load_robot,
                                   Workspace)
from newton_euler_ros.core import kernels as K
from numba.core.dispatcher import Dispatcher
import numpy as np
import pytest


def test_numba_still_has_the_callbacks_strict_entries_replace():
    for name in ('_compile_for_args', '_search_new_conversions'):
        assert callable(getattr(Dispatcher, name, None)), (
            f'numba.core.dispatcher.Dispatcher has no {name}: '
            f'core/calling.py strict_entry must be rewritten for this numba')


def test_one_signature_and_every_other_type_refused():
    arm = load_robot('puma560')
    ws = Workspace(arm)
    entry = calling.strict_entry(K.run_gravity_torques, calling.PACKED,
                                 calling.VEC, calling.MAT, calling.VEC)
    q = np.linspace(-1.0, 1.0, arm.n)
    tau = np.empty(arm.n)
    assert entry(arm.packed, q, ws.ws, tau) == -1
    # the same torques as the public call
    np.testing.assert_array_equal(tau, gravity_torques(arm, q))
    assert len(entry.signatures) == 1
    read_only = q.copy()
    read_only.setflags(write=False)
    for bad in (list(q), q.astype(np.float32), np.repeat(q, 2)[::2],
                read_only, q.astype(np.int64), q.reshape(1, -1)):
        with pytest.raises(calling.Refused):
            entry(arm.packed, bad, ws.ws, tau)
    with pytest.raises(calling.Refused):
        entry(arm.packed, q, ws.ws, np.empty(arm.n, np.float32))
    assert len(entry.signatures) == 1, 'a miss compiled a new signature'
