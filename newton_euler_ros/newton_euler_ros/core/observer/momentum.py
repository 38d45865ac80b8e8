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
Generalized-momentum observer: external joint torque, wrench and contact.

With the generalized momentum ``p = D(q) qd`` and ``Ddot = C + C^T``, the
equation of motion ``D qdd + C qd + g = tau + tau_ext`` gives
``pdot = tau + tau_ext + C^T qd - g``.  The residual

    r(t) = K [p(t) - p(0) - integral_0^t (tau + C^T qd - g + r) ds]

obeys ``rdot = K (tau_ext - r)``: a first-order low-pass of the external
joint torque with gain ``K`` (1/s), needing no acceleration and no
differentiation (De Luca and Mattone, ICRA 2005; Haddadin, De Luca and
Albu-Schaeffer, T-RO 2017).  ``tau`` is what the drives apply: the
JointState effort, times the drives' torque constants when the effort is
a motor current (``torque_constant``, N m per effort unit), so that
everything here is in N m (or N).  What the model knows is not external
is taken out first: the drive friction (``drive_torque``) and the rotor
inertia (``armature``, added to the momentum); the payload is part of the
model.

Static friction at rest.  At rest, static friction holds any torque up to
its static level F_s, depending on how the joint came to rest: no model
knows it, and the drive friction ``F_c tanh(qd / eps)`` is 0 there.  So
joint j is in contact when ``|r_j|`` exceeds its threshold plus an
*allowance*: the bound ``B_j = F_s,j (1 - |tanh(qd_j / eps_j)|)`` on
that unmodelled friction, passed through the residual's own lag
(``A_k = a A_(k-1) + (1 - a) max(B_(k-1), B_k)``), so that it bounds
its share of r through stops and starts too; falling, no faster than
over ``ALLOWANCE_HOLD`` (friction settles over some travel after a
start, not at once).  The cost: at rest a joint feels only what exceeds
its static friction band.  :func:`drive_options`
takes F_s as a multiple (1.5 by default) of the Coulomb friction.

Discretization.  Between two samples the running sum
``S = p(0) + integral (tau + C^T qd - g + r) ds`` advances with the
trapezoid rule for the known torques and the exact integral of ``r``
for a constant external torque over the interval, so that
``r = K (p - S)`` holds at every sample and the residual is the exact
first-order lag of the interval's mean external torque, whatever the
step: ``r_k = a r_(k-1) + (1 - a) u_k`` with ``a = exp(-K dt)``.  Only
``S``, ``r`` and the previous known torque are carried: no history.

Stamps.  Time is the samples' stamps (seconds), not their count.  A
sample with the same stamp as the previous one is ignored; a gap longer
than ``max_gap`` or a stamp going backwards restarts the sum at the new
sample, keeping the residual (a contact held through a lost burst of
messages stays reported; a stale residual decays at the rate ``K``).

Functions, one per step: :func:`initial_state`, :func:`observer_step`,
:func:`external_wrench`, :func:`contact_step`, and
:func:`observe_recording` over a whole recording, then
:func:`suggest_thresholds` from a free-motion recording;
:func:`drive_options` takes the drive friction, rotor inertia, torque
constants and static friction from a model that has them.

