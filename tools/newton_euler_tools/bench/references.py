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
The references the benchmark checks us against before timing anything.

A naive numpy recursion (the textbook Newton-Euler, one numpy operation
at a time: the reference the compiled kernel is measured against), and
the peers (Pinocchio, Robotics Toolbox) set up from our model by
:mod:`newton_euler_tools.peers` and compared with ours at random states:
a peer that disagrees is marked INVALID and no verdict is drawn from it.
"""
import warnings

from newton_euler_ros.core import (coriolis_matrix, forward_dynamics,
                                   gravity_torques, inverse_dynamics,
                                   inverse_dynamics_batch, mass_matrix)
from newton_euler_ros.core.model import REVOLUTE, STANDARD
import numpy as np

from .. import peers


# --------------------------------------------------------------------------
# a naive reference: the textbook recursion, one numpy operation at a time


def _naive_dh(model, j, qj):
    """4x4 DH transform of joint j at joint value qj (allocates)."""
    a, alpha = model.a[j], model.alpha[j]
    d, theta = model.d[j], model.theta[j]
    if model.joint_types[j] == REVOLUTE:
        theta = theta + qj
    else:
        d = d + qj
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(alpha), np.sin(alpha)
    if model.convention == STANDARD:
        return np.array([[ct, -st * ca, st * sa, a * ct],
                         [st, ct * ca, -ct * sa, a * st],
                         [0.0, sa, ca, d],
                         [0.0, 0.0, 0.0, 1.0]])
    return np.array([[ct, -st, 0.0, a],
                     [st * ca, ct * ca, -sa, -sa * d],
                     [st * sa, ct * sa, ca, ca * d],
                     [0.0, 0.0, 0.0, 1.0]])


def naive_rnea(model, q, qd, qdd, gravity=True):
    """
    Newton-Euler in base-frame vectors with ``np.cross`` and ``@``.

    Forward: pose of every link by 4x4 products, then the angular velocity
    and acceleration and the acceleration of each centre of mass, passed
    from link to link through a point P on the joint axis.  Backward:
    forces and moments about the base origin, projected on each axis.
    Written for clarity, not speed: the reference the compiled kernel is
    measured against.
    """
    n = model.n
    T = np.array(model.base)
    w = np.zeros(3)
    wd = np.zeros(3)
    # acceleration of the reference point o of the previous body (the base
    # accelerates upwards at -g in place of gravity pulling every link)
    a = -np.asarray(model.gravity) if gravity else np.zeros(3)
    o = T[:3, 3].copy()
    z_axes, points, coms, forces, moments = [], [], [], [], []
    for j in range(n):
        T_prev = T
        T = T_prev @ _naive_dh(model, j, q[j])
        if model.convention == STANDARD:     # joint j moves about z_{j-1}
            z, P = T_prev[:3, 2], T_prev[:3, 3]
        else:                                # modified: about z_j
            z, P = T[:3, 2], T[:3, 3]
        R = T[:3, :3]
        c = R @ model.com[j] + T[:3, 3]
        r = P - o
        aP = a + np.cross(wd, r) + np.cross(w, np.cross(w, r))
        if model.joint_types[j] == REVOLUTE:
            wd = wd + np.cross(w, z) * qd[j] + z * qdd[j]
            w = w + z * qd[j]
        else:
            aP = aP + 2.0 * np.cross(w, z) * qd[j] + z * qdd[j]
        r = c - P
        ac = aP + np.cross(wd, r) + np.cross(w, np.cross(w, r))
        Iw = R @ model.inertia[j] @ R.T
        forces.append(model.mass[j] * ac)
        moments.append(Iw @ wd + np.cross(w, Iw @ w))
        z_axes.append(z)
        points.append(P)
        coms.append(c)
        a, o = ac, c
    tau = np.empty(n)
    f = np.zeros(3)
    m_o = np.zeros(3)          # moment about the base origin
    for j in range(n - 1, -1, -1):
        f = f + forces[j]
        m_o = m_o + moments[j] + np.cross(coms[j], forces[j])
        if model.joint_types[j] == REVOLUTE:
            tau[j] = z_axes[j] @ (m_o - np.cross(points[j], f))
        else:
            tau[j] = z_axes[j] @ f
    return tau


def naive_mass_matrix(model, q):
    """D(q) by n naive recursions with qdd = e_k."""
    n = model.n
    zero = np.zeros(n)
    D = np.empty((n, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = 1.0
        D[:, k] = naive_rnea(model, q, zero, e, gravity=False)
    return D


# --------------------------------------------------------------------------
# comparing with ours


def _maxdiff(x, y):
    return float(np.max(np.abs(np.asarray(x) - np.asarray(y))))


def _tolerance(ref):
    return 1e-9 * max(1.0, float(np.max(np.abs(ref))))


def ours_reference(model, states):
    """tau, D, C, g and FD (qdd as the torque) at each (q, qd, qdd)."""
    out = []
    for q, qd, qdd in states:
        out.append({'tau': inverse_dynamics(model, q, qd, qdd),
                    'D': mass_matrix(model, q),
                    'C': coriolis_matrix(model, q, qd),
                    'g': gravity_torques(model, q),
                    'FD': forward_dynamics(model, q, qd, qdd),
                    'Cqd': inverse_dynamics(model, q, qd, None,
                                            gravity=False)})
    return out


def compare(ref, got):
    """{term: max abs diff over states}, {term: ok} for the terms in got."""
    diffs, ok = {}, {}
    for term in got[0]:
        diffs[term] = max(_maxdiff(r[term], g[term]) for r, g in zip(ref, got))
        ok[term] = all(_maxdiff(r[term], g[term]) <= _tolerance(r[term])
                       for r, g in zip(ref, got))
    return diffs, ok


def check_references(result, ns, states, log):
    """Check the naive recursion and the peers against ours; peer spaces."""
    model = ns['model']
    n = model.n
    ref = ours_reference(model, states)
    log('correctness, max |ours - other| over 3 random states '
        '(tolerance 1e-9 x max(1, |ours|)):')
    naive_out = [{'tau': naive_rnea(model, *s),
                  'g': naive_rnea(model, s[0], np.zeros(n), np.zeros(n)),
                  'D': naive_mass_matrix(model, s[0])} for s in states]
    diffs, ok = compare(ref, naive_out)
    result['correctness']['naive'] = diffs
    result['valid']['naive'] = all(ok.values())
    log('  naive numpy : ' + _fmt_diffs(diffs, ok))
    Qc = np.array([s[0] for s in states])
    bat = inverse_dynamics_batch(model, Qc, [s[1] for s in states],
                                 [s[2] for s in states])
    bdiff = max(_maxdiff(bat[i], ref[i]['tau']) for i in range(len(ref)))
    log(f'  our batch   : tau {bdiff:.1e} vs single-state')
    result['correctness']['ours_batch_vs_single'] = bdiff
    pin_ns = _setup_pinocchio(model, states, ref, result, log)
    rtb_ns = _setup_rtb(model, states, ref, result, log)
    for extra in (pin_ns, rtb_ns):
        if extra is not None:
            extra.update({k: ns[k] for k in ('q', 'qd', 'qdd', 'Q', 'QD',
                                             'QDD')})
    return pin_ns, rtb_ns


def _fmt_diffs(diffs, ok):
    return '  '.join(f'{k} {v:.1e}{"" if ok[k] else " MISMATCH"}'
                     for k, v in diffs.items())


def _peer(key, label, load, result, log):
    """
    Return ``load()``, a peer's module, or None when it does not import.

    None is logged under ``label`` and marks the peer (``key``) neither
    valid nor invalid in ``result``.
    """
    try:
        return load()
    except Exception as exc:
        log(f'  {label:<12}: not importable ({type(exc).__name__}: {exc}); '
            f'skipped')
        result['valid'][key] = None
        return None


def _import_pinocchio():
    import pinocchio
    return pinocchio


def _import_rtb():
    import roboticstoolbox  # noqa: F401
    from roboticstoolbox.robot import frne
    return frne


def _setup_pinocchio(model, states, ref, result, log):
    pin = _peer('pin', 'Pinocchio', _import_pinocchio, result, log)
    if pin is None:
        return None
    pm = peers.pinocchio_model(model)
    pd = pm.createData()
    got = []
    upper_only = False
    for q, qd, qdd in states:
        M = np.array(pin.crba(pm, pd, q))
        upper_only = upper_only or (np.any(np.triu(M, 1) != 0.0)
                                    and np.all(np.tril(M, -1) == 0.0))
        Cp = np.array(pin.computeCoriolisMatrix(pm, pd, q, qd))
        got.append({
            'tau': np.array(pin.rnea(pm, pd, q, qd, qdd)),
            'D': np.triu(M) + np.triu(M, 1).T,
            'g': np.array(pin.computeGeneralizedGravity(pm, pd, q)),
            'C': Cp,
            'Cqd': Cp @ qd,
            'FD': np.array(pin.aba(pm, pd, q, qd, qdd)),
        })
    diffs, ok = compare(ref, got)
    result['correctness']['pin'] = diffs
    valid = ok['tau'] and ok['D'] and ok['g'] and ok['Cqd'] and ok['FD']
    result['valid']['pin'] = valid
    result['valid']['pin_C_is_christoffel'] = ok['C']
    log('  Pinocchio   : ' + _fmt_diffs(diffs, ok))
    if upper_only:
        log('                (crba fills only the upper triangle of D; '
            'symmetrised for this check, not in the timing)')
    if ok['C']:
        log('                computeCoriolisMatrix equals our Christoffel C')
    else:
        log(f'                computeCoriolisMatrix DIFFERS from our '
            f'Christoffel C by up to {diffs["C"]:.3e} '
            f'(C qd agrees to {diffs["Cqd"]:.1e})')
    if not valid:
        log('                Pinocchio model disagrees with ours: its '
            'timings are marked INVALID')
    return {'pm': pm, 'pd': pd, 'rnea': pin.rnea, 'crba': pin.crba,
            'computeCoriolisMatrix': pin.computeCoriolisMatrix,
            'computeGeneralizedGravity': pin.computeGeneralizedGravity,
            'aba': pin.aba}


def _setup_rtb(model, states, ref, result, log):
    frne = _peer('rtb', 'RTB', _import_rtb, result, log)
    if frne is None:
        return None
    robot = peers.rtb_robot(model)
    got = []
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        for q, qd, qdd in states:
            C = np.array(robot.coriolis(q, qd))
            got.append({'tau': np.array(robot.rne(q, qd, qdd)),
                        'D': np.array(robot.inertia(q)),
                        'C': C, 'g': np.array(robot.gravload(q)),
                        'Cqd': C @ qd,
                        'FD': np.array(robot.accel(q, qd, qdd))})
    c_ext = bool(getattr(frne, '_C_AVAILABLE', False)) and \
        robot._frne is not None
    diffs, ok = compare(ref, got)
    result['correctness']['rtb'] = diffs
    result['correctness']['rtb_c_extension'] = c_ext
    valid = all(ok.values())
    result['valid']['rtb'] = valid
    log('  RTB         : ' + _fmt_diffs(diffs, ok)
        + ('' if c_ext else '   (C extension NOT in use: pure-Python rne)'))
    if not valid:
        log('                RTB model disagrees with ours: its timings are '
            'marked INVALID')
    return {'robot': robot}
