r"""The tagged disk of a dilute gas: the linear Boltzmann (Boltzmann-Lorentz) process.

A tagged hard disk among equal-mass hard disks at low density, each collision with a
partner drawn afresh from the Maxwellian bath (molecular chaos, no recollisions), collides
at a rate that depends on its own velocity only, :math:`\lambda(v) = c\,\langle |v - w|
\rangle_w`, and its velocity changes at each collision. Its collision times are a Cox
process driven by that velocity: the null of the "speed carries it" reading, the process
that the gas would give if molecular chaos held exactly (Visco, van Wijland & Trizac,
J. Phys. Chem. B 112, 5412 (2008) and Phys. Rev. E 77, 041117 (2008)). Under the mirror
rule (every disk at unit speed, speed kept at a collision) the rate is constant and the
process is Poisson.

`dilute_tagged_times` draws it by exact event Monte Carlo (no time step).
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["DILUTE_RULES", "dilute_tagged_times"]

#: the collision rules `dilute_tagged_times` knows
DILUTE_RULES = ("elastic", "mirror")


@numba.njit(cache=True)
def _elastic_streams(gen, n_runs, t_window, c, kT):  # pragma: no cover - compiled
    """Flat collision times and speeds of ``n_runs`` elastic streams (see the caller)."""
    sigma = math.sqrt(kT)
    mean_w = sigma * math.sqrt(math.pi / 2.0)   # <|w|> of a 2-D Maxwellian
    times = np.empty(1024)
    speeds = np.empty(1024 + n_runs)
    lengths = np.zeros(n_runs, np.int64)
    nt = 0
    ns = 0
    for run in range(n_runs):
        # stationary start: the time-stationary velocity is Maxwellian
        vx = sigma * gen.standard_normal()
        vy = sigma * gen.standard_normal()
        t = 0.0
        count = 0
        while True:
            s = math.hypot(vx, vy)
            if ns >= speeds.size:
                speeds = np.concatenate((speeds, np.empty(speeds.size)))
            speeds[ns] = s
            ns += 1
            # thinning: candidates at rate c (|v| + <|w|>), w from (|v| + |w|) M(w),
            # kept with probability |v - w| / (|v| + |w|) <= 1: the kept ones are a Poisson
            # stream of rate c <|v - w|>_w, their partners of density |v - w| M(w)
            bound = c * (s + mean_w)
            while True:
                t += gen.exponential(1.0 / bound)
                if t > t_window:
                    break
                if gen.random() * (s + mean_w) < s:
                    wx = sigma * gen.standard_normal()
                    wy = sigma * gen.standard_normal()
                else:
                    # |w| M(w) in 2-D: speed a chi of 3 degrees of freedom, direction uniform
                    a = sigma * gen.standard_normal()
                    b = sigma * gen.standard_normal()
                    e = sigma * gen.standard_normal()
                    wr = math.sqrt(a * a + b * b + e * e)
                    ang = 2.0 * math.pi * gen.random()
                    wx = wr * math.cos(ang)
                    wy = wr * math.sin(ang)
                w = math.hypot(wx, wy)
                gx = vx - wx
                gy = vy - wy
                g = math.hypot(gx, gy)
                if gen.random() * (s + w) < g:
                    break
            if t > t_window:
                break
            # contact normal at angle phi from g, density cos(phi) / 2 on (-pi/2, pi/2):
            # the flux (g.n)+ over the contact directions
            phi = math.asin(2.0 * gen.random() - 1.0)
            cp = math.cos(phi)
            sp = math.sin(phi)
            nx = (gx * cp - gy * sp) / g
            ny = (gx * sp + gy * cp) / g
            gn = gx * nx + gy * ny
            # equal masses: the normal components are exchanged
            vx -= gn * nx
            vy -= gn * ny
            if nt >= times.size:
                times = np.concatenate((times, np.empty(times.size)))
            times[nt] = t
            nt += 1
            count += 1
        lengths[run] = count
    return times[:nt], speeds[:ns], lengths


def dilute_tagged_times(rule, rate, t_window, n_runs, rng, *, kT=0.5, speeds=False):
    r"""Collision times of a tagged disk in a dilute gas of equal hard disks (linear
    Boltzmann process), ``n_runs`` independent stationary streams on ``[0, t_window]``.

    Parameters
    ----------
    rule : {"elastic", "mirror"}
        ``"elastic"``: the tagged disk's velocity :math:`v` changes at each collision by the
        elastic equal-mass rule (the normal components are exchanged), with a partner
        :math:`w` from a Maxwellian bath at temperature ``kT``; ``"mirror"``: every disk
        keeps unit speed, so the rate is constant and the stream is Poisson of rate
        ``rate``.
    rate : float
        The stationary mean collision rate :math:`\nu` (``> 0``): under the elastic rule
        the time average of :math:`\lambda(v)`.
    t_window : float
        Each stream's window (``> 0``).
    n_runs : int
        Number of independent streams (``>= 1``).
    rng : numpy.random.Generator or int or None
        The random stream (`numpy.random.default_rng` of it; the compiled loop draws
        from it).
    kT : float
        The bath's temperature, unit masses (``> 0``); 0.5 on the energy shell
        :math:`\sum |v|^2 = N` of `kicktimes.initial_state`. Only the elastic rule uses it
        (the rate's shape in :math:`|v|`; its scale is fixed by ``rate``).
    speeds : bool
        Also return each stream's speed in each interval.

    Returns
    -------
    list of ndarray, or (list of ndarray, list of ndarray)
        One increasing array of collision times per stream; with ``speeds``, also one
        array per stream of ``len(times) + 1`` speeds (before the first collision,
        between collisions, after the last), as
        `kicktimes.experiment.disks_tasks.interval_speeds` reads them from the gas (all 1
        under the mirror rule).

    Notes
    -----
    Between collisions the tagged disk's rate is

    .. math:: \lambda(v) = c\,\langle |v - w| \rangle_{w \sim M}, \qquad
              c = \nu / \langle |w_1 - w_2| \rangle = \nu / \sqrt{\pi\,kT},

    so that its mean over the stationary (Maxwellian, :math:`M`) velocity is :math:`\nu`;
    :math:`\lambda(v) / \nu` is `kicktimes.stats.speed_rate_factor`. At a collision the
    pair (partner :math:`w`, contact direction :math:`n`) has density
    :math:`\propto ((v - w)\cdot n)^+ M(w)` and :math:`v \to v - ((v - w)\cdot n)\,n`.
    This is the Boltzmann-Lorentz process of Visco, van Wijland & Trizac, Phys. Rev. E 77,
    041117 (2008) (and J. Phys. Chem. B 112, 5412 (2008)) for equal masses in two
    dimensions. It is drawn exactly by thinning: candidate events at the constant rate
    :math:`c(|v| + \langle |w| \rangle)` while :math:`v` is fixed, each with a partner
    from the density :math:`\propto (|v| + |w|) M(w)` (a mixture of :math:`M` and of
    :math:`|w| M(w)`, whose speed is :math:`\sqrt{kT}\,\chi_3`), kept with probability
    :math:`|v - w| / (|v| + |w|)`; the kept events are a Poisson stream of rate
    :math:`\lambda(v)` with partners of density :math:`\propto |v - w| M(w)`, and
    :math:`n` at angle :math:`\phi` from :math:`v - w` has density
    :math:`\cos\phi / 2`. Each stream starts from the Maxwellian (stationary) velocity.

    The stream is a Cox process: its counts are over-dispersed (dispersion index above 1
    in long windows), and the rate just after a collision, averaged over collisions, is
    :math:`\langle\lambda^2\rangle / \langle\lambda\rangle > \nu` (the collisions sample
    the velocity with weight :math:`\lambda(v) M(v)`, and the elastic rule keeps that
    distribution).

    Examples
    --------
    >>> import numpy as np
    >>> times = dilute_tagged_times("elastic", 2.0, 50.0, 200, np.random.default_rng(1))
    >>> len(times), bool(abs(np.mean([t.size for t in times]) / 100 - 1) < 0.05)
    (200, True)
    >>> t, v = dilute_tagged_times("mirror", 1.0, 10.0, 3, 0, speeds=True)
    >>> [bool(np.all(s == 1.0)) and s.size == x.size + 1 for x, s in zip(t, v)]
    [True, True, True]
    """
    if rule not in DILUTE_RULES:
        raise ValueError(f"rule must be one of {DILUTE_RULES}, got {rule!r}")
    for name, value in (("rate", rate), ("t_window", t_window), ("kT", kT)):
        if isinstance(value, bool) or not isinstance(value, int | float | np.number):
            raise TypeError(f"{name} must be a real number > 0, got {value!r}")
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a finite real number > 0, got {value!r}")
    if isinstance(n_runs, bool) or not isinstance(n_runs, int | np.integer):
        raise TypeError(f"n_runs must be an integer >= 1, got {n_runs!r}")
    if n_runs < 1:
        raise ValueError(f"n_runs must be an integer >= 1, got {n_runs!r}")
    rng = np.random.default_rng(rng)
    if rule == "mirror":
        counts = rng.poisson(float(rate) * float(t_window), size=int(n_runs))
        times = [np.sort(rng.uniform(0.0, float(t_window), k)) for k in counts]
        if speeds:
            return times, [np.ones(t.size + 1) for t in times]
        return times
    c = float(rate) / math.sqrt(math.pi * float(kT))
    flat, flat_speeds, lengths = _elastic_streams(rng, int(n_runs), float(t_window), c,
                                                  float(kT))
    cut = np.cumsum(lengths)[:-1]
    times = np.split(flat, cut)
    if speeds:
        return times, np.split(flat_speeds, np.cumsum(lengths + 1)[:-1])
    return times
