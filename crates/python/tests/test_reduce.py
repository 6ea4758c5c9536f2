"""reduce on NumPy inputs: Craig-Bampton against its closed form (Guyan when no mode is
kept), the free-mode and enriched bases against the modes they must hold exactly."""

import numpy as np
import pytest

import stickslip


def chain(n, m=1.5, k=2.0e5):
    """n equal masses, n + 1 equal springs, grounded at both ends."""
    K = k * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    return m * np.eye(n), K


def lowest_hz(M, K, count):
    return stickslip.modes(M, K, count=count)[0]


def test_craig_bampton_without_modes_is_the_guyan_reduction():
    # Chain of 3, DOF 0 retained: K_ii = k [[2, -1], [-1, 2]], K_ib = -k e1, so the constraint
    # mode is ψ = -K_ii⁻¹ K_ib = [2/3, 1/3], T = [1, 2/3, 1/3]ᵀ, K_r = 2k - 2k/3 = 4k/3 and
    # M_r = m (1 + 4/9 + 1/9) = 14 m / 9.
    m, k = 1.5, 2.0e5
    M, K = chain(3, m, k)
    r = stickslip.reduce(M, K, retained=[0], modes=0, method="cb")
    # One sparse LDLᵀ of a 2x2 K_ii and two projections: round-off, 1e-13 relative.
    np.testing.assert_allclose(r["basis"], [[1.0], [2 / 3], [1 / 3]], rtol=1e-13)
    np.testing.assert_allclose(r["stiffness"], [[4 * k / 3]], rtol=1e-13)
    np.testing.assert_allclose(r["mass"], [[14 * m / 9]], rtol=1e-13)
    assert r["retained"] == [0]
    assert r["frequencies_hz"].shape == (0,)


def test_craig_bampton_with_every_interior_mode_is_exact():
    # Chain of 5, DOFs 0 and 4 retained, the 3 fixed-interface modes kept: T spans the whole
    # space, so the reduced model has the full model's frequencies. The fixed-interface modes
    # of the clamped 3-chain are 2 sqrt(k/m) sin(jπ/8), j = 1, 2, 3.
    m, k = 1.5, 2.0e5
    M, K = chain(5, m, k)
    r = stickslip.reduce(M, K, retained=[0, 4], modes=3, method="cb")
    T = r["basis"]
    assert T.shape == (5, 5)
    # The retained DOFs are the first reduced coordinates: T restricted to them is [I 0].
    np.testing.assert_allclose(T[[0, 4], :], np.eye(5)[:2], atol=1e-14)
    # The reduced matrices are the projections Tᵀ M T, Tᵀ K T (round-off of a 5x5 product).
    np.testing.assert_allclose(r["mass"], T.T @ M @ T, rtol=1e-12, atol=1e-12 * m)
    np.testing.assert_allclose(r["stiffness"], T.T @ K @ T, rtol=1e-12, atol=1e-9 * k)
    fixed = 2 * np.sqrt(k / m) * np.sin(np.arange(1, 4) * np.pi / 8) / (2 * np.pi)
    # Lanczos stops at a Ritz residual of 1e-10; the eigenvalue error is its square, so the
    # frequencies of the basis agree far below 1e-9.
    np.testing.assert_allclose(r["frequencies_hz"], fixed, rtol=1e-9)
    full = 2 * np.sqrt(k / m) * np.sin(np.arange(1, 6) * np.pi / 12) / (2 * np.pi)
    np.testing.assert_allclose(lowest_hz(r["mass"], r["stiffness"], 5), full, rtol=1e-9)


def test_the_free_mode_basis_keeps_the_lowest_modes_exactly():
    # Chain of 12, DOF 5 retained, 3 free modes: the reduced model's 3 lowest frequencies are
    # the full model's (closed form 2 sqrt(k/m) sin(jπ/26)), to the eigensolver's accuracy.
    m, k = 1.5, 2.0e5
    M, K = chain(12, m, k)
    r = stickslip.reduce(M, K, retained=[5], modes=3, method="free")
    assert r["basis"].shape == (12, 4)
    exact = 2 * np.sqrt(k / m) * np.sin(np.arange(1, 4) * np.pi / 26) / (2 * np.pi)
    np.testing.assert_allclose(r["frequencies_hz"], exact, rtol=1e-9)
    np.testing.assert_allclose(lowest_hz(r["mass"], r["stiffness"], 3), exact, rtol=1e-9)


def test_the_enriched_basis_holds_the_lowest_mode_with_the_joint_released():
    # Chain of 12 whose spring between DOFs 3 and 4 a joint replaces: released, it is a 4-chain
    # and an 8-chain, each grounded at one end and free at the other. The lowest mode of such
    # an N-chain is ω = 2 sqrt(k/m) sin(π / (2 (2N + 1))): the 8-chain's, sin(π/34).
    m, k = 1.5, 2.0e5
    M, K = chain(12, m, k)
    d = np.zeros(12)
    d[3], d[4] = 1.0, -1.0
    r = stickslip.reduce(M, K, retained=[0], modes=2, method="enriched", releases=[(d, k)], release_modes=1)
    T = r["basis"]
    released = K - k * np.outer(d, d)
    exact = 2 * np.sqrt(k / m) * np.sin(np.pi / 34) / (2 * np.pi)
    np.testing.assert_allclose(lowest_hz(M, released, 1), [exact], rtol=1e-12)
    reduced = lowest_hz(T.T @ M @ T, T.T @ released @ T, 1)
    # The released mode is in the basis (eigensolver accuracy, as above).
    np.testing.assert_allclose(reduced, [exact], rtol=1e-9)
    # Without the enrichment the released mode is not in the basis: visibly off.
    plain = stickslip.reduce(M, K, retained=[0], modes=2, method="free")["basis"]
    off = lowest_hz(plain.T @ M @ plain, plain.T @ released @ plain, 1)
    assert abs(off[0] - exact) > 1e-3 * exact


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        (dict(method="guyan"), stickslip.InputError, 'unknown method "guyan"'),
        (dict(method="enriched"), stickslip.InputError, "needs releases"),
        (dict(method="cb", release_modes=1), stickslip.InputError, 'go with method="enriched"'),
        (dict(retained=[7]), stickslip.SolveError, "retained DOF index 7 is out of range"),
        (dict(releases=[(np.ones(2), 1.0)], method="enriched", release_modes=1), stickslip.InputError,
         r"releases\[0\]: direction has 2 values, expected 3"),
    ],
)
def test_bad_reductions_say_what_is_expected(kwargs, error, message):
    M, K = chain(3)
    args = dict(retained=[0], modes=1, method="cb")
    args.update(kwargs)
    with pytest.raises(error, match=message):
        stickslip.reduce(M, K, **args)


def test_a_matrix_of_integers_is_refused_with_its_dtype():
    M, K = chain(3)
    with pytest.raises(stickslip.InputError, match="stiffness: expected a 2-D float64 array, got an array of dtype int64"):
        stickslip.reduce(M, K.astype(np.int64), retained=[0], modes=1)
