r"""Low-density theory of the stretching per perturbation, :math:`\lambda/\Gamma`, as r -> 0.

For small disks a perturbation (a disk-disk collision or a kick) is rare: between two of
them each disk runs for a time :math:`\tau \sim 1/\Gamma = O(1/r)` on a free orbit of the
circular billiard, which only *shears* a tangent vector (linear growth in time, no
exponential growth). The exponential growth is a product of one factor per perturbation,
and for :math:`r \to 0` each factor takes a universal form (docs/small_r.md, the
derivation):

* **the shear of the free flight.** A centre of speed :math:`c` on the orbit of unit-speed
  angular momentum :math:`\kappa` (chords of the circle :math:`|x| = \rho = 1 - r` tangent
  to :math:`|x| = |\kappa|`) runs :math:`\nu = c / (2\sqrt{\rho^2-\kappa^2})` chords per
  unit time, each turning the pattern by :math:`\Delta(\kappa) = \pm\pi -
  2\arcsin(\kappa/\rho)`. A deviation :math:`(\delta\kappa, \delta c)` of the orbit moves
  the centre after a time :math:`t \gg 1/\nu` by

  .. math:: \delta q(t) = t\Big[\Big(\frac{\kappa\,\delta\kappa}{\rho^2-\kappa^2}
            + \frac{\delta c}{c}\Big) v(t) - \frac{c\,\delta\kappa}{\rho^2-\kappa^2}\,
            \hat z \times q(t)\Big] + O(1),

  a slip along the orbit and a rotation of the pattern (`flight_shear`);
* **a disk-disk collision** (or a scattering kick off a virtual partner) at contact
  distance :math:`\sigma = 2r` turns a position deviation :math:`\delta q` into a velocity
  deviation of order :math:`|\delta q|/\sigma` through the variation of the contact normal,
  :math:`\delta n = (\delta q_{rel} + g\,\delta t)/\sigma` (Dellago, Posch & Hoover 1996),
  which changes the new orbit by :math:`\delta\kappa = O(1/\sigma)`;
* **a uniform kick** (a new direction drawn independently of the state) erases the
  velocity deviation; the position deviation alone changes the new orbit,
  :math:`\delta\kappa = \delta q \times \hat w`: no factor :math:`1/\sigma`.

So the growth factor per perturbation is :math:`G = (\tau/\sigma) F` for collisions and
scattering kicks and :math:`G = \tau F` for uniform kicks, with :math:`F` a function of the
geometry of two consecutive perturbations only, and

.. math:: \frac{\lambda}{\Gamma} = E[\ln G]
          = b \ln\frac1r + a + o(1), \qquad b = 2 \text{ (collisions, scattering kicks)},
          \quad b = 1 \text{ (uniform kicks)},

since :math:`E[\ln\tau] = -\gamma_E - \ln\Gamma` with :math:`\Gamma \propto r`. The kicked
/ two-disk ratio of the FTLE therefore tends to :math:`1/2` for uniform kicks and to
:math:`1` for scattering kicks, both like :math:`1/\ln(1/r)`. The constant :math:`a` is an
average over the invariant measure of the perturbations, which `stretching_theory`
computes by Monte Carlo of the product of these rank-one maps, with the exact linearised
collision maps of the simulators (`kicktimes.billiard.kernels.tangent.pair_tangent`,
`kicktimes.billiard.scatter.scatter_tangent`) and the collision geometry drawn as in the
limit :math:`r \to 0`:

* between perturbations each orbit's phase is uniform on its invariant torus, so the next
  collision of two disks happens at a point :math:`x` with density
  :math:`\propto p_1(x)\,p_2(x)\,|v_1 - v_2|` (`kicktimes.stats.conditional_kinetic_rate`,
  whose integrand this is), an impact parameter uniform on :math:`(-\sigma, \sigma)`, and
  after an exponential time of the rate :math:`\Gamma(\kappa_1, c_1, \kappa_2, c_2)` of the
  two orbits; :math:`E[\ln\tau]` is taken in closed form given the orbits
  (Rao-Blackwellised);
* a kick happens at a uniform phase of the kicked disk's orbit; a scattering kick's
  partner is drawn by the simulators' own law (`kicktimes.billiard.scatter.draw_partner`);
  the kick rate is the experiment's: the invariant-measure rate
  `kicktimes.stats.kinetic_rate` (``poisson``, ``poisson_scatter``) or the kinetic rate
  of the disk's own orbit, `kicktimes.stats.mean_kinetic_rate` (``uniform_kinetic``,
  ``poisson_kinetic``).

Neglected, all of relative order :math:`r` or vanishing as :math:`r \to 0`: the bounded
part of the flight's tangent map, position deviations against the :math:`1/\sigma` velocity
deviations at a collision, the pair's separation :math:`2r` at contact, re-collisions and
the slow equilibration on nearly resonant tori. The theory is not fitted to any simulation.

References
----------
.. [1] H. van Beijeren and J. R. Dorfman, "Lyapunov exponents and Kolmogorov-Sinai entropy
   for the Lorentz gas at low densities", Phys. Rev. Lett. 74, 4412 (1995): the same
   structure, :math:`\lambda/\nu = -2\ln(\tilde n) + \text{const}`, for the Lorentz gas.
.. [2] Ch. Dellago, H. A. Posch and W. G. Hoover, "Lyapunov instability in a system of hard
   disks in equilibrium and nonequilibrium steady states", Phys. Rev. E 53, 1485 (1996).
.. [3] S. Ranković and M. A. Porter, "Two-particle circular billiards versus randomly
   perturbed one-particle circular billiards", Chaos 23, 013123 (2013).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from kicktimes._results import Result
from kicktimes.billiard.kernels.tangent import pair_tangent
from kicktimes.billiard.scatter import collide_with_partner, draw_partner, scatter_tangent
from kicktimes.stats import (
    conditional_kinetic_rate,
    kinetic_rate,
    mean_kinetic_rate,
)
from kicktimes.validation import check_choice, check_int, check_real, check_rng

__all__ = ["SLOPES", "THEORY_SYSTEMS", "StretchingTheory", "flight_shear", "limit_ratio",
           "stretching_theory"]

#: the systems the theory covers: the two disks and the experiments' kicked systems
THEORY_SYSTEMS = ("two_particle", "poisson", "uniform_kinetic", "poisson_scatter",
                  "poisson_kinetic")
#: b of lambda/Gamma = b ln(1/r) + a: two factors 1/r per collision or scattering kick
#: (the normal's 1/sigma and the flight time ~ 1/Gamma), one per uniform kick
SLOPES = {"two_particle": 2, "poisson": 1, "uniform_kinetic": 1, "poisson_scatter": 2,
          "poisson_kinetic": 2}
_CODES = {s: k for k, s in enumerate(THEORY_SYSTEMS)}
_RULES = ("mirror", "elastic")
_EULER_GAMMA = 0.5772156649015329
#: Gauss-Legendre nodes of the rates' quadrature: against 24 nodes the rate moves by at most
#: 0.2 % and its mean log by 7e-5 nats, far inside the Monte Carlo error, at a quarter of
#: the cost
_RATE_NODES = 12


@njit(cache=True, inline="always")
def flight_shear(kappa, c, d_kappa, d_c, rho, x, y, vx, vy):
    r"""Position deviation per unit time after a long free flight, :math:`\delta q / t`.

    The orbit has unit-speed angular momentum ``kappa`` and speed ``c`` in the room
    ``|x| <= rho``; ``(x, y)`` and ``(vx, vy)`` are the centre and velocity at the end of
    the flight, ``(d_kappa, d_c)`` the orbit's deviation. Leading order in ``t`` of the
    exact tangent flow (module docstring): ``A v - B z x q`` with
    ``A = kappa d_kappa / (rho^2 - kappa^2) + d_c / c``, ``B = c d_kappa / (rho^2 -
    kappa^2)``. Returns ``(dqx, dqy)``.
    """
    w = rho * rho - kappa * kappa
    a = kappa * d_kappa / w + d_c / c
    b = c * d_kappa / w
    return a * vx + b * y, a * vy - b * x


@njit(cache=True, inline="always")
def _orbit_velocity(kappa, c, radius, sign):
    """Velocity of a centre at ``(radius, 0)`` on the orbit ``(kappa, c)``, radial part of
    sign ``sign``."""
    t = kappa / radius
    return sign * c * math.sqrt(max(1.0 - t * t, 0.0)), c * t


@njit(cache=True)
def _orbit_point(kappa, c, rho, gen):
    """A uniform phase of one orbit, put on the x-axis: ``(radius, vx, vy)``.

    The radius has the density ``R / sqrt(R^2 - kappa^2)`` on ``(|kappa|, rho)``, i.e.
    ``u = sqrt(R^2 - kappa^2)`` is uniform; the radial direction is in or out with
    probability 1/2."""
    u = gen.random() * math.sqrt(max(rho * rho - kappa * kappa, 0.0))
    radius = math.sqrt(kappa * kappa + u * u)
    sign = 1.0 if gen.random() < 0.5 else -1.0
    vx, vy = _orbit_velocity(kappa, c, max(radius, 1e-300), sign)
    return radius, vx, vy


@njit(cache=True)
def _meeting_point(k1, c1, k2, c2, rho, floor, gen):
    """Where two orbits meet: ``(radius, v1x, v1y, v2x, v2y)`` with the density
    ``R |v1 - v2| / (sqrt(R^2 - k1^2) sqrt(R^2 - k2^2))`` on ``(max|k|, rho)`` and the
    four in/out branches (rejection from ``1 / sqrt(u^2 + s^2)``, ``u^2 = R^2 - max k^2``,
    ``s^2 = max k^2 - min k^2``, floored at ``floor``: the disks' size smooths equal
    caustics)."""
    big = max(abs(k1), abs(k2))
    small = min(abs(k1), abs(k2))
    s = max(math.sqrt(big * big - small * small), floor)
    top = math.sqrt(max(rho * rho - big * big, 0.0))
    width = math.asinh(top / s)
    bound = c1 + c2
    while True:
        u = s * math.sinh(gen.random() * width)
        radius = math.sqrt(big * big + u * u)
        s1 = 1.0 if gen.random() < 0.5 else -1.0
        s2 = 1.0 if gen.random() < 0.5 else -1.0
        v1x, v1y = _orbit_velocity(k1, c1, radius, s1)
        v2x, v2y = _orbit_velocity(k2, c2, radius, s2)
        g = math.hypot(v1x - v2x, v1y - v2y)
        if gen.random() * bound < g:
            return radius, v1x, v1y, v2x, v2y


@njit(cache=True)
def _two_disk_chain(r, rule, k1, c1, k2, c2, n_steps, out_log, out_state, gen):
    """``n_steps`` collisions of one chain; per step the log of ``|dn|`` (the growth
    factor over the flight time) and the orbits of that flight ``(k1, c1, k2, c2)``."""
    rho = 1.0 - r
    sigma = 2.0 * r
    d1 = 1.0
    dc1 = 0.0
    d2 = -1.0
    dc2 = 0.0
    for step in range(n_steps):
        out_state[step, 0] = k1
        out_state[step, 1] = c1
        out_state[step, 2] = k2
        out_state[step, 3] = c2
        radius, v1x, v1y, v2x, v2y = _meeting_point(k1, c1, k2, c2, rho, sigma, gen)
        q1x, q1y = flight_shear(k1, c1, d1, dc1, rho, radius, 0.0, v1x, v1y)
        q2x, q2y = flight_shear(k2, c2, d2, dc2, rho, radius, 0.0, v2x, v2y)
        gx = v1x - v2x
        gy = v1y - v2y
        g = math.hypot(gx, gy)
        b = 2.0 * gen.random() - 1.0
        cb = math.sqrt(1.0 - b * b)
        nx = (-cb * gx - b * gy) / g       # n = -cos(phi) g^ + sin(phi) z x g^
        ny = (-cb * gy + b * gx) / g
        if rule == 0:
            p1 = 2.0 * (v1x * nx + v1y * ny)
            p2 = 2.0 * (v2x * nx + v2y * ny)
            w1x, w1y = v1x - p1 * nx, v1y - p1 * ny
            w2x, w2y = v2x - p2 * nx, v2y - p2 * ny
        else:
            p = gx * nx + gy * ny
            w1x, w1y = v1x - p * nx, v1y - p * ny
            w2x, w2y = v2x + p * nx, v2y + p * ny
        x1 = radius + 0.5 * sigma * nx
        y1 = 0.5 * sigma * ny
        x2 = radius - 0.5 * sigma * nx
        y2 = -0.5 * sigma * ny
        _, _, a2, a3, _, _, b2, b3 = pair_tangent(
            q1x, q1y, 0.0, 0.0, q2x, q2y, 0.0, 0.0, x1, y1, x2, y2, v1x, v1y, v2x, v2y,
            w1x, w1y, w2x, w2y, rule)
        # |dn|, the normal's variation: (dq_rel + g dt) / sigma, its part along t = z x n
        dt = -(nx * (q1x - q2x) + ny * (q1y - q2y)) / (gx * nx + gy * ny)
        mu = abs((-ny) * (q1x - q2x + gx * dt) + nx * (q1y - q2y + gy * dt)) / sigma
        out_log[step] = math.log(mu)
        a2 /= mu
        a3 /= mu
        b2 /= mu
        b3 /= mu
        c1 = math.hypot(w1x, w1y)
        c2 = math.hypot(w2x, w2y)
        k1 = radius * w1y / c1
        k2 = radius * w2y / c2
        dc1 = (w1x * a2 + w1y * a3) / c1
        dc2 = (w2x * b2 + w2y * b3) / c2
        d1 = radius * a3 / c1 - k1 * dc1 / c1
        d2 = radius * b3 / c2 - k2 * dc2 / c2
        if rule == 0:
            dc1 = 0.0                       # mirror: speeds stay 1, and so do deviations
            dc2 = 0.0


@njit(cache=True)
def _kicked_chain(r, rule, scatter, k, c, e0, n_steps, out_log, out_state, gen):
    """``n_steps`` kicks of one chain of a kicked disk (``scatter`` 0: uniform new
    direction; 1: a virtual partner); per step the log growth over the flight time and
    the orbit ``(k, c)`` of that flight."""
    rho = 1.0 - r
    sigma = 2.0 * r
    dk = 1.0
    dc = 0.0
    for step in range(n_steps):
        out_state[step, 0] = k
        out_state[step, 1] = c
        radius, vx, vy = _orbit_point(k, c, rho, gen)
        qx, qy = flight_shear(k, c, dk, dc, rho, radius, 0.0, vx, vy)
        if scatter == 0:
            theta = 2.0 * math.pi * gen.random()
            wx = math.cos(theta)
            wy = math.sin(theta)
            grow = qx * wy - qy * wx                 # d kappa' = dq x w^
            out_log[step] = math.log(abs(grow))
            k = radius * wy
            dk = 1.0
            dc = 0.0
            continue
        a = 2.0 * gen.random() - 1.0
        b = 2.0 * gen.random() - 1.0
        ux, uy, nx, ny = draw_partner(vx, vy, a, b, rule, e0, 0, 1.0, 1.0)
        if nx == 0.0 and ny == 0.0:
            out_log[step] = math.nan
            continue
        gx = vx - ux
        gy = vy - uy
        dt = -(nx * qx + ny * qy) / (gx * nx + gy * ny)
        mu = abs((-ny) * (qx + gx * dt) + nx * (qy + gy * dt)) / sigma
        out_log[step] = math.log(mu)
        _, _, dvx, dvy = scatter_tangent(vx, vy, ux, uy, nx, ny, sigma, rule, 1.0,
                                         qx / mu, qy / mu, 0.0, 0.0)
        wx, wy = collide_with_partner(vx, vy, ux, uy, nx, ny, rule, 1.0)
        c = math.hypot(wx, wy)
        k = radius * wy / c
        dc = (wx * dvx + wy * dvy) / c if rule == 1 else 0.0
        dk = radius * dvy / c - k * dc / c


def _invariant_orbits(n, r, rule, rng):
    """Orbits ``(k1, c1, k2, c2)`` of ``n`` draws of the two-disk invariant measure
    (centres uniform in the room, overlaps ignored; velocities as in
    `kicktimes.billiard.initial_conditions`)."""
    rho = 1.0 - r
    rad = rho * np.sqrt(rng.random((n, 2)))
    phi = rng.uniform(0, 2 * np.pi, (n, 2))
    if rule == "mirror":
        speed = np.ones((n, 2))
    else:
        z = rng.standard_normal((n, 4))
        z *= math.sqrt(2.0) / np.linalg.norm(z, axis=1, keepdims=True)
        speed = np.hypot(z[:, 0::2], z[:, 1::2])
    direction = rng.uniform(0, 2 * np.pi, (n, 2))
    # kappa = (q x v) / c for q at angle phi, v at angle direction
    kappa = rad * np.sin(direction - phi)
    return kappa[:, 0], speed[:, 0], kappa[:, 1], speed[:, 1]


@dataclass(frozen=True, repr=False)
class StretchingTheory(Result):
    r"""The low-density prediction of :math:`\lambda/\Gamma` for one system at radius r.

    ``stretch`` is :math:`E[\ln G]` per perturbation with its Monte Carlo 95 % interval
    (``ci_low``, ``ci_high``; standard error ``se`` over independent chains); ``slope`` is
    b and ``intercept`` :math:`a = \lambda/\Gamma - b \ln(1/r)` of the asymptotic form;
    ``rate`` the perturbation rate of the chains (each chain's perturbations over its
    time, :math:`1/E[1/\Gamma]` over its flights, averaged over the chains started from the
    invariant measure: for the two disks it must equal `kicktimes.stats.kinetic_rate` at
    small r);
    ``log_time`` :math:`E[\ln\tau]` and ``log_geometry`` :math:`E[\ln F]` its two parts.
    """

    _title: ClassVar[str] = "Low-density stretching per perturbation"
    _intervals: ClassVar[dict] = {"stretch": ("ci_low", "ci_high")}

    system: str
    rule: str
    r: float
    stretch: float
    se: float
    ci_low: float
    ci_high: float
    slope: int
    intercept: float
    rate: float
    log_time: float
    log_geometry: float
    n_chains: int
    n_steps: int
    reason: str | None = None


def stretching_theory(r, system="two_particle", *, rule="mirror", n_chains=400,
                      n_steps=1000, burn_in=100, rng=None) -> StretchingTheory:
    r"""Low-density prediction of the stretching per perturbation :math:`\lambda/\Gamma`.

    Parameters
    ----------
    r : float
        Disk radius, ``0 < r <= 0.1`` (the theory is the limit r -> 0; its neglected terms
        are of relative order r).
    system : str
        One of `THEORY_SYSTEMS`: ``"two_particle"``; the disk kicked in uniform new
        directions at the invariant-measure rate (``"poisson"``) or at its own orbit's
        kinetic rate (``"uniform_kinetic"``); scattering kicks off a virtual partner at
        those two rates (``"poisson_scatter"``, ``"poisson_kinetic"``).
    rule : {"mirror", "elastic"}
        The collision rule (of the two disks, of the scattering partner); it also fixes
        the speeds and the kick rate.
    n_chains, n_steps, burn_in : int
        Independent Markov chains of perturbations, the steps of each kept, and the steps
        discarded at the start of each (from the invariant measure).
    rng : None, int, SeedSequence or numpy.random.Generator
        Source of the chains' starts and of every draw of the chains (passed to the
        compiled kernels as a `numpy.random.Generator`).

    Returns
    -------
    StretchingTheory

    Notes
    -----
    :math:`\lambda/\Gamma = E[\ln\tau] + E[\ln F]` per perturbation with, given the orbits
    of a flight, :math:`E[\ln\tau] = -\gamma_E - \ln\Gamma_{orbits}` (exponential flight
    times), and :math:`\ln F` the log of the contact normal's variation (collisions,
    scattering kicks) or of the new orbit's angular-momentum deviation (uniform kicks) per
    unit flight time and unit incoming deviation (module docstring; docs/small_r.md).

    Examples
    --------
    >>> th = stretching_theory(1e-3, "two_particle", n_chains=20, n_steps=200, rng=1)
    >>> th.slope, 9 < th.stretch < 13
    (2, True)
    """
    r = check_real("r", r, low=0.0, high=0.1)
    if r <= 0.0:
        raise ValueError(f"r: must be in (0, 0.1], got {r!r}")
    check_choice("system", system, THEORY_SYSTEMS)
    check_choice("rule", rule, _RULES)
    n_chains = check_int("n_chains", n_chains, low=2)
    n_steps = check_int("n_steps", n_steps, low=1)
    burn_in = check_int("burn_in", burn_in, low=0)
    rng = check_rng(rng)
    code = 0 if rule == "mirror" else 1
    k1, c1, k2, c2 = _invariant_orbits(n_chains, r, rule, rng)
    total = burn_in + n_steps
    logs = np.empty((n_chains, n_steps))
    width = 4 if system == "two_particle" else 2
    states = np.empty((n_chains, n_steps, width))
    log_buf = np.empty(total)
    state_buf = np.empty((total, width))
    scatter = system in ("poisson_scatter", "poisson_kinetic")
    for i in range(n_chains):
        if system == "two_particle":
            _two_disk_chain(r, code, k1[i], c1[i], k2[i], c2[i], total, log_buf, state_buf,
                            rng)
        else:
            e0 = 0.5 * (c1[i] ** 2 + c2[i] ** 2)
            _kicked_chain(r, code, int(scatter), k1[i], c1[i], e0, total, log_buf, state_buf,
                          rng)
        logs[i] = log_buf[burn_in:]
        states[i] = state_buf[burn_in:]
    flat = states.reshape(-1, width)
    speeds = {} if rule == "mirror" else None
    if system == "two_particle":
        if rule == "elastic":
            speeds = {"speed1": flat[:, 1], "speed2": flat[:, 3]}
        rho = 1.0 - r
        lim = rho * flat[:, [1, 3]] * (1 - 1e-12)
        L1 = np.clip(flat[:, 0] * flat[:, 1], -lim[:, 0], lim[:, 0])
        L2 = np.clip(flat[:, 2] * flat[:, 3], -lim[:, 1], lim[:, 1])
        rates = conditional_kinetic_rate(r, L1, L2, rule=rule, n_nodes=_RATE_NODES, **speeds)
    elif system in ("poisson", "poisson_scatter"):
        rates = np.full(len(flat), kinetic_rate(r, rule=rule))
    else:
        if rule == "elastic":
            speeds = {"speed": flat[:, 1]}
        lim = (1.0 - r) * flat[:, 1] * (1 - 1e-12)
        L = np.clip(flat[:, 0] * flat[:, 1], -lim, lim)
        rates = mean_kinetic_rate(r, L, rule=rule, n_nodes=_RATE_NODES, **speeds)
    rates = np.asarray(rates, float).reshape(n_chains, n_steps)
    log_time = -_EULER_GAMMA - np.log(rates)
    growth = log_time + logs
    # each chain is one long run (an IC): its rate is perturbations over time, and runs
    # pool as the simulations' estimator does, sum(lambda_i) / sum(Gamma_i), a ratio of
    # means (the elastic rule conserves the pair's angular momentum, so a chain does not
    # forget its start and the weights matter)
    chain_rate = 1.0 / np.mean(1.0 / rates, axis=1)
    per_chain = np.nanmean(growth, axis=1)
    stretch = float(np.sum(chain_rate * per_chain) / np.sum(chain_rate))
    resid = chain_rate * (per_chain - stretch)
    se = float(np.std(resid, ddof=1) / np.mean(chain_rate) / math.sqrt(n_chains))
    slope = SLOPES[system]
    n_bad = int(np.isnan(logs).sum())
    reason = None if n_bad == 0 else f"{n_bad} perturbations without a collision left out"
    return StretchingTheory(
        system=system, rule=rule, r=r, stretch=stretch, se=se,
        ci_low=stretch - 1.959963984540054 * se, ci_high=stretch + 1.959963984540054 * se,
        slope=slope, intercept=stretch - slope * math.log(1.0 / r),
        rate=float(np.mean(chain_rate)), log_time=float(np.mean(log_time)),
        log_geometry=float(np.nanmean(logs)), n_chains=n_chains, n_steps=n_steps,
        reason=reason)


def limit_ratio(system) -> float:
    """The limit r -> 0 of the kicked / two-disk FTLE ratio: ``SLOPES[system] / 2``
    (1/2 for uniform kicks, 1 for scattering kicks).

    >>> limit_ratio("poisson"), limit_ratio("poisson_scatter")
    (0.5, 1.0)
    """
    check_choice("system", system, THEORY_SYSTEMS)
    return SLOPES[system] / SLOPES["two_particle"]
