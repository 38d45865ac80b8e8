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
The same Newton-Euler recursion in high precision (mpmath), as a reference.

The kernel files (``kernels``) are executed a second time with ``njit``
replaced by the identity and ``math`` by mpmath (``kernels.load_copy``), over numpy object arrays
of ``mpf`` numbers: one implementation of the recursion, evaluated at 50
significant digits (by default) from the exact float64 inputs.  The
model is compiled into kernel frames at that precision too (the same
``model.compile_arrays``): the cosines and sines of DH and URDF angles,
the joint-axis rotations, the re-expressed inertial parameters and the
base rotation applied to gravity; the model's float64 numbers (and the
float64 base/tool matrices) are taken as exact.

Slow (milliseconds per call): for measuring the error of the float64 and
float32 paths, never for control.
"""
import mpmath
import numpy as np

from . import kernels as K
from .calling import (bad_method as _bad_method, CORIOLIS_METHODS,
                      FORWARD_DYNAMICS_METHODS, MASS_MATRIX_METHODS)
from .model import compile_arrays


class _MpMath:
    """The few ``math`` functions the kernels call, in mpmath."""

    cos = staticmethod(mpmath.cos)
    sin = staticmethod(mpmath.sin)
    sqrt = staticmethod(mpmath.sqrt)

    @staticmethod
    def isfinite(x):
        """Return True for a finite number."""
        return bool(mpmath.isfinite(x))


def _identity(f=None, **options):
    """``njit`` replaced: the kernels run as plain Python."""
    return f if f is not None else (lambda g: g)


_MP = K.load_copy('mp', _identity, _MpMath)


def _mp_array(x):
    flat = [mpmath.mpf(float(v)) for v in np.ravel(x)]
    return np.array(flat, dtype=object).reshape(np.shape(x))


class _MpNumbers(_MpMath):
    """``compile_arrays``'s number type: mpf from exact float64 values."""

    @staticmethod
    def num(x):
        """Return x (a float64, or already an mpf) as an mpf."""
        return x if isinstance(x, mpmath.mpf) else mpmath.mpf(float(x))


