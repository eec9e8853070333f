"""Kick schedules: the random (or replayed) times at which the one-particle billiard is kicked.

A schedule is a small immutable *value* that describes a point process on ``(0, t_max]``;
``schedule.sample(t_max, rng)`` draws one realisation as a sorted float64 array. The
schedules are the bridge between the statistics of disk-disk collision times and the
perturbed one-particle billiard (docs/architecture.md, "Perturbed one-particle billiard"):

========================  ===============================================================
``Poisson(rate)``         homogeneous Poisson process; ``Poisson.from_run(run)`` uses the
                          paper's per-IC rate ``len(run.pp_times) / run.t_max``
``Renewal(dist)``         IID intervals from a frozen ``scipy.stats`` distribution (or a
                          ``kicktimes.stats.fit_renewal`` result); ``stationary=True`` draws
                          the first interval from the equilibrium distribution
``Replay(times)``         the actual disk-disk collision times, ``Replay.from_run(run)``
``Bootstrap(intervals)``  IID resampling of observed intervals, ``Bootstrap.from_run(run)``
========================  ===============================================================

Conventions shared by every schedule
------------------------------------
* ``sample(t_max, rng=None)`` returns kick times ``0 < t_1 <= t_2 <= ... <= t_max``.
  ``rng`` is a ``numpy.random.Generator``, an int seed, a ``SeedSequence`` or ``None``.
* Intervals are drawn in chunks whose sizes (1024, then growing by 25 %) do not depend on
  ``t_max`` or on the distribution, so horizons are *nested*: with the same seed,
  ``sample(t1, seed)`` equals ``sample(t2, seed)`` restricted to ``(0, t1]`` for
  ``t1 < t2``. Infinite-mean intervals need no special chunk sizing.
* Zero-length intervals (a bootstrap sample containing ties, or a distribution such as
  ``gamma(0.01)`` whose draws underflow to 0.0) give simultaneous kicks: the times are
  non-decreasing, not strictly increasing. A kick time that would be exactly 0.0 is
  replaced by the smallest positive double (5e-324, "0+") so the times stay in
  ``(0, t_max]``.

Schedules compare by value, have a readable ``repr``, serialise with ``to_json()`` /
:func:`from_json`, and sampled times are stored with :func:`write_kick_times` /
:func:`read_kick_times` (CSV with a JSON sidecar, or Parquet). See docs/schedules.md.
"""

from __future__ import annotations

import abc
import importlib
import json
import math
import numbers
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from kicktimes._validation import check_rng

__all__ = [
    "DEFAULT_MAX_KICKS",
    "Bootstrap",
    "Poisson",
    "Renewal",
    "Replay",
    "Schedule",
    "from_dict",
    "from_json",
    "from_spec",
    "read_kick_times",
    "resolve_distribution",
    "write_kick_times",
]

#: ``sample`` refuses to generate more kicks than this (8 bytes each) unless told otherwise.
DEFAULT_MAX_KICKS = 10**8
_FORMAT_VERSION = 1
_FIRST_CHUNK = 1024
_MAX_CHUNK = 2**21
_TINY = float(np.nextafter(0.0, 1.0))  # "0+": a kick time that underflowed to 0.0


# --------------------------------------------------------------------------- validation
def _real(value, name):
    if isinstance(value, (bool, np.bool_)) or not (
        isinstance(value, numbers.Real) or (isinstance(value, np.ndarray) and value.ndim == 0)
    ):
        raise TypeError(f"{name} must be a real number, got {value!r} ({type(value).__name__})")
    if isinstance(value, np.ndarray) and not np.issubdtype(value.dtype, np.number):
        raise TypeError(f"{name} must be a real number, got {value!r}")
    return float(value)


def _check_t_max(t_max, name="t_max"):
    value = _real(t_max, name)
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be finite and > 0, got {value!r}")
    return value


def _check_rate(rate):
    value = _real(rate, "rate")
    if not (math.isfinite(value) and value >= 0):
        raise ValueError(f"rate must be finite and >= 0 (0 means no kicks), got {value!r}")
    return value


def _check_bool(value, name):
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def _check_max_kicks(max_kicks):
    if isinstance(max_kicks, (bool, np.bool_)) or not isinstance(max_kicks, numbers.Integral):
        raise TypeError(f"max_kicks must be an int >= 1, got {max_kicks!r}")
    if max_kicks < 1:
        raise ValueError(f"max_kicks must be an int >= 1, got {max_kicks}")
    return int(max_kicks)


