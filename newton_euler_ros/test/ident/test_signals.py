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
The zero-phase low-pass of identification's signal preparation.

Written in the package (``ident.signals.lowpass``): a command that
imports ``scipy.signal`` pays 2 s for it.  Checked against
``scipy.signal.filtfilt`` on the Butterworth filter ``scipy.signal.butter``
designs, and by what a zero-phase low-pass must do to a constant and to
sines below and above its cutoff.
"""
import subprocess
import sys

from newton_euler_ros.ident.signals import butterworth, lowpass, ORDER
import numpy as np
import pytest


@pytest.mark.parametrize('wn', [0.004, 0.02, 0.1, 0.4, 0.9])
def test_the_design_is_scipys_butterworth(wn):
    from scipy.signal import butter
    b, a = butterworth(ORDER, wn)
    b_ref, a_ref = butter(ORDER, wn)
    np.testing.assert_allclose(a, a_ref, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(b, b_ref, rtol=1e-13, atol=1e-15 * b_ref[2])
    # unit gain at zero frequency (the polynomial form loses digits as
    # the cutoff drops: sum(a) ~ (pi wn)^4), none at Nyquist
    assert np.sum(b) / np.sum(a) == pytest.approx(1.0, rel=1e-6)
    assert abs(np.sum(b * (-1.0) ** np.arange(ORDER + 1))) < 1e-12


@pytest.mark.parametrize('m', [2, 5, 16, 17, 300, 20000])
@pytest.mark.parametrize('rate, cutoff', [(500.0, 10.0), (100.0, 20.0),
                                          (1000.0, 2.0)])
def test_it_is_scipys_filtfilt_with_odd_padding(m, rate, cutoff):
    from scipy.signal import butter, filtfilt
    rng = np.random.default_rng(m)
    X = np.cumsum(rng.standard_normal((m, 3)), axis=0) + 100.0
    b, a = butter(ORDER, cutoff / (0.5 * rate))
    ref = filtfilt(b, a, X, axis=0, padtype='odd',
                   padlen=min(3 * (ORDER + 1), m - 1))
    got = lowpass(X, rate, cutoff)
    assert got.shape == X.shape
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12 * np.abs(ref).max())


def test_a_constant_and_sines_come_through_as_a_low_pass_should():
    rate, cutoff = 500.0, 10.0
    t = np.arange(10000) / rate
    slow = np.sin(2 * np.pi * 1.0 * t)
    fast = np.sin(2 * np.pi * 50.0 * t)
    X = np.column_stack([np.full_like(t, 3.5), slow, fast, slow + fast])
    Y = lowpass(X, rate, cutoff)
    np.testing.assert_allclose(Y[:, 0], 3.5, rtol=1e-10)
    inner = slice(500, -500)
    # forward and backward: |H|^2 = 1 / (1 + (f / fc)^8), no phase
    assert np.max(np.abs(Y[inner, 1] - slow[inner])) < 1e-6
    assert np.max(np.abs(Y[inner, 2])) < 3e-6 * 1.5
    np.testing.assert_allclose(Y[inner, 3], Y[inner, 1] + Y[inner, 2],
                               atol=1e-12)


def test_preparing_a_recording_imports_no_scipy_signal():
    code = ('import sys\n'
            'import numpy as np\n'
            'from newton_euler_ros.ident.signals import prepare\n'
            't = np.arange(400) / 100.0\n'
            'q = np.column_stack([np.sin(t), np.cos(t)])\n'
            'assert prepare(t, q, None, q) is not None\n'
            'print("scipy.signal" in sys.modules)\n')
    out = subprocess.run([sys.executable, '-c', code], capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == 'False'


def test_a_cutoff_at_or_past_nyquist_is_refused():
    with pytest.raises(ValueError, match='Nyquist'):
        butterworth(ORDER, 1.0)
