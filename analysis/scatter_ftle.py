"""Does a scatter-kicked disk reproduce the two-disk chaos? The FTLE table at family A's radii.

For each radius of family A and each of the first ``--n-ics`` paper ICs (drawn at
r = 0.03, seed 1; 25 000 collision-truncated steps of tau = 0.2; the paper's
``max(lambda_x, lambda_y)``; exact tangent-space exponents):

* ``two``: the two-disk billiard (disk 0 tracked);
* ``uniform``: the paper's kicked disk, Poisson kicks at the two-disk run's own rate
  ``n_pp / t_max``, new direction uniform (state-blind);
* ``scatter``: the same Poisson kick times, scattering kicks (docs/scatter.md), mirror rule,
  weighted partner; ``scatter_unw``: the same numbers with the unweighted uniform partner;
* ``scatter_actual``: scattering kicks at the two-disk run's own collision times;
* ``two_fresh``: the two-disk trajectory, but the tangent vector of the partner disk is
  set to zero just before every disk-disk collision: the two-disk system as the scatter
  model sees it (a partner without deviation). ``two / two_fresh`` measures what the
  correlated re-collisions of the same two disks add.

Also off-diagonal RR, DET (eps = 0.001, Theiler 1) and the ACF curve R_1..R_5 of the
boundary angles, for ``two``, ``uniform`` and ``scatter``.

Writes the per-IC table (``--out``) and the page ``docs/results/scatter.md`` (``--page``):
per radius, ratios of means over ICs with 95 % bootstrap intervals (paired over ICs) and
their `kicktimes.stats.ratio_verdict`, without the sticky two-disk orbits and, as the
control, with them.

Run: python analysis/scatter_ftle.py [--n-ics 40] [--workers 2] [--out analysis/scatter_ftle.csv]
     python analysis/scatter_ftle.py --from-csv analysis/scatter_ftle.csv   (statistics only)
"""

import argparse
import math
import time
import warnings
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pandas as pd
from numba import njit

from kicktimes import initial_conditions, simulate_one_particle, simulate_two_particle
from kicktimes.billiard.kernels import two
from kicktimes.billiard.kernels.tangent import pair_tangent, renormalise, wall_tangent
from kicktimes.diagnostics import autocorrelation_function, boundary_angles, lyapunov, rqa
from kicktimes.experiment.presets import preset
from kicktimes.schedules import Poisson


@njit(cache=True)
def fresh_partner_tangent(st, rho, sigma, n_steps, tau, U):
    """`tangent_two_kernel` (paper sampling, mirror rule) with disk 1's deviation zeroed
    before each disk-disk collision. Returns ``(log_scale, t_end)``."""
    m = U.shape[0]
    ev = np.empty(3)
    two.init_events(st, ev, (rho, rho, 1.0, 1.0), sigma)
    log_scale = np.zeros(m)
    t_prev = 0.0
    for _ in range(n_steps):
        tk = min(t_prev + tau, st[0] + min(ev[0], min(ev[1], ev[2])))
        while True:
            ke, dt = two.next_event(two.load(st, ev))
            if not st[0] + dt <= tk:
                break
            for j in range(m):
                U[j, 0] += U[j, 2] * dt
                U[j, 1] += U[j, 3] * dt
                U[j, 4] += U[j, 6] * dt
                U[j, 5] += U[j, 7] * dt
            v0x, v0y, v1x, v1y = st[3], st[4], st[7], st[8]
            two.process_event(st, ev, ke, (rho, rho, 1.0, 1.0), sigma, 0)
            if ke == 2:
                for j in range(m):
                    for i in range(4, 8):
                        U[j, i] = 0.0
                    (U[j, 0], U[j, 1], U[j, 2], U[j, 3], U[j, 4], U[j, 5], U[j, 6],
                     U[j, 7]) = pair_tangent(U[j, 0], U[j, 1], U[j, 2], U[j, 3], U[j, 4],
                                             U[j, 5], U[j, 6], U[j, 7], st[1], st[2], st[5],
                                             st[6], v0x, v0y, v1x, v1y, st[3], st[4], st[7],
                                             st[8], 0)
                    renormalise(U, log_scale, j)
            else:
                o = 1 + 4 * ke
                vx = v0x if ke == 0 else v1x
                vy = v0y if ke == 0 else v1y
                if vx != st[o + 2] or vy != st[o + 3]:
                    for j in range(m):
                        (U[j, o - 1], U[j, o], U[j, o + 1], U[j, o + 2]) = wall_tangent(
                            U[j, o - 1], U[j, o], U[j, o + 1], U[j, o + 2], st[o], st[o + 1],
                            vx, vy, st[o + 2], st[o + 3], rho)
                        renormalise(U, log_scale, j)
        t_prev = tk
    dt = t_prev - st[0]
    for j in range(m):
        U[j, 0] += U[j, 2] * dt
        U[j, 1] += U[j, 3] * dt
    return log_scale, t_prev


