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
The accuracy/speed report: its pieces by physics, the whole as a smoke test.

The finite-difference Coriolis matrix is an independent route to C (the
Christoffel symbols of D), so agreeing with our exact recursion checks
both.  The quick report runs end to end as a user runs it; its assertions
are about accuracy only, never about time (timings on a shared machine
are too noisy for a test).
"""
import json
import math
import os
import subprocess
import sys
import warnings

from newton_euler_ros.core import coriolis_matrix, load_robot, mass_matrix
from newton_euler_tools.accuracy import chains, plots, scaling
from newton_euler_tools.accuracy.arithmetic import coriolis_by_differences
import numpy as np
import pytest

EPS = np.finfo(np.float64).eps


def _robot(name):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_robot(name)


@pytest.mark.parametrize('name', ['puma560', 'stanford', 'planar_rp'])
@pytest.mark.parametrize('central', [True, False])
def test_christoffel_differences_of_D_give_our_C(name, central):
    model = _robot(name)
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, qd = rng.uniform(-1.5, 1.5, (2, model.n))
        exact = coriolis_matrix(model, q, qd)
        fd = coriolis_by_differences(model, q, qd, central=central,
                                     h=(EPS ** (1 / 3) if central
                                        else EPS ** 0.5))
        scale = max(1.0, np.abs(exact).max())
        # central: h^2 truncation + eps/h rounding ~ 1e-10; forward ~ 1e-7
        assert np.abs(fd - exact).max() <= (1e-8 if central else 1e-6) * scale


def test_differences_of_D_reproduce_Ddot_minus_2C_skew():
    model = chains.random_chain(6)
    q, qd, _ = chains.random_states(model, 1)[0]
    C = coriolis_by_differences(model, q, qd)
    h = 1e-6
    Ddot = (mass_matrix(model, q + h * qd) - mass_matrix(model, q - h * qd)) \
        / (2 * h)
    N = Ddot - 2 * C
    assert np.abs(N + N.T).max() <= 1e-7 * np.abs(Ddot).max()


@pytest.mark.parametrize('n', [1, 6, 30])
def test_random_chains_are_physical_and_reproducible(n):
    a = chains.random_chain(n, seed=4)
    b = chains.random_chain(n, seed=4)
    assert np.array_equal(a.links_array, b.links_array)
    assert not np.array_equal(a.links_array,
                              chains.random_chain(n, seed=5).links_array)
    for q, qd, qdd in chains.random_states(a, 3):
        D = mass_matrix(a, q)
        assert np.all(np.linalg.eigvalsh(D) > 0)
        for j, t in enumerate(a.joint_types):
            if t == 'revolute':
                assert -math.pi <= q[j] <= math.pi


def test_pareto_front_keeps_only_undominated_points():
    pts = [(1.0, 1e-3), (2.0, 1e-5), (3.0, 1e-4), (0.5, 1e-1), (4.0, 1e-9),
           (2.0, 1e-2)]
    front = plots.pareto_front(pts)
    assert front == [(0.5, 1e-1), (1.0, 1e-3), (2.0, 1e-5), (4.0, 1e-9)]


def test_fitted_exponent_recovers_a_power_law():
    recs = [{'method': 'op', 'dof': n, 'us': 0.3 * n ** 1.7}
            for n in (3, 6, 12, 25, 50, 100)]
    recs += [{'method': 'flat', 'dof': n, 'us': 2.0} for n in (12, 50)]
    fits = scaling.fit_exponents(recs, fit_from=6)
    assert fits['op'][0] == pytest.approx(1.7, abs=1e-12)
    assert fits['op'][1] == pytest.approx(0.3, rel=1e-12)
    assert fits['flat'][0] == pytest.approx(0.0, abs=1e-12)


@pytest.fixture(scope='module')
def quick_report(tmp_path_factory):
    out = tmp_path_factory.mktemp('accuracy')
    env = dict(os.environ)
    proc = subprocess.run(
        [sys.executable, '-m', 'newton_euler_tools.accuracy', '--quick',
         '--out', str(out)], capture_output=True, text=True, env=env,
        timeout=600)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    with open(out / 'accuracy' / 'records.json', encoding='utf-8') as fh:
        data = json.load(fh)
    return out, proc.stdout, data['records'], data['context']


def test_quick_report_writes_markdown_plots_and_table(quick_report):
    out, stdout, records, context = quick_report
    md = (out / 'accuracy-vs-time.md').read_text(encoding='utf-8')
    for heading in ('## How to read this report', '## Findings',
                    '## Arithmetic and algorithms, per robot',
                    '## Cost growth with the number of links'):
        assert heading in md
    for name in ('pareto-puma560.png', 'pareto-chain100.png', 'scaling.png'):
        png = out / 'accuracy' / name
        assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
        assert f'accuracy/{name}' in md
    assert 'accuracy vs time' in stdout and 'float32' in stdout
    assert context['quick'] is True


def _arith(records, robot, quantity, method):
    for r in records:
        if (r['section'], r['robot'], r['quantity'], r['method']) == (
                'arithmetic', robot, quantity, method):
            return r
    raise AssertionError(f'no record {robot} {quantity} {method}')


def test_quick_report_errors_are_physically_ordered(quick_report):
    _, _, records, _ = quick_report
    robots = {r['robot']: r['dof'] for r in records
              if r['section'] == 'arithmetic'}
    assert {'puma560', 'panda', 'chain6', 'chain30', 'chain100'} <= set(robots)
    for robot, n in robots.items():
        bound = 10 * n * EPS
        for q, m in (('tau', 'float64'), ('g', 'float64'),
                     ('D', 'float64, n recursions'), ('D', 'float64, CRBA'),
                     ('C', 'float64, n recursions')):
            assert _arith(records, robot, q, m)['error'] <= bound, (robot, q, m)
        # float32 really is single precision: far above float64 round-off,
        # and still sane (eps32 = 1.2e-7)
        # the composite C sums moment arms about frame 0 (see
        # test_highprec): a looser constant
        err = _arith(records, robot, 'C', 'float64, composite, O(n^2)')
        assert err['error'] <= 100 * n * EPS, (robot, err['error'])
        for q, m in (('tau', 'float32'), ('D', 'float32, CRBA'),
                     ('C', 'float32, n recursions'),
                     ('C', 'float32, composite, O(n^2)')):
            err = _arith(records, robot, q, m)['error']
            assert 1e3 * EPS < err < 1e-7 * 100 * n, (robot, q, m, err)
        # forward dynamics amplifies by cond(D) (1e3..1e6 here): both
        # methods well inside single precision, float32 well outside
        for m in ('float64, ABA, O(n)', 'float64, Cholesky of D'):
            err = _arith(records, robot, 'FD', m)['error']
            assert err < 1e-10, (robot, m, err)
        err = _arith(records, robot, 'FD', 'float32, ABA')['error']
        assert 1e3 * EPS < err < 1e-2, (robot, err)
        fd = _arith(records, robot, 'C', 'central differences of D')
        assert 1e3 * EPS < fd['error'] < 1e-6, (robot, fd['error'])


def test_report_rerenders_from_its_records(quick_report, tmp_path):
    out, _, _, _ = quick_report
    proc = subprocess.run(
        [sys.executable, '-m', 'newton_euler_tools.accuracy', '--from-records',
         str(out / 'accuracy' / 'records.json'), '--out', str(tmp_path)],
        capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    again = (tmp_path / 'accuracy-vs-time.md').read_text(encoding='utf-8')
    assert again == (out / 'accuracy-vs-time.md').read_text(encoding='utf-8')
    bad = subprocess.run(
        [sys.executable, '-m', 'newton_euler_tools.accuracy', '--from-records',
         str(tmp_path / 'missing.json')], capture_output=True, text=True,
        timeout=300)
    assert bad.returncode == 2 and 'cannot read records' in bad.stderr


def test_report_modules_import_no_cycle():
    """The report's modules form a layered graph: no two import each other."""
    import ast
    folder = os.path.dirname(plots.__file__)
    graph = {}
    for name in os.listdir(folder):
        if name.endswith('.py'):
            with open(os.path.join(folder, name), encoding='utf-8') as fh:
                tree = ast.parse(fh.read())
            graph[name[:-3]] = {
                (n.module or '').split('.')[0] for n in ast.walk(tree)
                if isinstance(n, ast.ImportFrom) and n.level == 1}

    def reaches(start, goal, seen=()):
        return any(m == goal or (m in graph and m not in seen
                                 and reaches(m, goal, seen + (m,)))
                   for m in graph.get(start, ()))
    cycles = [m for m in graph if reaches(m, m)]
    assert not cycles, {m: sorted(graph[m]) for m in cycles}
