r"""Standard errors from an information matrix, with identifiability decided here.

Near a singular information matrix, whether ``np.linalg.inv`` or a Cholesky factorisation
succeeds, and what it returns, depends on the BLAS kernel and library versions (issue 47:
the same two-row fit gave finite standard errors under one OpenBLAS kernel and NaN under
another). :func:`inverse_information` decides first, on a criterion whose outcome can flip
only when the matrix sits within rounding of the threshold, far from the singularities the
fits meet: the information is scaled to unit diagonal,
:math:`R = D^{-1/2} I D^{-1/2}` with :math:`D = \operatorname{diag}(I)` (so the decision
does not depend on the parameters' units), and the parameters are identified when every
eigenvalue of ``R`` exceeds ``rtol`` times the largest (``rtol = 1e-10``: correlations
within :math:`10^{-10}` of :math:`\pm 1` are not).
"""

from __future__ import annotations

import numpy as np

__all__ = ["inverse_information", "IDENTIFIED_RTOL"]

#: smallest eigenvalue of the unit-diagonal information, relative to the largest, of an
#: identified parameter vector
IDENTIFIED_RTOL = 1e-10


def inverse_information(info, *, rtol=IDENTIFIED_RTOL):
    """The inverse of the symmetric information matrix ``info``, or all NaN when it is not
    finite, not positive definite, or its parameters are not identified (see the module
    notes). Returns ``(covariance, identified)``."""
    info = np.asarray(info, dtype=float)
    k = info.shape[0]
    nan = np.full((k, k), np.nan)
    if info.shape != (k, k) or not np.all(np.isfinite(info)):
        return nan, False
    info = 0.5 * (info + info.T)
    d = np.diag(info)
    if np.any(d <= 0):
        return nan, False
    s = 1.0 / np.sqrt(d)
    scaled = info * np.outer(s, s)
    eig = np.linalg.eigvalsh(scaled)
    if not np.all(np.isfinite(eig)) or eig[0] <= rtol * eig[-1]:
        return nan, False
    cov = np.linalg.inv(scaled) * np.outer(s, s)
    return 0.5 * (cov + cov.T), True
