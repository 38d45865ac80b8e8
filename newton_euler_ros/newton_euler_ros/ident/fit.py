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
Fit inertial and drive parameters to recordings, physically consistent.

The parameters theta = [pi (10nb, per body), drives (4n, per joint)]
enter the torques linearly, tau = Y theta (``core.regressor`` with
``drives=True``); when the efforts are motor currents, tau_j = K_j e_j
with a torque constant per joint.  On a chain nb = n; on a tree (a URDF
loaded without a tip) the bodies are every moving joint's link, a mimic
follower's too (its torque acts through its leader's row), and the n
coordinates are the independent joints, each with its drive terms: the
follower's friction and rotor inertia act through its leader's drive, so
a coordinate's drive terms are those of its actuator.  Every step below
is the same on both.  The pipeline:

1. Read, prepare and reduce each recording (``reduce``, ``problem``):
   per joint, the R factor of its rows, (p + 1)^2 numbers whatever the
   recording's length; a training part and held-out time blocks from
   each recording; every Coulomb width candidate among the columns.
2. What the efforts are (``effort``): per joint, the least-squares ratio
   of the nominal model's torque to the effort.  Torques must give about
   1, else the command stops and points to ``--effort current``.
3. Weights: each joint's rows by 1 / sigma_j, sigma_j the RMS residual of
   an unconstrained least-squares fit on the training parts (weighted
   least squares, Gautier & Poignet): small wrist torques count as much
   as the shoulder's.
4. Base parameters (``base.base_parameters``): the rank and condition
   number of the weighted regressor; recordings whose rank is far below
   the structural count do not excite the arm and are refused.
5. A semidefinite program (``sdp``: CVXPY, solved by Clarabel, every
   variable scaled to order one): minimise the mean weighted squared
   residual plus lambda ||D (theta - theta_0)||^2 toward the nominal
   model theta_0, with every link's 4x4 pseudo-inertia positive
   semi-definite (Wensing, Kim & Slotine 2018; every body of a tree),
viscous and Coulomb
   friction and armature >= 0.  D scales each parameter by its column's
   RMS in the weighted regressor, so lambda is a fraction of what a
   change costs in the data where the data sees it.  Parameters the
   recordings do not excite stay at the prior.
6. Hyperparameters on the held-out blocks: lambda over ``LAMBDAS`` (the
   largest whose held-out error is within ``LAMBDA_SLACK`` of the best),
   then the Coulomb width over ``WIDTHS`` at that lambda (the default
   kept unless another is better by ``WIDTH_SLACK``), then lambda again
   for that width.  The final fit uses all the data.

**Torque constants** (``effort='current'``).  The rows K_j e_j = Y_j theta
are homogeneous: K and theta scaled together fit equally well, so
something must fix the scale.  By default the nominal model's masses
and gravity: the D^2-weighted projection of theta's inertial part on the
nominal's is held at the nominal's value (the data decides the shape,
the nominal model the overall size, where gravity sees it).  With a
recording of a known mass at the tip (its centre of mass and inertia
unknown, a PSD body of that mass; at another link with
``known_mass_link``, which a tree with several tips needs), the mass
fixes the scale instead: the payload's torque is exactly known up to its
centre of mass and inertia, the arm's parameters are shared with the
other recordings.  Torque
constants given in the nominal URDF are used as given.

