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
The momentum observer's end-effector wrench: F = (J J^T + lambda^2 I)^-1 J r.

The residual ``r`` of :mod:`.momentum` is the joint torque the
environment applies, ``tau_ext = J^T F_ext``.  :func:`external_wrench`
returns ``F_ext = [f; m]``, the wrench the environment applies *to* the
end effector (a wrist force/torque sensor's sign), in base-frame axes,
the moment about the end-effector origin.  It is the opposite of the
dynamics' input ``F_e`` (the wrench the end effector exerts, which adds
``+J^T F_e`` to the torques): ``F_ext = -F_e``.  It is the damped
least-squares solution of ``J^T F = r``: with fewer than six joints (or
at a singularity) only its component in the range of ``J`` (the
directions in which the end effector can move, and so can feel a push)
is estimated; the rest is reported as zero (:func:`felt_directions`
gives that range).
"""
import math

from numba import njit
import numpy as np

from ..calling import (ARRAY, BOOL, EMPTY, F64, F8, INT, MAT, out_array, PACKED,
                       slow_inputs, status_error, strict_entry, TARGET, VEC,
                       vector)
from ..dynamics import jacobian
from ..errors import DynamicsInputError
from ..frames import AXES, frame_target
from ..kernels import (cholesky_solve, F_ROWS, F_TOOL, F_TREE, run_jacobian,
                       SIZE, T_TOOL)
from ..kernels._jit import ENTRY, uses_kernels

# this file's compiled functions call kernels: a kernel edit must
# recompile them (numba's cache stamps a function with its own file only)
uses_kernels(__file__)


@njit(**ENTRY)
def _damped_solve(J, n, rows, lam2, A, y):
    """
    Solve (G + lam2 I) x = y, x in y; False when the Cholesky fails.

    G is the Gram matrix of the 6 x n Jacobian J's rows (``rows``:
    J J^T, 6 x 6) or of its columns (J^T J, n x n); its lower triangle
    is built in A and factored in place.
    """
    size = 6 if rows else n
    for a in range(size):
        for b in range(a + 1):
            s = 0.0
            if rows:
                for j in range(n):
                    s += J[a, j] * J[b, j]
            else:
                for c in range(6):
                    s += J[c, a] * J[c, b]
            A[a, b] = s
        A[a, a] += lam2
    return cholesky_solve(A, y, A, y) == -1     # in place


@njit(**ENTRY)
def _dls_wrench(J, r, damping, A, y, F):
    """
    F = (J J^T + damping^2 I)^-1 J r, the damped (J^T)^+ r.

    Six joints or more: the 6 x 6 system.  Fewer: the same F as
    J (J^T J + damping^2 I)^-1 r, an n x n system that stays well
    conditioned when J J^T is singular.
    """
    n = r.shape[0]
    lam2 = damping * damping
    if n >= 6:
        for a in range(6):
            s = 0.0
            for j in range(n):
                s += J[a, j] * r[j]
            y[a] = s
        if not _damped_solve(J, n, True, lam2, A, y):
            return False
        for a in range(6):
            F[a] = y[a]
    else:
        for a in range(n):
            y[a] = r[a]
        if not _damped_solve(J, n, False, lam2, A, y):
            return False
        for c in range(6):
            s = 0.0
            for a in range(n):
                s += J[c, a] * y[a]
            F[c] = s
    for a in range(6):
        if not math.isfinite(F[a]):
            return False
    return True


@njit(**ENTRY)
def _wrench(P, q, r, damping, ws, Ts, J, A, y, F):
    """Return the end effector's wrench (:func:`_wrench_at`), base axes."""
    frames = P[P.shape[0] - F_ROWS:]        # the end effector's Jacobian
    return _wrench_at(P, q, r, damping, int(frames[F_TREE, T_TOOL]),
                      frames[F_TOOL], False, ws, Ts, J, A, y, F)


