"""Kick schedules: the random (or replayed) times at which the one-particle billiard is kicked.

A schedule is a small immutable *value* that describes a point process on ``(0, t_max]``;
``schedule.sample(t_max, rng=rng)`` draws one realisation as a sorted float64 array. The
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
``MMPP(rates, generator)`` Markov-modulated Poisson: a hidden Markov chain switches the
                          rate; ``MMPP.from_fit(fit)`` of a ``kicktimes.stats.fit_mmpp``
                          result, stationary from ``t = 0`` by default
========================  ===============================================================

``KineticRate(r)`` is the state-dependent kick law: not a schedule, since each interval
depends on the kicked disk's angular momentum after the previous kick; the event loop
draws its times (docs/mechanism.md).

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

from kicktimes.schedules._base import (
    Bootstrap,
    Poisson,
    Renewal,
    Replay,
    Schedule,
    from_dict,
    from_json,
)
from kicktimes.schedules._distributions import resolve_distribution
from kicktimes.schedules._io import read_kick_times, write_kick_times
from kicktimes.schedules._kinetic import KineticRate
from kicktimes.schedules._mmpp import MMPP
from kicktimes.schedules._specs import from_spec
from kicktimes.schedules._validate import DEFAULT_MAX_KICKS

__all__ = [
    "DEFAULT_MAX_KICKS",
    "Bootstrap",
    "KineticRate",
    "MMPP",
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
