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

`dilute_tagged_times` draws it by exact event Monte Carlo (no time step);
`dilute_tagged_disk` is the process as an object with its predictions (the collision rate
at each speed, the interval law and its hazard, the dispersion of counts, the share of
tagged disks a KS test of uniform times rejects), in units of the mean interval.

Enskog's contact value :math:`g(\sigma)` (`kicktimes.stats.contact_value`) multiplies
every rate of this model (the bath's density at contact, :math:`n\,g(\sigma)`, scales
:math:`\lambda(v)` for every :math:`v` alike) and enters nothing else: the collision
kernel (which partner, which contact direction) does not depend on it. A common factor of
every rate is a change of the time unit, so in units of the mean interval the predictions
do not depend on the packing. Nor do they depend on ``kT``: :math:`\lambda(v)/\bar\nu` is
a function of :math:`v/\sqrt{kT}` only, which ``kT`` rescales away (it only sets the
speed scale of `DiluteTaggedDisk.rate`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from kicktimes._results import Result
from kicktimes.validation import keyword_only_after

from ._checks import check_choice, check_int, check_real, check_rng
from .enskog import speed_rate_factor
from .findings import clopper_pearson
from .poisson import uniformity_ks

__all__ = ["DILUTE_RULES", "DiluteEstimate", "DiluteTaggedDisk", "dilute_tagged_disk",
           "dilute_tagged_times"]

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


@keyword_only_after(3, since="0.2.0", names=("n_runs", "rng"))
def dilute_tagged_times(rule, rate, t_window, *, n_runs, rng=None, kT=0.5, speeds=False):
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
    >>> times = dilute_tagged_times("elastic", 2.0, 50.0, n_runs=200, rng=np.random.default_rng(1))
    >>> len(times), bool(abs(np.mean([t.size for t in times]) / 100 - 1) < 0.05)
    (200, True)
    >>> t, v = dilute_tagged_times("mirror", 1.0, 10.0, n_runs=3, rng=0, speeds=True)
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
    rng = check_rng(rng, "rng")
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


#: post-collision speeds dropped at the start of each stream before the speed chain is
#: read: the first collision of a stationary start samples M, not lambda M (the chain's
#: correlation falls about fourfold per collision, so 20 leave 1e-12 of the start)
_BURN_IN = 20


@dataclass(frozen=True)
class DiluteEstimate(Result):
    """One prediction of `DiluteTaggedDisk`: the number, its error and the method.

    Attributes
    ----------
    quantity : str
        The predicted quantity (``"dispersion"``, ``"dispersion, window 30"``,
        ``"KS share, k = 30"``).
    value : float
        The estimate (``float(estimate)`` is it).
    stderr : float
        Its standard error (0 for a closed form).
    ci_low, ci_high : float
        Its 95 % interval (``value +- 1.96 stderr``, or Clopper-Pearson for a share).
    n : int
        The Monte Carlo's size (batches, windows or tagged disks; 0 for a closed form).
    method : str
        How it was computed, in words.
    """

    _title = "Dilute-gas prediction (DiluteTaggedDisk)"
    _summary_fields = ("quantity", "value", "stderr", "n", "method")
    _intervals = {"value": ("ci_low", "ci_high")}

    quantity: str
    value: float
    stderr: float
    ci_low: float
    ci_high: float
    n: int
    method: str

    def __float__(self) -> float:
        return float(self.value)

    def __repr__(self) -> str:
        return (f"DiluteEstimate({self.quantity}: {self.value:.4f} +- {self.stderr:.4f}, "
                f"95 % [{self.ci_low:.4f}, {self.ci_high:.4f}], n = {self.n})")


def _nonnegative(name, value):
    """``value`` as a float array, every entry finite and ``>= 0``, else a ValueError."""
    arr = np.asarray(value, dtype=float)
    bad = ~(np.isfinite(arr) & (arr >= 0))
    if bad.any():
        raise ValueError(f"{name} must be finite and >= 0, got {float(arr[bad].ravel()[0])!r}")
    return arr


def _normal_estimate(quantity, value, stderr, n, method):
    return DiluteEstimate(quantity, float(value), float(stderr), float(value - 1.96 * stderr),
                          float(value + 1.96 * stderr), int(n), method)


@dataclass(frozen=True)
class DiluteTaggedDisk(Result):
    r"""The tagged disk of a dilute gas of equal hard disks (`dilute_tagged_disk`), in
    units of the mean interval: the mean collision rate :math:`\bar\nu` is 1.

    Attributes
    ----------
    rule : {"elastic", "mirror"}
        The collision rule (`dilute_tagged_times`).
    kT : float
        The bath's temperature (unit masses; 0.5 on the energy shell of the gas).

    Notes
    -----
    **The post-collision speed law.** The tagged velocity :math:`V(t)` is a Markov jump
    process: it stays at :math:`v` for an exponential time of rate :math:`\lambda(v)`
    and then jumps to :math:`v'` with the kernel :math:`K(v, v')` of one collision.
    Elastic collisions with a Maxwellian bath :math:`M` at the same temperature obey
    detailed balance, :math:`M(v)\lambda(v)K(v, v') = M(v')\lambda(v')K(v', v)` (the
    collision map :math:`(v, w, n) \mapsto (v', w', n)` is an involution that keeps the
    energy, the Lebesgue measure and the flux :math:`|(v - w)\cdot n|`), so :math:`M`
    is the stationary law of :math:`V(t)`. In the stationary process the collisions
    sample the velocity at the rate they happen: the velocity just before a collision
    (the Palm law of the events) has density :math:`\lambda(v)M(v)/\bar\nu`. Just after:

    .. math:: p_\text{post}(v') = \int \frac{\lambda(v)M(v)}{\bar\nu} K(v, v')\,dv
              = \frac{\lambda(v')M(v')}{\bar\nu}\int K(v', v)\,dv
              = \frac{\lambda(v')M(v')}{\bar\nu},

    the same law (detailed balance, then :math:`\int K(v', \cdot) = 1`); both depend on
    the speed only (isotropy). With :math:`u = |v|^2/2kT` the 2-D Maxwell speed law is
    :math:`e^{-u}\,du` and :math:`p_\text{post}\,du = \rho(u)\,e^{-u}\,du`,
    :math:`\rho = \lambda/\bar\nu` (`rate`).

    **The intervals.** Between collisions the speed is constant, so the interval after a
    collision at post-collision speed :math:`v` is exponential of rate :math:`\lambda(v)`:

    .. math:: S(t) = \int_0^\infty \rho(u)\,e^{-u}\,e^{-\rho(u)t}\,du, \qquad
              f(t) = \int_0^\infty \rho(u)^2\,e^{-u}\,e^{-\rho(u)t}\,du,

    :math:`\langle\tau\rangle = \int e^{-u}\,du = 1` (the mean interval is
    :math:`1/\bar\nu`, as it must be) and :math:`\langle\tau^2\rangle =
    2\int e^{-u}/\rho\,du`. Given the chain of post-collision speeds :math:`V_n` the
    intervals are independent exponentials of rates :math:`\lambda(V_n)`, and
    :math:`V_{n+1}` is drawn from :math:`K(V_n, \cdot)` whatever :math:`\tau_n` was: a
    Markov renewal process, not a renewal process. Successive intervals are correlated
    through the speed (lag-1 correlation of :math:`1/\lambda(V_n)` about 0.22 under the
    elastic rule), so the long-window dispersion of counts is not the intervals'
    :math:`c_v^2` (`dispersion`).

    References
    ----------
    Visco, van Wijland & Trizac, Phys. Rev. E 77, 041117 (2008); Cox & Lewis, *The
    Statistical Analysis of Series of Events* (Methuen, 1966), ch. 4 (counts and
    intervals of a stationary point process); Cinlar, Adv. Appl. Probab. 1, 123 (1969)
    (Markov renewal processes).

    Examples
    --------
    >>> disk = dilute_tagged_disk("elastic")
    >>> round(disk.interval_cv2, 4), disk.hazard([0.0, 40.0]).round(3).tolist()
    (1.1084, [1.064, 0.732])
    >>> dilute_tagged_disk("mirror").hazard(3.0).tolist()
    1.0
    """

    _title = ("The tagged disk of a dilute gas of equal hard disks (a model, in units of the "
              "mean interval)")

    rule: str
    kT: float = 0.5

    def __post_init__(self):
        check_choice("rule", self.rule, DILUTE_RULES)
        object.__setattr__(self, "kT", check_real("kT", self.kT, low=0.0))

    def rate(self, v):
        r"""The collision rate at tagged speed ``v`` over the mean rate,
        :math:`\lambda(v)/\bar\nu`.

        Elastic: :math:`\langle |v - w|\rangle_w / \langle |w_1 - w_2|\rangle` over the
        Maxwellian at ``kT``, with :math:`y = v^2/4kT`,

        .. math:: \lambda(v)/\bar\nu = [(1 + 2y)\,e^{-y}I_0(y) + 2y\,e^{-y}I_1(y)]/\sqrt 2

        (the 2-D analogue of the 3-D :math:`\operatorname{erf}` formula; derived in
        `kicktimes.stats.speed_rate_factor`, which this is). Mirror: 1.

        Parameters
        ----------
        v : array_like
            Speeds, finite and ``>= 0``.

        Returns
        -------
        ndarray

        Examples
        --------
        >>> dilute_tagged_disk("elastic").rate([0.0, 1.0]).round(4).tolist()
        [0.7071, 1.0228]
        """
        v = _nonnegative("v", v)
        return speed_rate_factor(v, kT=self.kT) if self.rule == "elastic" else np.ones_like(v)

    def _rho(self, u):
        """``rate`` at ``u = v^2 / 2kT``."""
        return float(self.rate(math.sqrt(2.0 * self.kT * u)))

    def _moment(self, power, t):
        r""":math:`\int_0^\infty \rho(u)^p\,e^{-u - (\rho(u) - \rho(0))t}\,du` by quadrature,
        split where the integrand's scale :math:`1/(1 + \rho'(0)t)` says."""
        from scipy.integrate import quad

        rho0 = self._rho(0.0)
        scale = 1.0 / (1.0 + t / (2.0 * math.sqrt(2.0)))   # rho'(0) = 1/(2 sqrt 2) in u

        def f(u):
            r = self._rho(u)
            return r ** power * math.exp(-u - (r - rho0) * t)

        edges = scale * np.array([0.0, 1.0, 4.0, 16.0, 64.0])
        total = sum(quad(f, a, b, epsabs=0.0, epsrel=1e-11, limit=200)[0]
                    for a, b in zip(edges[:-1], edges[1:], strict=True))
        return total + quad(f, edges[-1], np.inf, epsabs=0.0, epsrel=1e-11, limit=200)[0]

    @property
    def interval_cv2(self) -> float:
        r""":math:`\langle\tau^2\rangle/\langle\tau\rangle^2 - 1` of the stationary interval
        law: :math:`2\int_0^\infty e^{-u}/\rho(u)\,du - 1` (class Notes), by quadrature;
        1 under the mirror rule (exponential intervals)."""
        if self.rule == "mirror":
            return 1.0
        return 2.0 * self._moment(-1, 0.0) / self._moment(0, 0.0) ** 2 - 1.0

    @property
    def gamma_shape(self) -> float:
        r"""The shape :math:`k` a gamma renewal model fitted by maximum likelihood to many
        intervals converges to: the root of
        :math:`\log k - \psi(k) = \log\langle\tau\rangle - \langle\log\tau\rangle`
        (the gamma likelihood's score in the shape), with the intervals' law of the class
        Notes, :math:`\langle\log\tau\rangle = -\gamma_E - \int_0^\infty \rho(u)
        e^{-u}\log\rho(u)\,du` (an exponential of rate :math:`\rho` has
        :math:`\langle\log\tau\rangle = -\gamma_E - \log\rho`). 1 under the mirror
        rule; below 1 for the elastic rule's over-dispersed intervals.

        Examples
        --------
        >>> round(dilute_tagged_disk("elastic").gamma_shape, 3) < 1.0
        True
        """
        if self.rule == "mirror":
            return 1.0
        from scipy.integrate import quad
        from scipy.optimize import brentq
        from scipy.special import digamma

        def f(u):
            r = self._rho(u)
            return r * math.exp(-u) * math.log(r)

        mean_log = -np.euler_gamma - quad(f, 0.0, np.inf, epsabs=0.0, epsrel=1e-11,
                                          limit=200)[0]
        gap = math.log(self._moment(0, 0.0)) - mean_log
        return brentq(lambda k: math.log(k) - digamma(k) - gap, 1e-3, 1e3, xtol=1e-13)

    def hazard(self, t):
        r"""The interval hazard :math:`f(t)/S(t)` over :math:`\bar\nu`, at ``t`` mean
        intervals after a collision.

        Parameters
        ----------
        t : array_like
            Times since the last collision, finite and ``>= 0``.

        Returns
        -------
        ndarray
            Same shape as ``t``.

        Notes
        -----
        :math:`f/S` of the class Notes, by quadrature (with :math:`e^{-\rho(0)t}`
        factored out of both). At :math:`t = 0` it is
        :math:`\langle\rho^2\rangle_M = \langle\lambda\rangle_\text{post}/\bar\nu`
        (about 1.064 for the elastic rule): just after a collision the disk is faster
        than a typical one. It falls as the fast disks collide again, towards the
        smallest rate, that of a disk at rest: :math:`\rho(0) = 1/\sqrt 2` in two
        dimensions (:math:`\langle|w|\rangle/\langle|w_1 - w_2|\rangle` with
        :math:`|w|` Rayleigh: :math:`\sqrt{\pi kT/2}/\sqrt{\pi kT}`; the issue's
        :math:`\nu/\sqrt 2`). It gets there slowly: :math:`p_\text{post}\,du` is finite
        and non-zero at :math:`u = 0` and :math:`\rho(u) \approx \rho(0) + u/(2\sqrt 2)`,
        so :math:`S(t) \approx \rho(0)e^{-\rho(0)t}/(1 + t/2\sqrt 2)` and
        :math:`f/S \approx 1/\sqrt 2 + 1/(t + 2\sqrt 2)` (0.730 at 40 mean intervals, the
        quadrature 0.732): a power law, not an exponential approach. Mirror: 1.

        Examples
        --------
        >>> dilute_tagged_disk("elastic").hazard([0.0, 5.0]).round(3).tolist()
        [1.064, 0.856]
        """
        arr = _nonnegative("t", t)
        if self.rule == "mirror":
            return np.ones_like(arr)
        out = [self._moment(2, x) / self._moment(1, x) for x in arr.ravel()]
        return np.asarray(out, dtype=float).reshape(arr.shape)

    @keyword_only_after(0, since="0.2.0", names=('window',))
    def dispersion(self, *, window=None, n_events=2_000_000, batch=500, rng=0):
        r"""The index of dispersion :math:`D = \operatorname{Var}N/\operatorname{E}N` of
        the collisions counted in a window of ``window`` mean intervals of the
        stationary process; its long-window limit :math:`D_\infty` for ``None``.

        Parameters
        ----------
        window : float or None
            The window's length in mean intervals (``> 0``), or None for the limit.
        n_events : int
            Collisions the Monte Carlo draws, about (``>= 10000``; its cost is about
            0.4 s per million).
        batch : int
            Collisions per batch of the long-window estimate (``>= 10``).
        rng : numpy.random.Generator or int or None
            The Monte Carlo's stream (seed 0 by default, so the numbers repeat).

        Returns
        -------
        DiluteEstimate
            The estimate, its standard error and 95 % interval, the method in words.
            Mirror: exactly 1 (a Poisson process), with no Monte Carlo.

        Notes
        -----
        **Long windows.** For a stationary point process whose interval sums have the
        asymptotic variance :math:`\sigma^2 = \lim \operatorname{Var}(\tau_1 + \dots +
        \tau_n)/n`, :math:`D_\infty = \sigma^2/\langle\tau\rangle^2` (Cox & Lewis 1966,
        §4.5): :math:`c_v^2` for a renewal process, here more. Given the post-collision
        speeds :math:`V_n`, :math:`\tau_n` is exponential of mean :math:`g(V_n) =
        1/\lambda(V_n)`, independent of the rest (class Notes), so (Rao-Blackwell)

        .. math:: D_\infty = \operatorname{E}_\text{post}[g^2] + \sigma^2_g,\qquad
                  \sigma^2_g = \operatorname{Var} g(V_0)
                  + 2\sum_{k\ge1}\operatorname{Cov}(g(V_0), g(V_k)),

        with :math:`\langle\tau\rangle = \operatorname{E}_\text{post}\,g = 1`. The first
        term is a quadrature (:math:`\int e^{-u}/\rho\,du`); :math:`\sigma^2_g`, the
        only part that needs the collision kernel, is the batch-means estimate over the
        speed chain of `dilute_tagged_times` (four streams, the first 20 collisions of
        each dropped, batches of ``batch`` collisions centred on the known mean 1):
        :math:`\hat\sigma^2_g = m\,\overline{(\bar g_b - 1)^2}` over the :math:`B`
        batches, standard error :math:`\hat\sigma^2_g\sqrt{2/B}`. The exponential noise
        of the intervals never enters, so the error is several times smaller than the
        same batch means over the raw intervals. The batch length's bias,
        :math:`O(\sum_k k\,\operatorname{Cov}_k / m)`, is below :math:`10^{-4}` at
        ``batch = 500`` (the speed correlation falls about fourfold per collision).

        **A finite window.** Counts of independent stationary streams
        (`dilute_tagged_times`, Maxwellian start) over ``[0, window]``, about
        ``n_events / window`` of them (at least 200): :math:`D = s^2/\bar N`, its
        standard error by the delta method (the influence function
        :math:`[(N - \mu)^2 - s^2]/\mu - D(N - \mu)/\mu`).

        Examples
        --------
        >>> d = dilute_tagged_disk("elastic").dispersion(n_events=200_000)
        >>> bool(1.1 < d.value < 1.2), 390 < d.n <= 400
        (True, True)
        >>> float(dilute_tagged_disk("mirror").dispersion(window=30.0))
        1.0
        """
        if window is not None:
            window = check_real("window", window, low=0.0)
        n_events = check_int("n_events", n_events, low=10_000)
        batch = check_int("batch", batch, low=10)
        rng = check_rng(rng)
        name = "dispersion" if window is None else f"dispersion, window {window:g}"
        if self.rule == "mirror":
            return DiluteEstimate(name, 1.0, 0.0, 1.0, 1.0, 0, "exact: a Poisson process")
        if window is None:
            n_streams = 4
            _, speeds = dilute_tagged_times("elastic", 1.0, n_events / n_streams, n_runs=n_streams,
                                            rng=rng, kT=self.kT, speeds=True)
            dev = []
            for s in speeds:
                g = 1.0 / self.rate(s[1 + _BURN_IN:])
                b = g.size // batch
                dev.append(g[: b * batch].reshape(b, batch).mean(axis=1) - 1.0)
            dev = np.concatenate(dev)
            if dev.size < 20:
                raise ValueError(f"n_events: {n_events} collisions give {dev.size} batches "
                                 f"of {batch}; give at least 20 * 4 * batch")
            var_g = batch * float(np.mean(dev ** 2))
            return _normal_estimate(
                name, self._moment(-1, 0.0) + var_g, var_g * math.sqrt(2.0 / dev.size),
                dev.size, f"E_post[1/rho^2] by quadrature + batch means of 1/rho over the "
                f"post-collision speed chain ({dev.size} batches of {batch} collisions)")
        n_runs = max(int(math.ceil(n_events / window)), 200)
        times = dilute_tagged_times("elastic", 1.0, window, n_runs=n_runs, rng=rng, kT=self.kT)
        c = np.array([x.size for x in times], dtype=float)
        mu, var = c.mean(), c.var(ddof=1)
        d = var / mu
        infl = ((c - mu) ** 2 - var) / mu - d * (c - mu) / mu
        return _normal_estimate(name, d, infl.std(ddof=1) / math.sqrt(c.size), c.size,
                                f"variance over mean of the counts of {c.size} independent "
                                f"stationary streams, delta-method error")

    @keyword_only_after(1, since="0.2.0", names=('alpha',))
    def ks_share(self, k, *, alpha=0.05, n_runs=4000, rng=0):
        r"""The share of tagged disks whose first ``k`` collision times a KS test of
        uniformity on the window up to collision ``k + 1`` rejects at ``alpha``.

        As the gas page reads its tagged disks (`kicktimes.studies.disks.null`,
        ``reject_uniformity_ks`` of `kicktimes.stats.poisson_group`): the times
        :math:`t_1 < \dots < t_k` over :math:`t_{k+1}` against U(0, 1), exact KS p-value
        (`kicktimes.stats.poisson.uniformity_ks`). Given :math:`t_{k+1}` the first
        ``k`` times of a Poisson process are uniform, so a Poisson stream is rejected at
        exactly ``alpha``.

        Parameters
        ----------
        k : int
            Collisions tested (``>= 1``).
        alpha : float
            The test's level, in ``(0, 1)``.
        n_runs : int
            Tagged disks drawn (``>= 1``).
        rng : numpy.random.Generator or int or None
            The Monte Carlo's stream (seed 0 by default).

        Returns
        -------
        DiluteEstimate
            The share, its binomial standard error and Clopper-Pearson 95 % interval.
            Mirror: exactly ``alpha``, with no Monte Carlo.

        Notes
        -----
        Each tagged disk is a stationary stream of `dilute_tagged_times` (Maxwellian
        start at time 0, as a disk of an equilibrated gas) over
        :math:`2(k + 1) + 50` mean intervals; in the rare draw where a stream has fewer
        than :math:`k + 1` collisions, the whole draw is repeated on twice the window, so
        no stream is selected by its own length.

        Examples
        --------
        >>> s = dilute_tagged_disk("elastic").ks_share(30, n_runs=500)
        >>> bool(0.0 < s.ci_low < s.value < s.ci_high < 0.3), s.n
        (True, 500)
        """
        k = check_int("k", k, low=1)
        alpha = check_real("alpha", alpha, low=0.0, high=1.0)
        n_runs = check_int("n_runs", n_runs, low=1)
        rng = check_rng(rng)
        name = f"KS share, k = {k}"
        if self.rule == "mirror":
            return DiluteEstimate(name, alpha, 0.0, alpha, alpha, 0,
                                  "exact: uniform times given collision k + 1 (Poisson)")
        window = 2.0 * (k + 1) + 50.0
        while True:
            times = dilute_tagged_times("elastic", 1.0, window, n_runs=n_runs, rng=rng, kT=self.kT)
            if min(x.size for x in times) > k:
                break
            window *= 2.0
        t = np.stack([x[: k + 1] for x in times])
        _, p = uniformity_ks(t[:, :k] / t[:, k:])
        n_rej = int(np.sum(p < alpha))
        share = n_rej / n_runs
        lo, hi = clopper_pearson(n_rej, n_runs)
        return DiluteEstimate(name, share, math.sqrt(share * (1.0 - share) / n_runs), lo, hi,
                              n_runs, f"exact KS p-values of {n_runs} stationary streams "
                              f"(dilute_tagged_times), Clopper-Pearson interval")


def dilute_tagged_disk(rule, *, kT=0.5):
    r"""The tagged disk of a dilute 2-D gas of equal hard disks (the linear Boltzmann
    process of `dilute_tagged_times`) as an object with its predictions.

    Parameters
    ----------
    rule : {"elastic", "mirror"}
        ``"elastic"``: the bath is the 2-D Maxwellian at ``kT`` (:math:`\langle|v|^2\rangle
        = 2kT`) and the tagged velocity changes at each collision; ``"mirror"``: unit
        speeds with uniform directions, the rate constant (a Poisson process).
    kT : float
        The bath's temperature (unit masses, ``> 0``); 0.5 on the energy shell of the gas.

    Returns
    -------
    DiluteTaggedDisk
        ``rate(v)``, ``interval_cv2``, ``hazard(t)``, ``dispersion(window)`` and
        ``ks_share(k)``, time in mean intervals (:math:`\bar\nu = 1`).

    Examples
    --------
    >>> disk = dilute_tagged_disk("elastic")
    >>> disk
    DiluteTaggedDisk(rule='elastic', kT=0.5)
    >>> round(float(disk.rate(0.0)), 4), round(disk.interval_cv2, 3)
    (0.7071, 1.108)
    """
    return DiluteTaggedDisk(rule, kT)
