"""modes, extract and timesim on NumPy inputs, against closed forms."""

import numpy as np
import pytest

import stickslip


def test_modes_of_a_two_mass_chain_match_the_closed_form():
    # M = m I, K = k [[2, -1], [-1, 2]]: ω² = k/m and 3k/m.
    m, k = 2.0, 8.0e4
    f, shapes = stickslip.modes(m * np.eye(2), k * np.array([[2.0, -1.0], [-1.0, 2.0]]))
    expected = np.sqrt([k / m, 3 * k / m]) / (2 * np.pi)
    # Dense Cholesky + symmetric eigensolver: 1e-12 relative is a few hundred ulps.
    np.testing.assert_allclose(f, expected, rtol=1e-12)
    # Mass-normalised: Φᵀ M Φ = I.
    np.testing.assert_allclose(shapes.T @ (m * np.eye(2)) @ shapes, np.eye(2), atol=1e-12)
    f1, s1 = stickslip.modes(m * np.eye(2), k * np.array([[2.0, -1.0], [-1.0, 2.0]]), count=1)
    assert f1.shape == (1,) and s1.shape == (2, 1)


def test_extract_recovers_the_harmonics_of_a_synthetic_record():
    fs, f0 = 10_000.0, 50.0
    t = np.arange(int(fs * 0.4)) / fs  # 20 cycles
    ref = np.cos(2 * np.pi * f0 * t)
    x = 0.3 + 2.0 * np.cos(2 * np.pi * f0 * t - 0.5) + 0.1 * np.sin(2 * np.pi * 3 * f0 * t)
    out = stickslip.extract(ref, {"x": x}, fs, harmonics=3, cycles_per_block=1000)
    c = out["responses"]["x"][0]
    # [c0, c1, s1, c2, s2, c3, s3]; a least-squares fit over whole sampled cycles of exact
    # sinusoids: exact to round-off, far below 1e-6 of the amplitudes.
    np.testing.assert_allclose(c, [0.3, 2 * np.cos(0.5), 2 * np.sin(0.5), 0, 0, 0, 0.1], atol=1e-6)
    assert out["frequency_hz"][0] == pytest.approx(f0, rel=1e-6)


def test_timesim_below_the_threshold_is_the_linear_response(root):
    study = stickslip.Study.from_toml(root / "examples" / "jenkins-1dof" / "study.toml")
    # 100 N at 150 Hz: the joint force stays far below its 1000 N threshold, the joint sticks
    # and the response is that of the linear oscillator with the total stiffness.
    f = 150.0
    r = study.timesim(f, 100.0)
    x = r["outputs"]["mass"]
    n = len(x)
    c1 = 2 / n * np.sum(x * np.cos(2 * np.pi * np.arange(n) / n))
    s1 = 2 / n * np.sum(x * np.sin(2 * np.pi * np.arange(n) / n))
    w = 2 * np.pi * f
    expected = 100.0 / abs(2.24e7 - 10.0 * w**2 + 1j * w * 350.0)
    # Newmark's average acceleration at 256 steps per period shifts the frequency by about
    # (ωΔt)²/12 = 5e-5 relative; at 150 Hz, far from the 238 Hz resonance, the amplitude
    # moves by about as much: 1e-3 is a safe bound.
    assert np.hypot(c1, s1) == pytest.approx(expected, rel=1e-3)
    assert r["dissipated_J"] > 0
