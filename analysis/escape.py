"""Escape through a hole: the two-disk system against the kicked and the free disk.

For each radius, the same paper ICs run with one hole in the wall:

* ``two_particle``: the two disks; disk 0's escape is the event, disk 1's first escape
  censors it (competing risks: the run ends at the first escape);
* ``poisson``, ``poisson_scatter``: disk 0 alone, kicked at Poisson times at the kinetic
  rate Γ(r) (the ensemble's collision rate), with uniform new directions (the paper's
  kick) or with scattering kicks;
* ``free``: disk 0 alone, never kicked (the integrable circle).

Writes ``escape_tails.csv`` (per system and radius the Kaplan-Meier survival at a few
times and the exponential and algebraic tail fits beyond ``t_min``) and
``escape_survival.png`` into ``--out``.

The free disk's algebraic tail is also checked against its exact constant: ``--n-free``
unit-speed ICs from the invariant measure per radius give t S(t) at a few times with its
binomial 95 % interval, against Bunimovich & Dettmann's C for the circle of radius 1 - r
(`kicktimes.stats.circle_escape_constant`); written to ``escape_constant.csv``.

Run: python analysis/escape.py [--n-ics 200] [--t-max 3000] [--n-free 40000]
     [--out docs/results/escape]
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np
import pandas as pd

from kicktimes import initial_conditions, schedules, simulate_one_particle, simulate_two_particle
from kicktimes.stats import (
    circle_escape_constant,
    escape_survival,
    fit_escape_tail,
    kinetic_rate,
)

RADII = (0.005, 0.01, 0.02, 0.03)
HOLE = [(0.0, 0.05)]
SYSTEMS = ("two_particle", "poisson", "poisson_scatter", "free")
LABELS = {"two_particle": "two disks (disk 0)", "poisson": "kicked, uniform kicks",
          "poisson_scatter": "kicked, scatter kicks", "free": "free disk (no kicks)"}


def escape_times(r, ics, t_max, seed):
    """Per system the escape time of disk 0 (inf: none by t_max, or disk 1 left first)."""
    rate = float(kinetic_rate(r))
    out = {s: np.full(len(ics), np.inf) for s in SYSTEMS}
    for i, ic in enumerate(ics):
        two = simulate_two_particle(ic, r, t_max=t_max, holes=HOLE)
        if two.escaped == 0:
            out["two_particle"][i] = two.escape_time
        elif two.escaped == 1:
            out["two_particle"][i] = -two.escape_time  # censored by disk 1's escape
        for system, law in (("poisson", "uniform"), ("poisson_scatter", "scatter")):
            run = simulate_one_particle(ic[0], r, t_max=t_max, holes=HOLE, kick_angle=law,
                                        kicks=schedules.Poisson(rate),
                                        rng=np.random.default_rng((seed, i)))
            out[system][i] = run.escape_time
        out["free"][i] = simulate_one_particle(ic[0], r, t_max=t_max, holes=HOLE).escape_time
    return out


def free_disk_constant(r, n, t_max, seed, times=(300.0, 1000.0, 3000.0)):
    """t S(t) of the free disk (unit speed, invariant-measure ICs) against the circle's C."""
    states = initial_conditions(n, r, method="uniform", seed=seed)[:, 0].copy()
    states[:, 2:] /= np.hypot(states[:, 2], states[:, 3])[:, None]
    escapes = np.array([simulate_one_particle(s, r, t_max=t_max, holes=HOLE).escape_time
                        for s in states])
    predicted = circle_escape_constant(HOLE[0][1], radius=1.0 - r)
    rows = []
    for t in times:
        alive = int(np.sum(escapes > t))
        half = 1.96 * t * math.sqrt(alive * (1.0 - alive / n)) / n
        rows.append({"radius": r, "t": t, "n": n, "alive": alive, "t_S": t * alive / n,
                     "t_S_low": t * alive / n - half, "t_S_high": t * alive / n + half,
                     "C_predicted": predicted})
    return rows


