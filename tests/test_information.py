"""Standard errors from an information matrix: identifiability decided by kicktimes
(kicktimes.stats._information), not by what a BLAS kernel returns near a singularity."""

from __future__ import annotations

import numpy as np
import pytest

from kicktimes.stats._information import IDENTIFIED_RTOL, inverse_information


def test_a_well_conditioned_information_is_inverted():
    info = np.array([[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]])
    cov, ok = inverse_information(info)
    assert ok
    np.testing.assert_allclose(cov, np.linalg.inv(info), rtol=1e-13)
    np.testing.assert_array_equal(cov, cov.T)


@pytest.mark.parametrize("scale", [1e-8, 1.0, 1e8])
def test_the_decision_does_not_depend_on_the_parameters_units(scale):
    # correlation 1 - 1e-12 (not identified) and 1 - 1e-6 (identified), in any units
    for rho, want in ((1 - 1e-12, False), (1 - 1e-6, True)):
        d = np.array([1.0, scale])
        info = np.array([[1.0, rho], [rho, 1.0]]) * np.outer(d, d)
        cov, ok = inverse_information(info)
        assert ok is want
        assert np.isnan(cov).all() != want


@pytest.mark.parametrize("info", [
    np.array([[1.0, 2.0], [2.0, 4.0]]),            # rank 1: exactly singular
    np.array([[1.0, 0.0], [0.0, -1.0]]),           # not positive definite
    np.array([[0.0, 0.0], [0.0, 1.0]]),            # a parameter with no information
    np.array([[1.0, np.nan], [np.nan, 1.0]]),      # not finite
])
def test_a_singular_or_indefinite_information_gives_nan(info):
    cov, ok = inverse_information(info)
    assert not ok and np.isnan(cov).all() and cov.shape == info.shape


def test_the_threshold_sits_far_from_rounding():
    # a kernel's rounding moves eigenvalues by ~1e-16 of the largest: the decision at
    # IDENTIFIED_RTOL cannot flip on it unless the matrix is built to sit there
    assert 1e-14 < IDENTIFIED_RTOL < 1e-6