def _float_array(values, name, *, lower, sorted_):
    """Validated read-only float64 copy; ``lower`` is "positive" or "non-negative"."""
    arr = np.asarray(values)
    if arr.dtype == object or arr.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be an array of real numbers, got dtype {arr.dtype}")
    if arr.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional, got shape {arr.shape}")
    arr = arr.astype(np.float64) + 0.0  # a copy; + 0.0 turns -0.0 into 0.0 (hash by bytes)
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise ValueError(f"{name} must be finite, got {float(arr[bad[0]])!r} at index {bad[0]}")
    bad = np.flatnonzero(arr <= 0 if lower == "positive" else arr < 0)
    if bad.size:
        bound = "> 0" if lower == "positive" else ">= 0"
        raise ValueError(f"{name} must be {bound}, got {float(arr[bad[0]])!r} at index {bad[0]}")
    if sorted_ and arr.size > 1:
        bad = np.flatnonzero(np.diff(arr) < 0)
        if bad.size:
            i = bad[0]
            raise ValueError(
                f"{name} must be sorted (non-decreasing), got {float(arr[i])!r} then "
                f"{float(arr[i + 1])!r} "
                f"at indices {i}, {i + 1}"
            )
    arr.flags.writeable = False
    return arr


def _run_times(run):
    """``(pp_times, t_max)`` of a duck-typed two-particle run, validated."""
    if not (hasattr(run, "pp_times") and hasattr(run, "t_max")):
        raise TypeError(
            "run must have attributes pp_times and t_max (e.g. a TwoParticleRun), "
            f"got {type(run).__name__}"
        )
    t_max = _check_t_max(run.t_max, "run.t_max")
    times = _float_array(run.pp_times, "run.pp_times", lower="positive", sorted_=True)
    if times.size and times[-1] > t_max:
        raise ValueError(
            f"run.pp_times must lie in (0, run.t_max={t_max!r}], got {float(times[-1])!r}"
        )
    return times, t_max


def _array_repr(arr, noun):
    if arr.size <= 6:
        return "[" + ", ".join(repr(float(x)) for x in arr) + "]"
    mean = f", mean {arr.mean():.6g}" if noun == "intervals" else ""
    return f"<{arr.size} {noun} in [{arr.min():.6g}, {arr.max():.6g}]{mean}>"


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
        values.append(_real(v if not isinstance(v, np.ndarray) else v[()], f"dist {label}"))
        if not math.isfinite(values[-1]):
            raise ValueError(f"dist parameter {label} must be finite, got {float(values[-1])!r}")
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


