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

:class:`Float32Dynamics` runs the very kernels of ``_kernels`` on float32
copies of a model's arrays.  The kernels take every constant from the
model's constants row, so numba compiles a float32 specialization in
which every intermediate is a float32 (the test suite checks numba's type
maps for that): this is genuine single-precision arithmetic, not float64
arithmetic rounded at the end.

What float32 buys here: almost nothing in time, for about nine fewer
digits.  The recursion is scalar code over 3-tuples (no loop numba can
vectorize), so a float32 operation costs what a float64 one costs; only
the workspace traffic shrinks.  Measured on x86-64 (warm, min of 7
repeats), raw kernels float32 vs float64: puma560 tau 1.22 vs 1.28 us,
D 1.46 vs 1.53 us (n recursions) and 0.75 vs 0.81 us (CRBA); a random
50-joint chain tau 3.05 vs 3.30 us.  From Python (these methods vs the
float64 functions) tau is 2.2 vs 2.4 us and C 3.6 vs 3.7 us on the
puma560: within 10%, about the timing noise, and passing float64 arrays
instead of float32 ones costs about 0.45 us per argument for the
conversion.  The relative error against the 50-digit reference is about
1e-7 to 7e-7 for tau, D, C and g on the puma560 and panda (a few float32
ulp; the tests bound it by 100 n eps32) instead of about 2e-16.  Its
use is to measure what single precision costs in accuracy (embedded
targets, GPUs), not to go faster.

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
import math

import numpy as np

from . import _kernels as K
from .dynamics import (_bad_method, _raise_nonfinite, _vector,
                       _WRENCH_FRAMES)
from .errors import DynamicsInputError

_F32 = np.float32
_F32_MAX = float(np.finfo(np.float32).max)
_ARG_NAMES = ('q', 'qd', 'qdd', 'wrench')


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


def _raise(code, rounded, given):
    """Raise for a bad input, naming float32 overflow as such."""
    if code != K.OVERFLOW:
        arg, i = divmod(code, 1000)
        if given[arg] is not None:
            value = float(np.ravel(np.asarray(given[arg],
                                              dtype=np.float64))[i])
            if math.isfinite(value):
                raise DynamicsInputError(
                    f'{_ARG_NAMES[arg]}[{i}] is {value!r}, outside the '
                    f'float32 range (|x| <= {_F32_MAX:.8g})')
    _raise_nonfinite(code, rounded, 'float32')


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
        self.links = _readonly32(model.links_array)
        self.frames = _readonly32(model.frames_array)
        self._ws = np.zeros((n, K.W_WIDTH), dtype=_F32)
        self._scratch = np.zeros((3, n), dtype=_F32)
        self._zeros = np.zeros(n, dtype=_F32)
        self._zero_wrench = np.zeros(6, dtype=_F32)
        # buffers for inputs that arrive as anything but float32 vectors
        self._in = (np.zeros(n, dtype=_F32), np.zeros(n, dtype=_F32),
                    np.zeros(n, dtype=_F32), np.zeros(6, dtype=_F32))

    def __repr__(self):
        """Return e.g. ``Float32Dynamics(puma560, n=6)``."""
        return f'Float32Dynamics({self.model.name}, n={self.n})'

    # ------------------------------------------------------------------
    # argument handling (the float64 helpers, plus the rounding)

    def _vec(self, arg, x, size):
        """Return x as a float32 vector of ``size`` entries, or raise."""
        if (type(x) is np.ndarray and x.dtype == _F32 and x.ndim == 1
                and x.flags.c_contiguous):
            if x.shape[0] != size:
                raise DynamicsInputError(
                    f'{_ARG_NAMES[arg]} must have {size} entries, '
                    f'got {x.shape[0]}')
            return x
        buf = self._in[arg]
        K.round_into(_vector(_ARG_NAMES[arg], x, size), buf)
        return buf

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
        if wrench is None:
            w32, mode = self._zero_wrench, K.WRENCH_NONE
        else:
            mode = _WRENCH_FRAMES.get(wrench_frame)
            if mode is None:
                raise DynamicsInputError(
                    f"wrench_frame must be 'base' or 'end_effector', "
                    f'got {wrench_frame!r}')
            w32 = self._vec(3, wrench, 6)
        tau = np.empty(n, dtype=_F32) if out is None else _out(out)
        bad = K.inverse_dynamics(self.links, self.frames, q32, qd32, qdd32,
                                 w32, gravity, velocity_products, mode,
                                 self._ws, tau)
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
        n = self.n
        q32 = self._vec(0, q, n)
        zeros = self._zeros
        bad = K.check_finite(q32, zeros, zeros, self._zero_wrench)
        if bad >= 0:
            _raise(bad, (q32, zeros, zeros, zeros), (q, None, None, None))
        D = np.empty((n, n), dtype=_F32) if out is None else _out(out)
        if method == 'newton_euler':
            bad = K.mass_matrix(self.links, self.frames, q32, self._ws,
                                self._scratch, D)
        elif method == 'crba':
            bad = K.mass_matrix_crba(self.links, self.frames, q32, self._ws,
                                     D)
        else:
            raise _bad_method(method)
        if bad >= 0:
            _raise_nonfinite(K.OVERFLOW, (), 'float32')
        return D

    def coriolis_matrix(self, q, qd, *, out=None):
        """Christoffel C(q, qd), (n, n) float32; n recursions."""
        n = self.n
        q32 = self._vec(0, q, n)
        qd32 = self._vec(1, qd, n)
        zeros = self._zeros
        bad = K.check_finite(q32, qd32, zeros, self._zero_wrench)
        if bad >= 0:
            _raise(bad, (q32, qd32, zeros, zeros), (q, qd, None, None))
        C = np.empty((n, n), dtype=_F32) if out is None else _out(out)
        if K.coriolis_matrix(self.links, self.frames, q32, qd32, self._ws,
                             self._scratch, C) >= 0:
            _raise_nonfinite(K.OVERFLOW, (), 'float32')
        return C

    def gravity_torques(self, q, *, out=None):
        """g(q) in float32: the joint torques that hold the arm still."""
        return self.inverse_dynamics(q, velocity_products=False, out=out)
