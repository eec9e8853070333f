r"""The paper's FTLE by its own protocol: every reading of eq. (4), per IC.

Ranković & Porter (2013, Sec. III C) compute

.. math::

    \lambda_{\max}(n) = \frac{1}{\tau n} \sum_{k=1}^{n}
    \log\frac{\lVert \delta d(k\tau) \rVert}{\lVert \delta d(0) \rVert},
    \qquad \lVert \delta d(0) \rVert = 1/5000,

on ``n`` collision-truncated steps of ``tau``, perturbing and measuring x and y of the
positions separately and keeping the larger exponent. What the text leaves open, each a
*choice* here (`CHOICES`):

* ``estimator``: ``"renormalised"`` (Benettin's algorithm, which the text names) or
  ``"literal"`` (eq. (4) as printed: the twin is never renormalised);
* ``measure``: ``"paper"`` (x and y separately, the max) or ``"norm"`` (one twin, the
  2-norm of the position deviation);
* ``twin_kicks`` (kicked systems): ``"shared"`` (the twin gets the run's kick angles) or
  ``"independent"`` (its own angles at the same times);
* ``kick_angle`` (kicked systems): ``"uniform"`` new directions (the paper's figures),
  or its N(0, 1) angles read as the new direction (``"normal"``) or as a rotation
  (``"gaussian"``).

For every IC of both of the paper's panels (`PANELS`: family A, Fig. 6 top, and family
B, Fig. 6 bottom) the three systems are computed under the factorial of the first three
choices at uniform kicks, and under both N(0, 1) readings with the paper's measure and
shared twins; kicktimes' tangent-space value is the reference row. Beside the FTLE, each
IC's lag-1 autocorrelation ``R_1`` of the boundary angles over ``[0, n tau]`` (the quantity
of the paper's Fig. 8; diagnostic ``"r1"``), for the uniform kicks, and the recurrence rate
of its Fig. 7 with and without the main diagonal (`rr_rows`), and, at the panel's
smallest radius, the least-squares line of its Fig. 4 (`times_rows`: Poisson kick times
against the two-disk collision times). `CONVERGENCE` runs the paper's reading and
Benettin's at ``T, 2T, 4T, 8T`` on a stated subset.

The kicks of an IC are drawn once per system and shared by every reading: Poisson times
at the rate of the IC's own two-disk run (its collision count over the horizon, as
`kicktimes.experiment` does), the actual times those of that run; uniform angles, and
one set of N(0, 1) numbers for both N(0, 1) readings (common random numbers across the
readings, so their differences are paired).
"""

from __future__ import annotations

import dataclasses
import itertools
import os
import time
import warnings

import numpy as np
import pandas as pd

from kicktimes.billiard import KickLaw
from kicktimes.billiard.initial import initial_conditions
from kicktimes.billiard.one_particle import draw_kick_angles, simulate_one_particle
from kicktimes.billiard.two_particle import simulate_two_particle
from kicktimes.diagnostics import Tangent, Twin
from kicktimes.diagnostics.autocorrelation import (
    UndefinedDiagnosticWarning,
    autocorrelation,
    boundary_angles,
)
from kicktimes.diagnostics.lyapunov import lyapunov
from kicktimes.diagnostics.recurrence import recurrence_rate
from kicktimes.experiment.presets import PRESETS
from kicktimes.fileio import atomic_write
from kicktimes.schedules import Poisson

__all__ = ["CHOICES", "COLUMNS", "CONVERGENCE", "D0", "EPS", "Panel", "compute_task",
           "panels", "rr_rows", "run_rows", "tasks", "times_rows"]

#: the paper's initial separation
D0 = 1.0 / 5000.0
#: the paper's N(0, 1) kick angles
SIGMA = 1.0
#: each choice: (kicktimes' default level, the other levels)
CHOICES = {
    "estimator": ("renormalised", ("literal",)),
    "measure": ("paper", ("norm",)),
    "twin_kicks": ("shared", ("independent",)),
    "kick_angle": ("uniform", ("normal", "gaussian")),
}
#: the rows a task writes: one FTLE per IC, system and reading
COLUMNS = ["panel", "radius", "ic", "system", "diagnostic", "estimator", "measure",
           "twin_kicks", "kick_angle", "horizon", "lam", "n_kicks"]
