"""Argument checks shared by the billiard API: every message names the argument,
the offending value and the valid range (docs/architecture.md, "Bad input")."""

from __future__ import annotations

import math

import numpy as np

from kicktimes.validation import check_choice, check_int, check_real

__all__ = ["check_choice", "check_holes", "check_masses", "check_radii", "check_int", "check_real",
           "check_state", "check_inside",
           "check_unit_speed", "check_speed", "check_sampling", "event_budget", "stall_time",
           "RULES", "SAMPLINGS", "CONTACT_TOL", "SPEED_RANGE", "TIME_LIMIT", "N_STEPS_MAX",
           "MAX_EVENTS_DEFAULT", "STALL_EVENTS"]

RULES = {"mirror": 0, "elastic": 1}
SAMPLINGS = ("uniform", "paper")
CONTACT_TOL = 1e-12
#: Non-zero speeds must lie in this range. The dynamics only depends on speed x time, so
#: nothing is lost; outside it |v|^2 under- or overflows (|v| >= 1e154 gave NaN event times).
SPEED_RANGE = (1e-6, 1e6)
#: Upper limit of t_max, tau and n_steps * tau: keeps the clock's resolution (ulp 1e-4 at
#: 1e12) far below any event spacing and every count of steps or events finite.
TIME_LIMIT = 1e12
#: At most this many sampling steps (24 bytes each: 2.4 GB of samples).
N_STEPS_MAX = 10**8
#: Default cap on the number of logged collisions of one run (about 33 bytes each).
MAX_EVENTS_DEFAULT = 2 * 10**7
#: This many consecutive events without the clock advancing (see `stall_time`) end a run
#: with an error: a state the kernel cannot make progress from.
STALL_EVENTS = 10_000


def check_state(name: str, value, shape: tuple[int, ...]) -> np.ndarray:
    """A finite float64 array of the given shape (a fresh C-contiguous copy)."""
    arr = np.array(value, dtype=np.float64, copy=True, order="C")
    if arr.shape != shape:
        raise ValueError(f"{name} must have shape {shape} (rows x, y, vx, vy), got {arr.shape}")
    # (math.isfinite on the few floats of a state: a third of the cost of np.isfinite().all())
    if not all(map(math.isfinite, arr.ravel().tolist())):
        raise ValueError(f"{name} must be finite, got NaN or inf in {arr.tolist()}")
    return arr


def check_inside(name: str, x: float, y: float, rho: float, r: float, which: str) -> None:
    dist = math.hypot(x, y)
    if dist > rho + CONTACT_TOL:
        raise ValueError(
            f"{name}: {which} centre at distance {dist:.15g} from the table centre lies outside "
            f"the table for r={r!r}; centres must satisfy |x| <= 1 - r = {rho:.15g}"
        )


def check_unit_speed(name: str, vx: float, vy: float, which: str, tol: float = 1e-9) -> None:
    speed = math.hypot(vx, vy)
    if abs(speed - 1.0) > tol:
        raise ValueError(
            f"{name}: {which} speed must be 1 (within {tol:g}) under this rule, got {speed!r}"
        )


def check_speed(name: str, vx: float, vy: float, which: str, *, allow_zero: bool) -> float:
    """A speed ``|v|`` in `SPEED_RANGE` (or exactly 0 when ``allow_zero``); returns it."""
    speed = math.hypot(vx, vy)
    if speed == 0.0 and allow_zero:
        return speed
    lo, hi = SPEED_RANGE
    if not lo <= speed <= hi:
        zero = "0 or " if allow_zero else ""
        raise ValueError(
            f"{name}: {which} speed must be {zero}in [{lo:g}, {hi:g}], got {float(speed)!r} "
            "(rescale time instead: the motion depends only on speed x time)"
        )
    return speed


def stall_time(rho: float, speed: float) -> float:
    """Events closer than this in time count as "no progress" (1e-9 of the table at ``speed``).

    The shortest legitimate spacing of boundary events is the grazing chord
    ``2 rho sin(delta) / |v|`` with ``delta = GRAZE_ANGLE`` (1e-4), five orders larger.
    """
    return 1e-9 * rho / speed


def event_budget(max_events, *, horizon: float, horizon_name: str, speed: float, rho: float,
                 n_disks: int) -> int:
    """The maximum number of logged collisions of a run.

    The expected number is ``n_disks |v| T / (pi rho / 2)`` (the mean free path of a
    disk of radius ``rho`` is ``pi rho / 2``). The default budget is a hundred times that
    plus 10^6, capped at `MAX_EVENTS_DEFAULT`; a run expected to need more than a quarter
    of the cap is refused up front, so that it fails at once rather than after minutes.
    """
    expected = n_disks * speed * horizon / (0.5 * math.pi * rho)
    if max_events is None:
        if expected > MAX_EVENTS_DEFAULT / 4:
            raise ValueError(
                f"{horizon_name}={float(horizon)!r} needs about {expected:.3g} collisions, more "
                f"than the default event budget ({MAX_EVENTS_DEFAULT:.3g}) allows; pass a shorter "
                f"{horizon_name} or max_events= (about 70 bytes of memory per event)"
            )
        return int(min(MAX_EVENTS_DEFAULT, 10**6 + 100.0 * expected))
    return check_int("max_events", max_events, low=1)