Links carrying rigidly attached children (a URDF's fixed joints and locked
off-chain subtrees: a hand, fingers) are constrained as the link's own
body: J(pi_k - pi_fixed_k) >= 0 with pi_fixed_k the nominal parameters
of the attached parts, which stay as published in the written URDF.
"""
from dataclasses import dataclass, field
import time

import numpy as np

from . import effort as effort_units
from .bag import DEFAULT_TOPIC
from .base import base_parameters, structural_base
from .constants import (determined, fit_constants, initial_constants,
                        mass_excitation, scale_pins)
from .problem import (joint_stats, Layout, Recording, recording_rows,
                      stacked)
from .reduce import IdentificationError, reduce_recording
from .sdp import body_scale, INACCURATE, objective_scale, ScaledBody, solve
from ..core.drives import DEFAULT_COULOMB_WIDTH, Drives, model_drives
from ..core.regressor import (inertial_parameters, N_DRIVE, N_INERTIAL,
                              with_parameters)

LAMBDAS = tuple(10.0 ** k for k in range(-8, 1))
LAMBDA_SLACK = 0.02
WIDTHS = (0.005, 0.01, 0.02, 0.05, 0.1)
WIDTH_SLACK = 0.01
#: an inertial parameter's prior weight (D), at least this x the median one
PRIOR_FLOOR = 1.0
#: a body's smallest pseudo-inertia eigenvalue, at least this x its largest
CONE_MARGIN = 1e-8
# a recording whose rank is below this fraction of the structural count
# does not excite the arm
MIN_RANK_FRACTION = 0.5
# a known mass whose torque changes by less than this many residual RMS on
# every joint does not fix the torque constants (constants.mass_excitation)
KNOWN_MASS_EXCITATION = 0.5
PAYLOAD_PRIOR = 1e-6


def accumulate(model, path, topic=DEFAULT_TOPIC, coulomb_width=None,
               cutoff=None, split=True):
    """
    Reduce a recording to the regressor's problem (``reduce``).

    Return (train, held_out or None, info dict): the rows of the torque
    regressor with drive terms (Coulomb width ``coulomb_width``) against
    the effort.
    """
    eps = DEFAULT_COULOMB_WIDTH if coulomb_width is None else coulomb_width
    layout = Layout(model.n, (eps,), nb=model.nb)
    return reduce_recording(path, model.joint_names,
                            recording_rows(model, layout, False),
                            layout.bag_columns(False), topic, cutoff, split)


def nominal_theta(model, coulomb_width=None):
    """Return theta_0: the model's 10nb inertial parameters and 4n drives."""
    d = model_drives(model)
    d = np.zeros(N_DRIVE * model.n) if d is None else d.parameters()
    return np.concatenate([inertial_parameters(model), d])


def fixed_parts(model, urdf_text=None, prior=False):
    """
    (nb, 10): nominal parameters of the parts rigidly attached to each body.

    For a URDF model, each body is its moving link's own ``<inertial>``
    plus the links joined to it by fixed joints (and, on a chain, locked
    off-chain subtrees); this returns the latter (the total minus the
    link's own).  Zeros for other models.
    """
    n = model.nb
    out = np.zeros((n, N_INERTIAL))
    report = (model.info or {}).get('urdf')
    if urdf_text is None or not report:
        return out
    from ..core.regressor import link_parameters
    from ..core.urdf import parse_urdf
    _, _, links, _ = parse_urdf(urdf_text, prior=prior)
    total = inertial_parameters(model).reshape(n, N_INERTIAL)
    for k, lname in enumerate(report['links']):
        lk = links[lname]
        own = link_parameters(lk.mass, lk.com, lk.inertia)
        out[k] = total[k] - own
    return out


@dataclass
class Result:
    """What :func:`identify` found; thetas are [pi (10nb), drives (4n)]."""

    model: object
    theta: np.ndarray
    theta0: np.ndarray
    drives: Drives
    coulomb_width: float
    rank: int
    structural_rank: int
    condition: float
    lam: float
    sigma: np.ndarray
    fit_stats: dict = field(default_factory=dict)
    validate_stats: dict = field(default_factory=dict)
    info: dict = field(default_factory=dict)
    seconds: float = 0.0
    validate_seconds: float = 0.0
    lambda_errors: list = field(default_factory=list)
    width_errors: list = field(default_factory=list)
    recordings: list = field(default_factory=list)   # (path, info)
    torque_constant: np.ndarray = None   # N m per effort unit, or None
    constants: str = 'none'     # 'none', 'given', 'identified'
    ratios: dict = field(default_factory=dict)   # bag: (K, explained)
    payload: dict = None        # the known mass's identified body
    payload_link: str = None    # the link it is fixed to
    mass_excitation: np.ndarray = None   # constants.mass_excitation
    notes: list = field(default_factory=list)
    undetermined_k: list = field(default_factory=list)  # joint indices