@njit(**ENTRY)
def _wrench_at(P, q, r, damping, body, target, local, ws, Ts, J, A, y, F):
    """
    J(q) of a frame and the damped least-squares wrench in one call.

    The frame on joint ``body``'s link at pose ``target`` (the Jacobian
    kernel's), its axes or the base's (``local``).  A kernel status code
    for q (or SIZE + 1 for r), else -1 with F the wrench, or zeros when
    the solve fails.
    """
    code = run_jacobian(P, q, body, target, local, ws, Ts, J)
    if code >= 0:
        return code
    if r.shape[0] != J.shape[1] or F.shape[0] != 6:
        return SIZE + 1
    if not _dls_wrench(J, r, damping, A, y, F):
        for a in range(6):
            F[a] = 0.0
    return -1


_wrench_strict = strict_entry(_wrench, PACKED, VEC, VEC, F8, MAT, MAT, MAT,
                              MAT, VEC, VEC, home=globals())
_wrench_at_strict = strict_entry(_wrench_at, PACKED, VEC, VEC, F8, INT,
                                 TARGET, BOOL, MAT, MAT, MAT, MAT, VEC, VEC,
                                 home=globals())


def external_wrench(obs, q, r, out=None, frame=None, axes='base'):
    """
    Return F_ext (6,), the wrench the environment applies to the tool.

    ``[fx, fy, fz, mx, my, mz]`` in base axes, moment about the
    end-effector origin (force/torque sensor sign; ``-F_e`` of the
    dynamics' input convention), the damped least-squares solution of
    ``J(q)^T F = r``.  Zeros if the solve fails (never NaN).  One
    compiled call (``_wrench``): J(q), then the solve.

    With ``frame``, a link of the model (a gripper of a tree; every
    URDF link is named) or ``'end_effector'``: the wrench at that frame,
    the moment about its origin, in base axes or the frame's own
    (``axes='link'``), from J of that frame.  Only the joints between it
    and the base take part; on a tree a push elsewhere that shows on
    those joints (a torso's) is read as this frame's: estimate several
    frames jointly with :func:`.wrenches.external_wrenches`.
    """
    if frame is not None:
        return _wrench_at_frame(obs, q, r, out, frame, axes)
    return _solved(_wrench_strict, obs, q, r, out)


def _solved(entry, obs, q, r, out, *frame):
    """
    Return the wrench one entry solves for; convert the inputs if refused.

    ``frame``: the entry's frame arguments (body, target, local axes),
    between the damping and the workspace; none for the end effector.
    """
    code = None
    if (type(q) is ARRAY and q.dtype is F64
            and type(r) is ARRAY):     # lists: converted below
        F = EMPTY(6) if out is None else out
        try:
            code = entry(obs._packed, q, r, obs.damping, *frame, obs.ws.ws,
                         obs.ws.frames, obs.J, obs._A, obs._y, F)
        except TypeError:           # read-only, strided: convert, again
            slow_inputs((q, r), ('q', 'r'), stacklevel=4)
    if code is None or code >= 0:
        q, r, F = vector('q', q, obs.n), vector('r', r, obs.n), out_array(
            out, (6,))
        code = entry(obs._packed, q, r, obs.damping, *frame, obs.ws.ws,
                     obs.ws.frames, obs.J, obs._A, obs._y, F)
        if code >= 0:
            raise status_error(code, (q,))
    return F


def felt_directions(obs, q, tol=1e-6):
    """
    Return an orthonormal basis (6, k) of the wrenches the arm feels at q.

    The range of J(q) (``[f; m]`` in base axes, moment about the
    end-effector origin): the estimate of :func:`external_wrench` is the
    projection of the true wrench onto it (for small damping).  ``k`` is
    6 for a six- or seven-joint arm away from singularities; a planar
    three-joint arm feels fx, fy and mz; a planar two-joint arm only two
    combinations of them.  Columns with singular values below ``tol``
    times the largest are left out.
    """
    J = jacobian(obs.model, q, 'base', ws=obs.ws)
    U, s, _ = np.linalg.svd(J, full_matrices=False)
    if not s.size or not s[0] > 0.0:
        return np.zeros((6, 0))
    return U[:, s > tol * s[0]]


def _wrench_at_frame(obs, q, r, out, frame, axes):
    if axes not in AXES:
        raise DynamicsInputError(f"axes must be 'base' or 'link', got "
                                 f'{axes!r}')
    body, target = frame_target(obs.model, frame)
    return _solved(_wrench_at_strict, obs, q, r, out, body, target,
                   axes == 'link')
