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
The same dynamics computed in single precision (float32) throughout.

:class:`Float32Dynamics` runs the very kernels of ``kernels`` on float32
copies of a model's arrays.  The kernels take every constant from the
model's constants row, so numba compiles a float32 specialization in
which every intermediate is a float32 (the test suite checks numba's type
maps for that): this is genuine single-precision arithmetic, not float64
arithmetic rounded at the end.

What float32 buys here: nothing in time, for about nine fewer digits.
The kernels are scalar code over 3-tuples (no loop numba can vectorize),
so a float32 operation costs what a float64 one costs, and from Python
these methods are slower than the float64 functions, which have a
faster entry path (``make accuracy`` times both: 0.9x to 2.3x).  The
relative error against the 50-digit reference is about 1e-7 to 7e-7 for
tau, D, C and g on the puma560 and panda (a few float32 ulp; the tests
bound it by 100 n eps32) instead of about 2e-16; forward dynamics
amplifies it by up to cond(D).  Its use is to measure what single
precision costs in accuracy (embedded targets, GPUs), not to go faster.

Error budget.  Three roundings make up the float32 error, and all three
are part of it by design: the model's parameters (DH values and their
cosines and sines, masses, centres of mass, inertias, gravity) are
rounded to float32 once, in the constructor; the inputs q, qd, qdd and
the wrench are rounded to float32 on every call (pass float32 arrays to
skip the conversion); and the arithmetic is float32.  A finite input
beyond the float32 range (|x| > 3.4e38) is refused, as is a non-finite
one, with :class:`~newton_euler_ros.core.errors.DynamicsInputError`, and
a result that overflows float32 raises it too, exactly like the float64
functions.

Examples
--------
>>> import numpy as np
>>> from newton_euler_ros.core import load_robot
>>> from newton_euler_ros.core.float32 import Float32Dynamics
>>> arm = Float32Dynamics(load_robot('planar_2r'))
>>> arm.gravity_torques([0.0, 0.0]).dtype
dtype('float32')