class _Program:
    """The SDP, compiled once, solved for any data and lambda."""

    def __init__(self, layout, fixed, theta0, D, scales, mass=None):
        import cvxpy as cp
        n, nb = layout.n, layout.nb
        d = layout.size
        self.layout = layout
        # R is upper triangular (``stacked``): declared so, the program
        # has half the entries, and solves take about 0.6 of the time
        self.R = cp.Parameter((d, d), sparsity=np.triu_indices(d))
        self.z = cp.Parameter(d)
        self.sl = cp.Parameter(nonneg=True)
        self.sl_pay = cp.Parameter(nonneg=True)
        self.bodies = [ScaledBody(cp, *scales['bodies'][k])
                       for k in range(nb)]
        self.dt = cp.Variable(N_DRIVE * n)
        parts = []
        for k, body in enumerate(self.bodies):
            parts += [fixed[k, i] + e for i, e in enumerate(body.params)]
        theta = cp.hstack(parts + [cp.multiply(scales['drives'], self.dt)])
        x = [theta]
        j = np.arange(n) * N_DRIVE
        cons = [self.dt[j] >= 0, self.dt[j + 1] >= 0, self.dt[j + 3] >= 0]
        obj = cp.sum_squares(self.sl * cp.multiply(D, theta - theta0))
        if layout.pay is not None:
            pay = ScaledBody(cp, mass, 0.1)
            x.append(cp.hstack(pay.params))
            cons.append(pay.params[0] == mass)
            # a faint pull of what the motion does not excite to zero,
            # scaled with the data like the prior
            obj += cp.sum_squares(self.sl_pay * cp.multiply(
                scales['payload'], cp.hstack(pay.params[1:])))
        self.x = cp.hstack(x) if len(x) > 1 else theta
        obj += cp.sum_squares(self.R @ self.x - self.z)
        self.problem = cp.Problem(cp.Minimize(obj), cons)
        self.trouble = []

    def solve(self, Aug, lam, label=''):
        """Return x (or None) for the square problem Aug and lambda."""
        from scipy.sparse import coo_array
        d = self.layout.size
        for more in (1.0, 30.0):    # once more, larger, if it stops early
            f = more * objective_scale(Aug)
            upper = self.R.sparse_idx
            self.R.value_sparse = coo_array((f * Aug[:d, :d][upper], upper),
                                            shape=(d, d))
            self.z.value = f * Aug[:d, d]
            self.sl.value = f * float(np.sqrt(lam))
            self.sl_pay.value = f * float(np.sqrt(PAYLOAD_PRIOR))
            result = solve(self.problem, label)
            if result.status != 'inaccurate':
                break
        if result.status == 'inaccurate':
            self.trouble.append(label)
        if not result.ok:
            return None
        return np.asarray(self.x.value, dtype=np.float64)


def _error(Aug, x):
    v = Aug @ np.append(x, -1.0)
    return float(v @ v)


def _weights(recordings, layout, k0):
    """Return sigma_j (N m): the residual of an unconstrained fit at k0."""
    ones = np.ones(layout.n)
    Aug, _ = stacked(recordings, 'train', layout, 0, ones, k0)
    d = layout.size
    x, *_ = np.linalg.lstsq(Aug[:d, :d], Aug[:d, d], rcond=1e-10)
    rms, rel = joint_stats(recordings, 'train', layout, 0, x, k0, k0)
    ref = np.where(rel > 0, rms / np.maximum(rel, 1e-300), 0.0)  # NaN: 0
    return np.maximum(rms, np.maximum(1e-3 * ref, 1e-6))


def _scales(model, theta0, D, layout, mass, Aall):
    """Typical sizes of the unknowns (``sdp``: solve in units of them)."""
    nb = model.nb
    pi0 = theta0[:N_INERTIAL * nb].reshape(nb, N_INERTIAL)
    bodies = [body_scale(pi0[k]) for k in range(nb)]
    Dd = D[N_INERTIAL * nb:layout.p_theta]
    drives = 1.0 / np.maximum(Dd, 1e-12 * max(float(Dd.max()), 1e-300))
    payload = None
    if mass is not None:    # the payload's columns' norms (its prior)
        Dp = np.linalg.norm(Aall[:, layout.pay.start + 1:layout.pay.stop],
                            axis=0)
        payload = np.maximum(Dp, 1e-3 * max(float(np.median(Dp)), 1e-12))
    return {'bodies': bodies, 'drives': drives, 'payload': payload}


def _reduce_all(model, layout, bags, known, topic, cutoff, frame=None):
    recordings = []
    for path, mass in [(b, None) for b in bags] + list(known):
        loaded = mass is not None
        train, held, info = reduce_recording(
            path, model.joint_names,
            recording_rows(model, layout, loaded, frame),
            layout.bag_columns(loaded), topic, cutoff)
        info['held_samples'] = 0 if held is None else int(held.rows.max())
        recordings.append(Recording(str(path), train, held, info, mass))
    return recordings


