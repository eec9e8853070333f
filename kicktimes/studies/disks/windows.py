r"""docs/results/disks.md: the dispersion of the counts against the window, D(K).

The index of dispersion :math:`D(K) = \operatorname{Var} n_K / \langle n_K\rangle` of one
disk's collision count in a window of K mean intervals grows with K when successive
intervals are positively correlated; for a Poisson process it is 1 at every K. The
dilute tagged disk (`kicktimes.stats.dilute_tagged_disk`, linear Boltzmann) predicts 1
under the mirror rule and a slowly rising curve under the elastic rule (1.13 at K = 15,
1.14 at K = 240): the speed's memory. The gas adds its re-collisions, its structure at
contact and, in the circle, the wall layer; the periodic square box of the same area
(side :math:`\sqrt\pi`, so the same radius gives the same packing ``N r^2``) has no wall,
so the difference between the circle and the box is the wall's.

Each state: ``N`` disks from `kicktimes.initial_state` (circle or box), run for
``skip + windows`` mean intervals (Enskog's), the first ``skip`` left out; every disk's
collisions are counted in consecutive windows of K mean intervals of the run's own
collision frequency, for each K of `DispersionWindows.windows`. D is the variance over the
mean of all counts of one (geometry, rule, boundary, K); its 95 % interval is a percentile
bootstrap over states (the disks of one state share a gas).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from numbers import Integral, Real
from pathlib import Path

import numpy as np
import pandas as pd

from kicktimes.fileio import atomic_write
from kicktimes.stats import (
    dilute_tagged_disk,
    format_interval,
    percentile_interval,
    ratio_interval,
    ratio_verdict,
    resample_counts,
)
from kicktimes.studies.cache import cached_tables

__all__ = ["BOUNDARIES", "DISPERSION_WINDOWS", "RUNS_COLUMNS", "DispersionWindows",
           "dispersion_runs", "one_state", "summarise", "windows_lines",
           "write_dispersion_windows"]

#: where the disks are: the unit circle, or the periodic square box of the same area
BOUNDARIES = ("circle", "box")
#: the columns of the cached runs: one row per (state, K), sums of the counts
RUNS_COLUMNS = ("n_disks", "packing", "rule", "boundary", "state", "window", "n", "s1", "s2",
                "nu")
#: the cache's folder under the study's work folder
CACHE = "dispersion-windows"


def _is_int(value) -> bool:
    return isinstance(value, Integral) and not isinstance(value, bool)


@dataclass(frozen=True)
class DispersionWindows:
    """The sweep's parameters; the defaults made docs/results/disks_dispersion_windows.csv.

    Parameters
    ----------
    n_disks : int
        Disks per state (``>= 2``).
    packings : tuple of float
        ``N r^2`` (each in ``(0, 0.5)``), in the circle and in the box of area π.
    rules : tuple of str
        Of ``"mirror"``, ``"elastic"``.
    boundaries : tuple of str
        Of `BOUNDARIES`.
    windows : tuple of int
        The windows K, in mean intervals (each ``>= 1``).
    states : int
        States per (packing, rule, boundary) (``>= 2``).
    length : float
        Each state's counted time, in mean intervals (``>= max(windows)``).
    skip : float
        Mean intervals left out at the start (``>= 0``).
    seed : int
        Root of the states' seeds.
    """

    n_disks: int = 1000
    packings: tuple = (0.02, 0.2)
    rules: tuple = ("mirror", "elastic")
    boundaries: tuple = BOUNDARIES
    windows: tuple = (15, 30, 60, 120, 240)
    states: int = 8
    length: float = 480.0
    skip: float = 20.0
    seed: int = 5151

    def __post_init__(self):
        for name in ("packings", "rules", "boundaries", "windows"):
            object.__setattr__(self, name, tuple(getattr(self, name)))
        if not _is_int(self.n_disks) or self.n_disks < 2:
            raise ValueError(f"n_disks must be an integer >= 2, got {self.n_disks!r}")
        if not self.packings or not all(isinstance(p, Real) and 0 < p < 0.5
                                        for p in self.packings):
            raise ValueError(f"packings must lie in (0, 0.5), got {self.packings!r}")
        if not self.rules or not set(self.rules) <= {"mirror", "elastic"}:
            raise ValueError(f"rules must be of 'mirror', 'elastic', got {self.rules!r}")
        if not self.boundaries or not set(self.boundaries) <= set(BOUNDARIES):
            raise ValueError(f"boundaries must be of {BOUNDARIES}, got {self.boundaries!r}")
        if not self.windows or not all(_is_int(k) and k >= 1 for k in self.windows):
            raise ValueError(f"windows must be integers >= 1, got {self.windows!r}")
        if not _is_int(self.states) or self.states < 2:
            raise ValueError(f"states must be an integer >= 2, got {self.states!r}")
        if not (isinstance(self.length, Real) and self.length >= max(self.windows)):
            raise ValueError(f"length must be >= the largest window {max(self.windows)}, "
                             f"got {self.length!r}")
        if not (isinstance(self.skip, Real) and self.skip >= 0):
            raise ValueError(f"skip must be >= 0, got {self.skip!r}")

    def groups(self) -> list[dict]:
        """One dict per (packing, rule, boundary): its cached table's parameters."""
        return [{"n_disks": self.n_disks, "packing": float(p), "packing_index": i,
                 "rule": rule, "boundary": b, "windows": [int(k) for k in self.windows],
                 "states": self.states, "length": float(self.length),
                 "skip": float(self.skip), "seed": self.seed}
                for i, p in enumerate(self.packings) for rule in self.rules
                for b in self.boundaries]