def fresh_lam(ic, r, n_steps, tau):
    st = np.zeros(11)
    st[1:9] = ic.ravel()
    st[10] = (ic[:, 2:] ** 2).sum()
    U = np.zeros((2, 8))
    U[0, 0] = 1.0
    U[1, 1] = 1.0
    log_scale, t_end = fresh_partner_tangent(st, 1.0 - r, 2.0 * r, n_steps, tau, U)
    return max((log_scale[0] + math.log(abs(U[0, 0]))) / t_end,
               (log_scale[1] + math.log(abs(U[1, 1]))) / t_end)


def shape_rows(run, particle):
    res = rqa(run.samples, 1e-3, theiler=1, l_min=2)
    with warnings.catch_warnings():
        # the 20-step warm-up run has too few boundary collisions for an ACF
        warnings.simplefilter("ignore")
        acf = autocorrelation_function(boundary_angles(run, particle), 5)
    return {"rr_offdiag": res.rr, "det": res.det, **{f"acf{k + 1}": acf[k] for k in range(5)}}


def one_ic(args):
    r, i, ic, n_steps, tau = args
    steps = dict(n_steps=n_steps, tau=tau, sampling="paper")
    ftle = dict(variant="paper", **steps)
    two = simulate_two_particle(ic, r, **steps)
    rate = two.n_pp / two.t_max
    rng = np.random.default_rng(np.random.SeedSequence(2026, spawn_key=(i, int(r * 1e6))))
    times = Poisson(rate).sample(n_steps * tau, rng)
    u_angles = rng.uniform(0.0, 2.0 * np.pi, times.size)
    s_numbers = rng.uniform(-1.0, 1.0, (times.size, 2))
    # actual collision times, continued to cover the kicked run (paper steps are longer)
    actual = simulate_two_particle(ic, r, t_max=n_steps * tau).pp_times
    a_numbers = rng.uniform(-1.0, 1.0, (actual.size, 2))
    uni = simulate_one_particle(ic[0], r, kicks=times, kick_angles=u_angles, **steps)
    sca = simulate_one_particle(ic[0], r, kicks=times, kick_angles=s_numbers,
                                kick_angle="scatter", **steps)
    row = {
        "radius": r, "ic": i, "rate": rate,
        "two": lyapunov(two, variant="paper").lam,
        "two_fresh": fresh_lam(ic, r, n_steps, tau),
        "uniform": lyapunov(uni, variant="paper").lam,
        "scatter": lyapunov(sca, variant="paper").lam,
        "scatter_unw": lyapunov(ic[0], r, kicks=times, kick_angles=s_numbers,
                                kick_angle="scatter", partner="uniform", **ftle).lam,
        "scatter_actual": lyapunov(ic[0], r, kicks=actual[actual <= n_steps * tau],
                                   kick_angles=a_numbers[actual <= n_steps * tau],
                                   kick_angle="scatter", **ftle).lam,
        "outside": sca.kick_log.outside.mean() if sca.n_kicks else math.nan,
    }
    for name, run, particle in (("two", two, 0), ("uniform", uni, None), ("scatter", sca, None)):
        for key, value in shape_rows(run, particle).items():
            row[f"{name}_{key}"] = value
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n-ics", type=int, default=40)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default="analysis/scatter_ftle.csv")
    ap.add_argument("--from-csv", help="only summarise a CSV written by an earlier run")
    ap.add_argument("--page", default="docs/results/scatter.md", help="the generated page")
    args = ap.parse_args()
    if args.from_csv:
        df = pd.read_csv(args.from_csv)
        summarise(df)
        write_page(df, args.page, f"python analysis/scatter_ftle.py --from-csv {args.from_csv}")
        return
    fam = preset("family_a")
    ics = initial_conditions(args.n_ics, fam.r_max, seed=fam.seed, method=fam.ic_method)
    jobs = [(r, i, ics[i], fam.n_steps, fam.tau) for r in fam.radii for i in range(args.n_ics)]
    t0 = time.perf_counter()
    # warm the numba caches once before forking the workers
    one_ic((fam.radii[0], 0, ics[0], 20, fam.tau))
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(one_ic, jobs, chunksize=4))
    df = pd.DataFrame(rows)
    df.to_csv(args.out, index=False)
    print(f"{args.n_ics} ICs per radius, {time.perf_counter() - t0:.0f} s")
    summarise(df)
    write_page(df, args.page, f"python analysis/scatter_ftle.py --n-ics {args.n_ics}")


