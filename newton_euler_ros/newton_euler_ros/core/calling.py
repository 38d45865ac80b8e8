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
How Python calls the kernels: strict entries, conversion, status decoding.

The one entry path of every dynamics function is

1. the fast call: arrays as given, straight into a *strict entry*
   (:class:`StrictEntry`), a numba dispatcher compiled for exactly
   float64, C-contiguous, writeable arrays and allowed no other
   signature.  numba matches argument types in C on every call anyway;
   a main input that is not an ndarray (a list) skips this step on one
   check of its type in Python (and, where a call costs microseconds,
   the derivatives and the observer, of its dtype too); anything else
   numba does not match (a float32, int, read-only or strided array, a
   workspace of another dtype) raises numba's ``TypeError``, after
   numba's own search for a conversion: about 0.1 ms, and the first
   such call in a process warns (:func:`slow_inputs`);
2. only then, or when the kernel returns a status code: the arguments
   converted once (:func:`vector`, :func:`out_array`,
   :func:`workspace`), the kernel called again, and its status decoded
   here (:func:`status_error`) into the one-line errors users see.

So a float64 array costs no Python check beyond its type, and a list
costs one conversion more.  Only numba's public API is used: ``njit``,
``Dispatcher.compile`` and ``disable_compile``.
"""
import gc
import math
import threading
import warnings

from numba import njit, types
import numpy as np

from . import kernels as K
from .errors import (DynamicsInputError, NotPositiveDefiniteError,
                     SlowInputWarning)
from .workspace import Workspace

# numba and the kernels' dispatchers are some 200,000 objects that live as
# long as the process.  Out of the cyclic collector's sight (gc.freeze),
# every later collection skips them: 15 % less CPU for a CLI command's or
# a node's start (1.16 -> 0.99 s, median of 8, `newton-euler dynamics`),
# and a long-running node's full collections stay short.  Whatever else
# the process held at this moment is frozen with them; gc.unfreeze()
# undoes it.  The first kernel load (numba's typing registries) is frozen
# the same way (``StrictEntry.load`` below).
gc.freeze()

INPUTS = ('q', 'qd', 'qdd', 'wrench')
FD_INPUTS = ('q', 'qd', 'tau', 'wrench')
WRENCH_FRAMES = {'base': K.WRENCH_BASE, 'end_effector': K.WRENCH_EE}
MASS_MATRIX_METHODS = ('newton_euler', 'crba')
CORIOLIS_METHODS = ('composite', 'newton_euler')
FORWARD_DYNAMICS_METHODS = ('aba', 'cholesky')

# argument types of the strict entries
F8 = types.float64
VEC = types.Array(F8, 1, 'C')
MAT = types.Array(F8, 2, 'C')
PACKED = types.Array(F8, 2, 'C', readonly=True)
TARGET = types.Array(F8, 1, 'C', readonly=True)
INT = types.int64
BOOL = types.boolean


_F64 = F64 = np.dtype(np.float64)   # compared by identity first: cheaper
# the fast paths' test of an input's type: a name of this module is
# found in about 8 ns, np.ndarray in about 21 (two lookups)
ARRAY = np.ndarray
# and their fresh results: np.empty through numpy's module costs some
# 40 ns more a call than through this name (measured on 2026-12-08)
EMPTY = np.empty


class StrictEntry:
    """
    A kernel entry point compiled for exactly one signature, on first use.

    Calling it compiles the one signature ``argtypes`` (or loads it from
    numba's cache), whatever the arguments, closes the dispatcher to
    other signatures (``disable_compile``), so that an argument of
    another type raises numba's ``TypeError`` instead of compiling a
    variant, and calls it.  With ``home`` (the registering module's
    ``globals()``), the names there bound to this entry are rebound to
    the dispatcher itself: from then on a call goes straight into numba's
    C dispatcher, with no Python frame between.  The dispatcher takes the
    entry points' options (``kernels.ENTRY``: numba's cache does not tell
    compilations of one function with other options apart).  Loading
    only what is called keeps a command's start short: a node on a chain
    never loads the tree's or the observer's entries.
    """

    __slots__ = ('kernel', 'signature', 'dispatcher', 'home', '_lock')

    def __init__(self, kernel, *argtypes, home=None):
        self.kernel = kernel
        self.signature = types.int64(*argtypes)
        self.dispatcher = None
        self.home = home
        self._lock = threading.Lock()

    def __call__(self, *args):
        return self.load()(*args)

    def load(self):
        """Compile (or load from the cache) the one signature; return it."""
        with self._lock:
            if self.dispatcher is None:
                K.package_locators()    # numba reads them here
                dispatcher = njit(**K.ENTRY)(self.kernel.py_func)
                dispatcher.compile(self.signature)
                dispatcher.disable_compile()
                # numba's typing registries, filled by this first load,
                # live as long as the process: out of the collector's
                # sight, as above
                gc.freeze()
                self.dispatcher = dispatcher
            if self.home is not None:
                for name, value in list(self.home.items()):
                    if value is self:
                        self.home[name] = self.dispatcher
        return self.dispatcher

    def __repr__(self):
        state = 'loaded' if self.dispatcher is not None else 'not loaded'
        return f'<StrictEntry {self.kernel.py_func.__name__} ({state})>'


strict_entry = StrictEntry


_SLOW_SAID = []     # the warning below is given once a process


def slow_inputs(values, names=INPUTS, stacklevel=3):
    """
    Warn, once a process, of an input numba's dispatcher did not take.

    Called where a fast call raised numba's ``TypeError``: if one of the
    ``values`` is the cause (an array of another dtype, a read-only or
    strided one, or a sequence beside arrays), numba's search for a conversion cost about
    0.1 ms, and will on every call given such an input.  The result is
    right all the same; the warning says which input and what to pass.
    ``stacklevel``: the user's call, counted as ``warnings.warn`` does
    from this function (3: the caller's caller).
    """
    if _SLOW_SAID:
        return
    for name, x in zip(names, values):
        if type(x) is ARRAY:
            if x.dtype != _F64:
                what = f'a {x.dtype} array'
            elif not x.flags.writeable:
                what = 'a read-only array'
            elif not x.flags.c_contiguous:
                what = 'a strided (not C-contiguous) array'
            else:
                continue
        elif type(x) in SEQUENCES:
            what = f'a {type(x).__name__} beside arrays'
        else:
            continue
        _SLOW_SAID.append(name)
        warnings.warn(
            f'{name} is {what}: numba looks for a conversion before it is '
            f'converted, about 0.1 ms more on every such call (the result '
            f'is the same); pass a writeable, C-contiguous float64 array, '
            f'e.g. np.array({name}, dtype=float). Said once',
            SlowInputWarning, stacklevel=stacklevel)
        return


# ---------------------------------------------------------------------------
# conversions, once

def workspace(model, ws):
    """Return ``ws`` once checked against the model (None: the default)."""
    if ws is None:
        return model.default_workspace
    if type(ws) is not Workspace or ws.n != model.n \
            or ws.nb != model.nb or (ws.dtype is not _F64
                                     and ws.dtype != _F64):
        raise DynamicsInputError(
            f'ws must be a float64 Workspace for a model of {model.n} '
            f'joints, got {ws!r}')
    return ws


def foreign_workspace(model, ws):
    """
    Raise the one-line error for a ``ws`` that is not a Workspace at all.

    Called where a fast path met an AttributeError: for any other ``ws``
    it returns, and the caller re-raises the AttributeError (a bug).
    """
    if ws is not None and type(ws) is not Workspace:
        workspace(model, ws)


def vector(name, x, size):
    """Return x as a contiguous float64 vector of the given size, or raise."""
    if (type(x) is ARRAY and x.dtype == np.float64 and x.ndim == 1
            and x.flags.c_contiguous and x.flags.writeable):
        arr = x
    else:
        try:
            arr = np.array(x, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise DynamicsInputError(
                f'{name} must be a sequence of {size} numbers: {exc}') from None
        if arr.ndim != 1:
            raise DynamicsInputError(
                f'{name} must be a vector of {size} numbers, '
                f'got shape {arr.shape}')
    if arr.shape[0] != size:
        raise DynamicsInputError(
            f'{name} must have {size} entries, got {arr.shape[0]}')
    return arr


SEQUENCES = (list, tuple)


def inputs(ws, names, q, qd=None, third=None, wrench=None):
    """
    Return the four inputs of an entry as float64 vectors, each checked.

    ``None`` is the workspace's zeros.  A list or tuple of the right
    length (a state as Python lists, the common case) is copied into a
    preallocated row of ``ws``, so no array is made; anything else goes
    through :func:`vector`, which converts it or names what is wrong
    (``names``: the inputs' names, ``INPUTS`` or ``FD_INPUTS``).  The rows
    are overwritten by the next call on ``ws``: use them at once.
    """
    n = ws.n
    if (type(q) is list and type(qd) is list and type(third) is list
            and len(q) == n and len(qd) == n and len(third) == n):
        # the common case, three (or four) lists: one copy into the rows
        try:
            if wrench is None:
                ws.given[:3 * n] = q + qd + third
                return ws.given_three
            if type(wrench) is list and len(wrench) == 6:
                ws.given[:] = q + qd + third + wrench
                return ws.given_four
        except (TypeError, ValueError):
            pass                # one at a time below: vector() names it
    given = (q, qd, third, wrench)
    out = [ws.zeros, ws.zeros, ws.zeros, ws.zero_wrench]
    for i in range(4):
        x = given[i]
        if x is None:
            continue
        size = 6 if i == 3 else n
        if type(x) in SEQUENCES and len(x) == size:
            row = ws.given_wrench if i == 3 else ws.given_rows[i]
            try:
                row[:] = x
                out[i] = row
                continue
            except (TypeError, ValueError):
                pass            # vector() says what is wrong
        out[i] = vector(names[i], x, size)
    return out


def out_array(out, shape, dtype=np.float64):
    """Return a new array of ``shape``, or ``out`` once checked."""
    if out is None:
        return np.empty(shape, dtype)
    want = _F64 if dtype is np.float64 else np.dtype(dtype)
    if (type(out) is not np.ndarray
            or (out.dtype is not want and out.dtype != want)
            or out.shape != shape or not out.flags.c_contiguous
            or not out.flags.writeable):
        raise DynamicsInputError(
            f'out must be a writeable, C-contiguous {np.dtype(dtype).name} '
            f'array of shape {shape}, got '
            + (f'{out.dtype} {out.shape}' if isinstance(out, np.ndarray)
               else type(out).__name__))
    return out


def matrix(name, X, cols, rows=None):
    """Return X as a finite, C-contiguous float64 (rows, cols), or raise."""
    try:
        X = np.ascontiguousarray(X, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise DynamicsInputError(f'{name} must be numeric: {exc}') from None
    if X.ndim != 2 or X.shape[1] != cols or (rows is not None
                                             and X.shape[0] != rows):
        want = f'({rows if rows is not None else "m"}, {cols})'
        raise DynamicsInputError(
            f'{name} must have shape {want}, got {X.shape}')
    if not X.flags.writeable:
        X = X.copy()
    if not np.isfinite(X).all():
        r, c = np.argwhere(~np.isfinite(X))[0]
        raise DynamicsInputError(
            f'{name}[{r}, {c}] is {float(X[r, c])!r}; every entry must be '
            f'finite')
    return X


def wrench_mode(wrench, wrench_frame):
    """Return the kernels' wrench mode for a wrench and its frame name."""
    if wrench is None:
        return K.WRENCH_NONE
    try:
        return WRENCH_FRAMES[wrench_frame]
    except KeyError:
        raise DynamicsInputError(
            f"wrench_frame must be 'base' or 'end_effector', "
            f'got {wrench_frame!r}') from None


def bad_method(method, methods=MASS_MATRIX_METHODS):
    """Return the ValueError for an unknown ``method``."""
    return ValueError(
        f'method must be one of {", ".join(map(repr, methods))}'
        f', got {method!r}')


# ---------------------------------------------------------------------------
# status codes, decoded once

def status_error(code, values=(), names=INPUTS, precision='float64',
                 model=None, q=None, ws=None, row=None, given=None):
    """
    Return the exception a kernel's status code (>= 0) stands for.

    ``values``: the inputs as the kernel saw them (for the non-finite
    entry's value); ``given``: the inputs as the caller gave them, when
    the kernel saw them rounded (float32: a finite input beyond its
    range became inf); ``model``, ``q`` and ``ws`` name the joint of a
    singular mass matrix; ``row`` the row of a batch.
    """
    at = '' if row is None else f' for row {row}'
    if K.SINGULAR <= code < K.MIMIC:
        err = not_positive_definite(model, q, code - K.SINGULAR, ws)
        if row is None:
            return err
        return NotPositiveDefiniteError(f'row {row}: {err}', err.joint)
    if code == K.OVERFLOW:
        return DynamicsInputError(
            f'the result{at} overflows {precision} (inputs too large); '
            f'nothing is returned')
    if code >= K.SIZE:
        # sizes are checked in Python before a second call; only a
        # workspace of another size can get here
        return DynamicsInputError(
            'ws does not fit this model (made for another number of joints)')
    arg, i = divmod(code, K.NONFINITE)
    if given is not None and given[arg] is not None:
        value = float(np.ravel(np.asarray(given[arg], dtype=np.float64))[i])
        if math.isfinite(value):
            limit = float(np.finfo(precision).max)
            return DynamicsInputError(
                f'{names[arg]}[{i}] is {value!r}, outside the {precision} '
                f'range (|x| <= {limit:.8g})')
    return DynamicsInputError(
        f'{names[arg]}[{i}] is {float(values[arg][i])!r}; every entry must '
        f'be finite')


def first_singular_pivot(D, rtol=1e-12):
    """
    Return the first joint where D is not positive definite, or None.

    The kernels' Cholesky factorisation of D - rtol max|diag D| 1: a
    pivot that is not clearly positive (relative to D's scale) counts.
    """
    D = np.asarray(D, dtype=np.float64)
    n = D.shape[0]
    scale = max(float(np.abs(np.diag(D)).max()), 1e-300) if n else 1.0
    shifted = D - rtol * scale * np.eye(n)
    bad = K.cholesky_solve(shifted, np.zeros(n), np.zeros((n, n)),
                           np.empty(n))
    return None if bad < 0 else int(bad)


def not_positive_definite(model, q, j, ws):
    """
    Return the NotPositiveDefiniteError for a singular D (first joint).

    The articulated-body algorithm meets the singularity from the tip; the
    joint named is the first one (from the base) at which the leading
    block of D stops being positive definite, as a Cholesky factorisation
    finds it, so both methods name the same joint.
    """
    ws = workspace(model, ws)
    D = np.empty((model.n, model.n))
    K.run_mass_matrix_crba(model.packed, vector('q', q, model.n), ws.ws, D)
    bad = K.cholesky_solve(D, ws.zeros, ws.chol, np.empty(model.n))
    if bad < 0:
        bad = j
    return NotPositiveDefiniteError(
        f'the mass matrix is not positive definite at joint {bad} '
        f'({model.joint_names[bad]}): no mass or inertia moves with that '
        f'joint given the joints before it', bad)