def _ratios(recordings, layout, theta):
    """Per bag (K, explained) of ``effort.ratios`` for the model theta."""
    out = {}
    for rec in recordings:
        red = rec.part('all')
        u = np.zeros(red.p)
        u[:layout.p_theta] = theta
        if rec.loaded:      # the known mass as a point at its link
            u[layout.bag_columns(False)] = rec.mass
        out[rec.path] = effort_units.ratios(red, u, layout.drive_columns)
    return out


def _check_units(recordings, layout, theta0, model, mode, k_given, urdf):
    """Per bag (K, explained); IdentificationError when impossible."""
    out = _ratios(recordings, layout, theta0)
    for path, (K, explained) in out.items():
        if k_given is not None:
            K = K / k_given
        effort_units.check(path, model.joint_names, K, explained, mode,
                           urdf)
    return out


def _check_mass(recording, layout, sigma):
    """Raise IdentificationError when the known mass's torque never changes."""
    excited = mass_excitation(recording, layout, sigma)
    if excited.max() < KNOWN_MASS_EXCITATION:
        raise IdentificationError(
            f'{recording.path}: the recording does not excite the known '
            f'{recording.mass:g} kg mass: its torque changes by at most '
            f'{excited.max():.2g} residual RMS on any joint beyond what the '
            f'drive terms explain (move the loaded arm through poses where '
            f'gravity acts on it differently: the shoulder and elbow '
            f'moving)')
    return excited


