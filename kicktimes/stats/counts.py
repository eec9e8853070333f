r"""Collision counts versus disk radius, and the kinetic-theory rate.

:func:`regress_counts` fits three models to per-IC counts ``count`` observed over
``t_window`` at radius ``radius``:

* **OLS line** (the paper's Fig. "mean number of collisions vs radius"): one point
  per radius, the pooled rate :math:`\sum N / \sum T`, regressed linearly on ``r``;
  when every window has the same length ``T`` it is the paper's line of the mean
  count on ``r``, divided by ``T``;
* **Poisson GLM** with log link and offset :math:`\log T`:
  :math:`\log E[N] = \beta_0 + \beta_1 g(r) + \log T`;
* **negative binomial** (NB2, ``statsmodels.discrete.NegativeBinomial``, dispersion
  :math:`\alpha` estimated: :math:`\mathrm{Var}\,N = \mu + \alpha\mu^2`) with the same
  mean model; counts across ICs are overdispersed (sticky orbits, angular-momentum
  components), which the Poisson model ignores.

``g(r) = log r`` (default; a power law :math:`\Gamma \propto r^{\beta_1}`, which
contains the kinetic small-r law with :math:`\beta_1 = 1`) or ``g(r) = r``.

:func:`kinetic_rate` is the exact collision rate under the invariant measure.
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats
from statsmodels.discrete.discrete_model import NegativeBinomial
from statsmodels.genmod import families
from statsmodels.genmod.generalized_linear_model import GLM
from statsmodels.regression.linear_model import OLS
from statsmodels.tools.tools import add_constant

from kicktimes._results import nan_reason
from kicktimes.validation import keyword_only_after

from ._checks import as_1d_float, check_choice
from ._information import inverse_information
from .renewal import FitWarning

# |coefficient| beyond this on log-rate scale means the MLE ran off to infinity
# (e.g. every count zero at one of two radii: perfect separation)
_DIVERGED_COEF = 1e3

_MEAN_APPROACH = {"mirror": 4.0 / math.pi**2, "elastic": 4.0 / (3.0 * math.pi)}
_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(64)


def lens_area(d, a):
    r"""Area of the overlap of two disks of radius ``a`` whose centres are ``d`` apart:
    :math:`L(d) = 2a^2\arccos\frac{d}{2a} - \frac{d}{2}\sqrt{4a^2 - d^2}` for
    :math:`0 \le d \le 2a`."""
    d = np.asarray(d, dtype=float)
    a = np.asarray(a, dtype=float)
    ratio = np.clip(d / (2 * a), 0.0, 1.0)
    return 2 * a**2 * np.arccos(ratio) - 0.5 * d * np.sqrt(np.maximum(4 * a**2 - d**2, 0.0))


def lens_area_two(d, a, b):
    r"""Area of the overlap of two disks of radii ``a`` and ``b`` whose centres are ``d``
    apart: :math:`a^2 \arccos\frac{d^2 + a^2 - b^2}{2da} + b^2 \arccos\frac{d^2 + b^2 -
    a^2}{2db} - \frac12\sqrt{(-d+a+b)(d+a-b)(d-a+b)(d+a+b)}` for :math:`|a-b| < d < a+b`,
    :math:`\pi \min(a, b)^2` for :math:`d \le |a - b|` (one disk inside the other)."""
    d = np.asarray(d, dtype=float)
    inside = d <= abs(a - b)
    dd = np.where(inside, abs(a - b) + 1.0, d)  # (a placeholder where one disk is inside)
    ca = np.clip((dd * dd + a * a - b * b) / (2 * dd * a), -1.0, 1.0)
    cb = np.clip((dd * dd + b * b - a * a) / (2 * dd * b), -1.0, 1.0)
    k = np.maximum((-dd + a + b) * (dd + a - b) * (dd - a + b) * (dd + a + b), 0.0)
    area = a * a * np.arccos(ca) + b * b * np.arccos(cb) - 0.5 * np.sqrt(k)
    return np.where(inside, np.pi * min(a, b) ** 2, np.where(d >= a + b, 0.0, area))


def _kinetic_rate_unequal(r0, r1, rule):
    """`kinetic_rate` of two disks of radii ``r0``, ``r1`` (equal masses)."""
    a, b, sigma = 1.0 - r0, 1.0 - r1, r0 + r1
    # the configurations with the centres closer than sigma, excluded: the 2-D integral of
    # L over the distance (smooth on [0, sigma]; a kink at |a - b| < sigma is split off)
    edges = sorted({0.0, min(abs(a - b), sigma), sigma})
    excluded = 0.0
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        if hi > lo:
            rho = lo + (hi - lo) * 0.5 * (1.0 + _GL_NODES)
            excluded += 0.5 * (hi - lo) * float(
                (2 * np.pi * rho * lens_area_two(rho, a, b) * _GL_WEIGHTS).sum())
    volume = (np.pi * a * a) * (np.pi * b * b) - excluded
    contact = 2 * np.pi * sigma * float(lens_area_two(sigma, a, b))
    return contact * _MEAN_APPROACH[rule] / volume


_TABLE_METHODS = ("check_radius", "area", "covariogram", "configuration_volume")


def _kinetic_rate_table(r, rule, table):
    """`kinetic_rate` (equal masses) of two disks of radius ``r`` in a table other than the
    unit circle, from its covariogram (duck-typed: `_TABLE_METHODS`)."""
    missing = [m for m in _TABLE_METHODS if not callable(getattr(table, m, None))]
    if missing:
        raise TypeError(f"table must be None or a kicktimes.tables table (Circle, Stadium, "
                        f"Ellipse: with {', '.join(_TABLE_METHODS)}), got "
                        f"{type(table).__name__} (no {', '.join(missing)})")
    if isinstance(r, tuple):
        raise ValueError(f"r: two disks of different radii {r!r} are the unit circle's only "
                         f"(table=None); give one radius for {table!r}")
    if isinstance(r, str | bytes):
        raise TypeError(f"r must be a number or an array of numbers, got {type(r).__name__}")
    scalar = np.ndim(r) == 0
    arr = as_1d_float("r", np.ravel(r), allow_empty=False)
    # each distinct radius once (a store's table repeats its radii per IC; one quadrature
    # of the ellipse's covariogram takes about a second), cached per (table, radius)
    values, inverse = np.unique(arr, return_inverse=True)
    out = np.empty(values.size)
    for i, ri in enumerate(values):
        ri = table.check_radius(float(ri))
        try:
            out[i] = _table_rate(table, ri, rule)
        except ValueError:
            where = "" if scalar else f"[{int(np.flatnonzero(arr == ri)[0])}]"
            raise ValueError(f"r: two disks of radius r{where} = {ri!r} do not fit in "
                             f"{table!r} with their centres 2 r apart") from None
    out = out[inverse]
    return float(out[0]) if scalar else out.reshape(np.shape(r))


@functools.lru_cache(maxsize=256)
def _table_rate(table, r: float, rule: str) -> float:
    """`_kinetic_rate_table` at one checked radius (a ValueError if the disks do not fit)."""
    sigma = 2.0 * r
    contact = float(table.covariogram(sigma, r))
    if not contact > 0.0:
        raise ValueError("no contact")
    return 2 * np.pi * sigma * contact * _MEAN_APPROACH[rule] / float(
        table.configuration_volume(r))


def configuration_volume(r):
    r"""Volume of the two-disk configuration space,
    :math:`|Q| = (\pi a^2)^2 - \int_0^{2r} 2\pi\rho L(\rho)\,d\rho` with ``a = 1 - r``
    (64-point Gauss-Legendre; the integrand is smooth on ``[0, 2r]`` for r < 1/2)."""
    r = np.asarray(r, dtype=float)
    a = 1.0 - r
    rho = r[..., None] * (1.0 + _GL_NODES)  # maps [-1, 1] onto [0, 2r]
    integrand = 2 * np.pi * rho * lens_area(rho, a[..., None])
    excluded = r * (integrand * _GL_WEIGHTS).sum(axis=-1)
    return (np.pi * a**2) ** 2 - excluded


#: A two-disk run is *sticky* when its disk-disk collision rate exceeds this multiple of the
#: kinetic rate Gamma(r) (`kinetic_rate`): the disks stay close together for long stretches
#: near a regular orbit. The one definition of the rule (`is_sticky`), used by every page.
STICKY_FACTOR = 5.0


def is_sticky(rate, kinetic, *, factor=STICKY_FACTOR):
    r"""Whether runs are sticky: :math:`\hat\Gamma > c\,\Gamma(r)`, ``c = factor``.

    Parameters
    ----------
    rate : float or array_like
        Observed disk-disk collision rates :math:`\hat\Gamma = N / T` of the runs.
    kinetic : float or array_like
        The kinetic rate :math:`\Gamma(r)` of each run's disks (`kinetic_rate`),
        broadcast against ``rate``.
    factor : float
        The multiple ``c`` (default `STICKY_FACTOR`, 5): a run faster than ``c`` kinetic
        rates is sticky. Invariant-measure runs have :math:`E[\hat\Gamma] = \Gamma`, so
        the rule flags the runs caught near a regular orbit, not the spread of ordinary
        ones.

    Returns
    -------
    bool or ndarray of bool
        ``rate > factor * kinetic`` (a NaN rate is not sticky).

    Examples
    --------
    >>> from kicktimes import stats
    >>> g = stats.kinetic_rate(0.02)
    >>> stats.is_sticky([0.5 * g, 4.9 * g, 5.1 * g], g).tolist()
    [False, False, True]
    """
    out = np.asarray(rate, dtype=float) > factor * np.asarray(kinetic, dtype=float)
    return out if out.ndim else bool(out)


@keyword_only_after(1, since="0.2.0", names=('rule',))
def kinetic_rate(r, *, rule="mirror", masses=None, table=None):
    r"""Disk-disk collision rate of two disks of radius ``r`` under the invariant measure.

    Parameters
    ----------
    r : float or array_like or tuple
        Disk radius, ``0 < r < 0.5`` (an array: one rate per radius); a *tuple*
        ``(r0, r1)``: two disks of different radii (equal masses), one rate.
    rule : {"mirror", "elastic"}
        Collision rule, which fixes the velocity measure.
    masses : (float, float), optional
        Elastic rule: the disks' masses, normalised to ``(m0 + m1) / 2 = 1`` (velocities
        uniform on ``m0 |v0|^2 + m1 |v1|^2 = 2``, as
        ``initial_conditions(..., masses=...)`` draws them); default equal.
    table : None or a table, optional
        The billiard table (`kicktimes.tables`): ``None`` or ``Circle()`` is the unit
        circle (the closed form below); another table (``Stadium(a)``, ``Ellipse(a, b)``,
        or any object with ``check_radius(r)``, ``area(r)``, ``covariogram(d, r)`` and
        ``configuration_volume(r)``) gives the rate by the quadrature of its centre
        region's covariogram (Notes). Two disks of the same radius only there.

    Returns
    -------
    float or ndarray
        :math:`\Gamma = 4\pi r\, L(2r)\, E[(w\cdot n)^-] / |Q|` (collisions per unit
        time), same shape as ``r``.

    Notes
    -----
    With ``a = 1 - r``, ``L`` the lens area and ``|Q|`` the configuration volume
    (:func:`lens_area`, :func:`configuration_volume`). The flux factor is
    :math:`E[(w\cdot n)^-] = 4/\pi^2` for the mirror rule (unit speeds, independent
    uniform directions) and :math:`4/(3\pi)` for the elastic rule
    (:math:`|v_1|^2 + |v_2|^2 = 2`, uniform on that sphere). For small r the mirror
    rate tends to :math:`16 r / (\pi^2 a^2)`. Because the measure is invariant,
    :math:`E[N(T)] = \Gamma T` exactly when ICs are drawn from it. Unequal disks, radii
    :math:`r_0, r_1` (centres in :math:`|x_i| \le a_i = 1 - r_i`, contact at
    :math:`\sigma = r_0 + r_1`): :math:`\Gamma = 2\pi\sigma\, L(\sigma; a_0, a_1)\,
    E[(w\cdot n)^-] / |Q|` with :math:`L(d; a_0, a_1)` the overlap of disks of radii
    :math:`a_0, a_1` at distance :math:`d` (`lens_area_two`) and :math:`|Q| = \pi^2 a_0^2
    a_1^2 - \int_0^\sigma 2\pi d\, L(d; a_0, a_1)\,dd`.

    *Any table.* The centres keep to the table's inner parallel domain :math:`D_r`
    (docs/tables.md) and the same argument gives, with :math:`\sigma = 2r`,

    .. math::  \Gamma = 2\pi\sigma\, g(\sigma)\, E[(w\cdot n)^-] / |Q|, \qquad
               |Q| = |D_r|^2 - \int_0^\sigma 2\pi d\, g(d)\, dd ,

    :math:`g` the isotropic set covariogram of :math:`D_r` (the area of
    :math:`D_r \cap (D_r + d\,e(\phi))` averaged over :math:`\phi`; in the circle the
    lens area :math:`L`), by the table's quadrature (``table.covariogram``,
    ``table.configuration_volume``); the flux factor does not depend on the table. As
    :math:`r \to 0`, :math:`g(\sigma) = |D_r| - L_r \sigma / \pi + O(\sigma^2)`
    (:math:`L_r` the perimeter of :math:`D_r`) and :math:`|Q| = |D_r|^2 (1 + O(\sigma^2))`,
    so :math:`\Gamma = (2\pi\sigma E[(w\cdot n)^-] / |D_r|)\,(1 - L_r\sigma/(\pi |D_r|)
    + O(\sigma^2))`; in the circle this is :math:`16 r / (\pi^2 a^2)` to first order.

    Examples
    --------
    >>> from kicktimes import stats
    >>> round(float(stats.kinetic_rate(0.01)), 5)
    0.01633
    >>> from kicktimes.tables import Stadium
    >>> round(float(stats.kinetic_rate(0.01, table=Stadium(1.0))), 5)
    0.00717
    """
    check_choice("rule", rule, tuple(_MEAN_APPROACH))
    factor = 1.0
    if masses is not None:
        if rule != "elastic":
            raise ValueError(f"masses apply to rule='elastic', got rule={rule!r}")
        m = as_1d_float("masses", np.asarray(masses, dtype=float), allow_empty=False)
        if m.size != 2 or (m <= 0).any():
            raise ValueError(f"masses must be a pair of positive masses, got {masses!r}")
        m = 2.0 * m / m.sum()
        # the projection of (sqrt(m0) v0, sqrt(m1) v1), uniform on a 3-sphere of radius
        # sqrt 2, on two directions is uniform on a disk: E[(w.n)^-] scales with
        # sqrt((1/m0 + 1/m1) / 2)
        factor = math.sqrt((1.0 / m[0] + 1.0 / m[1]) / 2.0)
    if table is not None and not getattr(table, "is_unit_circle", False):
        return factor * _kinetic_rate_table(r, rule, table)
    if isinstance(r, tuple):
        # two disks of different radii
        if len(r) != 2:
            raise ValueError(f"r: a tuple gives the two disks' radii (r0, r1), got {r!r}")
        radii = as_1d_float("r", np.asarray(r, dtype=float), allow_empty=False)
        if ((radii <= 0) | (radii >= 0.5)).any():
            raise ValueError(f"r: each radius must satisfy 0 < r < 0.5, got {r!r}")
        return factor * _kinetic_rate_unequal(float(radii[0]), float(radii[1]), rule)
    scalar = np.ndim(r) == 0
    if isinstance(r, str | bytes):
        raise TypeError(f"r must be a number or an array of numbers, got {type(r).__name__}")
    arr = as_1d_float("r", np.ravel(r), allow_empty=False)
    bad = (arr <= 0) | (arr >= 0.5)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        where = "" if scalar else f"[{i}]"
        raise ValueError(
            f"r must satisfy 0 < r < 0.5 for two disks, got r{where} = {float(arr[i])!r}"
        )
    a = 1.0 - arr
    rate = (
        4 * np.pi * arr * lens_area(2 * arr, a) * _MEAN_APPROACH[rule] / configuration_volume(arr)
    )
    rate = rate * factor if masses is not None else rate
    return float(rate[0]) if scalar else rate.reshape(np.shape(r))


def _check_frame(df, radius, count, t_window):
    if not isinstance(df, pd.DataFrame):
        raise TypeError(f"df must be a pandas DataFrame, got {type(df).__name__}")
    for col in (radius, count, t_window):
        if col not in df.columns:
            raise ValueError(f"df must have a column {col!r}; it has {list(df.columns)!r}")
    if len(df) == 0:
        raise ValueError("df must not be empty")
    r = as_1d_float(f"df[{radius!r}]", df[radius].to_numpy())
    n = as_1d_float(f"df[{count!r}]", df[count].to_numpy())
    t = as_1d_float(f"df[{t_window!r}]", df[t_window].to_numpy())
    checks = [
        (r, (r <= 0) | (r >= 0.5), radius, "0 < radius < 0.5"),
        (n, (n < 0) | (n != np.round(n)), count, "non-negative integers"),
        (t, t <= 0, t_window, "positive"),
    ]
    for arr, bad, col, rule in checks:
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"df[{col!r}] must be {rule}, got row {i}: {float(arr[i])!r}")
    if np.unique(r).size < 2:
        raise ValueError(
            f"df[{radius!r}] takes one value ({float(r[0])!r}): no slope to estimate; give "
            "at least two radii"
        )
    hit = np.unique(r[n > 0])
    if hit.size < 2:
        # a log-linear slope needs counts at two radii at least, else it runs off to
        # +-inf (the counts at the other radii are 0: separation)
        where = "at no radius" if hit.size == 0 else f"only at radius {float(hit[0])!r}"
        raise ValueError(
            f"df[{count!r}] must be non-zero at 2 or more radii for the slope in radius to "
            f"exist; the counts are non-zero {where}"
        )
    return pd.DataFrame({"radius": r, "count": n, "t_window": t})


@dataclass(frozen=True, repr=False)
class CountRegression:
    """Result of :func:`regress_counts`: the three fits and their comparison.

    Every standard error, interval and log-likelihood here is decided by kicktimes from
    the data's shape (see :func:`regress_counts`, Notes), never by what a BLAS kernel or a
    statsmodels version happens to return near a singular matrix.

    Attributes
    ----------
    data : DataFrame
        ``radius``, ``count``, ``t_window`` as fitted.
    by_radius : DataFrame
        Per radius: ``n_ics``, ``total_count``, ``exposure``, ``rate`` (pooled),
        ``mean_count``, ``var_count``, ``dispersion_index`` (variance / mean).
    estimates : DataFrame
        The table :meth:`coefficients` returns.
    covariances : dict of str to ndarray
        ``"ols"``, ``"poisson"``, ``"negbin"``: the covariance of each model's parameters
        as kicktimes decided it (all NaN where undefined).
    loglik : dict of str to float
        Maximised log-likelihoods of ``"poisson"`` and ``"negbin"``.
    ols, poisson : statsmodels results
        The OLS line of rate on radius and the Poisson GLM, for everything else
        statsmodels offers (``rsquared``, residuals ...).
    negbin : statsmodels results or None
        The NB2 fit; None when the maximum-likelihood estimate is on the boundary
        ``alpha = 0``, where the model is the Poisson one and no optimiser is run.
    covariate : {"log_radius", "radius"}
        The regressor of the two count models.
    rule : str or None
        Collision rule of the kinetic-theory column, if any.
    converged : bool
        False when the Poisson or negative-binomial fit did not converge or a
        coefficient ran off to infinity; the numbers are then not an MLE.
    warnings : tuple of str
        Every problem (issued as a `FitWarning` by :func:`regress_counts`) and every
        note on an undefined quantity (a NaN is never left unexplained).
    """

    data: pd.DataFrame
    by_radius: pd.DataFrame
    estimates: pd.DataFrame
    covariances: dict
    loglik: dict
    ols: object
    poisson: object
    negbin: object
    covariate: str
    rule: str | None
    converged: bool = True
    warnings: tuple = ()

    def __repr__(self) -> str:
        flag = "" if self.converged else ", converged=False"
        return (
            f"CountRegression(n={len(self.data)}, radii={len(self.by_radius)}, "
            f"covariate={self.covariate!r}, alpha={self.alpha:.4g}{flag})"
        )

    @property
    def reason(self) -> str | None:
        """Why an estimate or a standard error is NaN (the `warnings`, where every NaN is
        explained), None when all are finite."""
        return nan_reason(self.estimates[["estimate", "stderr"]].to_numpy().ravel(),
                          self.warnings)

    @property
    def alpha(self) -> float:
        """Negative-binomial dispersion ``alpha`` (``Var N = mu + alpha mu^2``)."""
        return float(self.estimates.loc[("negbin", "alpha"), "estimate"])

    @property
    def aic(self) -> dict:
        """AIC of the Poisson (2 parameters) and negative-binomial (3) models."""
        return {"poisson": 4.0 - 2.0 * self.loglik["poisson"],
                "negbin": 6.0 - 2.0 * self.loglik["negbin"]}

    def params(self, model) -> np.ndarray:
        """Estimates of ``model`` (``"ols"``, ``"poisson"`` or ``"negbin"``), in order."""
        check_choice("model", model, _MODELS)
        return self.estimates.loc[model, "estimate"].to_numpy()

    def cov_params(self, model) -> np.ndarray:
        """Covariance of the estimates of ``model``; all NaN where kicktimes decided the
        standard errors are undefined (the reason is in ``warnings``)."""
        check_choice("model", model, _MODELS)
        return self.covariances[model].copy()

    def coefficients(self) -> pd.DataFrame:
        """Estimates, standard errors and 95% intervals of every model's parameters.

        The OLS interval uses Student's t on the line's residual degrees of freedom, the
        count models' are Wald intervals (as statsmodels' ``conf_int``).
        """
        return self.estimates.copy()

    def overdispersion(self) -> pd.Series:
        """Pearson dispersion of the Poisson fit and the LR test of ``alpha = 0``.

        The null ``alpha = 0`` is on the boundary, so the LR statistic is a 50:50
        mixture of 0 and chi-square(1): p = chi2.sf(LR, 1) / 2. The Pearson dispersion
        (chi-square over the residual degrees of freedom) is NaN for 2 rows, which leave
        none (`regress_counts` warns).
        """
        lr = max(0.0, 2 * (self.loglik["negbin"] - self.loglik["poisson"]))
        df_resid = len(self.data) - 2
        pearson = float(self.poisson.pearson_chi2 / df_resid) if df_resid > 0 else math.nan
        return pd.Series(
            {
                "pearson_dispersion": pearson,
                "lr_statistic": lr,
                "lr_pvalue": 0.5 * stats.chi2.sf(lr, 1) if lr > 0 else 1.0,
                "alpha": self.alpha,
            }
        )

    @keyword_only_after(1, since="0.2.0")
    def predict(self, radius, *, t_window=1.0) -> pd.DataFrame:
        """Expected counts at ``radius`` over ``t_window`` from each model.

        Columns ``radius``, ``t_window``, ``ols``, ``poisson``, ``negbin`` and, when
        a rule was given, ``kinetic`` (:func:`kinetic_rate` times ``t_window``).
        """
        r = as_1d_float("radius", radius, allow_empty=False)
        bad = (r <= 0) | (r >= 0.5)
        if bad.any():
            raise ValueError(f"radius must satisfy 0 < r < 0.5, got {float(r[bad][0])!r}")
        t = np.broadcast_to(as_1d_float("t_window", t_window, allow_empty=False), r.shape)
        if (t <= 0).any():
            raise ValueError(f"t_window must be positive, got {float(t[t <= 0][0])!r}")
        g = np.log(r) if self.covariate == "log_radius" else r
        b_ols, b_poi, b_nb = (self.params(m)[:2] for m in _MODELS)
        out = pd.DataFrame({"radius": r, "t_window": t})
        out["ols"] = (b_ols[0] + b_ols[1] * r) * t
        out["poisson"] = np.exp(b_poi[0] + b_poi[1] * g) * t
        out["negbin"] = np.exp(b_nb[0] + b_nb[1] * g) * t
        if self.rule is not None:
            out["kinetic"] = kinetic_rate(r, rule=self.rule) * t
        return out

    def to_frame(self) -> pd.DataFrame:
        """The coefficient table of every model (`coefficients`)."""
        return self.coefficients()

    def summary(self) -> str:
        """Coefficient tables, overdispersion and the per-radius table as text."""
        fmt = {"float_format": lambda v: f"{v:.5g}"}
        od = self.overdispersion()
        aic = self.aic
        lines = [
            f"Collision counts vs radius: {len(self.data)} ICs at {len(self.by_radius)} radii",
            "OLS line: pooled rate = intercept + slope * r (the paper's line, per unit time);",
            f"count models: log E[N] = b0 + b1 * {self.covariate} + log t_window",
            self.coefficients().to_string(**fmt),
            "",
            f"Poisson Pearson dispersion {od['pearson_dispersion']:.4g}; NB alpha = "
            f"{od['alpha']:.4g}, LR test of alpha = 0: {od['lr_statistic']:.4g} "
            f"(p = {od['lr_pvalue']:.3g})",
            f"AIC: Poisson {aic['poisson']:.6g}, negative binomial {aic['negbin']:.6g}",
            "",
            self.by_radius.to_string(**fmt),
        ]
        if not self.converged:
            lines.append("NOT CONVERGED: the count models above are not maximum-likelihood fits")
        lines.extend(f"warning: {w}" for w in self.warnings)
        return "\n".join(lines)


_MODELS = ("ols", "poisson", "negbin")


def _coefficient_rows(model, names, params, cov, quantile):
    """Rows of the coefficient table: estimate, standard error and the interval
    ``estimate +- quantile * stderr`` (NaN where the covariance is)."""
    se = np.sqrt(np.diag(cov))
    return [
        {"model": model, "term": term, "estimate": float(b), "stderr": float(s),
         "ci_low": float(b - quantile * s), "ci_high": float(b + quantile * s)}
        for term, b, s in zip(names, params, se, strict=True)
    ]


def _nb2_boundary_score(y, mu):
    r"""The score of the NB2 log-likelihood in ``alpha`` at ``alpha = 0`` and the Poisson
    MLE, :math:`\tfrac12\sum_i [(y_i - \mu_i)^2 - y_i]` (Cameron & Trivedi 1990). The
    score in the coefficients is zero there, so when this one is <= 0 the point
    ``(beta_Poisson, 0)`` meets the Karush-Kuhn-Tucker conditions of ``alpha >= 0``, and
    `regress_counts` takes it as the negative-binomial fit (the Poisson one) instead of
    running an optimiser towards the boundary."""
    return 0.5 * float(np.sum((y - mu) ** 2 - y))


def regress_counts(
    df, *, covariate="log_radius", rule=None, radius="radius", count="count", t_window="t_window"
):
    r"""Regress collision counts on radius: OLS line, Poisson and negative binomial.

    Parameters
    ----------
    df : pandas.DataFrame
        One row per initial condition with columns ``radius`` (``0 < r < 0.5``),
        ``count`` (non-negative integer) and ``t_window`` (positive).
    covariate : {"log_radius", "radius"}, optional
        Regressor ``g(r)`` of the count models (see the module notes).
    rule : {"mirror", "elastic"}, optional
        Add the kinetic-theory prediction for this rule to ``predict()``.
    radius, count, t_window : str, optional
        Column names.

    Returns
    -------
    CountRegression
        With ``summary()``, ``predict()``, ``coefficients()``, ``overdispersion()``,
        ``cov_params()``, ``aic``, ``converged`` and ``warnings``.

    Raises
    ------
    ValueError
        Bad input naming the column (``df['count']`` ...); one radius only (there is no
        slope to estimate: give at least two radii); counts non-zero at fewer than two
        radii (the slope runs off to infinity).

    Warns
    -----
    FitWarning
        A count model did not converge, a coefficient diverged, or a model has no
        residual degrees of freedom (its standard errors are then NaN, named in the
        warning; the estimates are still returned). Never a silent NaN.

    Notes
    -----
    Poisson: ``GLM(count, [1, g(r)], family=Poisson(), offset=log t)``. Negative
    binomial: ``NegativeBinomial(count, [1, g(r)], loglike_method="nb2",
    offset=log t)``, which estimates :math:`\alpha` by maximum likelihood (the GLM
    family would hold it fixed).

    Which standard errors exist is decided here from the data's shape, so that no result
    depends on how a BLAS kernel or a statsmodels version treats a singular matrix:

    * the OLS line (one point per radius, 2 coefficients) has ``k - 2`` residual degrees
      of freedom over ``k`` radii: through 2 radii it is exact and its standard errors
      are NaN;
    * the Poisson model's scale is fixed at 1, so its standard errors (the inverse Fisher
      information, full rank from two radii on) need no residual degrees of freedom; its
      Pearson dispersion does, and is NaN for 2 rows;
    * the negative binomial has 3 parameters: ``n <= 3`` rows leave it no residual
      degrees of freedom and its standard errors are NaN. When the score in
      :math:`\alpha` at :math:`\alpha = 0` is <= 0 (the Karush-Kuhn-Tucker condition of
      :math:`\alpha \ge 0` there) the fit is taken on that boundary, where it equals the
      Poisson fit (no optimiser is run): the coefficients' standard errors are
      then the Poisson ones (the NB2 information is block-diagonal at
      :math:`\alpha = 0`) and :math:`\alpha`'s is NaN (a Wald interval is not valid on a
      boundary; use the LR test of :meth:`CountRegression.overdispersion`).

    References
    ----------
    Cameron, A. C. & Trivedi, P. K. (1990). Regression-based tests for overdispersion in
    the Poisson model. *J. Econometrics* 46, 347-364.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> from kicktimes import stats
    >>> rng = np.random.default_rng(0)
    >>> r = np.repeat([0.01, 0.02, 0.03], 50)
    >>> df = pd.DataFrame({"radius": r, "count": rng.poisson(160 * r * 100), "t_window": 100.0})
    >>> reg = stats.regress_counts(df, rule="mirror")
    >>> round(float(reg.coefficients().loc[("poisson", "log_radius"), "estimate"]), 1)
    1.0
    """
    check_choice("covariate", covariate, ("log_radius", "radius"))
    if rule is not None:
        check_choice("rule", rule, tuple(_MEAN_APPROACH))
    data = _check_frame(df, radius, count, t_window)
    grouped = data.groupby("radius", observed=True)
    by_radius = pd.DataFrame(
        {
            "n_ics": grouped.size(),
            "total_count": grouped["count"].sum(),
            "exposure": grouped["t_window"].sum(),
            "mean_count": grouped["count"].mean(),
            "var_count": grouped["count"].var(ddof=1),
        }
    )
    by_radius.insert(3, "rate", by_radius["total_count"] / by_radius["exposure"])
    with np.errstate(divide="ignore", invalid="ignore"):
        by_radius["dispersion_index"] = by_radius["var_count"] / by_radius["mean_count"]
    g = (
        np.log(data["radius"].to_numpy())
        if covariate == "log_radius"
        else data["radius"].to_numpy()
    )
    exog = add_constant(g)
    offset = np.log(data["t_window"].to_numpy())
    y = data["count"].to_numpy()
    n_rows, n_radii = len(data), len(by_radius)
    problems, notes, no_df = [], [], []
    nan2, nan3 = np.full((2, 2), np.nan), np.full((3, 3), np.nan)
    with warnings.catch_warnings(record=True) as caught, np.errstate(all="ignore"):
        # statsmodels' own warnings are judged below and re-issued as one FitWarning
        warnings.simplefilter("always")
        ols = OLS(by_radius["rate"].to_numpy(), add_constant(by_radius.index.to_numpy())).fit()
        if n_radii > 2:
            cov = {"ols": np.asarray(ols.cov_params(), float)}
        else:
            cov = {"ols": nan2}
            no_df.append("the OLS line through 2 radii is exact (its standard errors are NaN)")
        poisson = GLM(y, exog, family=families.Poisson(), offset=offset).fit()
        if not getattr(poisson, "converged", True):
            problems.append("the Poisson GLM did not converge (IRLS iteration limit)")
        cov["poisson"] = inverse_information(-poisson.model.hessian(poisson.params))[0]
        loglik = {"poisson": float(poisson.llf)}
        if _nb2_boundary_score(y, np.asarray(poisson.mu, float)) <= 0:
            negbin = None
            nb_params = np.r_[np.asarray(poisson.params, float), 0.0]
            loglik["negbin"] = loglik["poisson"]
            cov["negbin"] = nan3.copy()
            cov["negbin"][:2, :2] = cov["poisson"]
            if n_rows > 3:
                notes.append(
                    "negative binomial: the maximum-likelihood alpha is on its boundary 0 "
                    "(no overdispersion: the score in alpha at 0 is <= 0), so the model is "
                    "the Poisson fit; alpha has no standard error there (use the LR test)")
        else:
            negbin = NegativeBinomial(y, exog, loglike_method="nb2", offset=offset).fit(
                disp=0, maxiter=500, start_params=np.r_[poisson.params, 0.1]
            )
            if not negbin.mle_retvals.get("converged", True):
                problems.append("the negative-binomial fit did not converge")
            nb_params = np.asarray(negbin.params, float)
            loglik["negbin"] = float(negbin.llf)
            # the observed information at the MLE, inverted under kicktimes' own rule
            cov["negbin"] = inverse_information(-negbin.model.hessian(nb_params))[0]
    converged = not problems
    if n_rows <= 2:
        no_df.append("2 rows leave the Poisson GLM none (its Pearson dispersion is NaN; its "
                     "standard errors need none)")
    if n_rows <= 3:
        no_df.append(f"{n_rows} rows leave the negative binomial's 3 parameters (2 "
                     "coefficients and alpha) none (its standard errors are NaN)")
        cov["negbin"] = nan3
    if no_df:
        problems.append(f"no residual degrees of freedom: {'; '.join(no_df)}; the estimates "
                        "are returned, and at least 3 radii and 4 rows give every standard "
                        "error")
    for name, coef in (("poisson", np.asarray(poisson.params)), ("negbin", nb_params[:2])):
        if not np.all(np.isfinite(coef)) or np.any(np.abs(coef) > _DIVERGED_COEF):
            problems.append(
                f"{name} coefficients {coef.tolist()} diverge (no finite MLE: e.g. all "
                "counts zero at one radius)"
            )
            converged = False
    alpha = float(nb_params[-1])
    if not np.isfinite(alpha):
        problems.append(f"the negative-binomial dispersion alpha is not finite ({alpha})")
        converged = False
    # what is left non-finite was not decided above: a numerical failure, said so
    decided_nan = {"ols": n_radii <= 2, "poisson": False, "negbin": n_rows <= 3}
    bad_se = [name for name in _MODELS if not decided_nan[name]
              and not np.all(np.isfinite(np.diag(cov[name])[: 2 if negbin is None else 3]))]
    if bad_se:
        problems.append(f"standard errors of the {', '.join(bad_se)} fit are not finite")
    if problems:
        # keep statsmodels' own words for the record (deduplicated)
        extra = sorted({str(w.message).splitlines()[0] for w in caught
                        if "converge" in str(w.message).lower()})
        problems.extend(f"statsmodels: {m}" for m in extra)
        status = "" if converged else "did not converge: "
        warnings.warn(
            f"regress_counts: {status}{'; '.join(problems)}", FitWarning, stacklevel=2
        )
    z = float(stats.norm.ppf(0.975))
    t_q = float(stats.t.ppf(0.975, n_radii - 2)) if n_radii > 2 else math.nan
    rows = _coefficient_rows("ols", ["intercept", "radius"], np.asarray(ols.params, float),
                             cov["ols"], t_q)
    rows += _coefficient_rows("poisson", ["intercept", covariate],
                              np.asarray(poisson.params, float), cov["poisson"], z)
    rows += _coefficient_rows("negbin", ["intercept", covariate, "alpha"], nb_params,
                              cov["negbin"], z)
    return CountRegression(
        data=data,
        by_radius=by_radius,
        estimates=pd.DataFrame(rows).set_index(["model", "term"]),
        covariances=cov,
        loglik=loglik,
        ols=ols,
        poisson=poisson,
        negbin=negbin,
        covariate=covariate,
        rule=rule,
        converged=converged,
        warnings=tuple(problems + notes),
    )
