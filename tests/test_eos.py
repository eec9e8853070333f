"""The hard-disk equations of state of `kicktimes.stats.eos`: the coefficients tied to the
exact ones and to each other, an independent large-N dataset, and bad input."""

import math

import numpy as np
import pytest
from numpy.polynomial import polynomial as P

from kicktimes import stats
from kicktimes.stats.eos import (
    KOLAFA_ROTTNER,
    KOLAFA_ROTTNER_MAX,
    VIRIAL_COEFFICIENT_ERRORS,
    VIRIAL_COEFFICIENTS,
)


def _kolafa_rottner_virial_coefficients(k_max):
    """b_k of the Kolafa-Rottner fit's Taylor expansion in phi (x = phi / (1 - phi)),
    k = 2..k_max."""
    deg = k_max - 1
    x = np.ones(deg + 1)  # phi + phi^2 + ... (x = phi / (1 - phi))
    x[0] = 0.0
    z = np.zeros(deg + 1)
    power = np.zeros(deg + 1)
    power[0] = 1.0
    for i in range(max(KOLAFA_ROTTNER) + 1):
        if i > 0:
            power = P.polymul(power, x)[: deg + 1]
        if i in KOLAFA_ROTTNER:
            z = P.polyadd(z, KOLAFA_ROTTNER[i] * power)[: deg + 1]
    return [z[k - 1] / 2.0 ** (k - 1) for k in range(2, k_max + 1)]


def test_the_exact_coefficients():
    assert VIRIAL_COEFFICIENTS[1] == pytest.approx(0.7820044379, abs=1e-10)
    assert VIRIAL_COEFFICIENTS[2] == pytest.approx(0.5322318070, abs=1e-10)
    # the series' first terms, in powers of phi: 2, 3.12802, 4.25785 (henderson_z's notes)
    assert 4 * VIRIAL_COEFFICIENTS[1] == pytest.approx(3.12802, abs=1e-5)
    assert 8 * VIRIAL_COEFFICIENTS[2] == pytest.approx(4.25785, abs=1e-5)


def test_the_fit_is_tied_to_the_exact_coefficients():
    """Kolafa & Rottner fix A_2 and A_3 by b_3 and b_4: A_2 = 4 b_3 - 2, A_3 = 8 b_4 - 2 - 2
    A_2 (to the digits the paper gives), so a mistyped coefficient shows here."""
    b3, b4 = VIRIAL_COEFFICIENTS[1], VIRIAL_COEFFICIENTS[2]
    assert KOLAFA_ROTTNER[2] == pytest.approx(4 * b3 - 2, abs=1e-8)
    assert KOLAFA_ROTTNER[3] == pytest.approx(8 * b4 - 2 - 2 * KOLAFA_ROTTNER[2], abs=1e-8)


def test_the_fits_expansion_gives_clisby_and_mccoys_coefficients():
    """The two sources are independent (a fit to molecular dynamics, Mayer-diagram
    integrals): b_5..b_10 of the fit within 3 of Clisby & McCoy's standard errors (b_5:
    1e-6, its error is 1e-8)."""
    fit = _kolafa_rottner_virial_coefficients(10)
    for k in range(5, 11):
        b, err = VIRIAL_COEFFICIENTS[k - 2], VIRIAL_COEFFICIENT_ERRORS[k - 2]
        assert abs(fit[k - 2] - b) < max(3 * err, 1e-6), (k, fit[k - 2], b)


def test_the_series_lies_below_the_fit_by_its_tail():
    """All b_k > 0: the truncated series is below Z, by 0.005 % at 0.3 and 0.07 % at 0.4."""
    phi = np.array([0.05, 0.1, 0.2, 0.3, 0.4, 0.5])
    gap = stats.virial_z(phi) / stats.kolafa_rottner_z(phi) - 1
    assert (gap <= 1e-9).all()
    assert abs(gap[3]) < 1e-4
    assert 5e-4 < abs(gap[4]) < 1e-3
    assert 4e-3 < abs(gap[5]) < 8e-3


def test_an_independent_large_simulation_at_the_edge_of_the_fluid():
    """Engel, Anderson, Glotzer, Isobe, Bernard & Krauth, PRE 87, 042134 (2013), 1024^2
    disks: Z = 10.3175 at phi = 0.698 (their beta P (2r)^2 times pi / (4 phi)); the fit
    lies 0.03 % above it."""
    assert stats.kolafa_rottner_z(0.698) == pytest.approx(10.3175, rel=5e-4)


def test_henderson_is_an_approximation_beside_them():
    phi = np.array([0.3, 0.4, 0.6, 0.68])
    off = stats.henderson_z(phi) / stats.kolafa_rottner_z(phi) - 1
    np.testing.assert_allclose(off, [2.5e-4, 1.4e-3, 1.18e-2, 5.1e-2], rtol=0.05)


def test_arrays_scalars_and_the_low_density_limit():
    assert isinstance(stats.virial_z(0.2), float)
    assert stats.virial_z(np.array([0.2, 0.3])).shape == (2,)
    assert stats.virial_z(0.1, order=2) == pytest.approx(1.2)
    assert stats.kolafa_rottner_z(0.0) == 1.0
    # the slope at 0 is B_2 rho / phi = 2
    h = 1e-7
    assert (stats.kolafa_rottner_z(h) - 1) / h == pytest.approx(2.0, rel=1e-5)


def test_contact_theorem_and_the_enskog_frequency():
    phi = 0.3
    z = stats.henderson_z(phi)
    g = stats.contact_from_z(z, phi)
    assert g == pytest.approx(float(stats.contact_value(phi)), rel=1e-12)
    r, n = 0.01, 955
    default = stats.enskog_frequency(r, n, rule="elastic", area=1.0)
    from_z = stats.enskog_frequency(r, n, rule="elastic", area=1.0,
                                    contact=stats.contact_from_z(
                                        stats.henderson_z(n * math.pi * r * r),
                                        n * math.pi * r * r))
    assert from_z == pytest.approx(default, rel=1e-12)


@pytest.mark.parametrize(("call", "match"), [
    (lambda: stats.virial_z(0.6), r"packing must lie in \[0, 0.5\]"),
    (lambda: stats.virial_z(-0.1), "packing"),
    (lambda: stats.virial_z(np.nan), "packing"),
    (lambda: stats.virial_z(0.2, order=11), r"order must lie in \[2, 10\]"),
    (lambda: stats.virial_z(0.2, order=1), "order"),
    (lambda: stats.kolafa_rottner_z(0.71), "packing must lie in"),
    (lambda: stats.contact_from_z(2.0, 0.0), "packing must be > 0"),
    (lambda: stats.contact_from_z(np.nan, 0.3), "z must be finite"),
    (lambda: stats.enskog_frequency(0.01, 100, contact=-1.0), "contact"),
])
def test_bad_input_names_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_bad_types():
    with pytest.raises(TypeError, match="order must be an integer"):
        stats.virial_z(0.2, order=3.0)
    assert KOLAFA_ROTTNER_MAX == pytest.approx(0.70686, abs=1e-5)
