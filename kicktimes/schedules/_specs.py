"""Schedules from the command line's specs (`from_spec`)."""

from __future__ import annotations

import os
import re

import numpy as np

from kicktimes.schedules._base import Bootstrap, Poisson, Renewal, Replay
from kicktimes.schedules._distributions import _is_frozen, resolve_distribution
from kicktimes.schedules._io import read_kick_times
from kicktimes.schedules._mmpp import MMPP

# --------------------------------------------------------------------------------- specs
_SPEC_MODELS = ("poisson", "renewal", "bootstrap", "replay", "mmpp")
#: the parameter names of an MMPP spec: rate<i>, q<i><j> (a switching rate), p<i> (an
#: initial probability); one digit per state, so up to 10 states (more: a JSON file)
_MMPP_PARAM = re.compile(r"(rate)(\d)|(q)(\d)(\d)|(p)(\d)")


def from_spec(model, params=None, *, dist=None, stationary=False, times=None, window=None):
    """Schedule from a model name and parameters (the command line's path).

    Parameters
    ----------
    model : {"poisson", "renewal", "bootstrap", "replay", "mmpp"}
    params : mapping of str to float, optional
        ``poisson``: ``{"rate": r}``. ``renewal``: keyword parameters of ``dist``
        (shape names, ``loc``, ``scale``). ``bootstrap``/``replay``: none. ``mmpp``:
        ``rate0, rate1, ...`` (the kick rate of each hidden state), ``q01, q10, ...``
        (``q<i><j>``, the rate of switching from state ``i`` to ``j``; 0 when left out)
        and optionally ``p0, p1, ...`` (initial state probabilities; default the
        stationary law).
    dist : str or frozen distribution, keyword-only
        ``renewal`` only: a name resolved by :func:`resolve_distribution`.
    stationary : bool, keyword-only
        ``renewal`` and ``bootstrap``; ``mmpp`` starts stationary unless ``p<i>`` are
        given (``stationary=True`` with them is an error).
    times : array_like or path, keyword-only
        ``bootstrap``/``replay``: event times, or a CSV/Parquet file of them (read by
        :func:`read_kick_times`); ``bootstrap`` resamples their consecutive differences.
        (Fitting an ``mmpp`` to times is the statistics layer's job:
        ``MMPP.from_fit(kicktimes.stats.fit_mmpp(times, t_max))``.)
    window : float, keyword-only
        ``replay`` only: the observation window ``t_max`` of the times.

    Examples
    --------
    >>> from_spec("renewal", {"a": 2, "scale": 0.5}, dist="gamma")
    Renewal(dist=gamma(a=2.0, scale=0.5), stationary=False)
    >>> from_spec("mmpp", {"rate0": 0.5, "rate1": 4, "q01": 0.1, "q10": 0.4})
    MMPP(rates=[0.5, 4.0], generator=[[-0.1, 0.1], [0.4, -0.4]], initial='stationary')
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
        refuse("stationary", stationary, "renewal, bootstrap, mmpp")
    if model != "replay":
        refuse("window", window, "replay")
    if model in ("poisson", "renewal"):
        refuse("times", times, "bootstrap, replay")
    if model == "mmpp":
        return _mmpp_spec(params, stationary=stationary, times=times)

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


def _mmpp_spec(params, *, stationary, times):
    """`MMPP` from ``rate<i>``/``q<i><j>``/``p<i>`` parameters."""
    if times is not None:
        raise ValueError("model 'mmpp' takes rates and switching rates, not times: fit times "
                         "with kicktimes.stats.fit_mmpp and use MMPP.from_fit (the command "
                         "line's mmpp --input does both)")
    rates, switch, initial = {}, {}, {}
    for name, value in params.items():
        m = _MMPP_PARAM.fullmatch(name)
        if m is None:
            raise ValueError(f"unknown parameter {name!r} for model 'mmpp'; valid: rate<i> "
                             "(kick rate of state i), q<i><j> (switching rate i -> j), p<i> "
                             "(initial probability), e.g. rate0, rate1, q01, q10")
        if m.group(1):
            rates[int(m.group(2))] = value
        elif m.group(3):
            i, j = int(m.group(4)), int(m.group(5))
            if i == j:
                raise ValueError(f"parameter {name}: a switching rate needs two different "
                                 "states (the diagonal of the generator follows from the rows)")
            switch[i, j] = value
        else:
            initial[int(m.group(7))] = value
    n = len(rates)
    if sorted(rates) != list(range(n)) or n == 0:
        raise ValueError(f"model 'mmpp' needs the rates rate0, ..., rate<n-1> of its states, "
                         f"got {sorted(f'rate{i}' for i in rates)}")
    beyond = sorted(f"q{i}{j}" for i, j in switch if max(i, j) >= n)
    beyond += sorted(f"p{i}" for i in initial if i >= n)
    if beyond:
        raise ValueError(f"parameters {beyond} name a state beyond the {n} rates")
    generator = np.zeros((n, n))
    for (i, j), value in switch.items():
        generator[i, j] = value
    generator[np.diag_indices(n)] = -generator.sum(axis=1)
    if initial:
        if stationary:
            raise ValueError("stationary and the initial probabilities p<i> exclude each other")
        if sorted(initial) != list(range(n)):
            raise ValueError(f"initial probabilities need p0, ..., p{n - 1}, got "
                             f"{sorted(f'p{i}' for i in initial)}")
        start = np.array([initial[i] for i in range(n)])
    else:
        start = "stationary"
    return MMPP([rates[i] for i in range(n)], generator, initial=start)