# ---------------------------------------------------------------------------- sampling
def _renewal_times(draw, t_max, *, first=None, mean=None, max_kicks):
    """Kick times in (0, t_max] from ``draw(n)`` intervals, the first one optionally fixed.

    Chunks have sizes fixed in advance (not from t_max), so horizons are nested.
    """
    if mean is not None and math.isfinite(mean) and t_max / mean > max_kicks:
        raise ValueError(
            f"t_max={t_max!r} with mean interval {mean:.6g} means about {t_max / mean:.3g} "
            f"kicks, more than max_kicks={max_kicks}; shorten t_max or raise max_kicks"
        )
    pieces, last, count, n = [], 0.0, 0, _FIRST_CHUNK
    if first is not None:
        if first > t_max:
            return np.empty(0)
        pieces.append(np.array([first]))
        count, last = 1, first
    while True:
        times = np.cumsum(draw(n))
        times += last
        if times[-1] > t_max:
            times = times[: np.searchsorted(times, t_max, side="right")]
        count += times.size
        if count > max_kicks:
            raise ValueError(
                f"more than max_kicks={max_kicks} kicks in (0, {t_max!r}]; "
                "shorten t_max or raise max_kicks"
            )
        pieces.append(times)
        if times.size < n:
            break
        last = times[-1]
        n = min(n + n // 4, _MAX_CHUNK)  # integer growth: the same chunks on every platform
    out = np.concatenate(pieces)
    if out.size and out[0] == 0.0:  # underflowed (or tied-at-zero) leading intervals
        out[out == 0.0] = _TINY
    return out


# ---------------------------------------------------------------------------- schedules
class Schedule(abc.ABC):
    """Base class of kick schedules: ``sample``, value semantics and JSON."""

    _type = ""

    @abc.abstractmethod
    def sample(self, t_max, rng=None, *, max_kicks=DEFAULT_MAX_KICKS):
        """Sorted float64 kick times in ``(0, t_max]`` (see the subclass)."""

    def to_dict(self):
        """JSON-ready dict ``{"kicktimes_schedule": 1, "type": ..., ...parameters}``."""
        return {"kicktimes_schedule": _FORMAT_VERSION, "type": self._type, **self._params()}

    def to_json(self, *, indent=None):
        """JSON text; floats are written exactly, so ``from_json(s.to_json()) == s``."""
        return json.dumps(self.to_dict(), indent=indent, allow_nan=False)

    @classmethod
    def from_dict(cls, d):
        """Schedule from :meth:`to_dict` output; on a subclass the type must match."""
        schedule = from_dict(d)
        if cls is not Schedule and not isinstance(schedule, cls):
            raise ValueError(f"expected a {cls._type!r} schedule, got type {d.get('type')!r}")
        return schedule

    @classmethod
    def from_json(cls, s):
        """Schedule from :meth:`to_json` text."""
        return cls.from_dict(_loads(s))

    def __getstate__(self):  # samplers cached on the instance are rebuilt, not pickled
        return {k: v for k, v in self.__dict__.items() if k != "_cache"}

    def _cached(self, key, build):
        cache = self.__dict__.setdefault("_cache", {})
        if key not in cache:
            cache[key] = build()
        return cache[key]


@dataclass(frozen=True)
class Poisson(Schedule):
    """Homogeneous Poisson kicks: exponential intervals with mean ``1 / rate``.

    Parameters
    ----------
    rate : float
        Kicks per unit time, finite and ``>= 0``; ``rate = 0`` gives no kicks.

    Notes
    -----
    Intervals ``X_k = E_k / rate`` with ``E_k`` standard exponential; the process is
    stationary from ``t = 0`` (memorylessness), so it needs no ``stationary`` option.
    The paper's per-IC rate is ``N / T``, the number of disk-disk collisions of that IC's
    two-particle run over its duration (:meth:`from_run`).

    Examples
    --------
    >>> times = Poisson(2.0).sample(1000.0, rng=1)
    >>> bool(1900 < times.size < 2100)
    True
    """

    rate: float
    _type = "poisson"

    def __post_init__(self):
        object.__setattr__(self, "rate", _check_rate(self.rate))

    @property
    def mean_interval(self):
        """``1 / rate`` (inf for rate 0)."""
        return math.inf if self.rate == 0 else 1.0 / self.rate

    @classmethod
    def from_run(cls, run):
        """Rate ``len(run.pp_times) / run.t_max`` of one two-particle run (the paper's)."""
        times, t_max = _run_times(run)
        return cls(times.size / t_max)

    @classmethod
    def from_runs(cls, runs):
        """Pooled rate: total collisions over total time of several runs."""
        pairs = [_run_times(run) for run in runs]
        if not pairs:
            raise ValueError("runs must contain at least one run, got none")
        return cls(sum(t.size for t, _ in pairs) / sum(T for _, T in pairs))

    def sample(self, t_max, rng=None, *, max_kicks=DEFAULT_MAX_KICKS):
        """Kick times of a Poisson process on ``(0, t_max]``, sorted float64."""
        t_max = _check_t_max(t_max)
        max_kicks = _check_max_kicks(max_kicks)
        rng = check_rng(rng)
        if self.rate == 0:
            return np.empty(0)
        rate = self.rate

        def draw(n):
            # a subnormal rate overflows to inf: an interval beyond any window, no kick
            with np.errstate(over="ignore"):
                return rng.standard_exponential(n) / rate

        return _renewal_times(
            draw,
            t_max,
            mean=1.0 / rate,
            max_kicks=max_kicks,
        )

    def _params(self):
        return {"rate": self.rate}


@dataclass(frozen=True, eq=False, repr=False)
class Renewal(Schedule):
    """Renewal kicks: IID intervals from a continuous distribution on ``[0, inf)``.

    Parameters
    ----------
    dist : frozen scipy.stats distribution or fit result
        The interval law, e.g. ``scipy.stats.gamma(2, scale=0.5)``; families of
        ``kicktimes.stats.distributions`` work too. A ``kicktimes.stats.fit_renewal``
        result (anything whose ``.dist`` is such a frozen distribution) is accepted and
        replaced by its ``.dist`` (tail fits, with ``x_min`` set, are refused: they do
        not model the intervals below ``x_min``). The support must start at ``>= 0``;
        infinite means are allowed unless ``stationary``.
    stationary : bool, keyword-only
        ``False`` (ordinary renewal process): ``t = 0`` acts as a renewal, the first kick
        is at ``X_1 ~ F``. ``True``: the first kick is at the forward-recurrence time with
        the equilibrium density ``f_e(x) = S(x) / E[X]`` (``S = 1 - F``), which makes the
        kick process stationary from ``t = 0``: ``E[N(0, t]] = t / E[X]`` for every
        ``t``. Requires a finite mean.

    Notes
    -----
    The equilibrium first interval has mean ``E[X_e] = E[X^2] / (2 E[X])``. It is drawn
    exactly as ``U * X*`` (``X*`` length-biased, density ``x f(x) / E[X]``) for
    ``expon``, ``gamma``, ``weibull_min``, ``lognorm``; by inversion for ``lomax``
    (``X_e ~ lomax(c - 1)``); as mixtures for ``pareto`` (uniform below ``scale``,
    ``pareto(b - 1)`` above) and ``hyperexpon`` (the same rates, weights ``p_i / lam_i``
    renormalised); all with ``loc = 0``. Otherwise by polynomial inversion of
    ``f_e`` (``scipy.stats.sampling.NumericalInversePolynomial``, u-resolution 1e-12,
    set up once per schedule). Families without a fast ``rvs`` or ``ppf`` (where scipy
    would root-find the CDF per draw) are sampled by the same inversion of their pdf.

    Examples
    --------
    >>> import scipy.stats as st
    >>> schedule = Renewal(st.gamma(2.0, scale=0.5), stationary=True)
    >>> schedule
    Renewal(dist=gamma(a=2.0, scale=0.5), stationary=True)
    >>> times = schedule.sample(100.0, rng=7)
    """

    dist: object
    stationary: bool = field(default=False, kw_only=True)
    _type = "renewal"

    def __post_init__(self):
        object.__setattr__(self, "dist", _check_dist(self.dist))
        object.__setattr__(self, "stationary", _check_bool(self.stationary, "stationary"))
        if self.stationary and not math.isfinite(self.mean_interval):
            raise ValueError(
                f"stationary=True needs a finite mean interval, but dist "
                f"{_dist_repr(self.dist)} has mean {float(self.mean_interval)!r}; the equilibrium "
                "law S(x)/E[X] does not exist (use stationary=False)"
            )

    @classmethod
    def from_fit(cls, fit, *, stationary=False):
        """Schedule from a ``kicktimes.stats.fit_renewal`` result (uses ``fit.dist``)."""
        if not _is_frozen(getattr(fit, "dist", None)):
            raise TypeError(
                f"fit must have a frozen scipy distribution in .dist, got {type(fit).__name__}"
            )
        return cls(fit, stationary=stationary)

    @property
    def mean_interval(self):
        """``E[X]`` of the interval law (inf or nan when it does not exist)."""
        return self._cached("mean", lambda: float(self.dist.mean()))

    def sample(self, t_max, rng=None, *, max_kicks=DEFAULT_MAX_KICKS):
        """Kick times of the renewal process on ``(0, t_max]``, sorted float64."""
        t_max = _check_t_max(t_max)
        max_kicks = _check_max_kicks(max_kicks)
        rng = check_rng(rng)
        draw = self._cached("draw", lambda: _interval_sampler(self.dist))
        first = None
        if self.stationary:
            draw_first = self._cached(
                "first", lambda: _equilibrium_sampler(self.dist, self.mean_interval)
            )
            first = draw_first(rng)
        return _renewal_times(
            lambda n: draw(n, rng),
            t_max,
            first=first,
            mean=self.mean_interval,
            max_kicks=max_kicks,
        )

    def _params(self):
        return {"dist": _dist_to_dict(self.dist), "stationary": self.stationary}

    def __eq__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        return self.stationary == other.stationary and _dist_params(self.dist) == _dist_params(
            other.dist
        )

    def __hash__(self):
        return hash((self._type, _dist_params(self.dist), self.stationary))

    def __repr__(self):
        return f"Renewal(dist={_dist_repr(self.dist)}, stationary={self.stationary})"


@dataclass(frozen=True, eq=False, repr=False)
class Replay(Schedule):
    """Replay fixed kick times, e.g. the disk-disk collision times of a two-particle run.

    Parameters
    ----------
    times : array_like
        Sorted (non-decreasing), finite, ``> 0``.
    t_max : float or None, keyword-only
        The window ``(0, t_max]`` the times were observed in. When given, sampling a
        longer horizon is an error (the later times are unknown), rather than silently
        running out of kicks. ``from_run`` sets it to ``run.t_max``.

    Notes
    -----
    ``sample(t_max, rng)`` ignores ``rng`` and returns a copy of the times ``<= t_max``.

    Examples
    --------
    >>> Replay([0.5, 1.25, 3.0]).sample(2.0)
    array([0.5 , 1.25])
    """

    times: np.ndarray
    t_max: float | None = field(default=None, kw_only=True)
    _type = "replay"

    def __post_init__(self):
        times = _float_array(self.times, "times", lower="positive", sorted_=True)
        object.__setattr__(self, "times", times)
        if self.t_max is not None:
            t_max = _check_t_max(self.t_max)
            if times.size and times[-1] > t_max:
                raise ValueError(
                    f"times must lie in (0, t_max={t_max!r}], got {float(times[-1])!r}"
                )
            object.__setattr__(self, "t_max", t_max)

    @classmethod
    def from_run(cls, run):
        """Replay ``run.pp_times`` within the run's window ``(0, run.t_max]``."""
        times, t_max = _run_times(run)
        return cls(times, t_max=t_max)

    def sample(self, t_max, rng=None, *, max_kicks=DEFAULT_MAX_KICKS):
        """The stored times in ``(0, t_max]`` (a copy); ``rng`` is validated and ignored."""
        t_max = _check_t_max(t_max)
        max_kicks = _check_max_kicks(max_kicks)
        check_rng(rng)
        if self.t_max is not None and t_max > self.t_max:
            raise ValueError(
                f"t_max={t_max!r} exceeds the replayed window (0, {float(self.t_max)!r}]; the "
                "kick times after it are unknown"
            )
        out = self.times[: np.searchsorted(self.times, t_max, side="right")].copy()
        if out.size > max_kicks:
            raise ValueError(f"{out.size} kicks exceed max_kicks={max_kicks}")
        return out

    def _params(self):
        return {"times": self.times.tolist(), "t_max": self.t_max}

    def __eq__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        return self.t_max == other.t_max and np.array_equal(self.times, other.times)

    def __hash__(self):
        return hash((self._type, self.times.tobytes(), self.t_max))

    def __repr__(self):
        return f"Replay(times={_array_repr(self.times, 'times')}, t_max={self.t_max!r})"


@dataclass(frozen=True, eq=False, repr=False)
class Bootstrap(Schedule):
    """Kicks with IID intervals resampled (with replacement) from observed intervals.

    Parameters
    ----------
    intervals : array_like
        Observed intervals, finite, ``>= 0``, at least one ``> 0``. Zeros (ties) are
        allowed and give simultaneous kicks.
    stationary : bool, keyword-only
        ``True`` draws the first interval from the equilibrium law of the empirical
        distribution: pick ``x_i`` with probability ``x_i / sum(x)`` (length bias) and
        multiply by ``U ~ Uniform(0, 1)``; exact, and the process is stationary from 0.

    Notes
    -----
    :meth:`from_run` uses the complete intervals ``diff(run.pp_times)``: the first
    time ``t_1`` (a forward-recurrence time from the arbitrary start, not an interval)
    and the right-censored tail ``T - t_n`` are dropped. Dropping the censored tail
    under-represents intervals comparable to ``T``; it is negligible when a run has
    many collisions.

    Examples
    --------
    >>> times = Bootstrap([0.5, 1.0, 2.5]).sample(10.0, rng=3)
    >>> bool(set(np.round(np.diff(times), 12)) <= {0.5, 1.0, 2.5})
    True
    """

    intervals: np.ndarray
    stationary: bool = field(default=False, kw_only=True)
    _type = "bootstrap"

    def __post_init__(self):
        x = _float_array(self.intervals, "intervals", lower="non-negative", sorted_=False)
        if x.size == 0 or not x.max() > 0:
            got = "no intervals" if x.size == 0 else f"{x.size} intervals, all 0"
            raise ValueError(f"intervals must contain at least one interval > 0, got {got}")
        object.__setattr__(self, "intervals", x)
        object.__setattr__(self, "stationary", _check_bool(self.stationary, "stationary"))

    @classmethod
    def from_times(cls, times, *, stationary=False):
        """Resample the intervals between consecutive ``times`` (see Notes)."""
        times = _float_array(times, "times", lower="positive", sorted_=True)
        if times.size < 2:
            raise ValueError(f"times must hold >= 2 events to form an interval, got {times.size}")
        return cls(np.diff(times), stationary=stationary)

    @classmethod
    def from_run(cls, run, *, stationary=False):
        """Resample ``diff(run.pp_times)`` of one run (first time and tail dropped)."""
        times, _ = _run_times(run)
        if times.size < 2:
            raise ValueError(
                f"run.pp_times must hold >= 2 collisions to form an interval, got {times.size}"
            )
        return cls(np.diff(times), stationary=stationary)

    @classmethod
    def from_runs(cls, runs, *, stationary=False):
        """Resample the complete intervals pooled over several runs (each run's own diffs)."""
        parts = [np.diff(_run_times(run)[0]) for run in runs]
        return cls(np.concatenate(parts) if parts else np.empty(0), stationary=stationary)

    @property
    def mean_interval(self):
        """Mean of the observed intervals."""
        return float(self.intervals.mean())

    def sample(self, t_max, rng=None, *, max_kicks=DEFAULT_MAX_KICKS):
        """Kick times with resampled intervals on ``(0, t_max]``, sorted float64."""
        t_max = _check_t_max(t_max)
        max_kicks = _check_max_kicks(max_kicks)
        rng = check_rng(rng)
        x = self.intervals
        first = None
        if self.stationary:
            cum = self._cached("cumsum", lambda: np.cumsum(x))
            # index i with probability x_i / sum(x): the length-biased empirical law
            i = min(int(np.searchsorted(cum, rng.random() * cum[-1], side="right")), x.size - 1)
            first = x[i] * rng.random()
        return _renewal_times(
            lambda n: x[rng.integers(0, x.size, size=n)],
            t_max,
            first=first,
            mean=self.mean_interval,
            max_kicks=max_kicks,
        )

    def _params(self):
        return {"intervals": self.intervals.tolist(), "stationary": self.stationary}

    def __eq__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        return self.stationary == other.stationary and np.array_equal(
            self.intervals, other.intervals
        )

    def __hash__(self):
        return hash((self._type, self.intervals.tobytes(), self.stationary))

    def __repr__(self):
        return (
            f"Bootstrap(intervals={_array_repr(self.intervals, 'intervals')}, "
            f"stationary={self.stationary})"
        )


_TYPES = {cls._type: cls for cls in (Poisson, Renewal, Replay, Bootstrap)}


# --------------------------------------------------------------------------------- JSON
def _loads(s):
    if not isinstance(s, (str, bytes, bytearray)):
        raise TypeError(f"s must be JSON text (str), got {type(s).__name__}")
    try:
        return json.loads(s)
    except json.JSONDecodeError as exc:
        raise ValueError(f"s is not valid JSON: {exc}") from None


def from_dict(d):
    """Schedule from the dict of ``Schedule.to_dict()`` (dispatching on ``"type"``)."""
    if not isinstance(d, dict):
        raise TypeError(f"a schedule dict must be a dict, got {type(d).__name__}")
    version = d.get("kicktimes_schedule")
    if version != _FORMAT_VERSION:
        raise ValueError(
            f"not a kicktimes schedule (format {_FORMAT_VERSION}): kicktimes_schedule={version!r}"
        )
    kind = d.get("type")
    if kind not in _TYPES:
        raise ValueError(f"unknown schedule type {kind!r}; valid types are {sorted(_TYPES)}")
    params = {k: v for k, v in d.items() if k not in ("kicktimes_schedule", "type")}
    cls = _TYPES[kind]
    expected = set(cls.__dataclass_fields__)
    if set(params) != expected:
        raise ValueError(f"a {kind!r} schedule has fields {sorted(expected)}, got {sorted(params)}")
    if kind == "renewal":
        params["dist"] = _dist_from_dict(params["dist"])
    first = next(iter(cls.__dataclass_fields__))
    return cls(params.pop(first), **params)


def from_json(s):
    """Schedule from ``Schedule.to_json()`` text.

    Examples
    --------
    >>> from_json(Poisson(0.5).to_json())
    Poisson(rate=0.5)
    """
    return from_dict(_loads(s))


# --------------------------------------------------------------------------------- specs
_SPEC_MODELS = ("poisson", "renewal", "bootstrap", "replay")


def from_spec(model, params=None, *, dist=None, stationary=False, times=None, window=None):
    """Schedule from a model name and parameters (the command line's path).

    Parameters
    ----------
    model : {"poisson", "renewal", "bootstrap", "replay"}
    params : mapping of str to float, optional
        ``poisson``: ``{"rate": r}``. ``renewal``: keyword parameters of ``dist``
        (shape names, ``loc``, ``scale``). ``bootstrap``/``replay``: none.
    dist : str or frozen distribution, keyword-only
        ``renewal`` only: a name resolved by :func:`resolve_distribution`.
    stationary : bool, keyword-only
        ``renewal`` and ``bootstrap`` only.
    times : array_like or path, keyword-only
        ``bootstrap``/``replay``: event times, or a CSV/Parquet file of them (read by
        :func:`read_kick_times`); ``bootstrap`` resamples their consecutive differences.
    window : float, keyword-only
        ``replay`` only: the observation window ``t_max`` of the times.

    Examples
    --------
    >>> from_spec("renewal", {"a": 2, "scale": 0.5}, dist="gamma")
    Renewal(dist=gamma(a=2.0, scale=0.5), stationary=False)
    """
    if not isinstance(model, str) or model.lower() not in _SPEC_MODELS:
        raise ValueError(f"model must be one of {list(_SPEC_MODELS)}, got {model!r}")
    model = model.lower()
    params = dict(params or {})
    for key, value in params.items():
        if isinstance(value, str):
            try:
                params[key] = float(value)
            except ValueError:
                raise ValueError(f"parameter {key} must be a number, got {value!r}") from None

    def refuse(name, value, allowed):
        if value is not None and value is not False:
            raise ValueError(f"{name} is not used by model {model!r} (only by {allowed})")

    if model != "renewal":
        refuse("dist", dist, "renewal")
    if model in ("poisson", "replay"):
        refuse("stationary", stationary, "renewal, bootstrap")
    if model != "replay":
        refuse("window", window, "replay")
    if model in ("poisson", "renewal"):
        refuse("times", times, "bootstrap, replay")

    if model == "poisson":
        if set(params) != {"rate"}:
            raise ValueError(
                f"model 'poisson' takes exactly the parameter rate, got {sorted(params)}"
            )
        return Poisson(params["rate"])
    if model == "renewal":
        if dist is None:
            raise ValueError("model 'renewal' needs dist, a distribution name such as 'gamma'")
        if _is_frozen(dist):
            if params:
                raise ValueError("params must be empty when dist is already a frozen distribution")
            return Renewal(dist, stationary=stationary)
        family = resolve_distribution(dist)
        allowed = [s.strip() for s in (family.shapes or "").split(",") if s.strip()]
        allowed += ["loc", "scale"]
        unknown = sorted(set(params) - set(allowed))
        if unknown:
            raise ValueError(f"unknown parameters {unknown} for {dist!r}; valid: {allowed}")
        missing = sorted(set(allowed[:-2]) - set(params))
        if missing:
            raise ValueError(f"missing shape parameters {missing} for {dist!r}")
        return Renewal(family(**params), stationary=stationary)
    if params:
        raise ValueError(f"model {model!r} takes no parameters, got {sorted(params)}")
    if times is None:
        raise ValueError(f"model {model!r} needs times (an array or a CSV/Parquet file)")
    if isinstance(times, (str, os.PathLike)):
        times, meta = read_kick_times(times, with_metadata=True)
        if window is None:  # a file written by write_kick_times knows its window
            window = meta.get("t_max")
    if model == "bootstrap":
        return Bootstrap.from_times(times, stationary=stationary)
    return Replay(times, t_max=window)


# ----------------------------------------------------------------------------------- I/O
_TIME_COLUMNS = ("kick_time", "pp_time", "pp_times", "time", "t")
_CSV_MARK = "# kicktimes metadata: "


def _check_path(path, name="path"):
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"{name} must be a str or path, got {type(path).__name__}")
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".parquet"):
        raise ValueError(f"{name} must end in .csv or .parquet, got {str(path)!r}")
    return path, suffix