def identify(model, path, topic=DEFAULT_TOPIC, validate=None,
             coulomb_width=None, cutoff=None, urdf_text=None,
             effort='torque', known_mass=None, urdf_label=None,
             known_mass_link=None):
    """
    Identify ``model``'s parameters from the bag(s) at ``path``.

    ``path`` is one bag or a list of them, fitted together (held-out
    blocks from each).  ``effort`` 'torque' (N m) or 'current'
    (proportional to torque: the torque constants are identified, unless
    the nominal URDF gives them); ``known_mass`` None or (bag, kg): a
    recording with that mass added at ``known_mass_link`` (default the
    tip; ``payload.payload_frame``).  ``model`` is a chain or a whole
    tree (``load_robot`` without a tip).  Returns a
    :class:`Result` whose ``model`` carries the identified inertials and
    ``drives`` the identified drive terms (with ``torque_constant``).
    Raises :class:`BagError` (or :class:`IdentificationError`) with one
    line.
    """
    start = time.perf_counter()
    bags = [path] if isinstance(path, (str, bytes)) or not hasattr(
        path, '__iter__') else list(path)
    nominal = model_drives(model)
    k_given = None if nominal is None else nominal.torque_constant
    estimate_k = effort == 'current' and k_given is None
    known = [] if known_mass is None else [tuple(known_mass)]
    w0 = (float(nominal.coulomb_width[0]) if nominal is not None
          else DEFAULT_COULOMB_WIDTH)
    widths = ((float(coulomb_width),) if coulomb_width is not None else
              (w0,) + tuple(w for w in WIDTHS if abs(w - w0) > 1e-12))
    n, nb = model.n, model.nb
    frame = None
    if known:
        from .payload import payload_frame
        frame = payload_frame(model, known_mass_link)
    layout = Layout(n, widths, bool(known), nb=nb)
    theta0 = nominal_theta(model)
    fixed = fixed_parts(model, urdf_text, prior=True)
    recordings = _reduce_all(model, layout, bags, known, topic, cutoff,
                             frame)
    mode = ('current' if estimate_k else 'given' if k_given is not None
            else 'torque')
    ratios = _check_units(recordings, layout, theta0, model, mode, k_given,
                          urdf_label)
    k0 = (initial_constants(ratios, n) if estimate_k else
          k_given if k_given is not None else np.ones(n))
    sigma_e = _weights(recordings, layout, k0) / k0
    w = 1.0 / (sigma_e * k0)
    excited = (_check_mass(recordings[-1], layout, sigma_e * k0)
               if estimate_k and known else None)
    Aall, _ = stacked(recordings, 'all', layout, 0, w, k0)
    base = base_parameters(Aall[:layout.p_theta, :layout.p_theta])
    struct = structural_base(model, drives=True)
    if base.rank < MIN_RANK_FRACTION * struct.rank:
        raise IdentificationError(
            f'{recordings[0].path}: the recording does not excite the arm: '
            f'rank {base.rank} of the regressor against {struct.rank} base '
            f'parameters (move every joint, with varied speeds and '
            f'accelerations)')
    D = np.linalg.norm(Aall[:, :layout.p_theta], axis=0)
    D = np.maximum(D, 1e-3 * max(float(np.median(D)), 1e-12))
    # a parameter the recordings hardly see (a link's mass where its frame
    # sits on the axes before it) is held to the prior like the others:
    # with its column's norm alone it drifts to whatever still fits
    pi = slice(0, N_INERTIAL * nb)
    D[pi] = np.maximum(D[pi], PRIOR_FLOOR * np.median(D[pi]))
    mass = known[0][1] if known else None
    program = _Program(layout, fixed, theta0, D,
                       _scales(model, theta0, D, layout, mass, Aall), mass)
    lam, width, lam_errors, width_errors = _choose(
        program, recordings, layout, w, k0)
    K, free, notes = k0, None, []
    if estimate_k:
        # the joints whose effort the first fit's rigid-body torque explains
        Aall, _ = stacked(recordings, 'all', layout, width, w, k0)
        x = program.solve(Aall, lam, 'first fit')
        free = determined(ratios, n)
        if x is not None:
            free |= determined(_ratios(recordings, layout,
                                       x[:layout.p_theta]), n)
        from .payload import carrying
        carried = carrying(model, frame[0]) if known else []
        K = fit_constants(
            recordings, layout, width, sigma_e, k0, lam, D, theta0, free,
            scale_pins(ratios, model, carried, notes,
                       frame[2] if known else None), mass)
        w = 1.0 / (sigma_e * K)
    Aall, _ = stacked(recordings, 'all', layout, width, w, K)
    x = program.solve(Aall, lam, 'final')
    if x is None:
        raise IdentificationError(f'{recordings[0].path}: the fit failed '
                                  f'(the solver found no solution)')
    eps = widths[width]
    theta = _clean(x[:layout.p_theta], fixed, nb, n)
    x[:layout.p_theta] = theta
    K_out = K if (estimate_k or k_given is not None) else None
    drives = Drives.from_parameters(theta[N_INERTIAL * nb:], eps, K_out)
    ident = with_parameters(model, theta[:N_INERTIAL * nb])
    info_ = dict(model.info or {})
    info_['drives'] = drives
    ident = ident.replace(info=info_)
    result = Result(
        model=ident, theta=theta, theta0=theta0, drives=drives,
        coulomb_width=eps, rank=base.rank, structural_rank=struct.rank,
        condition=base.condition, lam=lam, sigma=sigma_e * K,
        info=recordings[0].info, lambda_errors=lam_errors,
        width_errors=width_errors, torque_constant=K_out, ratios=ratios,
        constants=('identified' if estimate_k else 'given'
                   if k_given is not None else 'none'),
        recordings=[(r.path, r.info) for r in recordings],
        undetermined_k=([] if free is None
                        else [int(j) for j in np.flatnonzero(~free)]),
        mass_excitation=excited, notes=notes,
        payload_link=None if frame is None else frame[2])
    _report(result, recordings, layout, width, x, K, known, program)
    result.seconds = time.perf_counter() - start
    if validate is not None:
        val = reduce_recording(validate, model.joint_names,
                               recording_rows(model, layout, False),
                               layout.bag_columns(False), topic, cutoff,
                               split=False)
        rec = Recording(str(validate), val[0], None, val[2])
        result.validate_stats = _both(result, [rec], 'samples', layout,
                                      width, x, K)
        result.validate_seconds = (time.perf_counter() - start
                                   - result.seconds)
    return result


