"""What the drivers record around the event step: samples, growing logs, stalls, status.

The observers of a run, shared by the two-disk and the kicked-disk drivers:

* sampling (`sample_flight`, `sample_at_event`): the tracked disk's centre at the sample
  times that fall on the current free flight (interpolated, before the event), and, under
  the paper's collision-truncated steps, at the event itself; `sample_uniform` samples
  the same flights at ``k tau`` too (a paper-sampled run's uniform samples, in the same
  loop);
* logs that grow (`grow_to`, `grow_rows_to`): a driver's loop only *detects* a full
  buffer and returns `FULL`; its caller grows the buffer outside the loop (an array
  reassigned inside a numba loop costs reference counting on every iteration) and checks
  there, at no cost per event, the event budget and for stalls (`stalled`);
* the status codes of a run: `DONE`, `FULL`, `STALLED`, `OVER_BUDGET`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from kicktimes.billiard.checks import STALL_EVENTS

__all__ = ["DONE", "FULL", "OVER_BUDGET", "STALLED", "grow_boundary_log", "grow_rows_to",
           "grow_to", "in_hole", "new_boundary_log", "new_samples", "sample_at_event",
           "load_uniform", "sample_flight", "sample_uniform", "stalled", "store_uniform",
           "uniform_limit"]

# status codes of the event loops
DONE, FULL, STALLED, OVER_BUDGET = 0, 1, 2, 3


@njit(cache=True, error_model="numpy")
def grow_to(a, limit):
    """``a`` copied into a buffer twice as long, but no longer than ``limit`` (> len(a)).

    An element loop, not ``out[:n] = a``: numba compiles array-to-slice assignment with
    its shape-mismatch error message, string formatting included (seconds of compile time).
    """
    out = np.empty(min(2 * a.shape[0] + 16, limit), dtype=a.dtype)
    for i in range(a.shape[0]):
        out[i] = a[i]
    return out


@njit(cache=True, error_model="numpy")
def grow_rows_to(a, limit):
    """Rows of ``a`` copied into a buffer twice as long, but no longer than ``limit``."""
    out = np.empty((min(2 * a.shape[0] + 16, limit), a.shape[1]), dtype=a.dtype)
    for i in range(a.shape[0]):
        for j in range(a.shape[1]):
            out[i, j] = a[i, j]
    return out


@njit(cache=True, error_model="numpy")
def new_boundary_log(cap):
    """Buffers ``(time, x, y, sin_theta)`` of a boundary log for ``cap`` collisions."""
    return np.empty(cap), np.empty(cap), np.empty(cap), np.empty(cap)


@njit(cache=True, error_model="numpy")
def grow_boundary_log(bt, bx, by, bs, limit):
    """The boundary log's buffers grown (`grow_to`)."""
    return grow_to(bt, limit), grow_to(bx, limit), grow_to(by, limit), grow_to(bs, limit)


@njit(cache=True, error_model="numpy")
def new_samples(n):
    """Buffers ``(sample_times, samples)`` for ``n`` samples of a centre."""
    return np.empty(n), np.empty((n, 2))


@njit(cache=True, error_model="numpy")
def stalled(times, n, stall_dt):
    """True if the last `STALL_EVENTS` of the ``n`` logged ``times`` are less than
    ``stall_dt`` apart on average: the run makes no progress (e.g. disks jammed against
    the wall). Legitimate collisions are at least a grazing chord, ``2e-4 rho / |v|``,
    apart, five orders more than ``stall_dt``."""
    if n < STALL_EVENTS:
        return False
    return times[n - 1] - times[n - STALL_EVENTS] < STALL_EVENTS * stall_dt


@njit(cache=True, error_model="numpy")
def in_hole(x, y, arcs):
    """True if a wall contact of the centre ``(x, y)`` lies in one of the holes ``arcs``
    (rows ``[centre angle, half-width]``, radians): the contact point's polar angle is
    within a half-width of a hole's centre (angles compared on the circle)."""
    s = math.atan2(y, x)
    for i in range(arcs.shape[0]):
        d = s - arcs[i, 0]
        d -= 2.0 * math.pi * math.floor(d / (2.0 * math.pi) + 0.5)
        if abs(d) <= arcs[i, 1]:
            return True
    return False


