"""Kinetic kicks: kick times at the collision rate of the kicked disk's own state.

A `KineticRate` is not a `Schedule`: its times cannot be drawn before the run, because
each interval depends on the disk's angular momentum ``L = x vy - y vx`` right after the
previous kick. Between kicks ``L`` is conserved (wall reflections keep it), so the next
interval is exponential with the constant rate :math:`\\bar\\Gamma(r; L)`, the partner-
averaged kinetic rate of `kicktimes.stats.mean_kinetic_rate`; the event loop draws it
after every kick (`kicktimes.billiard.kernels.one.kinetic_delay`) from a standard
exponential number drawn beforehand, so runs are reproducible and twins share the kicks.

This is the one-disk model of the mechanism behind the two-disk collision statistics
(docs/mechanism.md): the collision process is a Cox process whose rate is reset at every
collision by the post-collision angular momenta.
"""

from __future__ import annotations

import math

import numpy as np

from kicktimes._validation import check_int, check_real

__all__ = ["KineticRate"]


class KineticRate:
    r"""Kicks whose rate is the kinetic collision rate of the disk's angular momentum.

    After every kick (and at the start) the next interval is exponential with rate
    :math:`s\,\bar\Gamma(r; L)`: :math:`\bar\Gamma` the collision rate of a disk of angular
    momentum ``L`` with a partner drawn from ``partner`` (`kicktimes.stats.mean_kinetic_rate`),
    ``s`` the factor ``scale``. It is tabulated once on ``n_grid`` midpoints of
    ``(-(1 - r), 1 - r)`` and interpolated linearly in the event loop.

    Parameters
    ----------
    r : float
        Disk radius, ``0 < r < 0.5``: the run's radius (checked when it is used).
    partner : "invariant" or array_like, optional
        The partner's angular-momentum law: its invariant law (default) or a sample, e.g.
        the post-collision angular momenta of a two-disk run (empirical law).
    scale : float, optional
        A factor on the rate (1: the kinetic rate; e.g. the ratio of an ensemble's observed
        to kinetic collision rate).
    n_grid : int, optional
        Table size (default 257, ``>= 8``).

    Notes
    -----
    Unit speeds (the mirror rule): the rate is tabulated for ``|v| = 1`` and the runs that
    use it must keep unit speed (uniform, gaussian or mirror-rule scattering kicks).

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import simulate_one_particle
    >>> from kicktimes.schedules import KineticRate
    >>> kicks = KineticRate(0.02)
    >>> run = simulate_one_particle(np.array([0.1, 0.2, 0.6, 0.8]), 0.02, t_max=500.0,
    ...                             kicks=kicks, kick_angle="scatter", rng=1)
    >>> bool(run.n_kicks > 0)
    True
    """

    def __init__(self, r, *, partner="invariant", scale=1.0, n_grid=257):
        from kicktimes.stats import mean_kinetic_rate

        self.r = check_real("r", r, low=0.0, high=0.5)
        self.scale = check_real("scale", scale, low=0.0)
        n = check_int("n_grid", n_grid, low=8)
        rho = 1.0 - self.r
        self.dl = 2.0 * rho / n
        self.l_first = -rho + 0.5 * self.dl
        ell = self.l_first + self.dl * np.arange(n)
        self.partner = "invariant" if isinstance(partner, str) else "sample"
        # a large sample is averaged over 256 equal-count strata (relative error ~1e-3,
        # kicktimes.stats.mean_kinetic_rate); the exact mean over 10^4 values takes minutes
        strata = None if isinstance(partner, str) or np.size(partner) <= 256 else 256
        rates = mean_kinetic_rate(self.r, ell, partner=partner, partner_strata=strata)
        self.rates = self.scale * np.asarray(rates, dtype=np.float64)
        if not (np.isfinite(self.rates).all() and (self.rates > 0.0).all()):
            raise ValueError(f"the kinetic rate of r={self.r!r} is not positive and finite on "
                             "every L: check r and partner")

    @property
    def max_rate(self) -> float:
        """The largest tabulated rate: an upper bound of the kick rate."""
        return float(self.rates.max())

    def rate(self, L) -> np.ndarray:
        """The tabulated rate at angular momenta ``L`` (the kernel's interpolation)."""
        ell = np.asarray(L, dtype=np.float64)
        f = (ell - self.l_first) / self.dl
        i = np.clip(np.floor(f).astype(np.int64), 0, self.rates.size - 2)
        w = np.clip(f - i, 0.0, 1.0)
        return self.rates[i] * (1.0 - w) + self.rates[i + 1] * w

    def capacity(self, horizon: float) -> int:
        """Kicks to draw numbers for on ``(0, horizon]``: the count of a Poisson process at
        `max_rate` (which the kinetic kicks never exceed) plus 8 standard deviations, so
        that running out has probability below 1e-15."""
        mean = self.max_rate * horizon
        return int(math.ceil(mean + 8.0 * math.sqrt(mean) + 16.0))

    def kernel_table(self, r) -> tuple:
        """``(rates, l_first, dl)`` for a run of radius ``r`` (which must be this table's)."""
        if not math.isclose(float(r), self.r, rel_tol=0.0, abs_tol=1e-15):
            raise ValueError(f"kicks: the KineticRate is tabulated for r={self.r!r}, the run "
                             f"has r={float(r)!r}; build it with the run's radius")
        return self.rates, self.l_first, self.dl

    def __repr__(self) -> str:
        return (f"KineticRate(r={self.r!r}, partner={self.partner!r}, scale={self.scale!r}, "
                f"n_grid={self.rates.size})")
