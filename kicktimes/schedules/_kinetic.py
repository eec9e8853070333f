"""Kinetic kicks: kick times at the collision rate of the kicked disk's own state.

A `KineticRate` is not a `Schedule`: its times cannot be drawn before the run, because
each interval depends on the disk's angular momentum ``L = x vy - y vx`` (and, under the
elastic rule, its speed ``c``) right after the previous kick. Between kicks both are
conserved (wall reflections keep them), so the next interval is exponential with the
constant rate :math:`\\bar\\Gamma(r; L)` (:math:`\\bar\\Gamma(r; L, c)`), the partner-
averaged kinetic rate of `kicktimes.stats.mean_kinetic_rate`; the event loop draws it
after every kick (`kicktimes.billiard.kernels.one.kinetic_delay`) from a standard
exponential number drawn beforehand, so runs are reproducible and twins share the kicks.

This is the one-disk model of the mechanism behind the two-disk collision statistics
(docs/mechanism.md): the collision process is a Cox process whose rate is reset at every
collision by the post-collision angular momenta (and speeds).
"""

from __future__ import annotations

import math

import numpy as np

from kicktimes.validation import check_choice, check_int, check_real

__all__ = ["KineticRate"]

#: the largest speed of a disk in kicktimes' elastic runs, ``|v0|^2 + |v1|^2 = 2``
ELASTIC_MAX_SPEED = math.sqrt(2.0)