def summarise(df):
    """Print the FTLE table (all ICs, and without sticky two-disk orbits) and RR/DET/ACF."""
    pd.set_option("display.width", 220)
    df = df.assign(sticky=_sticky(df))
    print("sticky ICs (radius, ic, rate, two, scatter):")
    print(df.loc[df.sticky, ["radius", "ic", "rate", "two", "scatter"]].to_string(index=False))
    cols = ["two", "two_fresh", "uniform", "scatter", "scatter_unw", "scatter_actual"]
    for label, part in (("all ICs", df), ("without sticky ICs", df[~df.sticky])):
        g = part.groupby("radius", observed=True)
        tab = g[cols].mean()
        tab["n"] = g.size()
        ratio = part["scatter"] / part["two"]
        tab["scatter/two"] = tab["scatter"] / tab["two"]
        tab["+-"] = np.sqrt(g["scatter"].var() / g.size()) / tab["two"]
        tab["median ratio"] = ratio.groupby(part["radius"], observed=True).median()
        tab["uniform/two"] = tab["uniform"] / tab["two"]
        tab["unw/two"] = tab["scatter_unw"] / tab["two"]
        tab["actual/two"] = tab["scatter_actual"] / tab["two"]
        tab["fresh/two"] = tab["two_fresh"] / tab["two"]
        tab["scatter/fresh"] = tab["scatter"] / tab["two_fresh"]
        tab["outside"] = g["outside"].mean()
        print(f"\nFTLE, mean over ICs ({label}); +- = standard error of scatter / two")
        print(tab.round(4).to_string())
    part = df[~df.sticky]
    names = [f"{n}_{k}" for n in ("two", "uniform", "scatter")
             for k in ("rr_offdiag", "det", "acf1", "acf5")]
    shape = part.groupby("radius", observed=True)[names].mean()
    for name in ("two", "uniform", "scatter"):
        shape[f"{name}_rr_offdiag"] *= 1e4
    print("\nwithout sticky ICs; rr_offdiag (eps = 0.001, Theiler 1) in units of 1e-4")
    print(shape.round(4).to_string())


#: (numerator, denominator, label) of the page's ratios of means
RATIOS = (("scatter", "two", "scatter kicks / two disks"),
          ("uniform", "two", "uniform kicks / two disks"),
          ("scatter_actual", "two", "scatter kicks at the actual times / two disks"),
          ("two_fresh", "two", "partner tangent zeroed / two disks"),
          ("scatter", "two_fresh", "scatter kicks / partner tangent zeroed"))


def _sticky(df):
    """A two-disk orbit is sticky when its exponent is below a quarter of its radius's
    median (a near-periodic head-on orbit with a collision rate ~10x the typical one)."""
    return df["two"] < 0.25 * df.groupby("radius", observed=True)["two"].transform("median")


def ratio_table(df, n_boot=1000, seed=0):
    """Per radius and IC set (without / with the sticky ICs) each ratio of means with a
    95 % bootstrap interval over ICs (paired: the same resampled ICs for both means) and
    its `ratio_verdict`."""
    from generated import MARGIN, ci

    from kicktimes.stats import ratio_verdict

    rng = np.random.default_rng(seed)
    sticky = _sticky(df)
    rows = []
    for ics, part in (("without sticky ICs", df[~sticky]), ("all ICs", df)):
        for r, g in part.groupby("radius", observed=True):
            picks = np.vstack([np.arange(len(g)), rng.integers(0, len(g), (n_boot, len(g)))])
            for num, den, label in RATIOS:
                q = g[num].to_numpy()[picks].mean(1) / g[den].to_numpy()[picks].mean(1)
                lo, hi = ci(q[1:])
                rows.append({"ics": ics, "radius": r, "n": len(g), "ratio": label,
                             "estimate": q[0], "ci_low": lo, "ci_high": hi,
                             "verdict": ratio_verdict(lo, hi, MARGIN)})
    return pd.DataFrame(rows)