def _choose(program, recordings, layout, w, k0):
    """Choose lambda and the width on the held-out blocks."""
    cache = {}

    def problems(width):
        if width not in cache:
            cache[width] = tuple(stacked(recordings, part, layout, width, w,
                                         k0)[0] for part in ('train',
                                                             'held'))
        return cache[width]

    def sweep(width):
        train, held = problems(width)
        errors = []
        for lam in LAMBDAS:
            x = program.solve(train, lam, f'prior weight {lam:g}')
            if x is not None:
                errors.append((lam, _error(held, x)))
        if not errors:
            raise IdentificationError(f'{recordings[0].path}: the fit '
                                      f'failed (the solver found no '
                                      f'solution)')
        best = min(e for _, e in errors)
        lam = max(lam for lam, e in errors if e <= best * (1 + LAMBDA_SLACK))
        return lam, errors
    lam, lam_errors = sweep(0)
    width_errors = []
    for i in range(len(layout.widths)):
        train, held = problems(i)
        x = program.solve(train, lam, f'Coulomb width '
                                      f'{layout.widths[i]:g}')
        if x is not None:
            width_errors.append((layout.widths[i], _error(held, x), i))
    width = 0
    if width_errors:
        best = min(width_errors, key=lambda t: t[1])
        default = [e for e in width_errors if e[2] == 0]
        if not default or best[1] < default[0][1] * (1 - WIDTH_SLACK):
            width = best[2]
    if width != 0:
        lam, lam_errors = sweep(width)
    return lam, width, lam_errors, [(a, b) for a, b, _ in width_errors]


def _both(result, recordings, part, layout, width, x, k_eff):
    """Nominal and identified stats of ``part`` (N m, relative)."""
    x0 = x.copy()
    x0[:layout.p_theta] = result.theta0
    return {'nominal': joint_stats(recordings, part, layout, width, x0,
                                   k_eff, k_eff),
            'identified': joint_stats(recordings, part, layout, width, x,
                                      k_eff, k_eff)}


def _report(result, recordings, layout, width, x, K, known, program):
    """Fill the result's statistics, payload and notes."""
    plain = [r for r in recordings if not r.loaded]
    result.fit_stats = _both(result, plain, 'samples', layout, width, x, K)
    if any(r.held is not None and r.held.rows.min() > 0 for r in plain):
        held = _both(result, plain, 'held_samples', layout, width, x, K)
        result.fit_stats['held_out_nominal'] = held['nominal']
        result.fit_stats['held_out_identified'] = held['identified']
    if known:
        from ..core.regressor import link_inertials
        m, c, Ic = link_inertials(x[layout.pay])
        result.payload = {'mass': float(m), 'com': c, 'inertia': Ic}
    if program.trouble:
        result.notes.append(
            f'{INACCURATE} for {", ".join(program.trouble[:3])}'
            + (' ...' if len(program.trouble) > 3 else ''))


def _clean(theta, fixed, nb, n):
    """
    Keep each body's own pseudo-inertia J inside the PSD cone.

    The fit leaves weakly excited bodies on the cone's edge (a point
    mass, a rod, a plate: some eigenvalue of J zero, or a solver's
    -1e-12), where the rounding of the inertia about the centre of mass
    tips a principal moment negative or breaks the triangle inequality
    and the written URDF would be refused on reading.  J's eigenvalues
    are raised to ``CONE_MARGIN`` times its largest: its inertia about
    the centre of mass then has principal moments at least twice that
    and their triangle inequality holds with that margin (the Schur
    complement of J >= d 1 is >= d 1), far beyond the reader's
    tolerance (``core.inertia.INERTIA_RTOL``), for a change in the torques
    of that relative size.
    """
    from ..core.regressor import pseudo_inertia
    theta = theta.copy()
    for k in range(nb):
        sl = slice(N_INERTIAL * k, N_INERTIAL * (k + 1))
        own = theta[sl] - fixed[k]
        J = pseudo_inertia(own)
        lam, V = np.linalg.eigh(J)
        floor = CONE_MARGIN * lam.max()
        if lam.max() > 0.0 and lam.min() < floor:
            J = (V * np.maximum(lam, floor)) @ V.T
            I = np.trace(J[:3, :3]) * np.eye(3) - J[:3, :3]  # noqa: E741
            own = np.array([J[3, 3], J[0, 3], J[1, 3], J[2, 3], I[0, 0],
                            I[0, 1], I[1, 1], I[0, 2], I[1, 2], I[2, 2]])
            theta[sl] = own + fixed[k]
    d = theta[N_INERTIAL * nb:].reshape(n, N_DRIVE)
    for col in (0, 1, 3):
        d[:, col] = np.maximum(d[:, col], 0.0)
    theta[N_INERTIAL * nb:] = d.ravel()
    return theta