class KineticRate:
    r"""Kicks whose rate is the kinetic collision rate of the disk's own orbit.

    After every kick (and at the start) the next interval is exponential with rate
    :math:`s\,\bar\Gamma`: :math:`\bar\Gamma` the collision rate of a disk of angular
    momentum ``L`` (and, under the elastic rule, speed ``c``) with a partner drawn from
    ``partner`` (`kicktimes.stats.mean_kinetic_rate`), ``s`` the factor ``scale``.

    Under ``rule="mirror"`` (unit speeds) it is tabulated once on ``n_grid`` midpoints of
    ``(-(1 - r), 1 - r)`` and interpolated linearly in ``L``. Under ``rule="elastic"``
    the disk's speed ``c`` changes at elastic scattering kicks, and the invariant partner
    of kicktimes' elastic runs has the speed :math:`\sqrt{2 - c^2}` (velocities on the
    energy shell :math:`|v_0|^2 + |v_1|^2 = 2`): the rate is tabulated on the midpoints of
    ``n_grid`` values of :math:`\kappa = L/c \in (-(1 - r), 1 - r)` (the orbit's caustic
    radius, signed) times ``n_speed`` values of :math:`c \in (0, \sqrt 2)`, and
    interpolated bilinearly in :math:`(\kappa, c)`.

    Parameters
    ----------
    r : float
        Disk radius, ``0 < r < 0.5``: the run's radius (checked when it is used).
    partner : "invariant" or array_like, optional
        The partner's angular-momentum law: its invariant law (default) or a sample, e.g.
        the post-collision angular momenta of a two-disk run (empirical law; the mirror
        rule only).
    scale : float, optional
        A factor on the rate (1: the kinetic rate; e.g. the ratio of an ensemble's observed
        to kinetic collision rate).
    n_grid : int, optional
        Table size in ``L`` (mirror) or :math:`\kappa` (elastic) (default 257, ``>= 8``).
    rule : {"mirror", "elastic"}, optional
        The collision rule whose speeds the table is for (default ``"mirror"``).
    n_speed : int, optional
        Elastic rule only: table size in ``c`` (default 64, ``>= 8``).

    Raises
    ------
    ValueError
        ``r``, ``scale``, ``n_grid``, ``n_speed`` or ``rule`` out of range, ``n_speed``
        with the mirror rule, a partner sample with the elastic rule, or a rate that is
        not positive and finite everywhere.

    Notes
    -----
    Mirror rule: the runs that use it must keep unit speed (uniform, gaussian or
    mirror-rule scattering kicks). Elastic rule: the speed may change at every kick
    (elastic scattering kicks with the pair's energy ``e0 = 1``, the energy of kicktimes'
    elastic two-disk ICs) and must stay below :math:`\sqrt 2`; outside the midpoint grids
    the rate is clamped to their ends. The linear interpolation in :math:`\kappa` is
    within 2e-3 of `kicktimes.stats.mean_kinetic_rate` for :math:`|\kappa| \le 0.9(1-r)`
    at r = 0.02 (the rate drops steeply on orbits that hug the rim, where the last cells
    are off by up to a few per cent, as in the mirror table); the one in ``c`` is within
    2.3e-4 next to the kink at :math:`c = \sqrt{2 - c^2} = 1`. Building the elastic table
    costs ``n_grid * n_speed`` partner averages (about 6 s at the defaults on one busy
    core).

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import simulate_one_particle
    >>> from kicktimes.billiard import KickLaw
    >>> from kicktimes.schedules import KineticRate
    >>> kicks = KickLaw(KineticRate(0.02), angle="scatter")
    >>> run = simulate_one_particle(np.array([0.1, 0.2, 0.6, 0.8]), 0.02, t_max=500.0,
    ...                             kicks=kicks, rng=1)
    >>> bool(run.n_kicks > 0)
    True
    >>> fast = KineticRate(0.02, rule="elastic", n_grid=16, n_speed=8)
    >>> bool(fast.rate(0.3, speed=0.5) > 0)
    True
    """

    def __init__(self, r, *, partner="invariant", scale=1.0, n_grid=257, rule="mirror",
                 n_speed=None):
        from kicktimes.stats import mean_kinetic_rate

        self.r = check_real("r", r, low=0.0, high=0.5)
        self.scale = check_real("scale", scale, low=0.0)
        self.rule = check_choice("rule", rule, ("mirror", "elastic"))
        n = check_int("n_grid", n_grid, low=8)
        if self.rule == "mirror":
            if n_speed is not None:
                raise ValueError(f"n_speed: the mirror rule's table has unit speed only; "
                                 f"pass n_speed with rule='elastic', got n_speed={n_speed!r}")
            n_c = 1
        else:
            n_c = check_int("n_speed", 64 if n_speed is None else n_speed, low=8)
            if not isinstance(partner, str):
                raise ValueError("partner: rule='elastic' tabulates the invariant partner on "
                                 "the energy shell; a sample needs its speeds, pass "
                                 "partner='invariant' or rule='mirror'")
        rho = 1.0 - self.r
        self.dl = 2.0 * rho / n
        self.l_first = -rho + 0.5 * self.dl
        ell = self.l_first + self.dl * np.arange(n)
        self.partner = "invariant" if isinstance(partner, str) else "sample"
        if self.rule == "mirror":
            # a large sample is averaged over 256 equal-count strata (relative error ~1e-3,
            # kicktimes.stats.mean_kinetic_rate); the exact mean over 10^4 values takes minutes
            strata = None if isinstance(partner, str) or np.size(partner) <= 256 else 256
            rates = mean_kinetic_rate(self.r, ell, partner=partner, partner_strata=strata)
            self.c_first, self.dc = 1.0, 1.0
        else:
            self.dc = ELASTIC_MAX_SPEED / n_c
            self.c_first = 0.5 * self.dc
            speed = (self.c_first + self.dc * np.arange(n_c))[:, None]
            rates = mean_kinetic_rate(self.r, ell[None, :] * speed, partner=partner,
                                      rule="elastic", speed=speed)
        # rows: speeds (one row, unit speed, under the mirror rule); columns: L or kappa
        self.rates = self.scale * np.asarray(rates, dtype=np.float64).reshape(n_c, n)
        if not (np.isfinite(self.rates).all() and (self.rates > 0.0).all()):
            raise ValueError(f"the kinetic rate of r={self.r!r} is not positive and finite on "
                             "every L: check r and partner")

    @property
    def max_rate(self) -> float:
        """The largest tabulated rate: an upper bound of the kick rate."""
        return float(self.rates.max())

    def rate(self, L, speed=None) -> np.ndarray:
        """The tabulated rate at angular momenta ``L`` (and speeds ``speed``, required under
        the elastic rule, broadcast with ``L``): the kernel's interpolation."""
        ell = np.asarray(L, dtype=np.float64)
        if self.rule == "mirror":
            if speed is not None:
                raise ValueError(f"speed: the mirror rule's table has unit speed; pass speed "
                                 f"only to an elastic KineticRate, got speed={speed!r}")
            return self._linear(self.rates[0], (ell - self.l_first) / self.dl)
        if speed is None:
            raise ValueError("speed: an elastic KineticRate is tabulated over (L / speed, "
                             "speed); pass the disks' speeds")
        c = np.asarray(speed, dtype=np.float64)
        if not (np.isfinite(c).all() and (c > 0.0).all()):
            raise ValueError(f"speed must be positive and finite, got min {float(c.min())!r}")
        ell, c = np.broadcast_arrays(ell, c)
        f = (ell / c - self.l_first) / self.dl
        g = (c - self.c_first) / self.dc
        j = np.clip(np.floor(g).astype(np.int64), 0, self.rates.shape[0] - 2)
        u = np.clip(g - j, 0.0, 1.0)
        low = self._linear(self.rates[j], f, rows=True)
        high = self._linear(self.rates[j + 1], f, rows=True)
        return low * (1.0 - u) + high * u

    @staticmethod
    def _linear(rates, f, rows=False):
        """Linear interpolation at fractional indices ``f`` (clamped to the ends), in one
        row or, with ``rows``, in the row of each ``f``."""
        n = rates.shape[-1]
        i = np.clip(np.floor(f).astype(np.int64), 0, n - 2)
        w = np.clip(f - i, 0.0, 1.0)
        if rows:
            return (np.take_along_axis(rates, i[..., None], -1)[..., 0] * (1.0 - w)
                    + np.take_along_axis(rates, i[..., None] + 1, -1)[..., 0] * w)
        return rates[i] * (1.0 - w) + rates[i + 1] * w

    def capacity(self, horizon: float) -> int:
        """Kicks to draw numbers for on ``(0, horizon]``: the count of a Poisson process at
        `max_rate` (which the kinetic kicks never exceed) plus 8 standard deviations, so
        that running out has probability below 1e-15."""
        mean = self.max_rate * horizon
        return int(math.ceil(mean + 8.0 * math.sqrt(mean) + 16.0))

    def kernel_table(self, r) -> tuple:
        """``(rates, l_first, dl, c_first, dc)`` for a run of radius ``r`` (which must be
        this table's): ``rates[j, i]`` the rate at speed ``c_first + j dc`` and ``L`` (one
        row, unit speed: mirror) or ``L / c`` (elastic) ``= l_first + i dl``."""
        if not math.isclose(float(r), self.r, rel_tol=0.0, abs_tol=1e-15):
            raise ValueError(f"kicks: the KineticRate is tabulated for r={self.r!r}, the run "
                             f"has r={float(r)!r}; build it with the run's radius")
        return self.rates, self.l_first, self.dl, self.c_first, self.dc

    def summary(self) -> str:
        """One paragraph: the law of the kicks and the table's parameters."""
        partner = self.partner if isinstance(self.partner, str) else "an empirical sample"
        lines = ["KineticRate kick schedule: exponential intervals at the kinetic collision rate "
                 "of the disk's own orbit, redrawn after every kick",
                 f"  r: {self.r!r}", f"  rule: {self.rule}", f"  partner: {partner}",
                 f"  scale: {self.scale!r}", f"  n_grid: {self.rates.shape[1]}"]
        if self.rule == "elastic":
            lines.append(f"  n_speed: {self.rates.shape[0]}")
        return "\n".join(lines)

    def __repr__(self) -> str:
        shape = (f"n_grid={self.rates.shape[1]}" if self.rule == "mirror" else
                 f"n_grid={self.rates.shape[1]}, rule='elastic', n_speed={self.rates.shape[0]}")
        return (f"KineticRate(r={self.r!r}, partner={self.partner!r}, scale={self.scale!r}, "
                f"{shape})")
