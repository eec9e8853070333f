"""The largest Lyapunov exponent of N hard disks, from a twin trajectory (Benettin).

`disks_lyapunov` follows a reference state and a twin a distance ``d0`` away through the
N-disk engine (`kicktimes.simulate_disks`) in segments of length ``segment``: after each,
the separation ``d_k`` of the two states is measured, ``log(d_k / d0)`` summed and the
twin put back at distance ``d0`` along the separation (Benettin, Galgani & Strelcyn, Phys.
Rev. A 14, 2338 (1976)). The estimate is ``lambda = sum_k log(d_k / d0) / t``. Each segment
is a fresh `simulate_disks` call from the two states, so the engine is used through its
public API only (its tangent-space extension, the linearised collision map of Dellago,
Posch & Hoover, Phys. Rev. E 53, 1485 (1996), is not written).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kicktimes._validation import check_choice, check_real, check_rng

__all__ = ["DisksLyapunov", "disks_lyapunov"]


@dataclass(frozen=True, repr=False)
class DisksLyapunov:
    """Result of `disks_lyapunov`.

    Attributes
    ----------
    exponent : float
        ``sum_k log(d_k / d0) / t``, per unit time.
    logs : ndarray
        ``log(d_k / d0)`` of each segment.
    segment, t_max, d0 : float
    n_collisions : int
        Disk-disk collisions of the reference run.
    final_state : ndarray
        The reference's state at ``t_max``.
    """

    exponent: float
    logs: np.ndarray
    segment: float
    t_max: float
    d0: float
    n_collisions: int
    final_state: np.ndarray

    def __repr__(self) -> str:
        return (f"DisksLyapunov(exponent={self.exponent:.5g}, segments={self.logs.size}, "
                f"t_max={self.t_max:g}, d0={self.d0:g})")


def _twin(state, offset, d0, rule):
    twin = state + offset * (d0 / np.linalg.norm(offset))
    if rule == "mirror":
        # unit speeds: the deviation is second order in d0, put back on the constraint
        speed = np.hypot(twin[:, 2], twin[:, 3])
        twin[:, 2:] /= speed[:, None]
    return twin


def disks_lyapunov(state, r, *, t_max, segment, rule="mirror", d0=1e-9, rng=None
                   ) -> DisksLyapunov:
    r"""The largest Lyapunov exponent of an N-disk state, from a Benettin twin.

    Parameters
    ----------
    state : array_like, shape (n_disks, 4)
        The reference's rows ``(x, y, vx, vy)`` (`kicktimes.initial_state`).
    r : float
        The disks' radius.
    t_max : float
        Duration (``> 0``); ``floor(t_max / segment)`` segments are run.
    segment : float
        Time between renormalisations (``> 0``, at most ``t_max``): short enough that the
        separation stays far below the disks' radius (``d0 e^{lambda segment}``).
    rule : {"mirror", "elastic"}
    d0 : float
        The twin's distance in phase space, ``1e-13 <= d0 <= 1e-5``.
    rng : Generator or int, optional
        The first offset's direction (uniform on the sphere of positions and velocities;
        under the mirror rule the twin's speeds are put back to 1).

    Returns
    -------
    DisksLyapunov

    Notes
    -----
    With :math:`X_k` and :math:`X'_k` the two states (all positions and velocities) at the
    end of segment :math:`k`, :math:`d_k = \lVert X'_k - X_k\rVert`, and the twin restarts
    at :math:`X_k + d_0 (X'_k - X_k) / d_k`; :math:`\lambda = \sum_k \log(d_k/d_0) / (K
    \Delta t)`. For a dilute hard-disk gas kinetic theory gives :math:`\lambda \propto \nu
    \ln(1/\tilde n)` (van Zon, van Beijeren & Dellago, Phys. Rev. Lett. 80, 2035 (1998)).
    A twin whose collision sequence departs from the reference's (a grazing collision
    missed) shows as one large ``log(d_k / d0)``; keep ``d0`` small. Each restart moves the
    reference by round-off, which the chaos amplifies: after some ``37 / lambda`` the
    reference is another trajectory than one uninterrupted run's, so the exponent of one
    state compares with another method's only on average over states (two disks: the mean
    of 12 states is 0.99 of `kicktimes.diagnostics.lyapunov`'s tangent mean,
    ``tests/test_disks_gas.py``).

    Examples
    --------
    >>> import kicktimes as kt
    >>> from kicktimes.diagnostics.gas_lyapunov import disks_lyapunov
    >>> s = kt.initial_state(20, 0.05, seed=3)
    >>> res = disks_lyapunov(s, 0.05, t_max=20.0, segment=1.0, rng=1)
    >>> res.logs.size, bool(res.exponent > 0)
    (20, True)
    """
    from kicktimes.billiard import simulate_disks

    ref = np.array(state, dtype=np.float64)
    check_choice("rule", rule, ("mirror", "elastic"))
    t_max = check_real("t_max", t_max, low=0.0)
    segment = check_real("segment", segment, low=0.0, high=t_max, high_open=False)
    d0 = check_real("d0", d0, low=1e-13, high=1e-5, low_open=False, high_open=False)
    gen = check_rng(rng)
    offset = gen.normal(size=ref.shape)
    twin = _twin(ref, offset, d0, rule)
    n_seg = int(math.floor(t_max / segment + 1e-9))
    logs = np.empty(n_seg)
    n_pp = 0
    for k in range(n_seg):
        a = simulate_disks(ref, r, t_max=segment, rule=rule)
        b = simulate_disks(twin, r, t_max=segment, rule=rule)
        ref, diff = a.final_state, b.final_state - a.final_state
        n_pp += a.n_pp
        d = float(np.linalg.norm(diff))
        logs[k] = math.log(d / d0)
        twin = _twin(ref, diff, d0, rule)
    return DisksLyapunov(float(logs.sum() / (n_seg * segment)), logs, segment,
                         n_seg * segment, d0, n_pp, ref)