class HighPrecisionModel:
    """A model's kernel arrays compiled in mpmath at ``dps`` digits."""

    def __init__(self, model, dps=50):
        self.model = model
        self.dps = dps
        with mpmath.workdps(dps):
            links, frames = compile_arrays(model, _MpNumbers)
            self.links = np.array(
                [list(row) for row in links],
                dtype=object).reshape(model.nb, K.L_WIDTH)
            self.frames = np.array(frames, dtype=object)

    def _vec(self, x, size):
        if x is None:
            return _mp_array(np.zeros(size))
        return _mp_array(np.asarray(x, dtype=np.float64))

    def inverse_dynamics(self, q, qd=None, qdd=None, wrench=None,
                         wrench_frame='base', gravity=True,
                         velocity_products=True):
        """Return tau as an object array of mpf (see the float64 API)."""
        n = self.model.n
        mode = K.WRENCH_NONE if wrench is None else (
            K.WRENCH_BASE if wrench_frame == 'base' else K.WRENCH_EE)
        with mpmath.workdps(self.dps):
            ws = self._ws()
            tau = np.empty(n, dtype=object)
            qv = self._vec(q, n)
            qdv = self._vec(qd, n)
            _MP.joint_trig(self.links, self.frames, qv, ws)
            _MP.recursion(self.links, self.frames, qdv, qdv,
                          self._vec(qdd, n), self._vec(wrench, 6), ws,
                          gravity, velocity_products, mode, False, ws, tau)
        return tau

    def _ws(self):
        """Return a fresh (nb, W_WIDTH) workspace of mpf zeros."""
        return np.full((self.model.nb, K.W_WIDTH), mpmath.mpf(0),
                       dtype=object)

    def mass_matrix(self, q, method='newton_euler'):
        """
        Return D(q) as an (n, n) object array of mpf.

        ``method`` as in :func:`~newton_euler_ros.core.dynamics.mass_matrix`:
        ``'newton_euler'`` (n recursions, not symmetrized) or ``'crba'``.
        """
        n = self.model.n
        if method not in MASS_MATRIX_METHODS:
            raise _bad_method(method)
        with mpmath.workdps(self.dps):
            ws = self._ws()
            D = np.empty((n, n), dtype=object)
            qv = self._vec(q, n)
            if method == 'crba':
                _MP.mass_matrix_crba(self.links, self.frames, qv, ws, D)
                return D
            return self._unit_columns(qv, qv, False, ws, D)

    def _unit_columns(self, q, qd, coriolis, ws, M):
        """Fill M column by column, one recursion each (D, or C)."""
        n = self.model.n
        _MP.joint_trig(self.links, self.frames, q, ws)
        scratch = np.full((3, n), mpmath.mpf(0), dtype=object)
        _MP.unit_columns(self.links, self.frames, qd, coriolis, ws, scratch,
                         M)
        return M

    def coriolis_matrix(self, q, qd, method='newton_euler'):
        """
        Return the Christoffel C(q, qd) as an object array of mpf.

        ``method`` as in :func:`~newton_euler_ros.core.dynamics.coriolis_matrix`:
        ``'newton_euler'`` (n recursions, the default here: the reference)
        or ``'composite'`` (the O(n^2) algorithm, to measure it).
        """
        n = self.model.n
        if method not in CORIOLIS_METHODS:
            raise _bad_method(method, CORIOLIS_METHODS)
        with mpmath.workdps(self.dps):
            ws = self._ws()
            C = np.empty((n, n), dtype=object)
            qv, qdv = self._vec(q, n), self._vec(qd, n)
            if method == 'composite':
                cw = np.full((self.model.nb + 1, K.CW_WIDTH), mpmath.mpf(0),
                             dtype=object)
                _MP.coriolis_matrix_composite(self.links, self.frames, qv,
                                              qdv, ws, cw, C)
                return C
            return self._unit_columns(qv, qdv, True, ws, C)

    def forward_dynamics(self, q, qd, tau, wrench=None, wrench_frame='base',
                         method='aba'):
        """
        Return qdd as an object array of mpf.

        ``method='aba'``: the articulated-body kernel at this precision;
        ``'cholesky'``: D and the bias torques from the recursion, solved
        by mpmath's LU (the independent reference).
        """
        n = self.model.n
        if method not in FORWARD_DYNAMICS_METHODS:
            raise _bad_method(method, FORWARD_DYNAMICS_METHODS)
        mode = K.WRENCH_NONE if wrench is None else (
            K.WRENCH_BASE if wrench_frame == 'base' else K.WRENCH_EE)
        with mpmath.workdps(self.dps):
            if method == 'cholesky':
                D = self.mass_matrix(q, method='crba')
                bias = self.inverse_dynamics(q, qd, None, wrench,
                                             wrench_frame)
                rhs = [self._vec(tau, n)[i] - bias[i] for i in range(n)]
                x = mpmath.lu_solve(mpmath.matrix(D.tolist()),
                                    mpmath.matrix(rhs))
                return np.array([x[i] for i in range(n)], dtype=object)
            ws = self._ws()
            aw = np.full((self.model.nb + 1, K.A_WIDTH), mpmath.mpf(0),
                         dtype=object)
            qdd = np.empty(n, dtype=object)
            _MP.articulated_body(self.links, self.frames, self._vec(q, n),
                                 self._vec(qd, n), self._vec(tau, n),
                                 self._vec(wrench, 6), ws, True, True, mode,
                                 False, ws, aw, qdd)
        return qdd


def relative_error(approx, exact):
    """Return max |approx - exact| / max(max |exact|, tiny), as a float."""
    exact = np.asarray(exact, dtype=object)
    diff = max(abs(mpmath.mpf(float(a)) - e)
               for a, e in zip(np.ravel(approx), np.ravel(exact)))
    scale = max(abs(e) for e in np.ravel(exact))
    return float(diff / max(scale, mpmath.mpf('1e-300')))
