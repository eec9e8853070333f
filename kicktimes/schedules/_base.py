"""The schedules (`Schedule`, `Poisson`, `Renewal`, `Replay`, `Bootstrap`), the nested-horizon
sampling they share, and their registry for JSON (`from_dict`, `from_json`)."""

from __future__ import annotations

import abc
import json
import math
from dataclasses import dataclass, field

import numpy as np

from kicktimes._results import format_value
from kicktimes.schedules._distributions import (
    _check_dist,
    _dist_from_dict,
    _dist_params,
    _dist_repr,
    _dist_to_dict,
    _equilibrium_sampler,
    _interval_sampler,
    _is_frozen,
)
from kicktimes.schedules._validate import (
    _FIRST_CHUNK,
    _FORMAT_VERSION,
    _MAX_CHUNK,
    _TINY,
    DEFAULT_MAX_KICKS,
    _array_repr,
    _check_bool,
    _check_max_kicks,
    _check_rate,
    _check_t_max,
    _float_array,
    _run_times,
)
from kicktimes.validation import check_rng, keyword_only_after


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
    @keyword_only_after(1, since="0.2.0", names=('rng',))
    def sample(self, t_max, *, rng=None, max_kicks=DEFAULT_MAX_KICKS):
        """Sorted float64 kick times in ``(0, t_max]`` (see the subclass)."""

    #: the law of the kick times in words (the first line of `summary`)
    _law = ""

    def summary(self) -> str:
        """One paragraph: the schedule's law and its parameters (a schedule is a model, not
        a result, but summarises itself like one)."""
        lines = [f"{type(self).__name__} kick schedule: {self._law}"]
        lines += [f"  {name}: {format_value(value)}" for name, value in self._params().items()]
        mean = getattr(self, "mean_interval", None)
        if isinstance(mean, int | float):
            lines.append(f"  mean interval: {mean:.6g}")
        return "\n".join(lines)

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

    _law = "homogeneous Poisson kicks (IID exponential intervals of mean 1 / rate)"

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

    @keyword_only_after(1, since="0.2.0", names=('rng',))
    def sample(self, t_max, *, rng=None, max_kicks=DEFAULT_MAX_KICKS):
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

    _law = "renewal kicks (IID intervals from a continuous law on [0, inf))"

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

    @keyword_only_after(1, since="0.2.0", names=('rng',))
    def sample(self, t_max, *, rng=None, max_kicks=DEFAULT_MAX_KICKS):
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
    ``sample(t_max, rng=rng)`` ignores ``rng`` and returns a copy of the times ``<= t_max``.

    Examples
    --------
    >>> Replay([0.5, 1.25, 3.0]).sample(2.0)
    array([0.5 , 1.25])
    """

    _law = "the given kick times, replayed"

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

    @keyword_only_after(1, since="0.2.0", names=('rng',))
    def sample(self, t_max, *, rng=None, max_kicks=DEFAULT_MAX_KICKS):
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

    _law = "renewal kicks whose intervals are drawn with replacement from a sample"

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

    @keyword_only_after(1, since="0.2.0", names=('rng',))
    def sample(self, t_max, *, rng=None, max_kicks=DEFAULT_MAX_KICKS):
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


def _register(cls):
    """Add a schedule class defined in another module (``MMPP``) to the JSON registry."""
    _TYPES[cls._type] = cls
    return cls


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