def _censor(times, t_max):
    """Escape times and per-run horizons: a negative time is a censoring at |t|."""
    t = np.asarray(times, dtype=float)
    horizon = np.where(t < 0, -t, t_max)
    return np.where(t < 0, np.inf, t), horizon


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n-ics", type=int, default=200)
    ap.add_argument("--t-max", type=float, default=3000.0)
    ap.add_argument("--t-min", type=float, default=50.0, help="where the tail fits start")
    ap.add_argument("--n-free", type=int, default=40000,
                    help="ICs per radius for the free disk's constant C")
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--out", default="docs/results/escape")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    rows, curves = [], {}
    for r in RADII:
        ics = initial_conditions(args.n_ics, max(RADII), seed=args.seed)
        times = escape_times(r, ics, args.t_max, args.seed)
        for system, t in times.items():
            t, horizon = _censor(t, args.t_max)
            km = escape_survival(t, horizon)
            curves[(r, system)] = km
            tail = fit_escape_tail(t, horizon, t_min=args.t_min)
            surv = {f"S({x:g})": float(km.loc[km.time <= x, "survival"].iloc[-1])
                    if (km.time <= x).any() else 1.0 for x in (100.0, 1000.0)}
            rows.append({"radius": r, "system": system, "kinetic_rate": float(kinetic_rate(r)),
                         "n": t.size, "escaped": int(np.isfinite(t).sum()), **surv,
                         "rate": tail.rate, "rate_low": tail.rate_ci[0],
                         "rate_high": tail.rate_ci[1], "alpha": tail.alpha,
                         "alpha_low": tail.alpha_ci[0], "alpha_high": tail.alpha_ci[1],
                         "aic_exp_minus_alg": tail.aic_exponential - tail.aic_algebraic,
                         "best_tail": tail.best})
    table = pd.DataFrame(rows)
    table.to_csv(out / "escape_tails.csv", index=False)
    constant = pd.DataFrame([row for r in RADII for row in free_disk_constant(
        r, args.n_free, max(args.t_max, 3000.0), args.seed)])
    constant.to_csv(out / "escape_constant.csv", index=False)
    print(constant.round(3).to_string())
    figure(curves).savefig(out / "escape_survival.png", dpi=110)
    print(table.round(4).to_string())
    print(f"written to {out} in {time.perf_counter() - t0:.0f} s")


def figure(curves):
    from matplotlib.figure import Figure

    from kicktimes.report.figures import system_style

    styles = {"two_particle": system_style("two_particle"), "poisson": system_style("poisson"),
              "poisson_scatter": system_style("poisson_scatter"),
              "free": {"color": "tab:gray", "marker": "x"}}
    fig = Figure(figsize=(3.2 * len(RADII), 3.6), layout="constrained")
    axes = fig.subplots(1, len(RADII), sharey=True)
    for ax, r in zip(axes, RADII, strict=True):
        for system in SYSTEMS:
            km = curves[(r, system)]
            if km.empty:
                continue
            ax.step(km["time"], km["survival"], where="post", color=styles[system]["color"],
                    label=LABELS[system])
            ax.fill_between(km["time"], km["ci_low"], km["ci_high"], step="post",
                            color=styles[system]["color"], alpha=0.15, linewidth=0)
        tt = np.geomspace(50.0, 3000.0, 20)
        ax.plot(tt, 50.0 / tt * 0.5, color="k", linestyle=":", linewidth=1,
                label="slope of C / t")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(1e-3, 1.05)
        ax.set_xlim(10.0, 3000.0)
        ax.set_title(f"r = {r:g}, Γ(r) = {float(kinetic_rate(r)):.3f}",
                     fontsize="medium")
        ax.set_xlabel("time t")
    axes[0].set_ylabel("survival S(t) (Kaplan-Meier, 95 % CI)")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=len(labels),
               fontsize="small")
    fig.suptitle("Escape through one hole (half-width 0.05 rad): who escapes like the two "
                 "disks?", fontsize="medium")
    return fig


if __name__ == "__main__":
    main()