#: the paper's recurrence threshold (Fig. 7)
EPS = 1e-3
#: horizons of the convergence runs, in units of the panel's n_steps
CONVERGENCE = (1, 2, 4, 8)
_SYSTEM_ID = {"two_particle": 0, "poisson": 1, "actual": 2}


@dataclasses.dataclass(frozen=True)
class Panel:
    """One panel of the paper's Fig. 6: its radii, ICs, steps and seed.

    ``convergence_radii`` and ``convergence_ics``: the subset run at ``T, 2T, 4T, 8T``.
    """

    name: str
    figure: str
    radii: tuple
    n_ics: int
    n_steps: int
    tau: float
    seed: int
    block: int
    convergence_radii: tuple
    convergence_ics: int

    @property
    def ic_radius(self) -> float:
        return max(self.radii)

    def initial_conditions(self) -> np.ndarray:
        """The panel's ICs: the paper's procedure at the largest radius (as its family)."""
        return initial_conditions(self.n_ics, self.ic_radius, rng=self.seed, method="paper")


def panels(scale: str = "paper") -> tuple[Panel, ...]:
    """The two panels of Fig. 6 at ``scale`` ``"paper"`` (the paper's radii, ICs, ``n`` and
    ``tau``, the ICs of kicktimes' families A and B) or ``"quick"`` (2 radii, 8 ICs, 1500
    steps: a pipeline check)."""
    if scale not in ("paper", "quick"):
        raise ValueError(f"scale must be 'paper' or 'quick', got {scale!r}")
    out = []
    for name, figure in (("family_a", "Fig. 6 top"), ("family_b", "Fig. 6 bottom")):
        exp = PRESETS[name]
        radii = tuple(exp.radii)
        if scale == "paper":
            conv = (radii[0], radii[len(radii) // 2], radii[-1])
            out.append(Panel(name, figure, radii, exp.n_ics, exp.n_steps, exp.tau, exp.seed,
                             25, conv, 100))
        else:
            out.append(Panel(name, figure, (radii[0], radii[-1]), 8, 1500, exp.tau, exp.seed,
                             4, (radii[-1],), 4))
    return tuple(out)


def tasks(panel: Panel) -> list[tuple]:
    """The tasks of a panel: ``("main", radius, first IC, last IC + 1)`` for every radius
    and block of ICs, ``("convergence", radius, a, b)`` blocks of the convergence subset,
    ``("rr", radius, a, b)`` blocks of the recurrence rows, and ``("times", r_min, 0,
    n_ics)``, the Fig. 4 rows at the smallest radius (one cheap task)."""
    out = [("main", r, a, min(a + panel.block, panel.n_ics))
           for r in panel.radii for a in range(0, panel.n_ics, panel.block)]
    for r in panel.convergence_radii:
        for a in range(0, panel.convergence_ics, panel.block):
            out.append(("convergence", r, a, min(a + panel.block, panel.convergence_ics)))
    # the recurrence rate: blocks of four times as many ICs (a cheap task)
    out += [("rr", r, a, min(a + 4 * panel.block, panel.n_ics))
            for r in panel.radii for a in range(0, panel.n_ics, 4 * panel.block)]
    out.append(("times", min(panel.radii), 0, panel.n_ics))
    return out


def _rng(panel: Panel, radius: float, ic: int, system: str, stream: int = 0):
    return np.random.default_rng([panel.seed, 48, ic, round(radius * 10**6),
                                  _SYSTEM_ID[system], stream])


def _readings(kind: str, kicked: bool):
    """(estimator, measure, twin_kicks, kick_angle) of the twin readings of a task."""
    if kind == "convergence":
        return [(e, "paper", "shared", "uniform") for e in ("renormalised", "literal")]
    if not kicked:
        return [(e, m, "shared", "uniform") for e, m in
                itertools.product(("renormalised", "literal"), ("paper", "norm"))]
    rows = list(itertools.product(("renormalised", "literal"), ("paper", "norm"),
                                  ("shared", "independent"), ("uniform",)))
    rows += [(e, "paper", "shared", a) for e in ("renormalised", "literal")
             for a in ("normal", "gaussian")]
    return rows


def run_rows(panel: Panel, kind: str, radius: float, ic_index: int, ic: np.ndarray,
             factor: int = 1) -> list[tuple]:
    """The FTLE rows (`COLUMNS`) of one IC at one radius: the two-disk run, its Poisson-
    and actual-time kicked disks, under every reading of ``kind`` (``"main"`` or
    ``"convergence"``), over ``factor * n_steps`` collision-truncated steps."""
    n, tau = factor * panel.n_steps, panel.tau
    steps = {"n_steps": n, "tau": tau, "sampling": "paper"}
    horizon = n * tau
    rows = []

    def add(system, reading, lam, n_kicks, diagnostic="ftle"):
        rows.append((panel.name, radius, ic_index, system, diagnostic, *reading, factor,
                     float(lam), int(n_kicks)))

    two = simulate_two_particle(ic, radius, t_max=horizon)
    if kind == "main":
        add("two_particle", ("-", "-", "-", "-"), _r1(two, 0), two.n_pp, "r1")
    for reading in _readings(kind, kicked=False):
        e, m, _, _ = reading
        res = lyapunov(ic, radius, **steps,
                       method=Twin(variant=m, d0=D0, renormalize=e == "renormalised"))
        add("two_particle", reading, res.lam, res.n_perturbations)
    if kind == "main":
        res = lyapunov(ic, radius, method=Tangent(variant="paper"), **steps)
        add("two_particle", ("tangent", "paper", "-", "-"), res.lam, res.n_perturbations)
    for system in ("poisson", "actual"):
        times, angles = _kicks(panel, radius, ic_index, system, two, horizon)
        for reading in _readings(kind, kicked=True):
            e, m, k, a = reading
            twin = Twin(variant=m, d0=D0, renormalize=e == "renormalised", twin_kicks=k)
            res = lyapunov(ic[0], radius, method=twin,
                           kicks=KickLaw(times, angle=a, angles=angles[a], sigma=SIGMA),
                           rng=_rng(panel, radius, ic_index, system, 1), **steps)
            add(system, reading, res.lam, res.n_perturbations)
        if kind == "main":
            uniform = KickLaw(times, angle="uniform", angles=angles["uniform"], sigma=SIGMA)
            res = lyapunov(ic[0], radius, method=Tangent(variant="paper"), kicks=uniform,
                           **steps)
            add(system, ("tangent", "paper", "-", "uniform"), res.lam, res.n_perturbations)
            one = simulate_one_particle(ic[0], radius, t_max=horizon, kicks=uniform)
            add(system, ("-", "-", "-", "uniform"), _r1(one, None), one.n_kicks, "r1")
    return rows


def _kicks(panel, radius, ic_index, system, two, horizon):
    """The kick times of ``system`` (Poisson at the two-disk run's rate, or its collision
    times) and their angles: ``{"uniform", "normal", "gaussian"}`` (one set of N(0, 1)
    numbers for both of their readings), drawn from the IC's own stream."""
    rng = _rng(panel, radius, ic_index, system)
    if system == "poisson":
        times = Poisson(two.n_pp / horizon).sample(horizon, rng=rng)
    else:
        times = np.asarray(two.pp_times, dtype=float)
    angles = {"uniform": draw_kick_angles(times.size, "uniform", SIGMA, rng)}
    angles["normal"] = angles["gaussian"] = draw_kick_angles(times.size, "normal", SIGMA, rng)
    return times, angles


def rr_rows(panel: Panel, radius: float, ic_index: int, ic: np.ndarray) -> list[tuple]:
    """The recurrence rows (`COLUMNS`, diagnostic ``"rr"``) of one IC at one radius: the
    paper's RR at ``EPS`` (Sec. III B: all pairs ``i, j`` of the ``n + 1`` samples, the
    main diagonal included, so ``RR >= 1/(n + 1)``; ``measure="with_diagonal"``) and the
    off-diagonal RR (pairs ``i != j``; ``measure="off_diagonal"``), on the paper's
    collision-truncated steps (``estimator="paper_steps"``) of the two-disk run and of
    its kicked disks with the main task's kicks (uniform angles)."""
    n, tau = panel.n_steps, panel.tau
    steps = {"n_steps": n, "tau": tau, "sampling": "paper"}
    horizon = n * tau
    rows = []

    def add(system, points, n_kicks):
        with_diagonal = recurrence_rate(points, eps=EPS)
        off = recurrence_rate(points, eps=EPS, theiler=1)
        for measure, value in (("with_diagonal", with_diagonal), ("off_diagonal", off)):
            rows.append((panel.name, radius, ic_index, system, "rr", "paper_steps", measure,
                         "-", "uniform", 1, float(value), int(n_kicks)))

    two = simulate_two_particle(ic, radius, t_max=horizon)
    sampled = simulate_two_particle(ic, radius, **steps)
    add("two_particle", sampled.samples, sampled.n_pp)
    for system in ("poisson", "actual"):
        times, angles = _kicks(panel, radius, ic_index, system, two, horizon)
        one = simulate_one_particle(ic[0], radius, **steps,
                                    kicks=KickLaw(times, angle="uniform", angles=angles["uniform"]))
        add(system, one.samples, one.n_kicks)
    return rows


def times_rows(panel: Panel, radius: float, ic_index: int, ic: np.ndarray) -> list[tuple]:
    """The rows of the paper's Fig. 4 (`COLUMNS`, system ``"poisson"``) of one IC: the
    least-squares line through the points ``(t_k, s_k)``, the k-th two-disk collision time
    against the k-th Poisson kick time (the main task's kicks, at the IC's own rate), for
    ``k`` up to the shorter sequence; diagnostic ``"fig4_slope"`` its slope and
    ``"fig4_r2"`` its coefficient of determination, ``n_kicks`` the points (NaN below 3)."""
    horizon = panel.n_steps * panel.tau
    two = simulate_two_particle(ic, radius, t_max=horizon)
    kicks, _ = _kicks(panel, radius, ic_index, "poisson", two, horizon)
    actual = np.asarray(two.pp_times, dtype=float)
    k = min(actual.size, kicks.size)
    slope = r2 = np.nan
    if k >= 3:
        slope, intercept = np.polyfit(actual[:k], kicks[:k], 1)
        residual = kicks[:k] - (intercept + slope * actual[:k])
        r2 = 1.0 - residual @ residual / np.sum((kicks[:k] - kicks[:k].mean()) ** 2)
    return [(panel.name, radius, ic_index, "poisson", name, "-", "-", "-", "uniform", 1,
             float(value), int(k)) for name, value in (("fig4_slope", slope), ("fig4_r2", r2))]


def _r1(run, particle) -> float:
    """The paper's lag-1 autocorrelation ``R_1`` of the boundary angles over ``[0, T]``;
    NaN (kept in the rows, dropped from the ratios) for a constant series: an unkicked
    stretch of a one-disk run repeats its angle."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UndefinedDiagnosticWarning)
        return float(autocorrelation(boundary_angles(run, particle=particle), 1))


def compute_task(panel: Panel, task: tuple, path: str | os.PathLike) -> float:
    """Compute one task (see `tasks`) and write its rows to the parquet file ``path``
    (atomically: a reader sees the whole file or none). Returns the seconds it took."""
    start = time.perf_counter()
    kind, radius, a, b = task
    ics = panel.initial_conditions()
    factors = CONVERGENCE[1:] if kind == "convergence" else (1,)
    rows = []
    for i in range(a, b):
        if kind in ("rr", "times"):
            rows.extend((rr_rows if kind == "rr" else times_rows)(panel, radius, i, ics[i]))
            continue
        for f in factors:
            rows.extend(run_rows(panel, kind, radius, i, ics[i], f))
    frame = pd.DataFrame(rows, columns=COLUMNS)
    atomic_write(path, lambda f: frame.to_parquet(f, index=False))
    return time.perf_counter() - start
