"""Interval distributions of renewal schedules: scipy names, (de)serialisation, samplers."""

from __future__ import annotations

import importlib
import math

import numpy as np

from kicktimes.validation import check_real


# ------------------------------------------------------------------------ distributions
def _is_frozen(obj):
    from scipy.stats import rv_continuous  # scipy.stats only when a law is used

    return isinstance(getattr(obj, "dist", None), rv_continuous) and hasattr(obj, "args")


def resolve_distribution(name):
    """Continuous distribution family from its name.

    The name is looked up first in ``scipy.stats`` and then in
    ``kicktimes.stats.distributions`` (extra families of the statistics layer, e.g.
    ``hyperexpon``), by attribute name or by the family's ``.name``.

    Parameters
    ----------
    name : str
        For example ``"gamma"``, ``"weibull_min"``, ``"lomax"``.

    Returns
    -------
    scipy.stats.rv_continuous
        The (unfrozen) family; call it with parameters to freeze it.

    Examples
    --------
    >>> resolve_distribution("gamma")(2.0, scale=0.5).mean()
    np.float64(1.0)
    """
    import scipy.stats
    from scipy.stats import rv_continuous

    if not isinstance(name, str):
        raise TypeError(f"distribution name must be a str, got {name!r}")
    family = getattr(scipy.stats, name, None)
    if isinstance(family, rv_continuous):
        return family
    try:
        module = importlib.import_module("kicktimes.stats.distributions")
    except ImportError as exc:
        where = f"scipy.stats (kicktimes.stats.distributions is not importable: {exc})"
    else:
        family = getattr(module, name, None)
        if isinstance(family, rv_continuous):
            return family
        for obj in vars(module).values():
            if isinstance(obj, rv_continuous) and obj.name == name:
                return obj
        where = "scipy.stats or kicktimes.stats.distributions"
    raise ValueError(f"unknown distribution name {name!r}: no continuous distribution in {where}")


def _dist_params(dist):
    """Canonical ``(name, ((shape, value), ...), loc, scale)`` of a frozen distribution."""
    shapes, loc, scale = dist.dist._parse_args(*dist.args, **dist.kwds)
    names = [s.strip() for s in (dist.dist.shapes or "").split(",") if s.strip()]
    values = []
    for label, v in zip([*names, "loc", "scale"], [*shapes, loc, scale], strict=True):
        if np.ndim(v) != 0:
            raise ValueError(f"dist parameter {label} must be a scalar, got {v!r}")
        values.append(check_real(f"dist parameter {label}",
                                 v if not isinstance(v, np.ndarray) else v[()]))
    return dist.dist.name, tuple(zip(names, values[:-2], strict=True)), values[-2], values[-1]


def _check_dist(dist):
    from scipy.stats import rv_continuous, rv_discrete

    if not _is_frozen(dist) and _is_frozen(getattr(dist, "dist", None)):
        x_min = getattr(dist, "x_min", None)
        if x_min is not None:
            raise ValueError(
                f"dist is a tail fit (x_min={x_min!r}) of model "
                f"{getattr(dist, 'model', '?')!r}: it describes only intervals above x_min, "
                "not every interval; fit the full sample, or pass fit.dist explicitly if "
                "that is what you mean"
            )
        dist = dist.dist  # a kicktimes.stats fit result: use its frozen distribution
    if not _is_frozen(dist):
        if isinstance(getattr(dist, "dist", None), rv_discrete) or isinstance(dist, rv_discrete):
            raise TypeError(f"dist must be a continuous distribution, got discrete {dist!r}")
        if isinstance(dist, rv_continuous):
            raise TypeError(
                f"dist must be a frozen distribution with its parameters, e.g. "
                f"scipy.stats.{dist.name}(...), got the family {dist.name!r} itself"
            )
        raise TypeError(
            "dist must be a frozen scipy.stats continuous distribution (e.g. "
            f"scipy.stats.gamma(2, scale=0.5)) or a fit result with .dist, got {dist!r}"
        )
    name, shapes, _, scale = _dist_params(dist)
    lower = float(dist.support()[0])
    if not (scale > 0) or math.isnan(lower):
        raise ValueError(f"dist {_dist_repr(dist)} has invalid parameters for {name}")
    if lower < 0:
        raise ValueError(
            f"dist must have support in [0, inf) (intervals are durations), "
            f"got {_dist_repr(dist)} with support starting at {lower!r}"
        )
    return dist


def _dist_repr(dist):
    name, shapes, loc, scale = _dist_params(dist)
    parts = [f"{k}={v!r}" for k, v in shapes]
    parts += [f"loc={loc!r}"] * (loc != 0) + [f"scale={scale!r}"] * (scale != 1)
    return f"{name}({', '.join(parts)})"


def _dist_to_dict(dist):
    name, shapes, loc, scale = _dist_params(dist)
    try:
        family = resolve_distribution(name)
    except ValueError as exc:
        raise ValueError(f"cannot serialise dist {_dist_repr(dist)}: {exc}") from None
    if type(family) is not type(dist.dist):
        raise ValueError(
            f"cannot serialise dist {_dist_repr(dist)}: the name {name!r} resolves to a "
            f"different family ({type(family).__name__}, not {type(dist.dist).__name__})"
        )
    return {"name": name, "args": [], "kwds": {**dict(shapes), "loc": loc, "scale": scale}}