"""

import numpy as np

from . import kernels as K
from .calling import (bad_method as _bad_method, CORIOLIS_METHODS,
                      FD_INPUTS as _FD_INPUTS, INPUTS as _INPUTS,
                      not_positive_definite as _not_positive_definite,
                      status_error, vector as _vector,
                      wrench_mode as _wrench_mode)
from .errors import DynamicsInputError
from .workspace import Workspace

_F32 = np.float32
_F32_MAX = float(np.finfo(np.float32).max)


def _readonly32(x):
    arr = np.array(x, dtype=np.float64)
    if not np.all(np.abs(arr) <= _F32_MAX):
        raise ValueError('the model has a parameter outside the float32 '
                         f'range (|x| <= {_F32_MAX:.8g})')
    arr = arr.astype(_F32)
    arr.setflags(write=False)
    return arr


def _out(out):
    if type(out) is not np.ndarray or out.dtype != _F32:
        raise TypeError('out must be a float32 numpy array')
    return out


def _raise(code, rounded, given, names=_INPUTS):
    """Raise for a bad input, naming float32 overflow as such."""
    raise status_error(code, rounded, names, 'float32', given=given)


class Float32Dynamics:
    """
    Inverse dynamics, D, C and g of one robot, computed in float32.

    The methods mirror the float64 functions of
    :mod:`~newton_euler_ros.core.dynamics` and return float32 arrays.
    The instance holds its own float32 workspace: not thread-safe, give
    each thread its own instance.

    Parameters
    ----------
    model : RobotModel
        The robot; its kernel arrays are rounded to float32 once, here.

    """

    def __init__(self, model):
        n = model.n
        self.model = model
        self.n = n
        self.packed = _readonly32(model.packed)
        self._ws = Workspace(model, _F32)
        self._zeros = self._ws.zeros
        self._zero_wrench = self._ws.zero_wrench
        # buffers for inputs that arrive as anything but float32 vectors
        self._in = (np.zeros(n, dtype=_F32), np.zeros(n, dtype=_F32),
                    np.zeros(n, dtype=_F32), np.zeros(6, dtype=_F32))

    def __repr__(self):
        """Return e.g. ``Float32Dynamics(puma560, n=6)``."""
        return f'Float32Dynamics({self.model.name}, n={self.n})'

    # ------------------------------------------------------------------
    # argument handling (the float64 helpers, plus the rounding)

    def _vec(self, arg, x, size, names=_INPUTS):
        """Return x as a float32 vector of ``size`` entries, or raise."""
        if (type(x) is np.ndarray and x.dtype == _F32 and x.ndim == 1
                and x.flags.c_contiguous):
            if x.shape[0] != size:
                raise DynamicsInputError(
                    f'{names[arg]} must have {size} entries, '
                    f'got {x.shape[0]}')
            return x
        buf = self._in[arg]
        K.round_into(_vector(names[arg], x, size), buf)
        return buf

    def _finite_square(self, q, q32, qd, qd32, out):
        """
        Check q and qd finite in float32; return D's or C's array.

        That array is ``out``, checked, or a new (n, n) float32 one.
        """
        zeros = self._zeros
        bad = K.check_finite(q32, qd32, zeros, self._zero_wrench)
        if bad >= 0:
            _raise(bad, (q32, qd32, zeros, zeros), (q, qd, None, None))
        n = self.n
        return np.empty((n, n), dtype=_F32) if out is None else _out(out)

    # ------------------------------------------------------------------
    # dynamics

    def inverse_dynamics(self, q, qd=None, qdd=None, wrench=None,
                         wrench_frame='base', gravity=True,
                         velocity_products=True, *, out=None):
        """
        Joint forces tau = D qdd + C qd + g + J^T F_e, in float32.

        Arguments as :func:`~newton_euler_ros.core.dynamics.inverse_dynamics`
        (``None`` means zeros); they are rounded to float32.  ``out``, if
        given, must be a float32 (n,) array.  Returns (n,) float32.
        """
        n = self.n
        q32 = self._vec(0, q, n)
        qd32 = self._zeros if qd is None else self._vec(1, qd, n)
        qdd32 = self._zeros if qdd is None else self._vec(2, qdd, n)
        mode = _wrench_mode(wrench, wrench_frame)
        w32 = (self._zero_wrench if wrench is None
               else self._vec(3, wrench, 6))
        tau = np.empty(n, dtype=_F32) if out is None else _out(out)
        bad = K.run_inverse_dynamics(
            self.packed, q32, qd32, qdd32, w32,
            K.flags(gravity, velocity_products, mode), self._ws.ws, tau)
        if bad >= 0:
            _raise(bad, (q32, qd32, qdd32, w32), (q, qd, qdd, wrench))
        return tau

    def mass_matrix(self, q, *, method='crba', out=None):
        """
        Joint-space inertia matrix D(q), (n, n) float32.

        ``method`` is ``'crba'`` (composite-rigid-body algorithm, the
        default) or ``'newton_euler'`` (n recursions), as in
        :func:`~newton_euler_ros.core.dynamics.mass_matrix`.
        """
        q32 = self._vec(0, q, self.n)
        D = self._finite_square(q, q32, None, self._zeros, out)
        if method not in ('newton_euler', 'crba'):
            raise _bad_method(method)
        if K.run_mass_matrix(self.packed, q32, method == 'crba', self._ws.ws,
                             self._ws.scratch, D) >= 0:
            raise status_error(K.OVERFLOW, precision='float32')
        return D

    def coriolis_matrix(self, q, qd, *, method='composite', out=None):
        """
        Christoffel C(q, qd), (n, n) float32.

        ``method`` is ``'composite'`` (O(n^2), the default) or
        ``'newton_euler'`` (n recursions), as in
        :func:`~newton_euler_ros.core.dynamics.coriolis_matrix`.
        """
        n = self.n
        if method not in CORIOLIS_METHODS:
            raise _bad_method(method, CORIOLIS_METHODS)
        q32 = self._vec(0, q, n)
        qd32 = self._vec(1, qd, n)
        C = self._finite_square(q, q32, qd, qd32, out)
        if K.run_coriolis_matrix(self.packed, q32, qd32, method == 'composite',
                                 self._ws.ws, self._ws.cw, self._ws.scratch,
                                 C) >= 0:
            raise status_error(K.OVERFLOW, precision='float32')
        return C

    def forward_dynamics(self, q, qd, tau, wrench=None, wrench_frame='base',
                         *, out=None):
        """
        Joint accelerations in float32, by the articulated-body algorithm.

        Arguments as :func:`~newton_euler_ros.core.dynamics.forward_dynamics`;
        raises :class:`~newton_euler_ros.core.errors.NotPositiveDefiniteError`
        where D is singular.
        """
        n = self.n
        q32 = self._vec(0, q, n)
        qd32 = self._vec(1, qd, n)
        tau32 = self._vec(2, tau, n, _FD_INPUTS)
        mode = _wrench_mode(wrench, wrench_frame)
        w32 = (self._zero_wrench if wrench is None
               else self._vec(3, wrench, 6))
        qdd = np.empty(n, dtype=_F32) if out is None else _out(out)
        bad = K.run_forward_dynamics(self.packed, q32, qd32, tau32, w32,
                                     K.flags(True, True, mode), self._ws.ws,
                                     self._ws.aw, qdd)
        if bad == K.MIMIC:      # coupled joints: D qdd = tau - bias
            bad = self._solve(q32, qd32, tau32, w32, mode, qdd)
        if bad >= K.SINGULAR:
            raise _not_positive_definite(self.model, np.asarray(q, float),
                                         bad - K.SINGULAR,
                                         self.model.default_workspace)
        if bad >= 0:
            _raise(bad, (q32, qd32, tau32, w32), (q, qd, tau, wrench),
                   _FD_INPUTS)
        return qdd

    def _solve(self, q32, qd32, tau32, w32, mode, qdd):
        """Solve D qdd = tau - bias by Cholesky, in float32 (mimic joints)."""
        n = self.n
        ws = self._ws
        bias = np.empty(n, dtype=_F32)
        bad = K.run_inverse_dynamics(self.packed, q32, qd32, ws.zeros, w32,
                                     K.flags(True, True, mode), ws.ws, bias)
        if bad >= 0:
            return bad
        D = np.empty((n, n), dtype=_F32)
        if K.run_mass_matrix_crba(self.packed, q32, ws.ws, D) >= 0:
            return K.OVERFLOW
        bad = K.cholesky_solve(D, tau32 - bias, ws.chol, qdd)
        return -1 if bad < 0 else K.SINGULAR + bad

    def gravity_torques(self, q, *, out=None):
        """g(q) in float32: the joint torques that hold the arm still."""
        return self.inverse_dynamics(q, velocity_products=False, out=out)