def write_kick_times(times, path, *, t_max=None, schedule=None, seed=None, metadata=None):
    """Write kick times to ``path`` (.csv or .parquet) atomically, with metadata.

    Parameters
    ----------
    times : array_like
        Sorted, finite, ``> 0`` (and ``<= t_max`` when given). Stored as the float64
        column ``kick_time``; values round-trip exactly in both formats.
    path : str or path
        ``.csv`` or ``.parquet``. Written to a temporary file in the same directory
        and moved into place with ``os.replace``: readers never see a partial file.
    t_max, schedule, seed, metadata : keyword-only, optional
        Stored as JSON ``{"format", "kicktimes_version", "n_kicks", "t_max", "seed",
        "schedule", "metadata"}``: in the Parquet schema metadata (key ``kicktimes``) or,
        for a CSV, in the sidecar file ``<path>.json`` (``kicks.csv.json``), so that the
        CSV itself is plain (one header line ``kick_time``, one time per line) and any CSV
        reader takes it as it is.

    Returns
    -------
    pathlib.Path
    """
    path, suffix = _check_path(path)
    arr = _float_array(times, "times", lower="positive", sorted_=True)
    if t_max is not None:
        t_max = _check_t_max(t_max)
        if arr.size and arr[-1] > t_max:
            raise ValueError(f"times must lie in (0, t_max={t_max!r}], got {float(arr[-1])!r}")
    if schedule is not None and not isinstance(schedule, Schedule):
        raise TypeError(f"schedule must be a kicktimes Schedule, got {type(schedule).__name__}")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, numbers.Integral)):
        raise TypeError(f"seed must be an int or None, got {seed!r}")
    from kicktimes import __version__

    meta = {
        "format": "kicktimes.kick_times/1",
        "kicktimes_version": __version__,
        "n_kicks": int(arr.size),
        "t_max": t_max,
        "seed": None if seed is None else int(seed),
        "schedule": None if schedule is None else schedule.to_dict(),
        "metadata": metadata,
    }
    try:
        meta_json = json.dumps(meta, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"metadata must be JSON-serialisable without NaN/inf: {exc}") from None

    from kicktimes.fileio import atomic_write

    if suffix == ".csv":

        def write_csv(tmp):
            with open(tmp, "w", newline="") as fh:
                fh.write("kick_time\n")
                # repr is the shortest string that parses back to the same double
                fh.writelines(f"{x!r}\n" for x in arr.tolist())

        # sidecar first: a reader that sees the new CSV also sees its metadata
        atomic_write(_sidecar(path), lambda tmp: Path(tmp).write_text(meta_json + "\n"))
        atomic_write(path, write_csv)
    else:
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.table({"kick_time": pa.array(arr, type=pa.float64())})
        table = table.replace_schema_metadata({"kicktimes": meta_json})
        atomic_write(path, lambda tmp: pq.write_table(table, tmp))
    return path


