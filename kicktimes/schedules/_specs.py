"""Schedules from the command line's specs (`from_spec`)."""

from __future__ import annotations

import os

from kicktimes.schedules._base import Bootstrap, Poisson, Renewal, Replay
from kicktimes.schedules._distributions import _is_frozen, resolve_distribution
from kicktimes.schedules._io import read_kick_times

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
