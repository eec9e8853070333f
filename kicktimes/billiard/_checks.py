"""Argument checks shared by the billiard API: every message names the argument,
the offending value and the valid range (design.md, "Bad input")."""

from __future__ import annotations

import math

import numpy as np

from kicktimes._validation import check_choice, check_int, check_real

__all__ = ["check_choice", "check_int", "check_real", "check_state", "check_inside",
           "check_unit_speed", "check_sampling", "RULES", "SAMPLINGS", "CONTACT_TOL"]

RULES = {"mirror": 0, "elastic": 1}
SAMPLINGS = ("uniform", "paper")
CONTACT_TOL = 1e-12


def check_state(name: str, value, shape: tuple[int, ...]) -> np.ndarray:
    """A finite float64 array of the given shape (a fresh C-contiguous copy)."""
    arr = np.array(value, dtype=np.float64, copy=True, order="C")
    if arr.shape != shape:
        raise ValueError(f"{name} must have shape {shape} (rows x, y, vx, vy), got {arr.shape}")
    if not np.isfinite(arr).all():
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


def check_sampling(t_max, n_steps, tau, sampling):
    """Resolve the time arguments of a simulator call.

    Returns ``(t_max, n_steps, tau, mode)`` with mode 0 (no samples), 1 (uniform) or
    2 (paper). ``t_max`` is ``nan`` for paper sampling (the run ends when ``n_steps``
    collision-truncated steps are done).
    """
    check_choice("sampling", sampling, SAMPLINGS)
    if tau is not None:
        tau = check_real("tau", tau, low=0.0)
    if n_steps is not None:
        n_steps = check_int("n_steps", n_steps, low=1)
    if t_max is not None:
        t_max = check_real("t_max", t_max, low=0.0)

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
        n_steps = int(math.floor(t_max / tau * (1.0 + 1e-12)))
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