Signs and frames.  The residual is the joint torque the environment
applies, ``tau_ext = J^T F_ext``; :func:`external_wrench` (in
:mod:`.wrench`) returns ``F_ext``, the wrench the environment
applies to the end effector, in base axes.
"""
from dataclasses import dataclass, field
import math

from numba import njit
import numpy as np

from .contact import contact_step, initial_contact
from .wrench import external_wrench
from ..calling import (ARRAY, F64, F8, MAT, PACKED, slow_inputs,
                       status_error, strict_entry, VEC, vector, workspace)
from ..drives import DEFAULT_COULOMB_WIDTH
from ..errors import DynamicsInputError
from ..kernels import NONFINITE, run_momentum_terms, SIZE
from ..kernels._jit import ENTRY, uses_kernels
from ..workspace import Workspace

# this file's compiled functions call kernels: a kernel edit must
# recompile them (numba's cache stamps a function with its own file only)
uses_kernels(__file__)

#: s: the static friction allowance decays no faster than this (a
#: joint's friction settles to the moving friction over some travel)
ALLOWANCE_HOLD = 0.1
#: what :func:`observer_step` did with a sample
UPDATED, STARTED, RESTARTED, DUPLICATE = 'updated', 'started', \
    'restarted', 'duplicate'


# ---------------------------------------------------------------------------
# compiled arithmetic (no allocation, finiteness checked here)

# rows of MomentumObserver._buf, the step's buffer (n columns)
_DQD, _CTQD, _G = 0, 1, 2       # D qd, C^T qd, g (run_momentum_terms)
_P, _BETA = 3, 4                # momentum and known torque of the sample
_ARMATURE, _GAIN = 5, 6         # the configuration: rotor inertia, K,
_KT, _STATIC, _WIDTH = 7, 8, 9  # torque constant, F_s and eps
_ROWS = 10
# the status of a non-finite momentum or known torque at joint i
_BAD_TORQUE = 2 * NONFINITE


@njit(**ENTRY)
def _step(P, q, qd, tau, lost, dt, ws, cw, buf, S, r, beta_prev, fric):
    """
    One sample in one call: D qd, C^T qd, g (one recursion), then S, r.

    p = D qd + armature qd and beta = K_t tau - lost + C^T qd - g; if one
    is not finite the state is left untouched and ``_BAD_TORQUE`` + the
    joint returned (a kernel status code for bad q or qd).  Else S and r
    advance over ``dt`` (``dt <= 0``: S restarts here, keeping r), and
    so does the static friction allowance ``fric[0]`` (``fric[1]``: the
    bound at this sample), and -1 is returned (-2 if r came out
    non-finite and was reset to 0).
    """
    code = run_momentum_terms(P, q, qd, ws, cw, buf[:3])
    if code >= 0:
        return code
    n = q.shape[0]
    if (tau.shape[0] != n or lost.shape[0] != n or buf.shape[0] != _ROWS
            or buf.shape[1] != n or S.shape[0] != n or r.shape[0] != n
            or beta_prev.shape[0] != n or fric.shape[0] != 2
            or fric.shape[1] != n):
        return SIZE + 2
    for i in range(n):
        p = buf[_DQD, i] + buf[_ARMATURE, i] * qd[i]
        beta = buf[_KT, i] * tau[i] - lost[i] + buf[_CTQD, i] - buf[_G, i]
        if not (math.isfinite(p) and math.isfinite(beta)):
            return _BAD_TORQUE + i
        buf[_P, i] = p
        buf[_BETA, i] = beta
    restart = not dt > 0.0
    ok = True
    for i in range(n):
        # what static friction may hold at this speed (0 when moving)
        bound = buf[_STATIC, i] * (
            1.0 - abs(math.tanh(qd[i] / buf[_WIDTH, i])))
        if restart:
            fric[0, i] = max(fric[0, i], bound)
        else:
            k = buf[_GAIN, i]
            a = math.exp(-k * dt)
            b = 1.0 - a
            known = 0.5 * dt * (buf[_BETA, i] + beta_prev[i])
            # mean external torque over the interval: the momentum
            # change that the known torques do not explain
            u = (buf[_P, i] - (S[i] + r[i] / k) - known) / dt
            S[i] += known + r[i] * b / k + u * (dt - b / k)
            r[i] = a * r[i] + b * u
            ok &= math.isfinite(r[i]) and math.isfinite(S[i])
            # the same lag on the interval's larger bound; falling, no
            # faster than ALLOWANCE_HOLD (friction lags a start)
            target = max(bound, fric[1, i])
            if target < fric[0, i] and k * ALLOWANCE_HOLD > 1.0:
                a = math.exp(-dt / ALLOWANCE_HOLD)
            fric[0, i] = a * fric[0, i] + (1.0 - a) * target
        fric[1, i] = bound
    for i in range(n):
        if not ok or not math.isfinite(r[i]):
            r[i] = 0.0          # cannot happen for finite input; never
        if restart or not ok:   # hand out NaN
            S[i] = buf[_P, i] - r[i] / buf[_GAIN, i]
        beta_prev[i] = buf[_BETA, i]
    return -1 if ok else -2


_step_strict = strict_entry(_step, PACKED, VEC, VEC, VEC, VEC, F8, MAT, MAT,
                            MAT, VEC, VEC, VEC, MAT, home=globals())


# ---------------------------------------------------------------------------
# configuration and state

def _per_joint(name, value, n, positive=True):
    x = np.array(value, dtype=np.float64).reshape(-1)
    if x.size == 1:
        x = np.full(n, x[0])
    if x.size != n:
        raise ValueError(f'{name}: must have 1 or {n} values (one per '
                         f'joint), got {x.size}')
    low = (x <= 0.0) if positive else (x < 0.0)
    if not np.isfinite(x).all() or low.any():
        raise ValueError(f'{name}: must be finite and '
                         f'{"> 0" if positive else ">= 0"}, got '
                         f'{x.tolist()}')
    return np.ascontiguousarray(x)


class MomentumObserver:
    """
    The observer's configuration and reusable buffers for one model.

    Parameters
    ----------
    model : the robot model, payload included (``payload_model``).
    gain : K in 1/s, one value or one per joint (20 to 100 is typical):
        the residual follows the external torque with time constant 1/K.
    max_gap : seconds; a longer interval between samples restarts the
        sum (as does a stamp going backwards).
    drive_torque : optional callable ``(qd, qdd_or_None) -> tau_lost``,
        the torque the drives lose to friction (model order); called with
        ``qdd=None`` (the observer has no acceleration).
    armature : optional per-joint reflected rotor inertia, added to the
        diagonal of D in the momentum.
    torque_constant : optional per-joint N m (or N) per effort unit: the
        efforts are multiplied by it (a current-sensing arm's amperes
        become joint torques); None: the efforts are torques.
    static_friction : optional per-joint torque (N m or N) static
        friction may hold at rest; the contact test allows for it near
        zero speed (module docstring).  None or 0: no allowance.
    friction_width : per-joint speed (rad/s or m/s) over which that
        allowance fades, the Coulomb friction's tanh width (0.02).
    damping : lambda of the damped least-squares wrench (same units as
        J: metres and 1); larger trades accuracy near singularities for
        a bounded estimate.
    thresholds : per-joint contact thresholds on |r| (N m or N), one
        value or one per joint (model order), on top of the static
        friction allowance.
    speed_thresholds, acceleration_thresholds : per joint (>= 0), the
        threshold's growth per rad/s of the joint's speed and per rad/s^2
        of its acceleration (``motion.py``); 0: constant.
    hysteresis : a joint in contact is released when |r| falls below
        this fraction of its threshold, plus the allowance
        (0 < hysteresis <= 1).
    rest_reference : also test, once the whole arm rests, each residual's
        change from the value it settled to (``contact.py``): a
        push on a resting arm is felt within the friction band.
    rest_thresholds : per joint (>= 0), the rest reference's own
        tolerance: its calm test and its test of the change use the
        larger of it and the threshold; 0: the threshold alone.  With
        thresholds that grow with speed, whose ``a`` can be near 0
        where the static friction allowance covers a resting joint
        (``thresholds.suggest_rest_thresholds``).
    ws : a :class:`Workspace` of the model (a new one by default); not
        shared with another thread.

    """

    def __init__(self, model, gain=50.0, *, max_gap=0.1, drive_torque=None,
                 armature=None, damping=0.01, thresholds=10.0,
                 hysteresis=0.5, torque_constant=None, static_friction=None,
                 friction_width=DEFAULT_COULOMB_WIDTH, rest_reference=True,
                 speed_thresholds=0.0, acceleration_thresholds=0.0,
                 rest_thresholds=0.0, ws=None):
        n = model.n
        self.model = model
        self.n = n
        self.ws = Workspace(model) if ws is None else workspace(model, ws)
        # the compiled step's buffer: the model terms, p and beta of the
        # last sample, then the configuration (rows _DQD ... _WIDTH)
        self._buf = np.zeros((_ROWS, n))
        # gain and armature: views of rows of it (change them in place)
        self.gain = self._buf[_GAIN]
        self.gain[:] = _per_joint('gain', gain, n)
        self.max_gap = float(max_gap)
        if not (math.isfinite(self.max_gap) and self.max_gap > 0.0):
            raise ValueError(f'max_gap: must be finite and > 0, got '
                             f'{max_gap!r}')
        if drive_torque is not None and not callable(drive_torque):
            raise ValueError('drive_torque: must be callable '
                             '(qd, qdd_or_None) -> torque')
        self.drive_torque = drive_torque
        self.armature = self._buf[_ARMATURE]
        if armature is not None:
            self.armature[:] = _per_joint('armature', armature, n, False)
        self.torque_constant = None if torque_constant is None else \
            _per_joint('torque_constant', torque_constant, n)
        self._buf[_KT] = 1.0 if torque_constant is None else \
            self.torque_constant
        self.static_friction = self._buf[_STATIC]
        if static_friction is not None:
            self.static_friction[:] = _per_joint('static_friction',
                                                 static_friction, n, False)
        self.friction_width = self._buf[_WIDTH]
        self.friction_width[:] = _per_joint('friction_width',
                                            friction_width, n)
        self.damping = float(damping)
        if not (math.isfinite(self.damping) and self.damping >= 0.0):
            raise ValueError(f'damping: must be finite and >= 0, got '
                             f'{damping!r}')
        self.thresholds = _per_joint('thresholds', thresholds, n)
        self.speed_thresholds = _per_joint('speed_thresholds',
                                           speed_thresholds, n, False)
        self.acceleration_thresholds = _per_joint(
            'acceleration_thresholds', acceleration_thresholds, n, False)
        self.rest_thresholds = _per_joint('rest_thresholds', rest_thresholds,
                                          n, False)
        self.hysteresis = float(hysteresis)
        if not (0.0 < self.hysteresis <= 1.0):
            raise ValueError(f'hysteresis: must be in (0, 1], got '
                             f'{hysteresis!r}')
        self.rest_reference = bool(rest_reference)
        self.J = np.zeros((6, n))
        self.p = self._buf[_P]          # momentum of the last sample
        self.beta = self._buf[_BETA]    # its known torque
        self.lost = np.zeros(n)
        self._no_allowance = np.zeros(n)
        self._A = np.zeros((min(n, 6), min(n, 6)))
        self._y = np.zeros(min(n, 6))
        self._packed = model.packed

    @property
    def moving_thresholds(self):
        """Whether a threshold grows with speed or acceleration."""
        return bool(self.speed_thresholds.any()
                    or self.acceleration_thresholds.any())

    def warm_up(self):
        """Compile (or load) every kernel once, before the first sample."""
        z = np.zeros(self.n)
        state = initial_state(self)
        observer_step(self, state, 0.0, z, z, z)
        observer_step(self, state, 1e-3, z, z, z)
        external_wrench(self, z, state.r)
        contact_step(self, initial_contact(self), state.r, state.allowance,
                     0.0, z, z)


def drive_terms(model):
    """
    Return ``(drive_torque, armature)`` from the drives a model carries.

    A model read from a URDF with identified drives (friction, offset,
    rotor inertia) carries them as ``model.info['drives']``, an object
    with ``torques(qd, qdd)`` and ``armature``; the friction and offset
    are what the drives lose (``drive_torque``, called with qdd None) and
    the rotor inertia goes into the momentum.  ``(None, None)`` when the
    model has none, or only zeros (every URDF model carries a record).
    """
    info = getattr(model, 'info', None) or {}
    drives = info.get('drives') if isinstance(info, dict) else None
    if drives is None or not callable(getattr(drives, 'torques', None)):
        return None, None
    is_zero = getattr(drives, 'is_zero', None)
    if callable(is_zero) and is_zero():     # a URDF without drive terms
        return None, None
    zero = np.zeros(model.n)

    def drive_torque(qd, _qdd=None):
        return drives.torques(qd, zero)

    armature = getattr(drives, 'armature', None)
    return drive_torque, armature


def drive_options(model, static_friction=1.5):
    """
    Return :class:`MomentumObserver` keyword arguments from a model's drives.

    ``drive_torque`` and ``armature`` (:func:`drive_terms`), the
    ``torque_constant`` (None unless the URDF gives it: the efforts are
    then torques), and the static friction allowance: ``static_friction``
    times each joint's Coulomb friction (URDF ``<dynamics friction>``, as
    identify writes it), fading over its tanh width.  The default 1.5:
    static friction is commonly 20-50 % above the Coulomb level, which an
    identification gives within some 10 %.  0 leaves the allowance out.
    """
    ratio = float(static_friction)
    if not (math.isfinite(ratio) and ratio >= 0.0):
        raise ValueError(f'static_friction: must be finite and >= 0, got '
                         f'{static_friction!r}')
    drive, armature = drive_terms(model)
    out = {'drive_torque': drive, 'armature': armature}
    info = getattr(model, 'info', None) or {}
    drives = info.get('drives') if isinstance(info, dict) else None
    constant = getattr(drives, 'torque_constant', None)
    if constant is not None:
        out['torque_constant'] = constant
    coulomb = getattr(drives, 'coulomb', None)
    if drive is not None and coulomb is not None and ratio > 0.0:
        out['static_friction'] = ratio * np.asarray(coulomb, dtype=float)
        width = getattr(drives, 'coulomb_width', None)
        if width is not None:
            out['friction_width'] = width
    return out


@dataclass
class ObserverState:
    """What the observer carries between samples: no history."""

    S: np.ndarray           # running sum p(0) + integral, model order
    r: np.ndarray           # residual (external joint torque estimate)
    beta_prev: np.ndarray   # known torque at the previous sample
    # (2, n): the static friction allowance, and its bound at the
    # previous sample
    friction: np.ndarray = None
    t_prev: float = None    # stamp of the previous sample (None: none)
    samples: int = 0        # samples used
    restarts: int = 0       # gaps and stamps going backwards
    duplicates: int = 0     # samples with the previous sample's stamp

    @property
    def allowance(self):
        """Per joint, what static friction may add to |r| now (a view)."""
        return self.friction[0]


def initial_state(obs):
    """Return a state before any sample: the first one starts the sum."""
    n = obs.n
    return ObserverState(np.zeros(n), np.zeros(n), np.zeros(n),
                         np.zeros((2, n)))


def observer_step(obs, state, t, q, qd, tau):
    """
    Use one sample at stamp ``t`` (seconds); return the residual.

    ``q``, ``qd``, ``tau`` (efforts: joint torques, or efforts the
    observer's ``torque_constant`` turns into torques) are float64 arrays
    in model order.  Returns ``(r, what)`` with ``r`` the state's residual (a view, updated
    in place; copy to keep it) and ``what`` one of ``UPDATED``,
    ``STARTED`` (first sample), ``RESTARTED`` (gap or stamp backwards),
    ``DUPLICATE`` (same stamp: ignored).  Non-finite or wrongly sized
    input raises :class:`DynamicsInputError` and leaves the state as it
    was.  One compiled call (``_step``): D qd, C^T qd and g from one
    recursion, then the update.
    """
    t = float(t)
    if not math.isfinite(t):
        raise DynamicsInputError(f'stamp must be finite, got {t!r}')
    t_prev = state.t_prev
    if t_prev is None:
        dt, what = 0.0, STARTED
    else:
        dt = t - t_prev
        if dt == 0.0:
            state.duplicates += 1
            return state.r, DUPLICATE
        if dt < 0.0 or dt > obs.max_gap:
            dt, what = 0.0, RESTARTED       # restart: the sum starts here
        else:
            what = UPDATED
    if obs.drive_torque is None:
        lost = obs.lost
    else:
        qd = _vector('qd', qd, obs.n)
        lost = _vector('drive_torque', obs.drive_torque(qd, None), obs.n)
    code = None
    if (type(q) is ARRAY and q.dtype is F64 and type(qd) is ARRAY
            and type(tau) is ARRAY):   # lists: converted below
        try:
            code = _step_strict(obs._packed, q, qd, tau, lost, dt,
                                obs.ws.ws, obs.ws.cw, obs._buf, state.S,
                                state.r, state.beta_prev, state.friction)
        except TypeError:           # read-only, strided: convert, again
            slow_inputs((q, qd, tau), ('q', 'qd', 'tau'))
    if code is None or code >= 0:
        _step_converted(obs, state, q, qd, tau, lost, dt)
    if what is RESTARTED:
        state.restarts += 1
    state.t_prev = t
    state.samples += 1
    return state.r, what


def _step_converted(obs, state, q, qd, tau, lost, dt):
    """Make the step again with its inputs converted; raise what failed."""
    n = obs.n
    q, qd, tau = (vector(k, x, n) for k, x in
                  (('q', q), ('qd', qd), ('tau', tau)))
    try:
        code = _step_strict(obs._packed, q, qd, tau,
                            vector('lost', lost, n), dt, obs.ws.ws,
                            obs.ws.cw, obs._buf, state.S, state.r,
                            state.beta_prev, state.friction)
    except TypeError:
        raise DynamicsInputError('state: not made by initial_state') from None
    if code < 0:
        return
    if _BAD_TORQUE <= code < _BAD_TORQUE + n:
        i = code - _BAD_TORQUE
        raise DynamicsInputError(
            f'non-finite momentum or torque at joint '
            f'{obs.model.joint_names[i]!r} (effort {float(tau[i])!r})')
    raise status_error(code, (q, qd))


def _vector(name, x, n):
    if isinstance(x, np.ndarray) and x.dtype == np.float64 and \
            x.shape == (n,) and x.flags.c_contiguous:
        return x
    try:
        x = np.ascontiguousarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise DynamicsInputError(f'{name}: must be {n} numbers') from None
    if x.shape != (n,):
        raise DynamicsInputError(f'{name}: must have {n} values, got '
                                 f'shape {x.shape}')
    return x


@dataclass
class ObserverRecording:
    """The observer over a recording, one row per sample."""

    t: np.ndarray                   # (m,) stamps, seconds
    residual: np.ndarray            # (m, n) external joint torque
    wrench: np.ndarray              # (m, 6) F_ext, base axes
    contact: np.ndarray             # (m,) bool
    status: list = field(default_factory=list)   # what each sample did
    contacts: int = 0               # contacts begun
    restarts: int = 0
    skipped: int = 0                # rows with non-finite input
    allowance: np.ndarray = None    # (m, n) static friction allowance
    q: np.ndarray = None            # (m, n) the input, for the thresholds
    qd: np.ndarray = None           # (m, n) (``suggest_thresholds``)
    rest_reference: bool = False    # whether its contact test was on
    max_gap: float = 0.1
    speed: np.ndarray = None        # (m, n) lagged |qd|, |qdd|
    acceleration: np.ndarray = None  # (``motion.py``)


def observe_recording(obs, T, Q, QD, TAU):
    """
    Run the observer over a recording: stamps T (m,), Q, QD, TAU (m, n).

    Rows are used in the given order, exactly as live samples would be
    (gaps and stamps going backwards restart the sum).  A row with a
    non-finite value is skipped as a lost message: its output holds the
    previous values.  Returns an :class:`ObserverRecording`.
    """
    T = np.asarray(T, dtype=np.float64).reshape(-1)
    m, n = T.shape[0], obs.n
    arrays = []
    for name, X in (('Q', Q), ('QD', QD), ('TAU', TAU)):
        X = np.ascontiguousarray(X, dtype=np.float64)
        if X.shape != (m, n):
            raise ValueError(f'{name}: must have shape ({m}, {n}), got '
                             f'{X.shape}')
        arrays.append(X)
    Q, QD, TAU = arrays
    out = ObserverRecording(T.copy(), np.zeros((m, n)), np.zeros((m, 6)),
                            np.zeros(m, dtype=np.bool_), [],
                            allowance=np.zeros((m, n)), q=Q, qd=QD,
                            rest_reference=obs.rest_reference,
                            max_gap=obs.max_gap, speed=np.zeros((m, n)),
                            acceleration=np.zeros((m, n)))
    state, contact = initial_state(obs), initial_contact(obs)
    F = np.zeros(6)
    for k in range(m):
        try:
            r, what = observer_step(obs, state, T[k], Q[k], QD[k], TAU[k])
            if what != DUPLICATE:
                external_wrench(obs, Q[k], r, out=F)
                contact_step(obs, contact, r, state.allowance, T[k], Q[k],
                             QD[k])
        except DynamicsInputError:
            out.skipped += 1
            what = 'skipped'
        out.residual[k] = state.r
        out.allowance[k] = state.allowance
        out.wrench[k] = F
        out.contact[k] = contact.in_contact
        out.speed[k] = contact.motion.speed
        out.acceleration[k] = contact.motion.acceleration
        out.status.append(what)
    out.contacts = contact.count
    out.restarts = state.restarts
    return out