def _sidecar(path: Path) -> Path:
    """The metadata file of a CSV of kick times: ``kicks.csv`` -> ``kicks.csv.json``."""
    return path.with_name(path.name + ".json")


def read_kick_times(path, *, column=None, with_metadata=False):
    """Read kick (or collision) times from a .csv or .parquet file.

    Parameters
    ----------
    path : str or path
    column : str, optional
        Column to read; by default ``kick_time``, else ``pp_time``, ``pp_times``,
        ``time``, ``t``, else the file's only column.
    with_metadata : bool, keyword-only
        Also return the metadata dict written by :func:`write_kick_times` (``{}`` for
        foreign files).

    Returns
    -------
    numpy.ndarray or (numpy.ndarray, dict)
        The times, validated: finite, ``> 0``, sorted, ``<= t_max`` of the metadata.
    """
    path, suffix = _check_path(path)
    meta = {}
    try:
        if suffix == ".csv":
            import pandas as pd

            skip = 0
            with open(path) as fh:
                # files written before version 0.2 carry the metadata in a comment line
                for line in fh:
                    if not line.startswith("#"):
                        break
                    skip += 1
                    if line.startswith(_CSV_MARK):
                        meta = json.loads(line[len(_CSV_MARK) :])
            sidecar = _sidecar(path)
            if not meta and sidecar.exists():
                meta = json.loads(sidecar.read_text())
                if not isinstance(meta, dict):
                    raise ValueError(f"{str(sidecar)!r} does not hold a JSON object")
            # read text and let float() parse it: correctly rounded whatever the pandas version
            frame = pd.read_csv(path, skiprows=skip, dtype=str, keep_default_na=False)
            data = {c: frame[c].to_numpy() for c in frame.columns}
        else:
            import pyarrow.parquet as pq

            table = pq.read_table(path)
            raw = (table.schema.metadata or {}).get(b"kicktimes")
            meta = {} if raw is None else json.loads(raw)
            data = {c: table.column(c).to_numpy() for c in table.column_names}
    except (ValueError, OSError) as exc:  # JSON, pandas and Arrow parse errors
        if isinstance(exc, FileNotFoundError):
            raise
        raise ValueError(f"invalid kick-time file {str(path)!r}: {exc}") from None
    columns = list(data)
    if column is None:
        column = next((c for c in _TIME_COLUMNS if c in columns), None)
        if column is None and len(columns) == 1:
            column = columns[0]
        if column is None:
            raise ValueError(
                f"{str(path)!r} has columns {columns}; pass column= (looked for {_TIME_COLUMNS})"
            )
    elif column not in columns:
        raise ValueError(f"column {column!r} is not in {str(path)!r}; columns are {columns}")
    what = f"column {column!r} of {str(path)!r}"
    try:
        values = data[column]
        if values.dtype == object:
            values = np.array([float(v) for v in values], dtype=np.float64)
        times = _float_array(values, what, lower="positive", sorted_=True)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"invalid kick-time file: {what}: {exc}") from None
    n_kicks = meta.get("n_kicks")
    if n_kicks is not None and n_kicks != times.size:
        raise ValueError(
            f"invalid kick-time file {str(path)!r}: its metadata says {n_kicks} kicks, the file "
            f"holds {times.size} (a stale {_sidecar(path).name}?)"
        )
    t_max = meta.get("t_max")
    if t_max is not None and times.size and times[-1] > t_max:
        raise ValueError(f"invalid kick-time file {str(path)!r}: times exceed t_max={t_max!r}")
    times = times.copy()
    return (times, meta) if with_metadata else times