#: the published sweep
DISPERSION_WINDOWS = DispersionWindows()


def one_state(n_disks, packing, packing_index, rule, boundary, windows, length, skip, seed,
              state) -> list:
    """The count sums of one state: rows ``(K, n, s1, s2, nu)`` per window K (`RUNS_COLUMNS`
    without the group's keys): ``n`` counts (every disk, every whole window after
    ``skip``), their sum and sum of squares, and the run's collision frequency."""
    from kicktimes.billiard import initial_state, simulate_disks
    from kicktimes.stats import enskog_frequency

    r = math.sqrt(packing / n_disks)
    box = math.sqrt(math.pi) if boundary == "box" else None
    key = (n_disks, packing_index, ("mirror", "elastic").index(rule),
           BOUNDARIES.index(boundary), state)
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=key))
    x = initial_state(n_disks, r, rng=rng, rule=rule, box=box)
    nu_e = enskog_frequency(r, n_disks, rule=rule)
    run = simulate_disks(x, r, t_max=(skip + length) / nu_e, rule=rule, box=box)
    t0 = skip / nu_e
    keep = run.pp_times >= t0
    nu = 2.0 * keep.sum() / (n_disks * (run.t_max - t0))
    times = np.concatenate([run.pp_times[keep], run.pp_times[keep]]) - t0
    disks = np.concatenate([run.pp_i[keep], run.pp_j[keep]])
    out = []
    for k in windows:
        width = k / nu
        m = int((run.t_max - t0) // width)
        if m < 1:
            continue
        inside = times < m * width
        cell = disks[inside] * m + (times[inside] // width).astype(np.int64)
        counts = np.bincount(cell, minlength=n_disks * m).astype(float)
        out.append((int(k), counts.size, counts.sum(), (counts ** 2).sum(), nu))
    return out


def _group_runs(n_disks, packing, packing_index, rule, boundary, windows, states, length,
                skip, seed):
    rows = []
    for s in range(states):
        for k, n, s1, s2, nu in one_state(n_disks, packing, packing_index, rule, boundary,
                                          windows, length, skip, seed, s):
            rows.append((n_disks, packing, rule, boundary, s, k, n, s1, s2, nu))
    return pd.DataFrame(rows, columns=list(RUNS_COLUMNS))


def _jobs(out, sweep):
    folder = Path(out) / CACHE
    return [(folder / f"n{g['n_disks']}-phi{g['packing']:g}-{g['rule']}-{g['boundary']}"
                      ".parquet", g, _group_runs,
             (g["n_disks"], g["packing"], g["packing_index"], g["rule"], g["boundary"],
              tuple(g["windows"]), g["states"], g["length"], g["skip"], g["seed"]))
            for g in sweep.groups()]


def dispersion_runs(out, sweep: DispersionWindows = DISPERSION_WINDOWS, *, workers=1,
                    progress=None) -> pd.DataFrame:
    """Every state's count sums (columns `RUNS_COLUMNS`), from the cache in
    ``out/dispersion-windows`` where its parameters match, else computed and cached."""
    cached = cached_tables(_jobs(out, sweep), workers=workers, progress=progress)
    return pd.concat([c.table for c in cached], ignore_index=True)


def _d(n, s1, s2):
    mean = s1 / n
    return (s2 / n - mean * mean) * n / (n - 1.0) / mean


def summarise(runs, *, n_boot=2000, seed=0, n_events=2_000_000) -> pd.DataFrame:
    """One row per (packing, rule, boundary, K): D with its bootstrap interval over states,
    the dilute tagged disk's prediction (`DiluteTaggedDisk.dispersion` at K, with its
    interval), their ratio (`kicktimes.stats.ratio_interval`) and its `ratio_verdict`
    (10 %, stated before the run)."""
    rng = np.random.default_rng(seed)
    predictions = {}
    rows = []
    for (n_disks, packing, rule, boundary, k), g in runs.groupby(
            ["n_disks", "packing", "rule", "boundary", "window"], sort=False):
        n, s1, s2 = (g[c].to_numpy(float) for c in ("n", "s1", "s2"))
        w = resample_counts(n.size, n_boot=n_boot, rng=rng)
        d = float(_d(n.sum(), s1.sum(), s2.sum()))
        boot = _d(w @ n, w @ s1, w @ s2)
        low, high = percentile_interval(boot)
        if (rule, k) not in predictions:
            est = dilute_tagged_disk(rule).dispersion(window=int(k), n_events=n_events, rng=int(k))
            p = float(est)
            p_low, p_high = ((p, p) if rule == "mirror" else (est.ci_low, est.ci_high))
            predictions[rule, k] = (p, p_low, p_high)
        p, p_low, p_high = predictions[rule, k]
        if rule == "mirror":
            ratio, r_low, r_high = d / p, low / p, high / p
        else:
            ratio, r_low, r_high = ratio_interval(d, low, high, p, p_low, p_high)
        rows.append({"n_disks": int(n_disks), "packing": packing, "rule": rule,
                     "boundary": boundary,
                     "window": int(k), "states": int(g["state"].nunique()),
                     "counts": int(n.sum()), "d": d, "d_low": low, "d_high": high,
                     "prediction": p, "prediction_low": p_low, "prediction_high": p_high,
                     "ratio": ratio, "ratio_low": r_low, "ratio_high": r_high,
                     "verdict": ratio_verdict(r_low, r_high)})
    return pd.DataFrame(rows)


def write_dispersion_windows(out, results_dir, sweep: DispersionWindows = DISPERSION_WINDOWS,
                             *, workers=1, progress=None) -> pd.DataFrame:
    """Compute (or reuse) the sweep in ``out`` and write ``disks_dispersion_windows.csv``
    (`summarise`) into ``results_dir``; returns that table."""
    table = summarise(dispersion_runs(out, sweep, workers=workers, progress=progress))
    path = Path(results_dir) / "disks_dispersion_windows.csv"
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(path, lambda tmp: table.to_csv(tmp, index=False))
    return table


def windows_lines(path) -> list:
    """The section "D against the window, in the circle and in the box" from
    ``disks_dispersion_windows.csv`` (empty when absent): one row per (packing, rule,
    boundary), one column per K, each cell D [CI] and its verdict against the dilute
    prediction; the predictions in a last row per rule."""
    path = Path(path)
    if not path.exists():
        return []
    t = pd.read_csv(path)
    ks = sorted(set(t["window"]))
    n_states = int(t["states"].min())
    head = ["packing, rule, boundary", *(f"K = {k}" for k in ks)]
    lines = [
        "## D against the window, in the circle and in the box", "",
        f"The index of dispersion of every disk's count in windows of K mean intervals, "
        f"N = {int(t['n_disks'].iloc[0])}, "
        f"{n_states} states per row (`kicktimes.studies.disks.windows`; "
        "[disks_dispersion_windows.csv](disks_dispersion_windows.csv)), in the unit circle "
        "and in the periodic square box of the same area (side √π: the same radius, the "
        "same packing, no wall). Each cell: D [95 % CI, bootstrap over states]; its "
        "ratio to the dilute tagged disk's prediction at the same K "
        "(`DiluteTaggedDisk.dispersion`: 1 under the mirror rule; last row) and that "
        "ratio's verdict (`ratio_verdict`, within 10 %, stated before the run, on the "
        "ratio's interval from both intervals).", "",
        "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for (packing, rule, boundary), g in t.groupby(["packing", "rule", "boundary"],
                                                  sort=False):
        g = g.set_index("window")
        cells = [f"{format_interval(g.loc[k, 'd'], g.loc[k, 'd_low'], g.loc[k, 'd_high'])}; "
                 f"{g.loc[k, 'ratio']:.2f}× predicted, {g.loc[k, 'verdict']}"
                 if k in g.index else "—" for k in ks]
        lines.append(f"| {packing:g}, {rule}, {boundary} | " + " | ".join(cells) + " |")
    el = t[t["rule"] == "elastic"].drop_duplicates("window").set_index("window")
    if len(el):
        lines.append("| prediction, elastic | " + " | ".join(
            format_interval(el.loc[k, "prediction"], el.loc[k, "prediction_low"],
                            el.loc[k, "prediction_high"]) if k in el.index else "—"
            for k in ks) + " |")
    return lines + [""]
