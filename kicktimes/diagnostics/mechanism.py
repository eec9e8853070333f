r"""Why the disk-disk collisions cluster, measured on runs (docs/mechanism.md).

Between disk-disk collisions each disk's angular momentum about the table's centre,
:math:`L_i = x_i v_{y,i} - y_i v_{x,i}`, is conserved (a wall reflection keeps it), so
the pair's collision rate is a function :math:`\Gamma(r; L_0, L_1)` that is reset at every
collision: the collision times are a Cox process driven by the post-collision angular
momenta. This module reads runs made with ``log_collisions=True``:

* `collision_table` / `collision_tables`: per collision the time, the angular momenta
  before and after, the impact parameter, the interval since the previous collision and
  the one after it, and the wall hits in between;
* `recollision_share` and `poisson_recollision_share`: how often the same pair meets
  again after at most one wall hit of each disk, and how often events placed at random
  at the same rate would;
* `initial_angular_momenta`, `predicted_rates`: each IC's rate from its initial
  :math:`(L_0, L_1)` through `kicktimes.stats.conditional_kinetic_rate`.

The statistics of the resulting intervals (hazard, rate mixtures, Cox twins) live in
`kicktimes.stats` (`interval_hazard`, `rate_mixture`, `simulate_cox_times`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from kicktimes._results import Result
from kicktimes.stats import percentile_interval, resample_indices
from kicktimes.validation import check_int, check_real, check_rng

__all__ = [
    "RecollisionShare",
    "angular_momentum",
    "collision_table",
    "collision_tables",
    "initial_angular_momenta",
    "poisson_recollision_share",
    "predicted_rates",
    "recollision_share",
]

#: Columns of `collision_table`, in order.
COLLISION_COLUMNS = (
    "time", "interval", "next_interval", "next_censored", "L0_pre", "L1_pre", "L0_post",
    "L1_post", "impact", "impact_ratio", "contact_radius", "wall_hits0", "wall_hits1",
    "speed0_post", "speed1_post",
)


def angular_momentum(x, y, vx, vy):
    """Angular momentum ``x vy - y vx`` about the table's centre (positive counter-clockwise).

    Examples
    --------
    >>> angular_momentum(0.5, 0.0, 0.0, 1.0)
    0.5
    """
    return x * vy - y * vx


def initial_angular_momenta(ics) -> np.ndarray:
    """``(L0, L1)`` of each two-disk initial condition.

    Parameters
    ----------
    ics : array_like, shape (2, 4) or (n, 2, 4)
        Rows ``(x, y, vx, vy)`` of disk 0 and disk 1 (`kicktimes.initial_conditions`).

    Returns
    -------
    ndarray, shape (2,) or (n, 2)

    Examples
    --------
    >>> initial_angular_momenta([[0.5, 0, 0, 1], [0, -0.3, 1, 0]]).tolist()
    [0.5, 0.3]
    """
    ics = np.asarray(ics, float)
    if ics.shape[-2:] != (2, 4) or ics.ndim not in (2, 3):
        raise ValueError(f"ics must have shape (2, 4) or (n, 2, 4), got {ics.shape}")
    return angular_momentum(ics[..., 0], ics[..., 1], ics[..., 2], ics[..., 3])


def _wall_hits(boundary_time, boundary_particle, event_times) -> np.ndarray:
    """Wall hits of each disk in ``(t_{k-1}, t_k]`` for each event ``k`` (``t_{-1} = 0``),
    and after the last event: shape ``(n_events + 1, 2)``."""
    out = np.zeros((event_times.size + 1, 2), int)
    for disk in (0, 1):
        t = boundary_time[boundary_particle == disk]
        slot = np.searchsorted(event_times, t, side="left")
        out[:, disk] = np.bincount(slot, minlength=event_times.size + 1)
    return out


def collision_table(run) -> pd.DataFrame:
    r"""One row per disk-disk collision of a two-disk run: the mechanism's raw material.

    Parameters
    ----------
    run : TwoParticleRun
        A run simulated with ``log_collisions=True``.

    Returns
    -------
    pandas.DataFrame
        Columns (`COLLISION_COLUMNS`):

        * ``time``; ``interval``, the time since the previous collision (NaN for the
          first: it follows the start, not a collision); ``next_interval``, the time to
          the next collision, or to ``t_max`` for the last one, which is then
          ``next_censored``;
        * ``L0_pre, L1_pre, L0_post, L1_post``: each disk's angular momentum
          :math:`x v_y - y v_x` about the table's centre just before and just after;
        * ``impact``: the impact parameter :math:`b = |d \times w| / |w|` of the relative
          motion (``d = x1 - x0`` at contact, ``w = v1 - v0`` before), the distance by
          which the incoming relative line would miss disk 0's centre;
          ``impact_ratio`` :math:`= b / 2r \in [0, 1]` (0 head-on, 1 grazing);
        * ``contact_radius``: distance of the pair's midpoint from the table's centre;
        * ``wall_hits0, wall_hits1``: boundary collisions of each disk since the previous
          disk-disk collision (since time 0 for the first);
        * ``speed0_post, speed1_post``: each disk's speed just after (1 under the mirror
          rule; the elastic rule exchanges the normal components, so the speeds change and
          the rate after a collision depends on them as well as on the angular momenta).

    Notes
    -----
    A wall reflection keeps :math:`L_i`, so ``L*_pre`` of collision ``k`` equals
    ``L*_post`` of collision ``k - 1`` (and the initial value for the first) up to
    rounding. Both rules leave the pair separating after a collision
    (:math:`w' \cdot n = -w \cdot n > 0`), so on straight flights :math:`|d + w' t|` only
    grows: no collision follows another without at least one wall hit in between.

    Examples
    --------
    >>> from kicktimes import initial_conditions, simulate_two_particle
    >>> ic = initial_conditions(1, 0.02, rng=1)[0]
    >>> run = simulate_two_particle(ic, 0.02, t_max=500.0, log_collisions=True)
    >>> tab = collision_table(run)
    >>> len(tab) == run.n_pp, bool(np.allclose(tab["L0_pre"][1:], tab["L0_post"][:-1]))
    (True, True)
    """
    log = run.collisions
    t = np.asarray(run.pp_times, float)
    n = t.size
    c = {name: log[name].to_numpy() for name in log.columns}
    dx, dy = c["x1"] - c["x0"], c["y1"] - c["y0"]
    wx, wy = c["vx1"] - c["vx0"], c["vy1"] - c["vy0"]
    with np.errstate(divide="ignore", invalid="ignore"):
        impact = np.abs(dx * wy - dy * wx) / np.hypot(wx, wy)
    hits = _wall_hits(run.boundary_log.time, run.boundary_log.particle, t)
    follows = np.append(t[1:], run.t_max) - t
    table = pd.DataFrame({
        "time": t,
        "interval": np.concatenate([[math.nan], np.diff(t)])[:n],
        "next_interval": follows,
        "next_censored": np.arange(n) == n - 1,
        "L0_pre": angular_momentum(c["x0"], c["y0"], c["vx0"], c["vy0"]),
        "L1_pre": angular_momentum(c["x1"], c["y1"], c["vx1"], c["vy1"]),
        "L0_post": angular_momentum(c["x0"], c["y0"], c["vx0_post"], c["vy0_post"]),
        "L1_post": angular_momentum(c["x1"], c["y1"], c["vx1_post"], c["vy1_post"]),
        "impact": impact,
        "impact_ratio": impact / (2.0 * run.r),
        "contact_radius": np.hypot(c["x0"] + c["x1"], c["y0"] + c["y1"]) / 2.0,
        "wall_hits0": hits[:n, 0],
        "wall_hits1": hits[:n, 1],
        "speed0_post": np.hypot(c["vx0_post"], c["vy0_post"]),
        "speed1_post": np.hypot(c["vx1_post"], c["vy1_post"]),
    })
    return table


def collision_tables(runs, *, keys=None) -> pd.DataFrame:
    """`collision_table` of every run, stacked, with a ``run`` column (position in ``runs``).

    Parameters
    ----------
    runs : sequence of TwoParticleRun
        Runs made with ``log_collisions=True``.
    keys : pandas.DataFrame, optional
        One row per run (in order) whose columns (e.g. ``radius``, ``ic``, ``method``) are
        copied onto the rows of that run.

    Returns
    -------
    pandas.DataFrame
        ``run``, the columns of ``keys``, then `COLLISION_COLUMNS`. A run without
        collisions adds no row.
    """
    runs = list(runs)
    if keys is not None and len(keys) != len(runs):
        raise ValueError(f"keys must have one row per run ({len(runs)}), got {len(keys)}")
    parts = []
    for i, run in enumerate(runs):
        tab = collision_table(run)
        tab.insert(0, "run", i)
        if keys is not None:
            for j, (name, value) in enumerate(keys.iloc[i].items()):
                tab.insert(1 + j, name, value)
        parts.append(tab)
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(
        columns=["run", *COLLISION_COLUMNS])


@dataclass(frozen=True, repr=False)
class RecollisionShare(Result):
    """Result of `recollision_share`: ``share`` of ``n_collisions`` (those with a previous
    collision) that are re-collisions, its bootstrap interval ``ci_low``, ``ci_high`` at
    ``level``, the counts and the definition (``max_wall_hits``)."""

    _title = "Share of disk-disk collisions that are re-collisions of the same pair"
    _summary_fields = ("share", "level", "n_recollisions", "n_collisions", "n_runs",
                       "max_wall_hits")
    _intervals = {"share": ("ci_low", "ci_high")}

    share: float
    ci_low: float
    ci_high: float
    n_recollisions: int
    n_collisions: int
    n_runs: int
    max_wall_hits: int
    level: float

    @property
    def reason(self) -> str | None:
        """Why ``share`` is NaN (None when it is defined)."""
        if self.n_collisions > 0:
            return None
        return "no disk-disk collision with a previous one to compare (n_collisions = 0)"

    @property
    def definition(self) -> str:
        """The definition in words."""
        return (f"a disk-disk collision with at most {self.max_wall_hits} wall hit(s) of each "
                "disk since the previous disk-disk collision")

    def __repr__(self) -> str:
        return (f"RecollisionShare(share={self.share:.4g}, ci=({self.ci_low:.4g}, "
                f"{self.ci_high:.4g}), n_recollisions={self.n_recollisions}, "
                f"n_collisions={self.n_collisions}, n_runs={self.n_runs}, "
                f"max_wall_hits={self.max_wall_hits})")


def recollision_share(table, *, max_wall_hits=1, level=0.95, n_boot=999,
                      rng=None) -> RecollisionShare:
    r"""Share of disk-disk collisions that are re-collisions of the same pair.

    Parameters
    ----------
    table : pandas.DataFrame
        `collision_table` / `collision_tables` output (columns ``interval``,
        ``wall_hits0``, ``wall_hits1`` and, for several runs, ``run``).
    max_wall_hits : int, optional
        A collision is a re-collision when each disk has hit the wall at most this often
        since the previous disk-disk collision (default 1).
    level : float, optional
        Confidence level.
    n_boot : int, optional
        Bootstrap resamples of runs for the interval.
    rng : Generator or int, optional
        The bootstrap's stream.

    Returns
    -------
    RecollisionShare

    Notes
    -----
    Only collisions with a previous collision count (``interval`` not NaN). Why one wall
    hit: with no wall hit in between a re-collision is impossible (the pair separates
    after a collision and flies straight, `collision_table`), so the smallest return is
    one in which each disk has hit the wall at most once: out to the rim and back, a
    time of order the table's diameter. That is exactly the pattern of the sticky runs,
    whose nearly radial disks meet near the centre every ~1.9 time units. Any longer
    return has let a disk sweep its caustic annulus, which the phase-averaged rate
    :math:`\Gamma(r; L_0, L_1)` already describes.

    The interval resamples whole runs (the collisions of one run are dependent): the
    share of resample :math:`b` is :math:`\sum_{i \in b} k_i / \sum_{i \in b} n_i`;
    percentile interval.

    Examples
    --------
    >>> import pandas as pd
    >>> nan = float("nan")
    >>> tab = pd.DataFrame({"run": [0, 0, 0, 1, 1], "interval": [nan, 2, 30, nan, 2],
    ...                     "wall_hits0": [3, 1, 9, 0, 1], "wall_hits1": [2, 1, 12, 5, 0]})
    >>> res = recollision_share(tab, rng=0)
    >>> res.n_recollisions, res.n_collisions, round(res.share, 3)
    (2, 3, 0.667)
    """
    max_wall_hits = check_int("max_wall_hits", max_wall_hits, low=0)
    level = check_real("level", level, low=0.0, high=1.0)
    n_boot = check_int("n_boot", n_boot, low=1)
    rng = check_rng(rng)
    missing = {"interval", "wall_hits0", "wall_hits1"} - set(table.columns)
    if missing:
        raise ValueError(f"table lacks the columns {sorted(missing)}")
    runs = table["run"].to_numpy() if "run" in table.columns else np.zeros(len(table), int)
    counted = np.isfinite(table["interval"].to_numpy(float))
    again = ((table["wall_hits0"].to_numpy() <= max_wall_hits)
             & (table["wall_hits1"].to_numpy() <= max_wall_hits) & counted)
    ids, inverse = np.unique(runs, return_inverse=True)
    k = np.bincount(inverse, weights=again, minlength=ids.size)
    n = np.bincount(inverse, weights=counted, minlength=ids.size)
    if n.sum() == 0:
        return RecollisionShare(math.nan, math.nan, math.nan, 0, 0, int(ids.size),
                                max_wall_hits, level)
    pick = resample_indices(ids.size, n_boot=n_boot, rng=rng)
    with np.errstate(invalid="ignore"):
        boots = k[pick].sum(axis=1) / n[pick].sum(axis=1)
    low, high = percentile_interval(boots, level=level)
    return RecollisionShare(float(k.sum() / n.sum()), float(low), float(high), int(k.sum()),
                            int(n.sum()), int(ids.size), max_wall_hits, level)


def poisson_recollision_share(runs, *, max_wall_hits=1, n_rep=10, level=0.95, n_boot=999,
                              rng=None) -> RecollisionShare:
    r"""The re-collision share that events at the same rate, placed at random, would have.

    For each run, ``n_rep`` homogeneous Poisson processes at the run's own collision rate
    ``n_pp / t_max`` are laid over its wall hits; every placed event with a previous one
    is scored as in `recollision_share` (at most ``max_wall_hits`` wall hits of each disk
    since the previous placed event).

    Parameters
    ----------
    runs : sequence of TwoParticleRun
        The runs (their boundary logs and collision counts).
    max_wall_hits, level, n_boot
        As in `recollision_share`.
    n_rep : int, optional
        Poisson processes per run.
    rng : Generator or int, optional
        The stream of the placed events and the bootstrap.

    Returns
    -------
    RecollisionShare
        The share under the null, with its interval (bootstrap over runs).

    Notes
    -----
    The null keeps the wall-hit pattern of each run and its rate and removes only the
    coupling between the collisions and the walls. Events placed at rate
    :math:`\Gamma` find a short excursion (about the time :math:`\tau_1` of a wall
    round trip) with probability about :math:`1 - e^{-\Gamma \tau_1}`, which is small
    for small disks; the observed share above it measures the returns.
    """
    n_rep = check_int("n_rep", n_rep, low=1)
    rng = check_rng(rng)
    parts = []
    for i, run in enumerate(runs):
        lam = run.n_pp / run.t_max if run.t_max > 0 else 0.0
        for _ in range(n_rep):
            m = rng.poisson(lam * run.t_max)
            times = np.sort(rng.uniform(0.0, run.t_max, m))
            hits = _wall_hits(run.boundary_log.time, run.boundary_log.particle, times)[:m]
            parts.append(pd.DataFrame({
                "run": i, "interval": np.concatenate([[math.nan], np.diff(times)])[:m],
                "wall_hits0": hits[:, 0], "wall_hits1": hits[:, 1]}))
    table = (pd.concat(parts, ignore_index=True) if parts
             else pd.DataFrame(columns=["run", "interval", "wall_hits0", "wall_hits1"]))
    return recollision_share(table, max_wall_hits=max_wall_hits, level=level, n_boot=n_boot,
                             rng=rng)


def predicted_rates(ics, r, *, rule="mirror") -> np.ndarray:
    r"""Each IC's collision rate predicted from its initial angular momenta.

    Parameters
    ----------
    ics : array_like, shape (2, 4) or (n, 2, 4)
        Two-disk initial conditions.
    r : float
        Disk radius.
    rule : {"mirror", "elastic"}, optional
        Collision rule (passed on; under ``"elastic"`` the rate is conditioned on the
        ICs' speeds as well).

    Returns
    -------
    float or ndarray, shape (n,)
        :math:`\Gamma(r; L_0, L_1)` (`kicktimes.stats.conditional_kinetic_rate`) at the
        ICs' :math:`(L_0, L_1)`.

    Notes
    -----
    The rate holds until the first collision resets the angular momenta; over a run of
    many collisions the observed rate is rather the time average of
    :math:`\Gamma(r; L_0(t), L_1(t))` along the run's own sequence of post-collision
    states (its compensator over ``t_max``).
    """
    # stats (scipy.stats, statsmodels) loads only when a rate is asked for: the sweep's
    # workers import the diagnostics and need none of it
    from kicktimes import stats

    L = initial_angular_momenta(ics)
    if rule != "elastic":
        return stats.conditional_kinetic_rate(r, L[..., 0], L[..., 1], rule=rule)
    speed = np.hypot(np.asarray(ics)[..., 2], np.asarray(ics)[..., 3])
    return stats.conditional_kinetic_rate(r, L[..., 0], L[..., 1], rule=rule,
                                          speed1=speed[..., 0], speed2=speed[..., 1])
