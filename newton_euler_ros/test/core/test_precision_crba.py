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
The composite-rigid-body D(q) and the genuine float32 path.

- CRBA against the n-recursion D: to 10 n eps in float64 on every bundled
  robot and on random chains (both DH conventions, mixed joints, massless
  links), and to 1e-40 at 50 digits (it is the same matrix, not an
  approximation of it).
- float32: numba's type maps of the float32 specializations of every
  kernel hold no float64 (so the arithmetic really is single precision),
  and the errors of :class:`Float32Dynamics` against the 50-digit
  reference are those of float32: well above float64 round-off, below
  100 n eps32.

The type-map check compiles every kernel afresh (numba's disk cache holds
no type maps): about two minutes.  Its verdict depends only on the
kernels' sources, this file, numba and Python, so a pass is recorded
under their digest beside numba's cache (``...-verdicts``) and the next
run with the same four reads the record instead of compiling again; any
change to one of them runs the check in full.  ``NEWTON_EULER_RECHECK=1``
runs it in full regardless.
"""
import doctest
import hashlib
import math
import os
import sys
import warnings

import mpmath
from newton_euler_ros.core import (bundled_robots, DynamicsInputError,
                                   load_robot, make_model, mass_matrix,
                                   mass_matrix_condition)
from newton_euler_ros.core import float32 as float32_module
from newton_euler_ros.core import kernels as K
from newton_euler_ros.core.float32 import Float32Dynamics
from newton_euler_ros.core.highprec import HighPrecisionModel, relative_error
from newton_euler_ros.core.model import make_chain, pose_matrix, rpy_matrix
import numba
from numba.core import types as nbtypes
import numpy as np
import pytest

EPS64 = float(np.finfo(np.float64).eps)
EPS32 = float(np.finfo(np.float32).eps)


def _robot(name):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot(name)


def _chain(n, seed, convention, massless=()):
    """Return a seeded random chain with mixed revolute/prismatic joints."""
    rng = np.random.default_rng(seed)
    types_ = ['prismatic' if rng.random() < 0.35 else 'revolute'
              for _ in range(n)]
    alpha = rng.choice([0.0, math.pi / 2, -math.pi / 2, 1.0], n)
    alpha = np.where(alpha == 1.0, rng.uniform(-math.pi, math.pi, n), alpha)
    mass = rng.uniform(0.3, 4.0, n)
    inertia = []
    for j in range(n):
        second = mass[j] * rng.uniform(0.002, 0.05, 3)
        principal = [second[1] + second[2], second[0] + second[2],
                     second[0] + second[1]]
        R = rpy_matrix(*rng.uniform(-math.pi, math.pi, 3))
        inertia.append(R @ np.diag(principal) @ R.T)
    inertia = np.array(inertia)
    for j in massless:
        mass[j] = 0.0
        inertia[j] = 0.0
    return make_model(
        f'chain{n}', convention, [f'j{k}' for k in range(n)], types_,
        a=rng.uniform(-0.3, 0.3, n), alpha=alpha,
        d=rng.uniform(-0.3, 0.3, n), theta=rng.uniform(-math.pi, math.pi, n),
        mass=mass, com=rng.uniform(-0.15, 0.15, (n, 3)), inertia=inertia,
        tool=pose_matrix(rng.uniform(-0.1, 0.1, 3),
                         rng.uniform(-math.pi, math.pi, 3)))


def _rel(a, b):
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


def _mp_rel(a, b):
    """Relative difference of two mpf arrays, without rounding either."""
    with mpmath.workdps(60):
        diff = max(abs(x - y) for x, y in zip(np.ravel(a), np.ravel(b)))
        scale = max(max(abs(y) for y in np.ravel(b)), mpmath.mpf('1e-300'))
        return diff / scale


# ---------------------------------------------------------------------------
# CRBA
# ---------------------------------------------------------------------------

def _check_crba(model, states=4, seed=0):
    rng = np.random.default_rng(seed)
    bound = 10 * model.n * EPS64
    worst = 0.0
    for _ in range(states):
        q = rng.uniform(-3.0, 3.0, model.n)
        D_ne = mass_matrix(model, q, method='newton_euler')
        D_crba = mass_matrix(model, q, method='crba')
        assert np.all(D_crba == D_crba.T)
        err = _rel(D_crba, D_ne)
        assert err <= bound, (model.name, q, err)
        worst = max(worst, err)
    return worst


@pytest.mark.parametrize('name', sorted(bundled_robots()))
def test_crba_equals_n_recursions_on_bundled_robots(name):
    _check_crba(_robot(name))


@pytest.mark.parametrize('convention', ['standard', 'modified'])
@pytest.mark.parametrize('n', [1, 2, 3, 4, 5, 6, 7, 8, 50])
def test_crba_equals_n_recursions_on_random_chains(n, convention):
    for seed in range(3):
        _check_crba(_chain(n, 100 * n + seed, convention), seed=seed)


def test_crba_with_massless_links_and_tail():
    for convention in ('standard', 'modified'):
        model = _chain(6, 7, convention, massless=(1, 2, 5))
        _check_crba(model)
        D = mass_matrix(model, np.linspace(-1.0, 1.0, 6), method='crba')
        assert np.all(D[5] == 0.0) and np.all(D[:, 5] == 0.0)


def test_crba_in_high_precision_is_the_same_matrix():
    models = [_robot('puma560'), _robot('stanford'),
              _chain(5, 3, 'standard'), _chain(5, 4, 'modified')]
    for model in models:
        hp = HighPrecisionModel(model, dps=50)
        q = np.random.default_rng(2).uniform(-2.0, 2.0, model.n)
        D_crba = hp.mass_matrix(q, method='crba')
        D_ne = hp.mass_matrix(q, method='newton_euler')
        assert all(isinstance(x, mpmath.mpf) for x in D_crba.ravel())
        # The random inertias R diag R^T are symmetric only to an ulp in
        # float64; the recursion uses all nine entries (its D is then
        # unsymmetric by ~1e-18 even at 50 digits), CRBA the symmetric part.
        # Exactly, CRBA is the symmetric part of the recursion's D.
        with mpmath.workdps(60):
            D_sym = (D_ne + D_ne.T) / 2
            assert _mp_rel(D_crba, D_sym) < mpmath.mpf('1e-40')
        # and the float64 CRBA is within a few ulp of it
        assert relative_error(mass_matrix(model, q, method='crba'),
                              D_ne) < 10 * model.n * EPS64


def test_mass_matrix_method_is_checked():
    model = _robot('planar_2r')
    for call in (lambda: mass_matrix(model, [0.0, 0.0], method='crb'),
                 lambda: HighPrecisionModel(model).mass_matrix(
                     [0.0, 0.0], method='aba'),
                 lambda: Float32Dynamics(model).mass_matrix(
                     [0.0, 0.0], method=None)):
        with pytest.raises(ValueError, match="'newton_euler', 'crba'"):
            call()


def test_crba_overflow_raises():
    model = _robot('planar_rp')
    with pytest.raises(DynamicsInputError, match='overflows float64'):
        mass_matrix(model, [0.0, 1e200], method='crba')


# ---------------------------------------------------------------------------
# float32: the type maps
# ---------------------------------------------------------------------------

def _fresh_kernels():
    """Compile the kernel files anew (no disk cache: full type maps)."""
    return K.load_copy('typed', lambda f=None, **kw: (
        numba.njit(f) if f is not None else numba.njit))


def _has_float(t, bits):
    """Return True when numba type t is or holds a float of ``bits`` bits."""
    if isinstance(t, nbtypes.Float):
        return t.bitwidth == bits
    if isinstance(t, nbtypes.Complex):
        return t.bitwidth == 2 * bits
    if isinstance(t, nbtypes.Array):
        return _has_float(t.dtype, bits)
    if isinstance(t, nbtypes.BaseTuple):
        return any(_has_float(x, bits) for x in t.types)
    return False


def _has_float64(t):
    return _has_float(t, 64)


def _all_float32(sig):
    """Return True for a float32 specialization: float32 in, no float64."""
    return (any(_has_float(a, 32) for a in sig)
            and not any(_has_float64(a) for a in sig))


def _float64_variables(mod):
    """Return ({kernel: [float64 variables]}, kernels without float32)."""
    found, missing = {}, []
    for name, obj in sorted(vars(mod).items()):
        if not isinstance(obj, numba.core.registry.CPUDispatcher):
            continue
        sigs = [s for s in obj.overloads if _all_float32(s)]
        if not sigs:
            missing.append(name)
        for sig in sigs:
            result = obj.overloads[sig]
            bad = sorted(f'{var}: {t}' for var, t in
                         result.type_annotation.typemap.items()
                         if _has_float64(t))
            if _has_float64(result.signature.return_type):
                bad.append(f'return: {result.signature.return_type}')
            if bad:
                found[name] = bad
    return found, missing


def _run_every_kernel(mod, model, dtype):
    n, nb = model.n, model.nb
    fd_ok = mod.MIMIC if nb != n else -1     # ABA refuses mimic joints
    f = dtype
    links = model.links_array.astype(f)
    frames = model.frames_array.astype(f)
    q = np.linspace(-1.0, 1.0, n).astype(f)
    ws = np.zeros((nb, mod.W_WIDTH), f)
    scratch = np.zeros((3, n), f)
    w = np.arange(6).astype(f)
    fext = np.ones((nb, 6), f)
    tau = np.zeros(n, f)
    M = np.zeros((n, n), f)
    for mode in (mod.WRENCH_NONE, mod.WRENCH_BASE, mod.WRENCH_EE):
        mod.joint_trig(links, frames, q, ws)
        mod.recursion(links, frames, q, q, q, w, fext, True, True, mode,
                      True, ws, tau)
    Q = np.tile(q, (3, 1))
    TAU = np.zeros((3, n), f)
    W = np.zeros((3, 6), f)
    status = np.zeros(1, np.int64)
    P = mod.pack(links, frames)
    aw = np.zeros((nb + 1, mod.A_WIDTH), f)
    cw = np.zeros((nb + 1, mod.CW_WIDTH), f)
    Ts = np.zeros((nb + 2, 12), f)
    J = np.zeros((6, n), f)
    target = frames[mod.F_TOOL].copy()
    for mode in (mod.WRENCH_NONE, mod.WRENCH_BASE, mod.WRENCH_EE):
        flags = mod.flags(True, True, mode)
        assert mod.run_inverse_dynamics(P, q, q, q, w, flags, ws, tau) == -1
        assert mod.run_forward_dynamics(P, q, q, q, w, flags, ws, aw,
                                        tau) == fd_ok
        flags = mod.flags(True, True, mode, True)
        assert mod.run_inverse_dynamics_links(P, q, q, q, w, fext, flags, ws,
                                              tau) == -1
        assert mod.run_forward_dynamics_links(P, q, q, q, w, fext, flags, ws,
                                              aw, tau) == fd_ok
    assert mod.run_gravity_torques(P, q, ws, tau) == -1
    assert mod.run_mass_matrix_crba(P, q, ws, M) == -1
    for method in (True, False):
        assert mod.run_mass_matrix(P, q, method, ws, scratch, M) == -1
        assert mod.run_coriolis_matrix(P, q, q, method, ws, cw, scratch,
                                       M) == -1
    assert mod.run_jacobian(P, q, nb - 1, target, True, ws, Ts, J) == -1
    assert mod.run_link_poses(P, q, ws, Ts) == -1
    terms = np.zeros((3, n), f)
    assert mod.run_momentum_terms(P, q, q, ws, cw, terms) == -1
    flags = mod.flags(True, True, mod.WRENCH_NONE)
    assert mod.run_inverse_dynamics_batch(P, Q, Q, Q, W, flags, ws, TAU,
                                          status) == -1
    assert mod.run_forward_dynamics_batch(P, Q, Q, Q, W, flags, ws, aw, TAU,
                                          status) == (0 if nb != n else -1)
    MM = np.zeros((3, n, n), f)
    assert mod.run_mass_matrix_batch(P, Q, ws, MM, status) == -1
    assert mod.run_gravity_torques_batch(P, Q, ws, TAU, status) == -1
    assert mod.run_coriolis_matrix_batch(P, Q, Q, ws, cw, MM, status) == -1
    # the derivatives (kernels/derivatives.py), every wrench mode
    dw = np.zeros((nb + 1, mod.DW_WIDTH), f)
    wext = np.ones((nb, 15), f)
    chol = np.zeros((n, n), f)
    zn = np.zeros(n, f)
    D2 = np.zeros((2, n, n), f)
    D3 = np.zeros((3, n, n), f)
    for mode in (mod.WRENCH_NONE, mod.WRENCH_BASE, mod.WRENCH_EE):
        flags = mod.flags(True, True, mode)
        assert mod.run_inverse_dynamics_derivatives(
            P, q, q, q, w, zn, flags, ws, cw, dw, D2) == -1
        assert mod.run_forward_dynamics_derivatives(
            P, q, q, q, w, zn, zn, flags, ws, cw, dw, chol, scratch, D3) == -1
        flags = mod.flags(True, True, mode, True)
        assert mod.run_inverse_dynamics_derivatives_links(
            P, q, q, q, w, fext, wext, zn, flags, ws, cw, dw, D2) == -1
        assert mod.run_forward_dynamics_derivatives_links(
            P, q, q, q, w, fext, fext, wext, zn, zn, flags, ws, cw, dw, chol,
            scratch, D3) == -1
    flags = mod.flags(True, True, mod.WRENCH_NONE)
    assert mod.run_inverse_dynamics_derivatives_batch(
        P, Q, Q, Q, W, zn, flags, ws, cw, dw, np.zeros((3, 2, n, n), f),
        status) == -1
    assert mod.run_forward_dynamics_derivatives_batch(
        P, Q, Q, Q, W, zn, zn, flags, ws, cw, dw, chol, scratch,
        np.zeros((3, 3, n, n), f), status) == -1
    YY = np.zeros((3, n, 10 * nb + 4 * n), f)
    assert mod.run_regressor_batch(P, Q, Q, Q, True, f(0.02), ws,
                                   np.zeros((nb, 6), f),
                                   np.zeros((10 * nb, 6), f), YY,
                                   status) == -1
    assert mod.mass_matrix_columns(links, frames, q, ws, scratch, M) == -1
    D = M.copy()
    assert mod.mass_matrix_crba(links, frames, q, ws, M) == -1
    assert mod.coriolis_matrix_columns(links, frames, q, q, ws, scratch,
                                       M) == -1
    Ts = np.zeros((nb + 2, 12), f)
    mod.forward_kinematics(links, frames, q, ws, Ts)
    J = np.zeros((6, n), f)
    mod.jacobian(links, frames, q, nb - 1, target, True, ws, Ts, J)
    x = np.zeros(n, f)
    assert mod.cholesky_solve(D + 10 * np.eye(n, dtype=f), q,
                              np.zeros((n, n), f), x) == -1
    mod.round_into(q, x)
    assert mod.check_finite(q, q, q, w) == -1     # Float32Dynamics calls it


def _tree_with_mimic():
    """Return a small tree: branches on the base and on body 1, a mimic."""
    nb = 5
    rng = np.random.default_rng(7)
    return make_chain(
        'tree', [f'j{k}' for k in range(nb)],
        ['revolute', 'prismatic', 'revolute', 'revolute', 'prismatic'],
        [[('xyz', *rng.uniform(-0.3, 0.3, 3)),
          ('rpy', *rng.uniform(-1, 1, 3))] for _ in range(nb)],
        rng.normal(size=(nb, 3)), rng.uniform(0.5, 2.0, nb),
        rng.uniform(-0.1, 0.1, (nb, 3)),
        [np.diag(rng.uniform(0.01, 0.02, 3)) for _ in range(nb)],
        parents=[-1, 0, 1, 1, -1], mimic=[None, None, None, (0, -0.7, 0.2),
                                          None])


def _verdict_file():
    """
    Return the file recording a pass of the type-map check, by digest.

    Of the kernels' sources (numba's cache key for them), this test file,
    numba's version and Python's.
    """
    digest = hashlib.sha256()
    digest.update(K._jit.package_stamp().encode())
    with open(__file__, 'rb') as fh:
        digest.update(fh.read())
    digest.update(f'{numba.__version__}\0{sys.version}'.encode())
    base = os.environ.get('NUMBA_CACHE_DIR') or os.path.join(
        os.environ.get('XDG_CACHE_HOME') or os.path.expanduser('~/.cache'),
        'newton_euler_ros', 'numba')
    return os.path.join(base.rstrip(os.sep) + '-verdicts',
                        f'float32-type-maps-{digest.hexdigest()[:32]}')


def test_float32_kernels_have_no_float64_anywhere():
    verdict = _verdict_file()
    if os.path.exists(verdict) and os.environ.get(
            'NEWTON_EULER_RECHECK') != '1':
        print(f'passed before on these sources: {verdict}')
        return
    fresh_kernels = _fresh_kernels()
    # a chain with both joint types in both conventions covers every branch
    for convention in ('standard', 'modified'):
        _run_every_kernel(fresh_kernels, _chain(4, 1, convention),
                          np.float32)
    # and a tree with branch points and a mimic joint, every code path
    _run_every_kernel(fresh_kernels, _tree_with_mimic(), np.float32)
    found, missing = _float64_variables(fresh_kernels)
    assert not missing, f'kernels never compiled for float32: {missing}'
    assert not found, found
    os.makedirs(os.path.dirname(verdict), exist_ok=True)
    with open(verdict, 'w', encoding='utf-8') as fh:
        fh.write('no float64 in the float32 type maps of every kernel\n')


def test_type_map_check_sees_float64():
    """The check flags a float literal mixed into float32 arithmetic."""
    @numba.njit
    def leaky(x):
        return 0.5 * x[0]

    leaky(np.ones(2, np.float32))
    (sig,) = leaky.overloads
    typemap = leaky.overloads[sig].type_annotation.typemap
    assert any(_has_float64(t) for t in typemap.values())


# ---------------------------------------------------------------------------
# float32: the results
# ---------------------------------------------------------------------------

@pytest.fixture(scope='module', params=['puma560', 'panda'])
def arm32(request):
    model = _robot(request.param)
    return model, Float32Dynamics(model), HighPrecisionModel(model, dps=50)


def test_float32_errors_are_float32_sized(arm32):
    model, f32, hp = arm32
    n = model.n
    low, high = 1e3 * EPS64, 100 * n * EPS32
    rng = np.random.default_rng(5)
    errors = {}
    for _ in range(3):
        q, qd, qdd = rng.uniform(-2.0, 2.0, (3, n))
        F = rng.normal(size=6) * 10.0
        results = {
            'tau': (f32.inverse_dynamics(q, qd, qdd),
                    hp.inverse_dynamics(q, qd, qdd)),
            'tau_wrench': (f32.inverse_dynamics(q, qd, qdd, F, 'end_effector'),
                           hp.inverse_dynamics(q, qd, qdd, F, 'end_effector')),
            'D_ne': (f32.mass_matrix(q, method='newton_euler'), hp.mass_matrix(q)),
            'D_crba': (f32.mass_matrix(q, method='crba'), hp.mass_matrix(q)),
            'C': (f32.coriolis_matrix(q, qd, method='newton_euler'),
                  hp.coriolis_matrix(q, qd)),
            'C_composite': (f32.coriolis_matrix(q, qd),
                            hp.coriolis_matrix(q, qd)),
            'g': (f32.gravity_torques(q),
                  hp.inverse_dynamics(q, velocity_products=False)),
        }
        for key, (approx, exact) in results.items():
            assert approx.dtype == np.float32, key
            err = relative_error(approx, exact)
            errors[key] = max(errors.get(key, 0.0), err)
            assert low < err < high, (key, err, low, high)
        # forward dynamics amplifies by up to cond(D): bound it so
        tau = hp.inverse_dynamics(q, qd, qdd)
        cond = mass_matrix_condition(model, q)
        err = relative_error(f32.forward_dynamics(q, qd, np.array(
            tau, dtype=float)), hp.forward_dynamics(q, qd, np.array(
                tau, dtype=float), method='cholesky'))
        assert low < err < high * cond, ('qdd', err, cond)
    # the same inputs as float32 arrays give the same results
    q32 = q.astype(np.float32)
    assert np.array_equal(f32.gravity_torques(q32), f32.gravity_torques(q))


def test_float32_out_and_symmetry(arm32):
    model, f32, _ = arm32
    q = np.linspace(-1.0, 1.0, model.n)
    out = np.empty((model.n, model.n), np.float32)
    assert f32.mass_matrix(q, method='crba', out=out) is out
    assert np.all(out == out.T)
    with pytest.raises(TypeError, match='float32'):
        f32.mass_matrix(q, out=np.empty((model.n, model.n)))


def test_float32_refuses_bad_input():
    model = _robot('puma560')
    f32 = Float32Dynamics(model)
    good = np.zeros(6)
    nan = np.array([0.0, 0.0, math.nan, 0.0, 0.0, 0.0])
    cases = [
        (lambda: f32.inverse_dynamics(nan), r'q\[2\] is nan'),
        (lambda: f32.inverse_dynamics(good, nan.astype(np.float32)),
         r'qd\[2\] is nan'),
        (lambda: f32.inverse_dynamics(good, None, [0, 0, 0, 0, 0, math.inf]),
         r'qdd\[5\] is inf'),
        (lambda: f32.inverse_dynamics(good, wrench=nan), r'wrench\[2\] is nan'),
        (lambda: f32.inverse_dynamics(good, wrench=good[:5]),
         'wrench must have 6 entries, got 5'),
        (lambda: f32.inverse_dynamics(good, wrench=good, wrench_frame='tool'),
         'wrench_frame must be'),
        (lambda: f32.inverse_dynamics(good[:5]), 'q must have 6 entries, got 5'),
        (lambda: f32.inverse_dynamics(np.zeros(5, np.float32)),
         'q must have 6 entries, got 5'),
        (lambda: f32.inverse_dynamics(np.zeros((2, 6))), 'q must be a vector'),
        (lambda: f32.inverse_dynamics('abc'), 'q must be a sequence'),
        (lambda: f32.mass_matrix(nan), r'q\[2\] is nan'),
        (lambda: f32.mass_matrix(good[:3], method='crba'),
         'q must have 6 entries, got 3'),
        (lambda: f32.coriolis_matrix(good, nan), r'qd\[2\] is nan'),
        (lambda: f32.gravity_torques([math.nan] * 6), r'q\[0\] is nan'),
        # finite, but beyond float32: refused, and said so
        (lambda: f32.inverse_dynamics(good, [0, 0, 1e39, 0, 0, 0]),
         r'qd\[2\] is 1e\+39, outside the float32 range'),
        # finite float32 input whose result overflows float32
        (lambda: f32.inverse_dynamics(good, np.full(6, 1e30)),
         'overflows float32'),
    ]
    for call, message in cases:
        with warnings.catch_warnings():
            warnings.simplefilter('error')      # and no numpy cast warning
            with pytest.raises(DynamicsInputError, match=message):
                call()


def test_float32_model_out_of_range():
    model = _chain(2, 0, 'standard')
    huge = model.replace(mass=[1e39, 1.0])
    with pytest.raises(ValueError, match='float32 range'):
        Float32Dynamics(huge)


def test_float32_docstring_example():
    assert doctest.testmod(float32_module).failed == 0
    assert 'Float32Dynamics(planar_2r, n=2)' == repr(
        Float32Dynamics(_robot('planar_2r')))
