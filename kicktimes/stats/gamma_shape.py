"""The maximum-likelihood gamma shape from two sufficient means, vectorised (for a
bootstrap that resamples sums of intervals rather than the intervals themselves)."""

from __future__ import annotations

import numpy as np
from scipy.special import digamma, polygamma

__all__ = ["gamma_shape_mle"]


def gamma_shape_mle(mean_x, mean_log_x) -> np.ndarray:
    r"""The gamma shape :math:`\hat k` of i.i.d. intervals with sample means
    :math:`\bar x` and :math:`\overline{\log x}`.

    The gamma likelihood depends on the data through these two means only; its shape
    solves :math:`\log k - \psi(k) = s` with :math:`s = \log \bar x - \overline{\log x}
    \ge 0` (Jensen), found by Newton's method from Minka's start
    :math:`k_0 = (3 - s + \sqrt{(s - 3)^2 + 24 s}) / (12 s)` (T. Minka, "Estimating a
    gamma distribution", 2002). ``s = 0`` (all intervals equal) gives ``inf``; NaN in,
    NaN out. Exponential intervals give :math:`\hat k \to 1`.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.random.default_rng(0).gamma(2.5, size=200_000)
    >>> round(float(gamma_shape_mle(x.mean(), np.log(x).mean())), 1)
    2.5
    """
    s = np.log(np.asarray(mean_x, float)) - np.asarray(mean_log_x, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = (3.0 - s + np.sqrt((s - 3.0) ** 2 + 24.0 * s)) / (12.0 * s)
        for _ in range(6):
            k = k - (np.log(k) - digamma(k) - s) / (1.0 / k - polygamma(1, k))
    return np.where(s == 0, np.inf, k)