def check_sampling(t_max, n_steps, tau, sampling):
    """Resolve the time arguments of a simulator call.

    Returns ``(t_max, n_steps, tau, mode)`` with mode 0 (no samples), 1 (uniform) or
    2 (paper). ``t_max`` is ``nan`` for paper sampling (the run ends when ``n_steps``
    collision-truncated steps are done).
    """
    check_choice("sampling", sampling, SAMPLINGS)
    if tau is not None:
        tau = check_real("tau", tau, low=0.0, high=TIME_LIMIT, high_open=False)
    if n_steps is not None:
        n_steps = check_int("n_steps", n_steps, low=1, high=N_STEPS_MAX)
    if t_max is not None:
        t_max = check_real("t_max", t_max, low=0.0, high=TIME_LIMIT, high_open=False)
    if n_steps is not None and tau is not None and n_steps * tau > TIME_LIMIT:
        raise ValueError(
            f"n_steps * tau must be <= {TIME_LIMIT:g}, got {n_steps} * {tau!r} = {n_steps * tau!r}"
        )

    if tau is None and n_steps is None:
        if t_max is None:
            raise ValueError("give t_max (> 0), or n_steps and tau for a sampled run")
        return t_max, None, None, 0
    if tau is None:
        raise ValueError("tau must be given (a positive step length) when n_steps is given")
    if sampling == "paper":
        if n_steps is None:
            raise ValueError("sampling='paper' needs n_steps (>= 1) and tau")
        if t_max is not None:
            raise ValueError(
                "sampling='paper' runs until n_steps collision-truncated steps are done; "
                "do not pass t_max"
            )
        return math.nan, n_steps, tau, 2
    if n_steps is None:
        if t_max is None:
            raise ValueError("give n_steps or t_max together with tau")
        steps = math.floor(t_max / tau * (1.0 + 1e-12))
        if steps > N_STEPS_MAX:
            raise ValueError(
                f"t_max / tau must be <= {N_STEPS_MAX} steps, got {t_max!r} / {tau!r} = "
                f"{t_max / tau:.6g}; pass a larger tau or a shorter t_max"
            )
        n_steps = int(steps)
        if n_steps < 1:
            raise ValueError(f"t_max={t_max!r} is shorter than one step tau={tau!r}")
        return t_max, n_steps, tau, 1
    if t_max is None:
        t_max = n_steps * tau
    elif t_max < n_steps * tau * (1.0 - 1e-12):
        raise ValueError(
            f"t_max={t_max!r} is shorter than n_steps * tau = {n_steps * tau!r}; "
            "pass t_max >= n_steps * tau or omit it"
        )
    return t_max, n_steps, tau, 1


def check_holes(holes):
    """Holes in the table's wall as a float64 array of rows ``(centre angle, half-width)``,
    or ``None``; half-widths in ``(0, pi)``, angles finite."""
    if holes is None:
        return None
    try:
        arcs = np.array(holes, dtype=np.float64, copy=True, ndmin=2)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"holes must be rows (centre angle, half-width), got "
                        f"{type(holes).__name__} ({exc})") from None
    if arcs.ndim != 2 or arcs.shape[1] != 2 or arcs.shape[0] == 0:
        raise ValueError(f"holes must have shape (n, 2), rows (centre angle, half-width), "
                         f"got shape {arcs.shape}")
    if not np.isfinite(arcs).all():
        raise ValueError("holes must be finite; got NaN or inf")
    if ((arcs[:, 1] <= 0.0) | (arcs[:, 1] >= np.pi)).any():
        raise ValueError(f"holes: each half-width must lie in (0, pi), got {arcs[:, 1].tolist()}")
    return arcs


def check_radii(r):
    """The two disks' radii ``(r0, r1)`` from ``r``: one radius for equal disks, or a pair
    for unequal ones, each in ``(0, 0.5)``. Returns ``(r0, r1, r)`` with ``r`` a float for
    equal disks (given as one number) and the tuple otherwise."""
    if isinstance(r, tuple | list | np.ndarray) and np.ndim(r) == 1:
        if len(r) != 2:
            raise ValueError(f"r must be one radius or a pair (r0, r1), got {len(r)} values")
        r0 = check_real("r[0]", r[0], low=0.0, high=0.5)
        r1 = check_real("r[1]", r[1], low=0.0, high=0.5)
        return r0, r1, (r0, r1)
    r = check_real("r", r, low=0.0, high=0.5)
    return r, r, r


def check_masses(masses, rule):
    """The disks' masses ``(m0, m1)`` (positive, finite), or ``None`` (equal masses); only
    the elastic rule has masses (the mirror rule keeps each speed)."""
    if masses is None:
        return None
    if rule != "elastic":
        raise ValueError(f"masses apply to rule='elastic' (the mirror rule keeps each disk's "
                         f"speed), got rule={rule!r}")
    if isinstance(masses, str | bytes) or np.ndim(masses) != 1 or len(masses) != 2:
        raise ValueError(f"masses must be a pair (m0, m1), got {masses!r}")
    m0 = check_real("masses[0]", masses[0], low=0.0)
    m1 = check_real("masses[1]", masses[1], low=0.0)
    return (m0, m1)