def _dist_from_dict(d):
    if not isinstance(d, dict) or set(d) - {"name", "args", "kwds"} or "name" not in d:
        raise ValueError(f"dist must be a JSON object with name, args, kwds; got {d!r}")
    family = resolve_distribution(d["name"])
    try:
        return family(*d.get("args", []), **d.get("kwds", {}))
    except TypeError as exc:
        raise ValueError(f"bad parameters for dist {d['name']!r}: {exc}") from None


def _generic_rvs(family):
    from scipy.stats import rv_continuous

    # rv_continuous falls back to root-finding the CDF (itself a quadrature of the pdf)
    # for every draw when a family defines neither _rvs nor _ppf: far too slow for 1e6.
    cls = type(family)
    return cls._rvs is rv_continuous._rvs and cls._ppf is rv_continuous._ppf


def _interval_sampler(dist):
    """``draw(n, rng)`` returning ``n`` IID intervals from ``dist``."""
    if not _generic_rvs(dist.dist):
        return lambda n, rng: dist.rvs(size=n, random_state=rng)
    from scipy.stats.sampling import NumericalInversePolynomial

    lower, upper = dist.support()
    try:
        pinv = NumericalInversePolynomial(dist, domain=(lower, upper), u_resolution=1e-12)
    except Exception:  # UNU.RAN cannot tabulate this density: slow but exact scipy path
        return lambda n, rng: dist.rvs(size=n, random_state=rng)
    return lambda n, rng: pinv.rvs(size=n, random_state=rng)


class _EquilibriumDensity:
    """Density ``S(x) / E[X]`` on ``[0, sup X)`` for UNU.RAN's PINV method."""

    def __init__(self, dist, mean):
        self.dist, self.mean = dist, mean

    def pdf(self, x):
        return self.dist.sf(x) / self.mean


def _equilibrium_sampler(dist, mean, *, method="auto"):
    """``draw(rng)`` returning one forward-recurrence time with density ``S(x)/E[X]``.

    Exact closed forms use ``X_e = U * X*`` (``X*`` length-biased, density ``x f(x)/E[X]``;
    ``U`` uniform), direct inversion or a mixture; other families use polynomial inversion of the
    density (PINV, u-resolution 1e-12) or, if PINV cannot be set up, root-finding on
    ``E[min(X, x)] / E[X] = u`` with quadrature.
    """
    name, shapes, loc, scale = _dist_params(dist)
    shape = shapes[0][1] if shapes else None
    if method == "auto" and loc == 0:
        if name == "expon":  # memoryless: the equilibrium law is the law itself
            return lambda rng: scale * rng.standard_exponential()
        if name == "gamma":  # length-biased gamma(a) is gamma(a + 1)
            return lambda rng: scale * rng.standard_gamma(shape + 1.0) * rng.random()
        if name == "weibull_min":  # (X*/scale)**c is gamma(1 + 1/c)
            return lambda rng: (
                scale * rng.standard_gamma(1.0 + 1.0 / shape) ** (1.0 / shape) * rng.random()
            )
        if name == "lognorm":  # length-biasing shifts log X by s**2
            return lambda rng: (
                scale * math.exp(shape * shape + shape * rng.standard_normal()) * rng.random()
            )
        if name == "lomax":  # S(x)/E[X] is the lomax(c - 1) density: invert its survival fn
            return lambda rng: scale * math.expm1(-math.log1p(-rng.random()) / (shape - 1.0))
        if name == "pareto":  # uniform on [0, scale) w.p. (b-1)/b, else pareto(b - 1)
            return lambda rng: (
                scale
                * (
                    rng.random()
                    if rng.random() < (shape - 1.0) / shape
                    else (1.0 - rng.random()) ** (-1.0 / (shape - 1.0))
                )
            )
        if name == "hyperexpon" and [k for k, _ in shapes] == ["p", "lam1", "lam2"]:
            # kicktimes.stats.distributions: S(x)/E[X] is again a mixture of the two
            # exponentials, component i reweighted by its mean p_i / lam_i
            p, lam1, lam2 = (v for _, v in shapes)
            w = (p / lam1) / (p / lam1 + (1.0 - p) / lam2)
            return lambda rng: (
                scale * rng.standard_exponential() / (lam1 if rng.random() < w else lam2)
            )
    if method in ("auto", "pinv"):
        from scipy.stats.sampling import NumericalInversePolynomial

        try:
            pinv = NumericalInversePolynomial(
                _EquilibriumDensity(dist, mean),
                mode=0.0,
                domain=(0.0, dist.support()[1]),
                u_resolution=1e-12,
            )
        except Exception:  # UNU.RAN raises various errors on awkward densities
            if method == "pinv":
                raise
        else:
            return lambda rng: float(pinv.rvs(random_state=rng))
    return _quad_equilibrium_sampler(dist, mean)


def _quad_equilibrium_sampler(dist, mean):
    from scipy.integrate import quad
    from scipy.optimize import brentq

    lower, upper = dist.support()

    def partial_mean(x):  # E[min(X, x)] = integral of S over [0, x]
        points = [lower] if 0 < lower < x else None
        return quad(dist.sf, 0.0, x, points=points, limit=200)[0]

    def draw(rng):
        target = rng.random() * mean
        b = max(float(dist.median()), lower, 1e-300)
        while partial_mean(b) < target and b < upper:
            b = min(2.0 * b, upper)
        return brentq(lambda x: partial_mean(x) - target, 0.0, b, xtol=1e-300, rtol=1e-13)

    return draw