@njit(cache=True, inline="always")
def load_uniform(uni):
    """The uniform observer's arrays and state, as the drivers carry them:
    ``(u_times, u_samples, ku, uni_on, u_limit)`` from ``uni = (times, samples, counters)``
    with counters ``(next index, on, limit)``."""
    u_times, u_samples, u_cnt = uni
    return u_times, u_samples, u_cnt[0], u_cnt[1] != 0, u_cnt[2]


@njit(cache=True, inline="always")
def store_uniform(uni, ku, uni_on, u_limit):
    """Write the uniform observer's state back between driver calls (see `load_uniform`)."""
    u_cnt = uni[2]
    u_cnt[0] = ku
    u_cnt[1] = 1 if uni_on else 0
    u_cnt[2] = u_limit


@njit(cache=True, inline="always", error_model="numpy")
def _sample_steps(stimes, samples, k, limit, next_time, t, dt, x, y, vx, vy, mode, tau):
    """The one sampler of free flights: record the samples strictly before the next
    event, ``dt`` from now, on the flight from ``(x, y)`` at time ``t``, from sample ``k``
    at ``next_time`` and below ``limit``; returns ``(k, next_time)``. ``mode`` 1: samples
    at ``k tau``; 2: the paper's steps of ``tau``."""
    while k < limit and next_time - t < dt:
        ds = next_time - t
        stimes[k] = next_time
        samples[k, 0] = x + vx * ds
        samples[k, 1] = y + vy * ds
        k += 1
        next_time = k * tau if mode == 1 else next_time + tau
    return k, next_time


@njit(cache=True, inline="always", error_model="numpy")
def sample_flight(stimes, samples, k, next_time, t, dt, x, y, vx, vy, mode, tau):
    """Record the samples strictly before the next event, ``dt`` from now, on the free
    flight from ``(x, y)`` at time ``t``; returns ``(k, next_time)``, the next sample's
    index and time. ``mode`` 1: samples at ``k tau``; 2: the paper's steps of ``tau``."""
    return _sample_steps(stimes, samples, k, stimes.shape[0], next_time, t, dt, x, y, vx, vy,
                         mode, tau)


@njit(cache=True, inline="always", error_model="numpy")
def sample_uniform(stimes, samples, k, limit, t, dt, x, y, vx, vy, tau):
    """`sample_flight` at ``k tau`` (its mode 1) with the samples capped at ``limit``;
    returns ``k``. A second sampler of the same flights: the uniform samples of a
    paper-sampled run, which a uniform run over the same time records bit for bit (the same
    sample times ``k tau``, the same interpolation)."""
    return _sample_steps(stimes, samples, k, limit, k * tau, t, dt, x, y, vx, vy, 1, tau)[0]


@njit(cache=True, inline="always", error_model="numpy")
def uniform_limit(t_end, tau, cap):
    """How many uniform samples a run to ``t_end`` has: ``k tau`` for ``k = 0 ..
    floor(t_end / tau (1 + 1e-12))``, as `kicktimes.billiard.checks.check_sampling` counts
    the steps of ``t_max = t_end`` (at most ``cap``)."""
    return min(np.int64(math.floor(t_end / tau * (1.0 + 1e-12))) + 1, cap)


@njit(cache=True, inline="always", error_model="numpy")
def sample_uniform_flight(u_times, u_samples, ku, u_limit, uni_on, sim_on, t, dt, x, y, vx, vy,
                          tau, t_fin):
    """The uniform samples of one free flight of both drivers' ``uni`` observer: while the
    simulation runs, as far as the buffer goes; once it has ended at ``t_fin``, up to
    ``floor(t_fin / tau)`` samples (`uniform_limit`) and no flight beyond the one a run to
    ``t_fin`` ends in. Returns ``(ku, u_limit, uni_on)``."""
    if sim_on:
        ku = sample_uniform(u_times, u_samples, ku, u_times.shape[0], t, dt, x, y, vx, vy, tau)
    else:
        if u_limit < 0:
            u_limit = uniform_limit(t_fin, tau, u_times.shape[0])
        ku = sample_uniform(u_times, u_samples, ku, u_limit, t, dt, x, y, vx, vy, tau)
        if t + dt > t_fin:
            uni_on = False
    return ku, u_limit, uni_on


@njit(cache=True, inline="always", error_model="numpy")
def sample_at_event(stimes, samples, k, t, x, y, tau):
    """The paper's step cut short by the event at ``t``: a sample there; returns
    ``(k, next_time)``."""
    stimes[k] = t
    samples[k, 0] = x
    samples[k, 1] = y
    return k + 1, t + tau