def write_page(df, page, command):
    """docs/results/scatter.md and its table ``scatter_ratios.csv``: every number from
    ``df`` (the per-IC CSV) through `ratio_table`."""
    from pathlib import Path

    from generated import header

    from kicktimes.stats import format_interval, ratio_rule

    tab = ratio_table(df)
    page = Path(page)
    tab.to_csv(page.parent / "scatter_ratios.csv", index=False)
    sticky = _sticky(df)
    lines = header("Scatter kicks against the two disks: the FTLE", command,
                   ["the per-IC table `analysis/scatter_ftle.csv` (family A's radii and "
                    f"first {df['ic'].nunique()} ICs; no store)"])
    lines += [f"Definitions and methods: [../scatter.md](../scatter.md). Ratios of means over "
              "ICs with 95 % bootstrap intervals over ICs (`scatter_ratios.csv`); verdicts: "
              f"{ratio_rule(0.1)}. Sticky two-disk orbits (exponent below a quarter of the "
              f"radius's median): {int(sticky.sum())} (radius, IC) runs, left out in the "
              "table; the control with them is in the CSV. The scatter-kick / two-disk "
              "ratio of [science.md](science.md), section 1, is the same quantity (mean FTLE "
              "of the kicked disk over the mean two-disk FTLE, ratio of means over ICs) on "
              "another sample: 100 paper ICs drawn with seed 11 (the FTLE sweep "
              "`stretching_small_r`), its own kick draws, all ICs kept; here the first "
              f"{df['ic'].nunique()} paper ICs drawn with seed 1, sticky orbits left out. At a "
              "radius both pages measure, their intervals differ by the sample and the "
              "sticky orbits, not by the definition.", ""]
    main = tab[tab["ics"] == "without sticky ICs"]
    labels = [label for _, _, label in RATIOS]
    lines += ["| r | " + " | ".join(labels) + " |", "|---|" + "---|" * len(labels)]
    for r, g in main.groupby("radius", observed=True):
        g = g.set_index("ratio")
        lines.append(f"| {r:g} | " + " | ".join(
            f"{format_interval(g.loc[x, 'estimate'], g.loc[x, 'ci_low'], g.loc[x, 'ci_high'])}"
            f", {g.loc[x, 'verdict']}" for x in labels) + " |")
    lines.append("")
    for label in labels:
        both = tab[tab["ratio"] == label]
        counts = main[main["ratio"] == label]["verdict"].value_counts()
        changed = (both.pivot(index="radius", columns="ics", values="verdict")
                   .nunique(axis=1) > 1).sum()
        lines.append(f"- {label}: " + ", ".join(
            f"{v} at {k} radi{'us' if k == 1 else 'i'}"
            for v, k in zip(counts.index, counts.to_numpy(), strict=True))
                     + f" (range {main[main['ratio'] == label]['estimate'].min():.3f}–"
                     f"{main[main['ratio'] == label]['estimate'].max():.3f}); the sticky ICs "
                     f"change the verdict at {changed} of {main['radius'].nunique()} radii.")
    fresh = main[main["ratio"] == labels[3]]["estimate"]
    gap = main[main["ratio"] == labels[0]]["estimate"]
    lines += ["", "**What the zeroed partner tangent measures.** The fourth column runs the "
              "real two-disk trajectory but sets the partner disk's tangent vector to zero "
              "just before every disk-disk collision: the deviation the partner carries into "
              "a collision (built up in its earlier collisions with the tracked disk and its "
              "flights since) is removed at every collision. It measures the exponent carried "
              "by the partner's tangent memory, not the re-collisions (returns within one wall "
              "round trip, [../mechanism.md](../mechanism.md)); zeroing changes the exponent to "
              f"{fresh.min():.3f}–{fresh.max():.3f} of the two-disk value, while the scatter "
              f"kicks reach {gap.min():.3f}–{gap.max():.3f}. The scatter kicks' gap is not "
              "decomposed here.", ""]
    page.write_text("\n".join(lines), encoding="utf-8")
    print(f"{page} written")


if __name__ == "__main__":
    main()
